#!/usr/bin/env python3
"""Peer for bench_recursive: the recursive prediction-error method of the seed's chapter 6 as
an engineer would write it with NumPy and SciPy - the extended system (6.27) of the three-mass
model (3.21) built at the current estimate every sample and sampled with scipy.linalg.expm
(zero-order hold), then Algorithm 6.1 (forgetting factor) or 6.2 (Kalman gain).

Usage: peer_recursive.py DIR   (DIR holds data.csv and setup.json written by bench_recursive)
Prints one JSON line per algorithm: name, seconds (the recursion only, interpreter start-up
and reading excluded; peer_common's clock), samples, theta (final estimate: k_T, J_a^-1,
f_m)."""
import json
import sys

import numpy as np
from scipy.linalg import expm

from peer_common import emit, median_seconds


def three_mass(p):
    """(3.21), x = (r phi_m - phi_g, phi_g - phi_a, phi_m', phi_g', phi_a'), input k_T u."""
    jm, jg, ja, fm, kg, ka, dg, da, r, kt = (p[k] for k in
                                             ("J_m", "J_g", "J_a", "f_m", "k_g", "k_a", "d_g",
                                              "d_a", "r", "k_T"))
    a = np.zeros((5, 5))
    a[0, 2], a[0, 3] = r, -1.0
    a[1, 3], a[1, 4] = 1.0, -1.0
    a[2, 0], a[2, 2], a[2, 3] = -kg * r / jm, -(fm + dg * r * r) / jm, dg * r / jm
    a[3, 0], a[3, 1], a[3, 2] = kg / jg, -ka / jg, dg * r / jg
    a[3, 3], a[3, 4] = -(dg + da) / jg, da / jg
    a[4, 1], a[4, 3], a[4, 4] = ka / ja, da / ja, -da / ja
    b = np.zeros(5)
    b[2] = kt / jm
    return a, b


def derivatives(p):
    """dA/dtheta and dB/dtheta for theta = (k_T, J_a^-1, f_m)."""
    jm, ka, da = p["J_m"], p["k_a"], p["d_a"]
    da_kt, db_kt = np.zeros((5, 5)), np.zeros(5)
    db_kt[2] = 1.0 / jm
    da_ja = np.zeros((5, 5))
    da_ja[4, 1], da_ja[4, 3], da_ja[4, 4] = ka, da, -da
    da_fm = np.zeros((5, 5))
    da_fm[2, 2] = -1.0 / jm
    return [(da_kt, db_kt), (da_ja, np.zeros(5)), (da_fm, np.zeros(5))]


def extended(p, ts):
    """exp of the ZOH-augmented extended matrix (6.27): states z_1..z_3, x, then u."""
    a, b = three_mass(p)
    der = derivatives(p)
    n, q = 5, 3
    size = n * (q + 1) + 1
    m = np.zeros((size, size))
    xs = slice(n * q, n * q + n)
    for j, (daj, dbj) in enumerate(der):
        zs = slice(n * j, n * j + n)
        m[zs, zs] = a
        m[zs, xs] = daj
        m[zs, -1] = dbj
    m[xs, xs] = a
    m[xs, -1] = b
    return expm(m * ts)


def rpem(u, y, ts, nominal, theta0, p0, algorithm, lam, r1, r2):
    p = dict(nominal)
    theta = np.array(theta0, dtype=float)

    def set_theta(th):
        p["k_T"], p["J_a"], p["f_m"] = th[0], 1.0 / th[1], th[2]

    set_theta(theta)
    P = np.diag(p0)
    w = np.zeros(5 * 4 + 1)
    c = np.zeros(5)
    c[2] = 1.0
    e = extended(p, ts)
    for t in range(len(u)):
        x = w[15:20]
        yhat = c @ x
        psi = np.array([c @ w[0:5], c @ w[5:10], c @ w[10:15]])
        eps = y[t] - yhat
        if algorithm == "forgetting":
            pp = P / lam
            k = pp @ psi / (1.0 + psi @ pp @ psi)
            P = pp - np.outer(k, psi @ pp)
        else:
            k = P @ psi / (r2 + psi @ P @ psi)
            P = P - np.outer(k, psi @ P) + np.diag(r1)
        P = 0.5 * (P + P.T)
        theta = theta + k * eps
        set_theta(theta)
        e = extended(p, ts)
        w[-1] = u[t]
        w = e @ w
    return theta


def main():
    folder = sys.argv[1]
    data = np.loadtxt(folder + "/data.csv", delimiter=",", skiprows=1)
    setup = json.load(open(folder + "/setup.json"))
    u, y = data[:, 0], data[:, 1]
    for run in setup["runs"]:
        seconds, theta = median_seconds(1, lambda: rpem(
            u, y, setup["ts"], setup["nominal"], setup["theta0"], run["p0"], run["algorithm"],
            setup["lambda"], setup["r1"], setup["r2"]))
        emit(run["algorithm"], seconds, samples=len(u), theta=[float(v) for v in theta])

if __name__ == "__main__":
    main()

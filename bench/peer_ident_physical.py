#!/usr/bin/env python3
"""Peer of bench_ident_physical: the same output-error problems solved with
scipy.optimize.least_squares from the same data and start.

Usage: peer_ident_physical.py DIR   (DIR holds data.csv, three_mass.csv and start.json)
Prints one JSON line per problem: name, loss (mean squared error), seconds (the
least_squares call only, interpreter start-up excluded; one run, it takes seconds), nfev."""
import json
import sys

import numpy as np
from scipy.linalg import expm
from scipy.optimize import least_squares
from scipy.signal import lfilter

from peer_common import CLOCK


def two_mass(theta, r):
    jm, ja, fm, k, d = theta
    a = np.array([[0.0, r, -1.0],
                  [-r * k / jm, -(fm + r * r * d) / jm, r * d / jm],
                  [k / ja, r * d / ja, -d / ja]])
    b = np.array([0.0, 1.0 / jm, 0.0])
    return a, b


def three_mass(theta, r):
    """(3.21), x = (r phi_m - phi_g, phi_g - phi_a, phi_m', phi_g', phi_a')."""
    jm, jg, ja, fm, kg, ka, dg, da = theta
    a = np.zeros((5, 5))
    a[0, 2], a[0, 3] = r, -1.0
    a[1, 3], a[1, 4] = 1.0, -1.0
    a[2, 0], a[2, 2], a[2, 3] = -kg * r / jm, -(fm + dg * r * r) / jm, dg * r / jm
    a[3, 0], a[3, 1], a[3, 2] = kg / jg, -ka / jg, dg * r / jg
    a[3, 3], a[3, 4] = -(dg + da) / jg, da / jg
    a[4, 1], a[4, 3], a[4, 4] = ka / ja, da / ja, -da / ja
    b = np.zeros(5)
    b[2] = 1.0 / jm
    return a, b


def zoh_simulate(a, b, u, ts, out=1):
    n = a.shape[0]
    m = np.zeros((n + 1, n + 1))
    m[:n, :n] = a
    m[:n, n] = b
    e = expm(m * ts)
    ad, bd = e[:n, :n], e[:n, n]
    x = np.zeros(n)
    y = np.empty_like(u)
    for t, ut in enumerate(u):
        y[t] = x[out]
        x = ad @ x + bd * ut
    return y


def main():
    folder = sys.argv[1]
    data = np.loadtxt(folder + "/data.csv", delimiter=",", skiprows=1)
    start = json.load(open(folder + "/start.json"))
    u_phys, y_phys = data[:, 0], data[:, 1]

    # Two-mass OE with ZOH simulation, log parameters as in FlexArm.
    r, ts = start["r"], start["ts"]

    def res_phys(logp):
        a, b = two_mass(np.exp(logp), r)
        return y_phys - zoh_simulate(a, b, u_phys, ts)

    t0 = CLOCK()
    sol = least_squares(res_phys, np.log(np.array(start["two_mass"])), method="lm",
                        xtol=1e-10, ftol=1e-10)
    sec = CLOCK() - t0
    print(json.dumps({"name": "two-mass", "loss": float(np.mean(sol.fun ** 2)),
                      "seconds": sec, "nfev": int(sol.nfev)}))

    # Three-mass OE with ZOH simulation: logarithms of the positive parameters, the two
    # dampings (d_g < 0 in p6) scaled by their start values, as FlexArm searches them.
    d3 = np.loadtxt(folder + "/three_mass.csv", delimiter=",", skiprows=1)
    u3, y3 = d3[:, 0], d3[:, 1]
    s3 = np.array(start["three_mass"])
    r3, ts3 = start["r3"], start["ts3"]

    def theta3(p):
        return np.r_[np.exp(p[:6]), p[6:] * s3[6:]]

    def res_three(p):
        a, b = three_mass(theta3(p), r3)
        return y3 - zoh_simulate(a, b, u3, ts3, out=2)

    t0 = CLOCK()
    sol = least_squares(res_three, np.r_[np.log(s3[:6]), 1.0, 1.0], method="lm",
                        xtol=1e-10, ftol=1e-10)
    sec = CLOCK() - t0
    print(json.dumps({"name": "three-mass", "loss": float(np.mean(sol.fun ** 2)),
                      "seconds": sec, "nfev": int(sol.nfev)}))


if __name__ == "__main__":
    main()

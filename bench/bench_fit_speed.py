#!/usr/bin/env python3
"""Peer for bench_fit_speed: the output-error fit of the two-mass model (3.13) an engineer
would write with SciPy, as a whole process on a FlexArm CSV log: read the log, motor velocity
from the angle by central differences, means removed, scipy.optimize.least_squares on the
ZOH-sampled model simulated from zero state, started from the nominal values of Table 5.2
(the start `flexarm fit --model two-mass` uses).

Usage: bench_fit_speed.py LOG
Prints one JSON line: the estimated parameters, loss (mean squared output error of the motor
velocity) and nfev."""
import json
import sys

import numpy as np
from scipy.linalg import expm
from scipy.optimize import least_squares

NAMES = ["J_m", "J_a", "f_m", "k_a", "d_a"]
NOMINAL = [9e-4, 12.0, 0.1, 1.5e5, 70.0]  # Table 5.2
R = 1.0 / 118.0                            # gear ratio (fixed)


def read_log(path):
    meta, rows, header = {}, [], None
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                key, _, value = line[1:].partition(":")
                meta[key.strip()] = value.strip()
            elif header is None:
                header = line.strip().split(",")
            else:
                rows.append([float(x) for x in line.split(",")])
    data = np.array(rows)
    return {name: data[:, i] for i, name in enumerate(header)}, meta


def two_mass(theta):
    """(3.13) with x = (r phi_m - phi_a, phi_m', phi_a'), output phi_m'."""
    jm, ja, fm, k, d = theta
    a = np.array([[0.0, R, -1.0],
                  [-R * k / jm, -(fm + R * R * d) / jm, R * d / jm],
                  [k / ja, R * d / ja, -d / ja]])
    b = np.array([0.0, 1.0 / jm, 0.0])
    return a, b


def simulate(theta, u, ts):
    a, b = two_mass(theta)
    m = np.zeros((4, 4))
    m[:3, :3] = a
    m[:3, 3] = b
    e = expm(m * ts)
    ad, bd = e[:3, :3], e[:3, 3]
    x = np.zeros(3)
    y = np.empty_like(u)
    for t, ut in enumerate(u):
        y[t] = x[1]
        x = ad @ x + bd * ut
    return y


def main():
    cols, meta = read_log(sys.argv[1])
    ts = cols["time_s"][1] - cols["time_s"][0]
    u = cols["torque_ref_nm"]
    y = np.gradient(cols["motor_angle_rad"], ts)
    u = u - u.mean()
    y = y - y.mean()

    def residuals(logp):
        return y - simulate(np.exp(logp), u, ts)

    sol = least_squares(residuals, np.log(NOMINAL), method="lm", xtol=1e-10, ftol=1e-10)
    print(json.dumps({"parameters": dict(zip(NAMES, np.exp(sol.x).tolist())),
                      "loss": float(np.mean(sol.fun ** 2)), "nfev": int(sol.nfev)}))


if __name__ == "__main__":
    main()

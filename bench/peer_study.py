"""Peer of bench_study: two-mass output-error fits from given starts with
scipy.optimize.least_squares ('lm'), as peer_ident_physical does one, in a multiprocessing
pool.

Usage: peer_study.py DIR   (DIR holds data.csv and starts.json: starts, r, ts, processes)
Prints one JSON line: name "study", seconds (all fits, wall time), losses (per start)."""
import json
import sys
import time
from multiprocessing import Pool

import numpy as np
from scipy.optimize import least_squares

from peer_common import emit
from peer_ident_physical import two_mass, zoh_simulate

DATA = {}


def fit(start):
    u, y, r, ts = DATA["u"], DATA["y"], DATA["r"], DATA["ts"]

    def residuals(logp):
        a, b = two_mass(np.exp(logp), r)
        return y - zoh_simulate(a, b, u, ts)

    try:
        sol = least_squares(residuals, np.log(np.asarray(start)), method="lm",
                            xtol=1e-10, ftol=1e-10)
        return float(np.mean(sol.fun ** 2))
    except (ValueError, np.linalg.LinAlgError, FloatingPointError):
        return float("inf")


def main():
    folder = sys.argv[1]
    data = np.loadtxt(folder + "/data.csv", delimiter=",", skiprows=1)
    with open(folder + "/starts.json", encoding="ascii") as f:
        spec = json.load(f)
    DATA.update(u=data[:, 0], y=data[:, 1], r=spec["r"], ts=spec["ts"])
    with Pool(spec["processes"]) as pool:
        t0 = time.perf_counter()
        losses = pool.map(fit, spec["starts"], chunksize=1)
        sec = time.perf_counter() - t0
    emit("study", sec, losses=[l if np.isfinite(l) else 1e300 for l in losses])


if __name__ == "__main__":
    main()

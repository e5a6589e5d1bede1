"""Peer of bench_ident_poly: the black-box problems as a NumPy/SciPy user solves them.

Usage: peer_ident_poly.py REPEATS ARX_JSON PROBLEM_JSON...
Each JSON holds structure, orders [na nb nc nd nf nk], start (parameter vector
[a b c d f]), u and y. ARX: regressors and numpy.linalg.lstsq. The others: the prediction
errors (4.5) eps = D/C (A y - B/F u) by scipy.signal.lfilter, the first max(orders) samples
left out as FlexArm does, minimized by scipy.optimize.least_squares (method 'lm') from the
start. Prints one JSON line per problem: name, seconds (median), loss (mean squared error
over the samples used), theta, nfev."""
import json
import os
import sys

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import lfilter

from peer_common import emit, median_seconds


def split(theta, orders):
    na, nb, nc, nd, nf, nk = orders
    i = 0
    parts = []
    for count in (na, nb, nc, nd, nf):
        parts.append(theta[i:i + count])
        i += count
    a, b, c, d, f = parts
    return (np.r_[1.0, a], np.r_[np.zeros(nk), b], np.r_[1.0, c], np.r_[1.0, d], np.r_[1.0, f])


def first_used(orders):
    na, nb, nc, nd, nf, nk = orders
    return max(na, nb + nk - 1, nc, nd, nf)


def arx(u, y, na, nb, nk):
    n = len(y)
    first = max(na, nb + nk - 1)
    cols = [-y[first - k:n - k] for k in range(1, na + 1)]
    cols += [u[first - k:n - k] for k in range(nk, nk + nb)]
    phi = np.column_stack(cols)
    theta = np.linalg.lstsq(phi, y[first:], rcond=None)[0]
    res = y[first:] - phi @ theta
    return theta, float(res @ res) / len(res)


def pem(problem):
    orders = problem["orders"]
    u, y = np.asarray(problem["u"]), np.asarray(problem["y"])
    n0 = first_used(orders)

    def residuals(theta):
        a, b, c, d, f = split(theta, orders)
        v = (lfilter(a, [1.0], y) if len(a) > 1 else y) - lfilter(b, f, u)
        eps = lfilter(d, c, v) if len(c) > 1 or len(d) > 1 else v
        return eps[n0:]

    sol = least_squares(residuals, np.asarray(problem["start"]), method="lm",
                        xtol=1e-12, ftol=1e-12)
    return sol, float(np.mean(sol.fun ** 2))


def main():
    repeats = int(sys.argv[1])
    with open(sys.argv[2], encoding="ascii") as f:
        p = json.load(f)
    u, y = np.asarray(p["u"]), np.asarray(p["y"])
    na, nb, _, _, _, nk = p["orders"]
    sec, (theta, loss) = median_seconds(4 * repeats, lambda: arx(u, y, na, nb, nk))
    emit("arx", sec, loss=loss, theta=theta.tolist())
    for path in sys.argv[3:]:
        with open(path, encoding="ascii") as f:
            p = json.load(f)
        name = os.path.splitext(os.path.basename(path))[0]
        reps = repeats if len(p["y"]) <= 16000 else min(repeats, 3)
        sec, (sol, loss) = median_seconds(reps, lambda: pem(p))
        emit(name, sec, loss=loss, theta=sol.x.tolist(), nfev=int(sol.nfev))


main()

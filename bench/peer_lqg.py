"""Peer of bench_lqg: one LQG slider move in SciPy.

Redesign with scipy.linalg.solve_continuous_are (LQR of the four-state arm, Kalman filter of
the model with the arm-load state x5), frequency responses of F_y G and G_0 on the grid
that FlexArm used, |S| and |T|, and the closed-loop disturbance steps (Figure 8.3) by a
zero-order-hold discretization, as FlexArm does. Prints one JSON line: name "lqg", seconds
(median), max_s and peak_arm of case (ii) (R2 = 1e-8), regulator_rhp_poles.
Usage: peer_lqg.py GRID_FILE REPETITIONS
"""
import sys

import numpy as np
from scipy.linalg import expm, solve_continuous_are

from peer_common import CLOCK, emit

Jm, Ja, fm, fa, k, d = 0.0043, 0.0762, 0.02, 0.005, 43.0, 0.05
A = np.array([[0, 1, 0, 0],
              [-k / Jm, -(d + fm) / Jm, k / Jm, d / Jm],
              [0, 0, 0, 1],
              [k / Ja, d / Ja, -k / Ja, -(d + fa) / Ja]])
B = np.array([[0], [1 / Jm], [0], [0]])
Bv = np.array([[0], [0], [0], [1 / Ja]])
C = np.array([[1.0, 0, 0, 0]])
Ab = np.block([[A, Bv], [np.zeros((1, 5))]])
Bb = np.vstack([B, [[0]]])
Cb = np.hstack([C, [[0]]])


def response(Am, Bm, Cm, s):
    """C (sI - A)^-1 B at each s (one batched solve)."""
    n = Am.shape[0]
    M = s[:, None, None] * np.eye(n)[None] - Am[None]
    X = np.linalg.solve(M, np.broadcast_to(Bm, (len(s),) + Bm.shape))
    return (Cm[None] @ X)[:, 0, 0]


def slider_move(r2, s):
    X = solve_continuous_are(A, B, np.diag([100.0, 1, 0, 0]), np.eye(1))
    L = B.T @ X
    X12 = np.linalg.solve((A - B @ L).T, -X @ Bv)
    Lb = np.hstack([L, B.T @ X12])
    P = solve_continuous_are(Ab.T, Cb.T, np.diag([0.0, 0, 0, 0, 1]), np.array([[r2]]))
    K = P @ Cb.T / r2
    Ar = Ab - Bb @ Lb - K @ Cb
    poles = [np.linalg.eigvals(M) for M in (A, Ar)]
    loop = response(Ar, K, Lb, s) * response(A, B, C, s)
    g0 = response(Ab, Bb, Lb, s)
    S = 1 / np.abs(1 + loop)
    T = np.abs(loop) * S
    Acl = np.block([[A, -B @ Lb], [K @ C, Ar]])
    poles.append(np.linalg.eigvals(Acl))
    Bcl = np.vstack([np.hstack([B, Bv]), np.zeros((5, 2))])
    h = 1e-3
    M = np.zeros((11, 11))
    M[:9, :9] = Acl * h
    M[:9, 9:] = Bcl * h
    E = expm(M)
    Phi, Gam = E[:9, :9], E[:9, 9:]
    x = np.zeros(9)
    arm = np.empty(3001)
    for i in range(3001):
        t = i * h
        arm[i] = x[2]
        x = Phi @ x + Gam @ np.array([1.0, 1.0 if t >= 1 - 1e-12 else 0.0])
    return S.max(), T.max(), np.abs(arm).max(), poles, g0


def main():
    grid = np.loadtxt(sys.argv[1])
    reps = int(sys.argv[2])
    s = 1j * grid
    times = []
    for i in range(reps):
        r2 = 10.0 ** (-8.0 + 2.0 * (i % 20) / 19.0)
        t0 = CLOCK()
        slider_move(r2, s)
        times.append(CLOCK() - t0)
    ms, _, peak, poles, _ = slider_move(1e-8, s)
    emit("lqg", float(np.median(times)), max_s=float(ms), peak_arm=float(peak),
         regulator_rhp_poles=int((poles[1].real > 1e-9 * np.abs(poles[1]).max()).sum()))


main()

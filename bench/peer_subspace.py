"""Peer of bench_subspace: N4SID as a NumPy/SciPy user writes it from Van Overschee and De Moor
(1996), the combined algorithm through the state sequences, independent of FlexArm's route.

Usage: peer_subspace.py REPEATS PROBLEM_JSON...
Each JSON holds u, y, the order n and the block rows i. Block Hankel matrices of 2i rows; the
oblique projections O_i = Y_f /_{U_f} W_p and O_{i-1} = Y_f^- /_{U_f^-} W_p^+; the SVD of O_i
gives Gamma_i; the states X_i = Gamma_i^+ O_i and X_{i+1} = Gamma_{i-1}^+ O_{i-1}; A, B, C
(D = 0) by least squares on [X_{i+1}; Y_i|i] = [A B; C 0] [X_i; U_i|i]; the residuals' covariances
Q, S, R and the Kalman gain K from the Riccati equation (scipy.linalg.solve_discrete_are).
Prints one JSON line per problem: name, seconds (median), the resonances (rad/s of the complex
poles), the one-step prediction loss over samples i.. and the singular values."""
import json
import sys

import numpy as np
from scipy.linalg import solve_discrete_are

from peer_common import emit, median_seconds


def hankel(x, rows, cols):
    return np.stack([x[k:k + cols] for k in range(rows)])


def perp(A, B):
    """A projected onto the orthogonal complement of the row space of B."""
    return A - (A @ B.T) @ np.linalg.pinv(B @ B.T) @ B


def oblique(Yf, Uf, Wp):
    """Yf /_{Uf} Wp: the part of Yf along Wp's row space, projected along Uf."""
    return perp(Yf, Uf) @ np.linalg.pinv(perp(Wp, Uf)) @ Wp


def n4sid(u, y, n, i):
    N = len(y)
    j = N - 2 * i
    U, Y = hankel(u, 2 * i + 1, j), hankel(y, 2 * i + 1, j)
    Up, Uf, Yp, Yf = U[:i], U[i:2 * i], Y[:i], Y[i:2 * i]
    Wp = np.vstack([Up, Yp])
    Oi = oblique(Yf, Uf, Wp)
    # Shifted: the past one block longer, the future one shorter.
    Wp1 = np.vstack([U[:i + 1], Y[:i + 1]])
    Oi1 = oblique(Y[i + 1:2 * i], U[i + 1:2 * i], Wp1)
    Us, s, _ = np.linalg.svd(Oi, full_matrices=False)
    G = Us[:, :n] * np.sqrt(s[:n])
    Xi = np.linalg.pinv(G) @ Oi
    Xi1 = np.linalg.pinv(G[:-1]) @ Oi1
    Uii, Yii = U[i:i + 1], Y[i:i + 1]
    theta = Xi1 @ np.linalg.pinv(np.vstack([Xi, Uii]))
    A, B = theta[:, :n], theta[:, n:]
    C = Yii @ np.linalg.pinv(Xi)  # D = 0
    res = np.vstack([Xi1 - A @ Xi - B @ Uii, Yii - C @ Xi])
    cov = res @ res.T / j
    Q, S, R = cov[:n, :n], cov[:n, n:], cov[n:, n:]
    P = solve_discrete_are(A.T, C.T, Q, R, s=S)
    K = (A @ P @ C.T + S) @ np.linalg.inv(C @ P @ C.T + R)
    return A, B.ravel(), C.ravel(), K.ravel(), s


def loss(A, B, C, K, u, y, skip):
    x = np.zeros(A.shape[0])
    At = A - np.outer(K, C)
    e = np.empty(len(y))
    for t in range(len(y)):
        e[t] = y[t] - C @ x
        x = At @ x + B * u[t] + K * y[t]
    return float(np.mean(e[skip:] ** 2))


def resonances(A, T):
    z = np.linalg.eigvals(A)
    w = [abs(np.log(p) / T) for p in z if p.imag > 1e-9]
    return sorted(w)


def main():
    repeats = int(sys.argv[1])
    for path in sys.argv[2:]:
        with open(path) as f:
            p = json.load(f)
        u, y = np.asarray(p["u"]), np.asarray(p["y"])
        seconds, (A, B, C, K, s) = median_seconds(repeats, lambda: n4sid(u, y, p["order"], p["horizon"]))
        emit(p["name"], seconds, resonances=resonances(A, p["sample_time"]),
             loss=loss(A, B, C, K, u, y, p["horizon"]), singular_values=[float(v) for v in s[:12]])


if __name__ == "__main__":
    main()

"""Peer of bench_nonparametric: ETFE (4.24)-(4.25) and SPA (4.28) written with NumPy.

Usage: peer_nonparametric.py UY_F64 N REPEATS   (u then y, float64)
Prints one JSON line per estimate: name (etfe, spa), seconds (median), magnitude (|G|)."""
import sys

import numpy as np

from peer_common import emit, median_seconds

TS = 0.005


def etfe(u, y, width=16):
    U, Y = np.fft.rfft(u), np.fft.rfft(y)
    x = np.arange(-width + 1, width) / width
    a = 0.5 * (1.0 + np.cos(np.pi * x))  # Hann over frequency, |x| < 1
    num = np.convolve(Y * np.conj(U), a, mode="same")
    den = np.convolve(np.abs(U) ** 2, a, mode="same")
    return (num / den)[1:len(u) // 2 + 1]


def spa(u, y, m=30, count=128):
    n = len(u)
    taus = np.arange(0, m + 1)
    ru = np.array([u[t:] @ u[:n - t] for t in taus]) / n
    ry = np.array([y[t:] @ y[:n - t] for t in taus]) / n
    ryu_pos = np.array([y[t:] @ u[:n - t] for t in taus]) / n
    ryu_neg = np.array([y[:n - t] @ u[t:] for t in taus]) / n
    win = 0.5 * (1.0 + np.cos(np.pi * taus / m))
    omega = np.pi / TS * np.arange(1, count + 1) / count
    wt = np.outer(omega * TS, taus)
    c, s = np.cos(wt), np.sin(wt)
    w2 = 2.0 * win
    w2[0] = 1.0
    phi_u = c @ (w2 * ru)
    # sum_tau w (R_yu(tau) e^{-i w tau} + R_yu(-tau) e^{i w tau}), tau 0 counted once
    wp = win.copy()
    wp[0] = 0.5
    phi_yu = (c @ (wp * (ryu_pos + ryu_neg))) + 1j * (s @ (wp * (ryu_neg - ryu_pos)))
    return phi_yu / phi_u


def main():
    n, repeats = int(sys.argv[2]), int(sys.argv[3])
    data = np.fromfile(sys.argv[1], dtype=np.float64)
    u, y = data[:n], data[n:]
    for name, work in (("etfe", lambda: etfe(u, y)), ("spa", lambda: spa(u, y))):
        sec, g = median_seconds(repeats, work)
        emit(name, sec, magnitude=np.abs(g).tolist())


main()

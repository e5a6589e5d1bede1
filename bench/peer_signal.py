"""Peer of bench_signal: NumPy/SciPy on the same raw channels (float64, one after another).

Usage: peer_signal.py gradient IN OUT REPEATS N
         numpy.gradient (second order inside and at the ends) of the second channel
       peer_signal.py decimate IN OUT REPEATS N FACTOR
         scipy.signal.decimate(ftype="fir", zero_phase=True) of each channel; the taps of
         the filter it uses (firwin(20 FACTOR + 1, 1 / FACTOR, hamming)) go to OUT.taps
       peer_signal.py resample IN OUT REPEATS N UP DOWN
         scipy.signal.resample_poly(up, down) of each channel
Writes the result to OUT (raw float64) and prints {"name", "seconds"}."""
import sys

import numpy as np
from scipy import signal

from peer_common import emit, median_seconds


def main():
    mode, src, dst, repeats, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
    x = np.fromfile(src, dtype=np.float64).reshape(-1, n)
    if mode == "gradient":
        angle = x[1]
        sec, out = median_seconds(repeats, lambda: np.gradient(angle, 0.0005, edge_order=2))
    elif mode == "resample":
        up, down = int(sys.argv[6]), int(sys.argv[7])
        sec, out = median_seconds(repeats, lambda: np.concatenate(
            [signal.resample_poly(c, up, down) for c in x]))
    else:
        q = int(sys.argv[6])
        sec, out = median_seconds(repeats, lambda: np.concatenate(
            [signal.decimate(c, q, ftype="fir", zero_phase=True) for c in x]))
        # The filter scipy.signal.decimate designs for ftype="fir" (its source: n = 20 q).
        signal.firwin(20 * q + 1, 1.0 / q, window="hamming").tofile(dst + ".taps")
    np.asarray(out, dtype=np.float64).tofile(dst)
    emit(mode, sec)


main()

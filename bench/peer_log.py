"""Peer for bench_log: reads the same FlexArm CSV log with NumPy and decimates every channel
by the same factor with SciPy (FIR, zero phase). Prints one line: read_s decimate_s samples."""
import sys
import time

import numpy as np
from scipy import signal

path, factor = sys.argv[1], int(sys.argv[2])
t0 = time.perf_counter()
# np.loadtxt cannot skip the named header after comments, so hand it the lines after it.
with open(path, "r", encoding="ascii") as f:
    lines = [ln for ln in f if not ln.startswith("#")]
data = np.loadtxt(lines[1:], delimiter=",")
t1 = time.perf_counter()
out = [signal.decimate(data[:, c], factor, ftype="fir", zero_phase=True) for c in range(1, data.shape[1])]
t2 = time.perf_counter()
print(f"{t1 - t0:.6f} {t2 - t1:.6f} {len(out[0])}")

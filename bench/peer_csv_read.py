"""Peer for bench_csv_read: reads the same FlexArm CSV log with pandas.read_csv (median of
REPEATS) and once with numpy.loadtxt. Prints: pandas_s numpy_s sum1 sum2 sum3 (the sums of the
three channel columns, to check that both sides read the same values)."""
import statistics
import sys
import time

import numpy as np
import pandas as pd

path, repeats = sys.argv[1], int(sys.argv[2])
times = []
for _ in range(repeats):
    t0 = time.perf_counter()
    frame = pd.read_csv(path, comment="#")
    times.append(time.perf_counter() - t0)
t0 = time.perf_counter()
with open(path, "r", encoding="ascii") as f:
    lines = [ln for ln in f if not ln.startswith("#")]
data = np.loadtxt(lines[1:], delimiter=",")
numpy_s = time.perf_counter() - t0
sums = [float(frame.iloc[:, c].sum()) for c in range(1, 4)]
print(f"{statistics.median(times):.6f} {numpy_s:.6f} {sums[0]!r} {sums[1]!r} {sums[2]!r}")

"""Peer for bench_resample: the same channels (raw float64, channel after channel) decimated
and resampled with SciPy, as an engineer would do it instead:
  decimate10    scipy.signal.decimate(x, 10, ftype="fir", zero_phase=True)
  resample_3_4  scipy.signal.resample_poly(x, 3, 4)          (2000 -> 1500 Hz)
  resample_2_1  scipy.signal.resample_poly(x, 2, 1)          (1000 -> 2000 Hz)
Usage: peer_resample.py DATA CHANNELS SAMPLES OUTDIR REPEATS
Prints one line per task: "task median_wall_seconds median_processor_seconds"; writes each task's outputs to
OUTDIR/task.f64 (raw float64, channel after channel) for the agreement check."""
import os
import sys
import time

import numpy as np
from scipy import signal

path, channels, samples, outdir, repeats = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], int(sys.argv[5])
data = np.fromfile(path, dtype="<f8").reshape(channels, samples)

tasks = {
    "decimate10": lambda x: signal.decimate(x, 10, ftype="fir", zero_phase=True),
    "resample_3_4": lambda x: signal.resample_poly(x, 3, 4),
    "resample_2_1": lambda x: signal.resample_poly(x, 2, 1),
}
for name, fn in tasks.items():
    times, cpu = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = [fn(data[c]) for c in range(channels)]
        cpu.append(time.process_time() - c0)
        times.append(time.perf_counter() - t0)
    np.concatenate(out).astype("<f8").tofile(os.path.join(outdir, name + ".f64"))
    print(f"{name} {float(np.median(times)):.6f} {float(np.median(cpu)):.6f}", flush=True)

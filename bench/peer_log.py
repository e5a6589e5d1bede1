"""Peer of bench_log: reads the same FlexArm CSV logs with pandas.read_csv, writes the last
as a MATLAB .mat file (scipy.io.savemat) and reads it back with scipy.io.loadmat.

Usage: peer_log.py REPEATS MAT_PATH CSV...
Prints one JSON line per file: name (csv0, csv1, ..., mat), seconds (median), samples and
the sums of squares of torque_ref_nm, motor_angle_rad, angle_ref_rad."""
import sys

import numpy as np
import pandas as pd
import scipy.io

from peer_common import emit, median_seconds

COLUMNS = ("torque_ref_nm", "motor_angle_rad", "angle_ref_rad")


def main():
    repeats, mat_path, files = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
    frame = None
    for i, path in enumerate(files):
        # comment="#" skips the metadata lines; the header follows them. As many repeats
        # as FlexArm's side (bench_log.cpp).
        sec, frame = median_seconds(repeats, lambda: pd.read_csv(path, comment="#"))
        emit(f"csv{i}", sec, samples=len(frame),
             sums=[float((frame[c] ** 2).sum()) for c in COLUMNS])
    scipy.io.savemat(mat_path, {c: frame[c].to_numpy() for c in ("time_s",) + COLUMNS},
                     oned_as="column")
    sec, mat = median_seconds(repeats, lambda: scipy.io.loadmat(mat_path))
    emit("mat", sec, samples=int(mat["time_s"].size),
         sums=[float(np.sum(mat[c] ** 2)) for c in COLUMNS])


main()

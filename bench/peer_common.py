"""What the Python peers share: median timing and one JSON line per result on stdout.

A peer prints {"name": ..., "seconds": ..., free fields} per problem; the bench program that
started it turns these into result rows (bench/README.md)."""
import json
import os
import sys
import time

# FLEXARM_BENCH_CLOCK=cpu: the process's CPU time instead of the wall clock, as the bench
# programs do (bench_common.h).
CLOCK = time.process_time if os.environ.get("FLEXARM_BENCH_CLOCK") == "cpu" else time.perf_counter


def median_seconds(repeats, work):
    """Median time of `repeats` calls of work(); returns (seconds, last result)."""
    times, result = [], None
    for _ in range(max(1, repeats)):
        t0 = CLOCK()
        result = work()
        times.append(CLOCK() - t0)
    times.sort()
    return times[len(times) // 2], result


def emit(name, seconds, **fields):
    fields.update(name=name, seconds=seconds)
    print(json.dumps(fields), flush=True)


def note(text):
    print(text, file=sys.stderr, flush=True)

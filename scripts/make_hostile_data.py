#!/usr/bin/env python3
"""Writes the hostile inputs of tests/data/hostile (README.md there lists them).

    python3 scripts/make_hostile_data.py --small DIR   the small files kept in the repository
    python3 scripts/make_hostile_data.py --big DIR [NAME...]
                                                      the large ones (or only those named),
                                                      made at test time

Each file is wrong in one way an attacker (or an unlucky user) would try: sizes that claim
far more than the file holds, lines or headers of millions of fields, sessions that point at
devices or repeat one item thousands of times, text in UTF-16 or with a byte-order mark.
"""
import json
import os
import struct
import sys
import zlib

MAT_HEADER_TEXT = b"MATLAB 5.0 MAT-file, FlexArm hostile test data"


def mat5_header():
    text = MAT_HEADER_TEXT.ljust(116, b" ")
    return text + b"\0" * 8 + struct.pack("<H", 0x0100) + b"IM"


def tag(mi_type, nbytes):
    return struct.pack("<II", mi_type, nbytes)


def small_tag(mi_type, data):
    assert len(data) <= 4
    return struct.pack("<I", mi_type | (len(data) << 16)) + data.ljust(4, b"\0")


def pad8(b):
    return b + b"\0" * (-len(b) % 8)


def matrix(name, dims, data_type, data, claimed=None):
    """A miMATRIX element of class double; `claimed` overrides the data tag's byte count."""
    flags = tag(6, 8) + struct.pack("<II", 6, 0)
    dim = tag(5, 4 * len(dims)) + b"".join(struct.pack("<i", d) for d in dims)
    dim = pad8(dim)
    nm = small_tag(1, name) if len(name) <= 4 else pad8(tag(1, len(name)) + name)
    body = flags + dim + nm + pad8(tag(data_type, len(data) if claimed is None else claimed) + data)
    return tag(14, len(body)) + body


def write(path, data):
    with open(path, "wb") as f:
        f.write(data)


def session(logs, models=None):
    return {
        "format": "flexarm-session",
        "version": 1,
        "written_by": "FlexArm 0.1.0",
        "logs": [{"name": n, "path": p, "sha256": "0" * 64, "read": {"format": "auto"}} for n, p in logs],
        "preprocessing": {"applied": False, "differentiate_angle": False, "range_samples": None,
                          "decimation": {"factor": 1, "filter": "fir", "stopband_db": 80.0},
                          "detrend": "none"},
        "ranges": {"estimation_s": None, "validation_s": None},
        "parts": {"models": models or []},
    }


def model(name, parameters):
    return {"name": name, "structure": "two-mass", "output": "motor-velocity",
            "arm_acceleration": False, "parameters": parameters, "effects": []}


def small(out):
    # A 48 KB .mat whose header claims 2^31 - 1 doubles (16 GiB).
    write(os.path.join(out, "mat_claims_2g_elements.mat"),
          mat5_header() + matrix(b"u", [2**31 - 1, 1], 9, b"\0" * 48000))
    # A variable name that claims 2 GiB.
    body = tag(6, 8) + struct.pack("<II", 6, 0) + tag(5, 8) + struct.pack("<ii", 4, 1) + tag(1, 2**31 - 8) + b"u"
    write(os.path.join(out, "mat_huge_name.mat"), mat5_header() + tag(14, len(body)) + body)
    # A compressed variable whose inflated size claims 4 GiB - 1.
    inner = tag(14, 2**32 - 1) + b"\0" * 64
    comp = zlib.compress(inner)
    write(os.path.join(out, "mat_compressed_claims_4g.mat"), mat5_header() + tag(15, len(comp)) + comp)
    # Level 4: one record of 2^31 - 1 x 2^31 - 1 doubles in 40 bytes.
    write(os.path.join(out, "mat_v4_claims_huge.mat"),
          struct.pack("<iiiii", 0, 2**31 - 1, 2**31 - 1, 0, 2) + b"u\0" + b"\0" * 18)
    # Time steps of 1e-310 s: "inf Hz".
    with open(os.path.join(out, "time_step_1e-310.csv"), "w") as f:
        f.write("# flexarm-log: 1\ntime_s,torque_ref_nm,motor_angle_rad\n")
        for i in range(5):
            f.write(f"{i * 1e-310!r},0.{i},0.{i}\n")
    log = "# flexarm-log: 1\ntime_s,torque_ref_nm,motor_angle_rad\n0.0,1,2\n0.001,1,2\n0.002,1,2\n"
    write(os.path.join(out, "utf16le_bom.csv"), b"\xff\xfe" + log.encode("utf-16-le"))
    write(os.path.join(out, "utf16be_bom.csv"), b"\xfe\xff" + log.encode("utf-16-be"))
    write(os.path.join(out, "utf16le_no_bom.csv"), log.encode("utf-16-le"))
    write(os.path.join(out, "utf8_bom.csv"), b"\xef\xbb\xbf" + log.encode())
    dead_logs(out)
    message_cases(out)
    v73_small(out)
    for dev in ("zero", "urandom"):
        with open(os.path.join(out, f"session_log_dev_{dev}.json"), "w") as f:
            json.dump(session([("estimation", f"/dev/{dev}")]), f, indent=1)


DEAD_HEADER = ("# flexarm-log: 1\n# sample_rate_hz: {rate:g}\n# gear_ratio: 0.00847457627119\n"
               "# controller_rate_hz: 2000\n# controller_kp: 40\n# controller_kv: 0.3\n"
               "# controller_ti: 0.05\ntime_s,torque_ref_nm,motor_angle_rad,angle_ref_rad\n")


def dead_log(path, torque, angle, reference, step=0.0005, n=400):
    """A closed-loop log of n samples whose columns are the functions given of the sample index."""
    with open(path, "w") as f:
        f.write(DEAD_HEADER.format(rate=1.0 / step))
        for i in range(n):
            f.write(f"{i * step!r},{torque(i)!r},{angle(i)!r},{reference(i)!r}\n")


def dead_logs(out):
    """Logs with nothing to learn from: each refused before any analysis, naming the channel."""
    import math
    wave = lambda i: 0.3 * math.sin(0.05 * i) + 0.1 * math.sin(0.31 * i)
    ramp = lambda i: 1e-3 * i
    # A stuck encoder: the motor angle never moves while the torque does.
    dead_log(os.path.join(out, "dead_stuck_encoder.csv"), wave, lambda i: 1.25, ramp)
    dead_log(os.path.join(out, "dead_all_zero.csv"), lambda i: 0.0, lambda i: 0.0, lambda i: 0.0)
    # Values of 1e-315 (subnormal): their squares are zero.
    dead_log(os.path.join(out, "dead_subnormal.csv"), lambda i: 1e-315 * (i % 7), lambda i: 1e-315 * (i % 5),
             lambda i: 0.0)
    dead_log(os.path.join(out, "dead_zero_torque.csv"), lambda i: 0.0, wave, ramp)
    dead_log(os.path.join(out, "dead_torque_1e308.csv"), lambda i: 1e308 if i % 2 else -1e308, wave, ramp)
    # A stuck encoder at a large reading with noise in its last digits only.
    dead_log(os.path.join(out, "dead_stuck_large_reading.csv"), wave,
             lambda i: 1000.0 + 1e-13 * (i % 3), ramp)
    # A time step of 1e6 s (11.6 days between samples) on otherwise good data.
    dead_log(os.path.join(out, "time_step_1e6.csv"), wave, wave, ramp, step=1e6)


# MATLAB v7.3 files: HDF5 behind a 512-byte MATLAB header, one dataset a variable with its
# MATLAB_class attribute (written with h5py, python3-h5py).
MAT73_HEADER = (b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Sat Nov 28 00:00:00 2026 "
                b"HDF5 schema 1.00 .").ljust(116, b" ") + b"\0" * 8 + struct.pack("<H", 0x0200) + b"IM"


def h5():
    try:
        import h5py
        import numpy
    except ImportError:
        # Debian's python3-h5py belongs to the system's Python: run there when this one lacks it.
        if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
            os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
        raise
    return h5py, numpy


def matlab_class(obj, name):
    h5py, numpy = h5()
    tid = h5py.h5t.C_S1.copy()
    tid.set_size(len(name))
    tid.set_strpad(h5py.h5t.STR_NULLTERM)
    attr = h5py.h5a.create(obj.id, b"MATLAB_class", tid, h5py.h5s.create(h5py.h5s.SCALAR))
    attr.write(numpy.array(name.encode(), dtype="S%d" % len(name)), mtype=tid)


def mat73(path, build, **options):
    """Writes an HDF5 file through build(file) and puts the MATLAB header in its user block."""
    h5py, _ = h5()
    with h5py.File(path, "w", userblock_size=512, **options) as f:
        build(f)
    with open(path, "r+b") as f:
        f.write(MAT73_HEADER)


def log_variables(f, n=400, **dataset_options):
    """time_s, torque_ref_nm and motor_angle_rad as MATLAB row vectors."""
    _, numpy = h5()
    t = numpy.arange(n) * 0.0005
    for name, v in (("time_s", t), ("torque_ref_nm", numpy.sin(40 * t) + 0.2 * numpy.sin(170 * t)),
                    ("motor_angle_rad", numpy.cos(25 * t))):
        d = f.create_dataset(name, data=v.reshape(1, -1), **dataset_options)
        matlab_class(d, "double")


def v73_small(out):
    h5py, numpy = h5()

    def good(f):
        log_variables(f, compression="gzip")
        s = f.create_group("settings")  # a struct: named and ignored
        matlab_class(s, "struct")
        # Its field names as MATLAB and matio keep them: variable-length strings in the global heap.
        names = numpy.empty(1, dtype=object)
        names[0] = numpy.frombuffer(b"kp", dtype="S1")
        s.attrs.create("MATLAB_fields", names, dtype=h5py.vlen_dtype(numpy.dtype("S1")))
        matlab_class(s.create_dataset("kp", data=numpy.array([[40.0]])), "double")
        refs = f.create_group("#refs#")
        cell = refs.create_dataset("a", data=numpy.array([[1.0, 2.0]]))
        matlab_class(cell, "double")
        c = f.create_dataset("notes", (1, 1), dtype=h5py.ref_dtype)  # a cell: named and ignored
        c[0, 0] = cell.ref
        matlab_class(c, "cell")
    mat73(os.path.join(out, "v73_good.mat"), good)
    mat73(os.path.join(out, "v73_good_latest.mat"), lambda f: log_variables(f), libver="latest")

    # Data stored in another file: reading would copy /etc/passwd into the log. No data are
    # written (h5py would write them into that file).
    def external(f):
        log_variables(f)
        del f["motor_angle_rad"]
        d = f.create_dataset("motor_angle_rad", (1, 400), dtype="f8", external=[("/etc/passwd", 0, 3200)])
        matlab_class(d, "double")
    mat73(os.path.join(out, "v73_external_storage.mat"), external)

    def external_link(f):
        log_variables(f)
        f["leak"] = h5py.ExternalLink("/etc/passwd", "/x")
    mat73(os.path.join(out, "v73_external_link.mat"), external_link)

    def soft_link(f):
        log_variables(f)
        f["alias"] = h5py.SoftLink("/time_s")
    mat73(os.path.join(out, "v73_soft_link.mat"), soft_link)

    def cycle(f):
        log_variables(f)
        g = f.create_group("s")
        matlab_class(g, "struct")
        g["inner"] = g  # a hard link back to its own group
    mat73(os.path.join(out, "v73_hard_link_cycle.mat"), cycle)

    def reference_cycle(f):
        log_variables(f)
        refs = f.create_group("#refs#")
        c = refs.create_dataset("a", (1, 1), dtype=h5py.ref_dtype)
        c[0, 0] = c.ref  # a cell holding itself
        matlab_class(c, "cell")
        top = f.create_dataset("c", (1, 1), dtype=h5py.ref_dtype)
        top[0, 0] = c.ref
        matlab_class(top, "cell")
    mat73(os.path.join(out, "v73_reference_cycle.mat"), reference_cycle)

    # 128 MiB of zeros in 1 MiB chunks, about 130 KB compressed.
    def bomb(f):
        log_variables(f)
        d = f.create_dataset("zeros", (1, 1 << 24), dtype="f8", chunks=(1, 1 << 17), compression="gzip",
                             compression_opts=9)
        for k in range(0, 1 << 24, 1 << 20):
            d[0, k:k + (1 << 20)] = numpy.zeros(1 << 20)
        matlab_class(d, "double")
    mat73(os.path.join(out, "v73_gzip_bomb.mat"), bomb)

    # A filter number that makes HDF5 look for a plug-in library: written with shuffle (2), then
    # the filter's number changed to 32000 in the pipeline message.
    path = os.path.join(out, "v73_plugin_filter.mat")
    mat73(path, lambda f: log_variables(f, shuffle=True, chunks=(1, 100)))
    with open(path, "rb") as f:
        data = bytearray(f.read())
    pipeline = b"\x01\x01\x00\x00\x00\x00\x00\x00\x02\x00"
    at = data.find(pipeline)
    assert at > 0
    while at > 0:
        data[at + 8:at + 10] = struct.pack("<H", 32000)
        at = data.find(pipeline, at + 1)
    write(path, bytes(data))

    # Cut in half.
    with open(os.path.join(out, "v73_good.mat"), "rb") as f:
        whole = f.read()
    write(os.path.join(out, "v73_truncated.mat"), whole[:len(whole) // 2])

    # The global heap's free space made 0 bytes long (found by fuzz_mat73): HDF5, reading the
    # struct's field names from that heap, looped forever.
    bad = bytearray(whole)
    at = bad.find(b"GCOL")
    size = struct.unpack_from("<Q", bad, at + 8)[0]
    pos = at + 16
    while pos + 16 <= at + size:
        index, _, _, length = struct.unpack_from("<HHIQ", bad, pos)
        if index == 0:
            struct.pack_into("<Q", bad, pos + 8, 0)
            break
        pos += 16 + (length + 7) // 8 * 8
    write(os.path.join(out, "v73_heap_no_progress.mat"), bytes(bad))

    # A local heap's free list that points back at itself: HDF5 would follow it forever.
    bad = bytearray(whole)
    at = bad.find(b"HEAP")
    _, free, data = struct.unpack_from("<QQQ", bad, at + 8)
    struct.pack_into("<Q", bad, 512 + data + free, free)
    write(os.path.join(out, "v73_free_list_cycle.mat"), bytes(bad))


def v73_nested_3000(path):
    """3000 structs, each inside the one before."""
    def build(f):
        log_variables(f)
        g = f
        for _ in range(3000):
            g = g.create_group("s")
            matlab_class(g, "struct")
    mat73(path, build)


def v73_20000_variables(path):
    """20 000 scalar variables."""
    _, numpy = h5()

    def build(f):
        log_variables(f)
        for k in range(20000):
            matlab_class(f.create_dataset("v%d" % k, data=numpy.array([[float(k)]])), "double")
    mat73(path, build)


def v73_external_fifo(path):
    """Data stored in a named pipe beside the file (made here): reading it would block forever."""
    fifo = os.path.join(os.path.dirname(os.path.abspath(path)), "v73_fifo")
    if not os.path.exists(fifo):
        os.mkfifo(fifo)

    def build(f):
        log_variables(f)
        del f["motor_angle_rad"]
        matlab_class(f.create_dataset("motor_angle_rad", (1, 400), dtype="f8", external=[(fifo, 0, 3200)]),
                     "double")
    mat73(path, build)


def message_cases(out):
    """Inputs whose refusal used to be a library's words, a wrong number or silence."""
    import math
    good = lambda i: 0.3 * math.sin(0.05 * i) + 0.1 * math.sin(0.31 * i)
    rows = "".join(f"{i * 0.0005!r},{good(i)!r},{good(i + 7)!r}\n" for i in range(200))
    head = "# flexarm-log: 1\n# sample_rate_hz: 2000\n"
    columns = "time_s,torque_ref_nm,motor_angle_rad\n"
    write(os.path.join(out, "metadata_latin1.csv"),
          (head + "# description: Achse 1, gem\xe4\xdft\n" + columns + rows).encode("latin-1"))
    write(os.path.join(out, "column_invalid_utf8.csv"),
          (head + "time_s,torque_ref_nm,motor_angle_rad,temp_\xb0C\n").encode("latin-1") +
          "".join(f"{i * 0.0005!r},{good(i)!r},{good(i + 7)!r},20\n" for i in range(200)).encode())
    write(os.path.join(out, "controller_kp_1e308.csv"),
          (head + "# controller_rate_hz: 2000\n# controller_kp: 1e308\n# controller_kv: 0.3\n"
           "# controller_ti: 0.05\ntime_s,torque_ref_nm,motor_angle_rad,angle_ref_rad\n" +
           "".join(f"{i * 0.0005!r},{good(i)!r},{good(i + 7)!r},{1e-3 * i!r}\n" for i in range(400))).encode())
    write(os.path.join(out, "controller_rate_1e300.csv"),
          (head + "# controller_rate_hz: 1e300\n# controller_kp: 40\n# controller_kv: 0.3\n"
           "# controller_ti: 0.05\ntime_s,torque_ref_nm,motor_angle_rad,angle_ref_rad\n" +
           "".join(f"{i * 0.0005!r},{good(i)!r},{good(i + 7)!r},{1e-3 * i!r}\n" for i in range(400))).encode())
    write(os.path.join(out, "time_1.7e308.csv"),
          ("# flexarm-log: 1\n" + columns + "-1.7e308,0.1,0.2\n1.7e308,0.3,0.1\n").encode())
    write(os.path.join(out, "cr_only.csv"), (head + columns + rows).replace("\n", "\r").encode())
    # A session whose discovery part names a log the session does not have.
    s = session([("estimation", "../../../sample_logs/effect_torque_ripple.csv")])
    import hashlib
    with open(os.path.join(os.path.dirname(SAMPLE), "effect_torque_ripple.csv"), "rb") as f:
        s["logs"][0]["sha256"] = hashlib.sha256(f.read()).hexdigest()
    s["parts"] = {"discovery": {"request": {
        "base_structure": "two-mass", "data": "as-read", "estimation": {"log": "no_such_log", "range_s": [0.0, 6.0]},
        "validation": None,
        "options": {"candidates": ["coulomb_friction"], "observer_bandwidth_hz": 1.0, "max_rate_hz": 1100.0,
                    "substeps": 0, "base_iterations": 30, "candidate_iterations": 12, "level": 0.99,
                    "min_validation_improvement": 0.1, "tie_tolerance": 0.02, "threads": 1}}}}
    with open(os.path.join(out, "session_discovery_unknown_log.json"), "w") as f:
        json.dump(s, f, indent=1)


def header_1e7_columns(path):
    """A CSV header of 10^7 columns (90 MB)."""
    with open(path, "w") as f:
        f.write("# flexarm-log: 1\ntime_s,torque_ref_nm,motor_angle_rad")
        for start in range(3, 10**7, 10**5):
            f.write("".join(f",c{i}" for i in range(start, min(start + 10**5, 10**7))))
        f.write("\n0,0,0\n")


def table_one_100mb_line(path):
    """A headerless table of one 100 MB line."""
    with open(path, "w") as f:
        for _ in range(100):
            f.write("1 " * (5 * 10**5))
        f.write("\n")


SAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "sample_logs",
                      "three_mass_estimation_chirp.csv")
PARAMETER = {"name": "J_m", "value": 0.000456, "free": True}


def session_1e6_parameters(path):
    """One model listing one parameter 10^6 times (40 MB)."""
    text = json.dumps(session([("estimation", os.path.abspath(SAMPLE))], [model("m", [])]))
    item = json.dumps(PARAMETER)
    with open(path, "w") as f:
        head, tail = text.split('"parameters": []')
        f.write(head + '"parameters": [' + ", ".join([item] * 10**6) + "]" + tail)


def session_20000_models(path):
    """20 000 identical models."""
    with open(path, "w") as f:
        json.dump(session([("estimation", os.path.abspath(SAMPLE))], [model("m", [PARAMETER])] * 20000), f)


BIG = {f.__name__: f for f in (header_1e7_columns, table_one_100mb_line, session_1e6_parameters,
                               session_20000_models, v73_nested_3000, v73_20000_variables,
                               v73_external_fifo)}
EXTENSION = {"header_1e7_columns": ".csv", "table_one_100mb_line": ".dat", "v73_nested_3000": ".mat",
             "v73_20000_variables": ".mat", "v73_external_fifo": ".mat"}


def big(out, names):
    for name in names or BIG:
        BIG[name](os.path.join(out, name + EXTENSION.get(name, ".json")))


if __name__ == "__main__":
    if len(sys.argv) < 3 or sys.argv[1] not in ("--small", "--big"):
        sys.exit(__doc__)
    os.makedirs(sys.argv[2], exist_ok=True)
    if sys.argv[1] == "--small":
        small(sys.argv[2])
    else:
        big(sys.argv[2], sys.argv[3:])

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
    for dev in ("zero", "urandom"):
        with open(os.path.join(out, f"session_log_dev_{dev}.json"), "w") as f:
            json.dump(session([("estimation", f"/dev/{dev}")]), f, indent=1)


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
                               session_20000_models)}
EXTENSION = {"header_1e7_columns": ".csv", "table_one_100mb_line": ".dat"}


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

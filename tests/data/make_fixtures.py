#!/usr/bin/env python3
"""Regenerate the small recording fixtures in this directory.

Usage: python3 tests/data/make_fixtures.py   (needs numpy and scipy)

The fixtures are committed; CI does not run this script. Every recording is
the same 40-sample, 1 kHz move: rest for 10 samples, then a ramp of the command
at 0.1 m/s, the position following 2 samples later.
"""
import os
import struct

import numpy as np
import scipy.io

HERE = os.path.dirname(os.path.abspath(__file__))
N = 40
T = np.arange(N) * 1e-3
CMD = np.where(np.arange(N) < 10, 0.0, (np.arange(N) - 9) * 1e-4)
POS = np.concatenate([[0.0, 0.0], CMD[:-2]])


def path(name):
    return os.path.join(HERE, name)


def write_rows(name, rows, delim=",", header=None):
    with open(path(name), "w", newline="") as f:
        if header is not None:
            f.write(delim.join(header) + "\n")
        for r in rows:
            f.write(delim.join(r) + "\n")


def fmt(x):
    return repr(float(x))


def rows(t=T, c=CMD, p=POS):
    return [[fmt(a), fmt(b), fmt(d)] for a, b, d in zip(t, c, p)]


HEADER = ["time_s", "command_m", "position_m"]


def text_fixtures():
    write_rows("comma_header.csv", rows(), ",", HEADER)
    write_rows("semicolon.csv", rows(), ";", HEADER)
    write_rows("tab.tsv", rows(), "\t", HEADER)
    with open(path("whitespace.txt"), "w") as f:
        f.write("# exported by a data logger\n")
        f.write("  time_s    command_m    position_m\n")
        for r in rows():
            f.write("  " + "   ".join(r) + "\n")
    write_rows("no_header.csv", rows(), ",")
    # Units: time in ms, lengths in mm.
    write_rows("mm_ms.csv",
               [[fmt(a * 1e3), fmt(b * 1e3), fmt(c * 1e3)] for a, b, c in zip(T, CMD, POS)],
               ",", ["time_ms", "command_mm", "position_mm"])
    # Decimal comma (European export): ';' delimiter, ',' decimal separator.
    write_rows("decimal_comma.csv", [[c.replace(".", ",") for c in r] for r in rows()], ";", HEADER)
    r = rows(); r[14][2] = "NaN"
    write_rows("nan.csv", r, ",", HEADER)
    r = rows(); r[19][1] = "abc"
    write_rows("text_cell.csv", r, ",", HEADER)
    t = T.copy(); t[20], t[21] = t[21], t[20]
    write_rows("decreasing_time.csv", rows(t=t), ",", HEADER)
    t = T.copy(); t[21] = t[20]
    write_rows("duplicate_time.csv", rows(t=t), ",", HEADER)
    t = T.copy(); t[25:] += 0.2e-3  # one interval 20 % long
    write_rows("jitter.csv", rows(t=t), ",", HEADER)
    write_rows("header_only.csv", [], ",", HEADER)
    open(path("empty.csv"), "w").close()
    r = rows(); r[7] = r[7][:2]
    write_rows("ragged.csv", r, ",", HEADER)
    # Encoder counts at 1e-7 m/count, no time column: read with a rate of 1 kHz.
    write_rows("encoder_counts.csv",
               [[str(int(round(c / 1e-7))), str(int(round(p / 1e-7)))] for c, p in zip(CMD, POS)],
               ",", ["command_m", "position_m"])
    write_rows("standstill.csv", rows(c=np.zeros(N), p=np.zeros(N)), ",", HEADER)
    # Extra numeric column and a text status column.
    with open(path("extra_columns.csv"), "w") as f:
        f.write("time_s,current_A,command_m,position_m,status\n")
        for k, (a, b, c) in enumerate(zip(T, CMD, POS)):
            f.write(f"{fmt(a)},{fmt(0.1 * k)},{fmt(b)},{fmt(c)},ok\n")
    with open(path("invalid_utf8.csv"), "wb") as f:
        f.write(b"time_s,command_m,position_m\n0.0,0.0,0.0\n0.001,\xff\xfe,0.0\n")


def mat_fixtures():
    col = lambda v: np.asarray(v).reshape(-1, 1)
    # Uncompressed v5, double column vectors, as `save -v6`.
    scipy.io.savemat(path("double_v6.mat"), {"t": col(T), "qg": col(CMD), "qm": col(POS)},
                     do_compression=False)
    # Compressed v5 (as `save -v7`): row and column vectors, a scalar and
    # unsupported classes that must be listed but skipped.
    scipy.io.savemat(path("compressed_v7.mat"), {
        "t": T.reshape(1, -1),              # row vector
        "qg": col(CMD),
        "qm": col(POS),
        "vir": col(np.linspace(-1, 1, N)),  # extra channel
        "kp": np.array([[160.18]]),         # scalar
        "M": np.arange(9.0).reshape(3, 3),  # matrix, not a vector
        "label": "EMPS-like",               # char
        "z": col(CMD + 1j * POS),           # complex
        "s": {"a": 1.0},                    # struct
        "c": np.array([[1.0, "x"]], dtype=object),  # cell
    }, do_compression=True)
    # Integer and single classes: counts at 1e-7 m/count, time in single precision.
    scipy.io.savemat(path("int_types.mat"), {
        "t": col(T.astype(np.float32)),
        "cmd_counts": col(np.round(CMD / 1e-7).astype(np.int32)),
        "pos_counts": np.round(POS / 1e-7).astype(np.uint16).reshape(1, -1),
        "i8": col(np.arange(N, dtype=np.int8)),
        "u64": col(np.arange(N, dtype=np.uint64)),
    }, do_compression=True)
    # A NaN in the position (element 15, 1-based).
    qm = POS.copy(); qm[14] = np.nan
    scipy.io.savemat(path("nan_v7.mat"), {"t": col(T), "qg": col(CMD), "qm": col(qm)},
                     do_compression=True)
    # Truncated copy of the compressed file.
    data = open(path("compressed_v7.mat"), "rb").read()
    open(path("truncated.mat"), "wb").write(data[: len(data) // 2])
    # Fake v7.3: MATLAB's 512-byte text header followed by the HDF5 signature.
    head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
    head = head.ljust(116, b" ") + b"\0" * 8 + struct.pack("<H", 0x0200) + b"IM"
    open(path("v73.mat"), "wb").write(head.ljust(512, b"\0") + b"\x89HDF\r\n\x1a\n" + b"\0" * 64)
    write_big_endian(path("big_endian.mat"))


def write_big_endian(name):
    """A hand-written big-endian ('MI') v5 file with double vectors t, qg, qm
    (names in the small data element format)."""
    out = bytearray(b"MATLAB 5.0 MAT-file, written by make_fixtures.py (big-endian)".ljust(116, b" "))
    out += b"\0" * 8 + struct.pack(">H", 0x0100) + b"MI"

    def elem(dtype, payload):
        pad = (-len(payload)) % 8
        return struct.pack(">II", dtype, len(payload)) + payload + b"\0" * pad

    def small(dtype, payload):
        return struct.pack(">HH", len(payload), dtype) + payload.ljust(4, b"\0")

    for vname, values in (("t", T), ("qg", CMD), ("qm", POS)):
        body = elem(6, struct.pack(">II", 6, 0))            # flags: class double
        body += elem(5, struct.pack(">ii", len(values), 1))  # dims n x 1
        body += small(1, vname.encode())                     # name, small format
        body += elem(9, struct.pack(">%dd" % len(values), *values))
        out += elem(14, body)
    open(name, "wb").write(out)


if __name__ == "__main__":
    text_fixtures()
    mat_fixtures()

#!/usr/bin/env python3
"""Measures the table encodings tdex chose between, on a real recording.

usage: table_encodings.py RECORDING.mcap   (recorded with --exact-area)

Reads the table with the standard MCAP readers, then prints (1) the error of the 16-bit
sqrt(a) codes tdex stores by default (unit sqrt(pi) R_max / 65535), and (2) the zstd size
(level 3, batches of 65 536 rows as tdex writes them) of alternative column layouts.
Needs: mcap, mcap-protobuf-support, numpy, zstandard.
"""
import json
import math
import sys

import numpy as np
import zstandard
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

BATCH = 65536


def varint(values):
    """Protobuf varint encoding of an array of non-negative integers."""
    v = values.astype(np.uint64)
    nbytes = np.ones(len(v), dtype=np.int64)
    for k in range(1, 10):
        nbytes += (v >= (np.uint64(1) << np.uint64(7 * k))).astype(np.int64)
    out = np.zeros(int(nbytes.sum()), dtype=np.uint8)
    pos = np.concatenate([[0], np.cumsum(nbytes)[:-1]])
    for k in range(10):
        live = nbytes > k
        if not live.any():
            break
        byte = (v & np.uint64(0x7F)).astype(np.uint8) | ((nbytes > k + 1).astype(np.uint8) << 7)
        out[pos[live] + k] = byte[live]
        v = v >> np.uint64(7)
    return out.tobytes()


def main(path):
    cols = {"i": [], "j": [], "start": [], "dur": [], "area": []}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        meta = {m.name: json.loads(m.metadata["json"]) for m in reader.iter_metadata()}
        info = meta["tdex.recording"]
        assert info["area_encoding"] == "exact", "record with --exact-area"
        radius = 0.0
        for _, channel, _, msg in reader.iter_decoded_messages():
            if channel.topic == "/tdex/collisions":
                cols["i"].append(np.array(msg.i, dtype=np.uint32))
                cols["j"].append(np.array(msg.j, dtype=np.uint32))
                cols["start"].append(np.array(msg.start_step, dtype=np.uint64))
                cols["dur"].append(np.array(msg.duration_steps, dtype=np.uint32))
                cols["area"].append(np.array(msg.sqrt_area, dtype=np.float64))
            elif channel.topic == "/tdex/snapshots" and radius == 0.0:
                stride = msg.point_stride
                data = np.frombuffer(msg.data, dtype=np.uint8).reshape(-1, stride)
                radius = data[:, 36:44].copy().view("<f8").max()
    c = {k: np.concatenate(v) for k, v in cols.items()}
    rows = len(c["i"])
    unit = math.sqrt(math.pi) * radius / 65535.0
    code = np.round(c["area"] / unit)
    err = np.abs(code * unit - c["area"])
    touching = c["area"] > 0
    rel = err[touching] / c["area"][touching]
    print(f"{path}: {rows} rows, R_max {radius} m, code unit {unit:.4e} m, largest code {int(code.max())}")
    print(
        "sqrt(a) codes: relative error median %.2e, 99th percentile %.2e, heat-weighted %.2e"
        % (np.median(rel), np.percentile(rel, 99), err.sum() / c["area"].sum())
    )
    zc = zstandard.ZstdCompressor(level=3)

    def size(columns):
        total = 0
        for lo in range(0, rows, BATCH):
            s = slice(lo, lo + BATCH)
            total += len(zc.compress(b"".join(col(s) for col in columns)))
        return total / rows

    code = code.astype(np.uint32)
    v = lambda a: (lambda s: varint(a[s]))
    fixed = lambda a, t: (lambda s: a[s].astype(t).tobytes())
    ids = [v(c["i"]), v(c["j"]), v(c["start"]), v(c["dur"])]
    layouts = {
        "packed varints, area codes (tdex)": ids + [v(code)],
        "fixed u32 columns, area codes as u32": [fixed(c[k], np.uint32) for k in ("i", "j", "start", "dur")]
        + [fixed(code, np.uint32)],
        "fixed u32 ids/start, u8 duration/n, u16 codes": [fixed(c[k], np.uint32) for k in ("i", "j", "start")]
        + [lambda s: (c["dur"][s] // info["sample_every"]).astype(np.uint8).tobytes(), fixed(code, np.uint16)],
        "packed varints, f32 areas": ids + [fixed(c["area"], np.float32)],
        "packed varints, f64 areas (--exact-area)": ids + [fixed(c["area"], np.float64)],
    }
    for name, columns in layouts.items():
        print(f"{size(columns):6.2f} bytes per row  {name}")
    print(f"{size([v(code)]):6.2f} bytes per row  the area codes alone")
    print(f"{size([fixed(c['area'], np.float32)]):6.2f} bytes per row  f32 areas alone")


if __name__ == "__main__":
    main(sys.argv[1])

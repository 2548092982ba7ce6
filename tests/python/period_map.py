#!/usr/bin/env python3
"""How well does the recorded period predict the next one? (diagnostic, docs/validation.md)

usage: period_map.py RECORDING.mcap   (recorded with --reference >= 2, paired: `tdex pair`)

The extrapolation assumes that particle p, standing at t1 where g(p) stood at t0, ends the
next period where g(p) ended the recorded one: x_p(t2) ~ x_{g(p)}(t1). Prints the mean
distance of that prediction from the DEM's x_p(t2), in diameters, beside the baselines
(no motion, the inverse pairing, a random permutation) and per axis.
"""
import json
import sys

import numpy as np
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

POINT = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("T", "<f8"), ("id", "<u4"),
                  ("r", "<f8"), ("vx", "<f8"), ("vy", "<f8"), ("vz", "<f8")])


def snapshots(path):
    out = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, _, message, cloud in reader.iter_decoded_messages(topics=["/tdex/snapshots"]):
            assert cloud.point_stride == POINT.itemsize
            out[message.sequence] = np.frombuffer(cloud.data, dtype=POINT)
    return out


def main(path):
    snaps = snapshots(path)
    g = np.array(json.load(open(path + ".pairing.json"))["g"])
    pos = {k: np.stack([s["x"], s["y"], s["z"]], 1) for k, s in snaps.items()}
    d = 2 * snaps[0]["r"].mean()
    mean = lambda a, b: np.linalg.norm(a - b, axis=1).mean() / d
    x0, x1, x2 = pos[0], pos[1], pos[2]
    perm = np.random.default_rng(0).permutation(len(g))
    print(f"pairing           |x1[p] - x0[g p]|  {mean(x1, x0[g]):.3f} d")
    print(f"recorded motion   |x1[p] - x0[p]|    {mean(x1, x0):.3f} d")
    print(f"prediction        |x2[p] - x1[g p]|  {mean(x2, x1[g]):.3f} d")
    print(f"no motion         |x2[p] - x1[p]|    {mean(x2, x1):.3f} d")
    print(f"inverse pairing   |x2[p] - x1[g'p]|  {mean(x2, x1[np.argsort(g)]):.3f} d")
    print(f"random            |x2[p] - x1[s p]|  {mean(x2, x1[perm]):.3f} d")
    err = np.abs(x2 - x1[g]).mean(0) / d
    print("prediction error per axis (x, y, z): " + ", ".join(f"{e:.3f} d" for e in err))


if __name__ == "__main__":
    main(sys.argv[1])

#!/usr/bin/env python3
"""Where do the particles on short cycles of the pairing end up? (diagnostic, docs/validation.md)

usage: cycle_temperatures.py RECORDING.mcap EXTRA.mcap   (RECORDING paired: `tdex pair`)

Replaying one period applies the pairing g again and again, so a particle only ever plays the
roles of its own cycle of g; a fixed point keeps one role, and with it one place in the bed and
one set of contacts, for ever. At the extrapolation's last t_k this prints, for the roles on
fixed points, on cycles of at most 10 periods and on longer cycles, the mean |T - T_near| (K),
T_near the mean temperature of the role's 12 nearest roles at t1: how far each group strays
from its surroundings.
"""
import json
import sys

import numpy as np
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from period_map import POINT


def last_snapshot(path):
    last = None
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, _, message, cloud in reader.iter_decoded_messages(topics=["/tdex/snapshots"]):
            if last is None or message.sequence > last[0]:
                last = (message.sequence, np.frombuffer(cloud.data, dtype=POINT).copy())
    return last


def cycle_lengths(g):
    length = np.zeros(len(g), dtype=int)
    seen = np.zeros(len(g), dtype=bool)
    for start in range(len(g)):
        if seen[start]:
            continue
        members = []
        p = start
        while not seen[p]:
            seen[p] = True
            members.append(p)
            p = g[p]
        length[members] = len(members)
    return length


def main(recording, extra):
    g = np.array(json.load(open(recording + ".pairing.json"))["g"])
    k, snap = last_snapshot(extra)
    pos = np.stack([snap["x"], snap["y"], snap["z"]], 1)
    temp = snap["T"]
    length = cycle_lengths(g)
    near = np.empty(len(temp))
    for j in range(len(temp)):
        d = np.linalg.norm(pos - pos[j], axis=1)
        idx = np.argsort(d)[1:13]
        near[j] = temp[idx].mean()
    dev = np.abs(temp - near)
    print(f"t_{k}: bed mean {temp.mean():.4f} K, {len(temp)} roles")
    for name, mask in [("fixed points", length == 1),
                       ("cycles of 2-10 periods", (length > 1) & (length <= 10)),
                       ("cycles longer than 10", length > 10)]:
        if mask.any():
            print(f"{name:>24}: {mask.sum():5d} roles, mean |T - T_near| {dev[mask].mean():.4f} K, "
                  f"mean T - bed mean {(temp[mask] - temp.mean()).mean():+.4f} K")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])

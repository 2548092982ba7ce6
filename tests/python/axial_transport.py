#!/usr/bin/env python3
"""How much does one revolution's axial transport differ from the DEM's usual one?
(diagnostic, docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6)

usage: axial_transport.py RECORDING.mcap BIN_D   (RECORDING made with --reference K; the
       drum's axis is y; BIN_D: the axial bins' width in particle diameters)

For every revolution between two consecutive snapshots of the DEM (t0 → t1, the recorded
one, then t1 → t2 … of the reference), the mean axial displacement (diameters) of the
particles that start it in each axial bin: the revolution's axial transport field. Printed:
the fields' mean over the revolutions (the systematic transport, which every revolution
repeats: near the end caps particles can only move inwards), the rms of each revolution's
field about that mean (its own, random part), and the recorded revolution's field beside the
mean, and the recorded revolution's random part split into its halves even and odd in y
(bins mirrored about the mid-plane y = 0). The replay repeats the recorded revolution's
random part at every period, where the DEM draws a new one each revolution: a random part
that is small against the bins says the replay cannot build an axial pattern from it in a
few periods. With `--mirror` a period and its mirror image move the particles at y by
Δ(y) − Δ(−y): the even half cancels, the odd half adds up as without the mirror.
"""
import sys

import numpy as np

from spread import axial_slab, by_id, by_topic, diameter


def main(rec_path, bin_d):
    dem = by_topic(rec_path)["/tdex/snapshots"]
    ks = sorted(dem)
    d = diameter(dem)
    width = bin_d * d
    fields = []
    for a, b in zip(ks, ks[1:]):
        y0, y1 = by_id(dem[a], "y"), by_id(dem[b], "y")
        keys, inverse = np.unique(axial_slab(y0, width), return_inverse=True)
        counts = np.bincount(inverse.ravel())
        mean = np.bincount(inverse.ravel(), weights=y1 - y0) / counts / d
        fields.append(dict(zip(keys, mean)))
    common = sorted(set.intersection(*(set(f) for f in fields)))
    per_revolution = np.array([[f[k] for k in common] for f in fields])
    systematic = per_revolution.mean(axis=0)
    random = np.sqrt(((per_revolution - systematic) ** 2).mean(axis=1))
    print(f"{len(fields)} revolutions (t{ks[0]} → t{ks[-1]}), {len(common)} axial bins of {bin_d:g} d")
    print(f"systematic transport: rms {np.sqrt((systematic ** 2).mean()):.3f} d over the bins")
    print("random part, rms per revolution (d): " + " ".join(f"{x:.3f}" for x in random))
    print(f"  the recorded revolution's: {random[0]:.3f} d; the others' median {np.median(random[1:]):.3f} d")
    index = {k: i for i, k in enumerate(common)}
    pairs = [(i, index[-k - 1]) for i, k in enumerate(common) if -k - 1 in index]
    recorded = per_revolution[0] - systematic
    even = np.array([0.5 * (recorded[i] + recorded[j]) for i, j in pairs])
    odd = np.array([0.5 * (recorded[i] - recorded[j]) for i, j in pairs])
    print(
        f"  its halves even and odd in y: {np.sqrt((even ** 2).mean()):.3f} d and "
        f"{np.sqrt((odd ** 2).mean()):.3f} d"
    )
    print("the recorded revolution's field (d): " + " ".join(f"{x:+.2f}" for x in per_revolution[0]))
    print("the mean field (d):                  " + " ".join(f"{x:+.2f}" for x in systematic))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], float(sys.argv[2]))

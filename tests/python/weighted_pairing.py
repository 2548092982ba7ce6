#!/usr/bin/env python3
"""Does the heated bed's rate follow the pairing or the recorded period? (diagnostic,
docs/method.md#6-the-replay; needs scipy)

usage: weighted_pairing.py RECORDING.mcap LAMBDA OUT_DIR [--squared]

Pairs the recording's t1 with its t0 (600 particles or so: a dense assignment) at the cost
sqrt(|x1 - x0|^2 + LAMBDA (s1 - s0)^2) per pair, s the distance of a sphere's surface from
a mantle of radius R_MANTLE about the y axis (the drum's axis), or the square of it with
--squared. LAMBDA = 0 is tdex's own pairing (the script checks it gives the same total
distance). Writes the pairing as the recording's sidecar in OUT_DIR beside a link to the
recording, so that `tdex extrapolate OUT_DIR/RECORDING.mcap` replays through it; prints
the total distance and the mean change of wall distance of the spheres touching the mantle
at t1, for this pairing and for tdex's.
"""
import json
import os
import sys

import numpy as np
from scipy.optimize import linear_sum_assignment

from period_map import snapshots

R_MANTLE = 0.06  # m, heated_drum's


def by_id(points):
    points = np.sort(points, order="id")
    assert (points["id"] == np.arange(len(points))).all(), "ids are not 0..N-1"
    return points


def wall_distance(points):
    return R_MANTLE - points["r"] - np.hypot(points["x"], points["z"])


def positions(points):
    return np.stack([points["x"], points["y"], points["z"]], 1)


def weighted_pairing(start, end, lam, squared):
    """g[p]: the sphere at t0 that sphere p at t1 is paired with, at least total cost."""
    gap = positions(end)[:, None, :] - positions(start)[None, :, :]
    cost = (gap**2).sum(-1) + lam * (wall_distance(end)[:, None] - wall_distance(start)[None, :]) ** 2
    rows, cols = linear_sum_assignment(cost if squared else np.sqrt(cost))
    g = np.empty(len(rows), dtype=np.int64)
    g[rows] = cols
    return g


def main(recording, lam, out_dir, squared):
    snaps = snapshots(recording)
    start, end = by_id(snaps[0]), by_id(snaps[1])
    d = 2 * float(np.median(start["r"]))
    with open(recording + ".pairing.json", encoding="utf-8") as f:
        sidecar = json.load(f)
    tdex_g = np.array(sidecar["g"])
    g = weighted_pairing(start, end, lam, squared)

    def total(pairing):
        return np.linalg.norm(positions(end) - positions(start)[pairing], axis=1).sum() / d

    touching = wall_distance(end) / d < 0.05

    def wall_step(pairing):
        return np.abs(wall_distance(start)[pairing] - wall_distance(end))[touching].mean() / d

    print(f"{recording}: total distance {total(g):.2f} d (tdex {total(tdex_g):.2f} d), "
          f"{100 * np.mean(g == tdex_g):.0f} % of the pairs tdex's; the {touching.sum()} spheres "
          f"touching the mantle at t1 change wall distance by {wall_step(g):.3f} d "
          f"(tdex {wall_step(tdex_g):.3f} d)")
    os.makedirs(out_dir, exist_ok=True)
    link = os.path.join(out_dir, os.path.basename(recording))
    if not os.path.lexists(link):
        os.symlink(os.path.abspath(recording), link)
    sidecar["g"] = [int(v) for v in g]
    sidecar["summary"]["total_distance_diameters"] = float(total(g))
    sidecar["summary"]["mean_distance_diameters"] = float(total(g)) / len(g)
    with open(link + ".pairing.json", "w", encoding="utf-8") as f:
        json.dump(sidecar, f)


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--squared"]
    if len(args) != 3:
        sys.exit(__doc__)
    main(args[0], float(args[1]), args[2], "--squared" in sys.argv[1:])

#!/usr/bin/env python3
"""The Lacey mixing index of the initially hot and cold particles over time, for the DEM,
its twins and an extrapolation (diagnostic, docs/validation.md#long-horizons-100-periods-and-more).

usage: lacey.py RECORDING.mcap EXTRA.mcap K [K ...]   (RECORDING made with --twins)

The hot particles are those hotter than the bed mean at t0. The bed is cut into cubic
cells (edge chosen for about 10 particles a cell at t1; cells with fewer than 3 particles
left out); M = (s0^2 - s^2) / (s0^2 - sr^2), s^2 the variance of the hot fraction over the
cells, s0^2 = p (1 - p) (segregated), sr^2 = p (1 - p) / n (randomly mixed, n the mean
particles a cell): 0 segregated, 1 mixed. In the extrapolation a particle is where the role
it plays is (the snapshot's `id`), and its label moves with it. The cells are not `tdex
report`'s Voronoi cells, so the figures differ from the report's; DEM and extrapolation are
measured alike here.
"""
import sys

import numpy as np

from spread import by_topic, dem_runs


def lacey(points, hot_by_id, edge):
    hot = hot_by_id[points["id"]]
    keys = np.floor(np.stack([points["x"], points["y"], points["z"]]) / edge).astype(np.int64)
    _, cell, counts = np.unique(keys, axis=1, return_inverse=True, return_counts=True)
    cell = cell.ravel()
    hot_in = np.bincount(cell, weights=hot.astype(float))
    keep = counts >= 3
    frac, n = hot_in[keep] / counts[keep], counts[keep]
    p = hot.mean()
    s2 = np.average((frac - p) ** 2, weights=n)
    s0, sr = p * (1 - p), p * (1 - p) / n.mean()
    return (s0 - s2) / (s0 - sr)


def main():
    rec, extra, ks = sys.argv[1], sys.argv[2], [int(k) for k in sys.argv[3:]]
    reference, twins = dem_runs(rec)
    ext = by_topic(extra)["/tdex/snapshots"]
    runs = [reference] + twins
    t0 = runs[0][0]
    hot_by_id = np.zeros(len(t0), bool)
    hot_by_id[t0["id"]] = t0["T"] > t0["T"].mean()
    t1 = runs[0][1]
    volume = np.prod([np.ptp(t1[c]) for c in "xyz"])
    edge = (volume * 10 / len(t1)) ** (1 / 3)
    names = ["DEM"] + [f"twin {m}" for m in range(1, len(runs))] + ["extrapolated"]
    print(f"cells of {edge * 1e3:.1f} mm; Lacey index at " + ", ".join(f"t{k}" for k in ks))
    for name, series in zip(names, runs + [ext]):
        print(f"{name:>12}: " + "  ".join(
            f"{lacey(series[k], hot_by_id, edge):.3f}" if k in series else "  -  " for k in ks))


if __name__ == "__main__":
    main()

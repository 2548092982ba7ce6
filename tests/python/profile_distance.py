#!/usr/bin/env python3
"""Along which direction does an extrapolation's temperature profile depart from the DEM's
more than the DEM runs' profiles depart from each other? (diagnostic, docs/validation.md,
"Where the pilot drum's excess is")

usage: profile_distance.py [--each] RECORDING.mcap BIN_D EXTRA.mcap [EXTRA.mcap ...]
       (RECORDING made with --reference K --twins M; the drum's axis is y; BIN_D: the bins'
       width in particle diameters)

At every t_k that every run holds, the bed is binned along x (across, the `split` axis of
the hot/cold cases), y (the axis), z (up) and the depth below the mantle; a profile is the
bins' mean temperatures (bins holding fewer than half the median count of the first run
left out), and the distance of two runs the particle-weighted rms of their profiles'
difference (K). Printed per direction: each extrapolation's mean distance to the DEM runs
over the DEM pairs' mean distance, the median over the t_k. A ratio well above 1 along one
direction says the replay's large-scale pattern departs from the DEM's along it. A recording
without twins gives, per t_k, each extrapolation's distance to the reference and the
reference profile's own rms about the bed mean, to set beside them. `--each` also prints,
per direction and t_k, the DEM pairs' mean distance and each extrapolation's ratio.
"""
import sys

import numpy as np

from spread import by_topic, dem_runs, diameter, ratios_to_runs, well_filled

DIRECTIONS = ["x", "y", "z", "depth"]


def coordinate(points, direction):
    if direction != "depth":
        return points[direction]
    radial = np.hypot(points["x"], points["z"])
    return radial.max() + np.median(points["r"]) - radial


def profile(points, direction, width):
    bins = np.floor(coordinate(points, direction) / width).astype(np.int64)
    keys, inverse, counts = np.unique(bins, return_inverse=True, return_counts=True)
    sums = np.bincount(inverse.ravel(), weights=points["T"])
    return {k: (s / c, c) for k, s, c in zip(keys, sums, counts)}


def distance(a, b, direction, width):
    pa, pb = profile(a, direction, width), profile(b, direction, width)
    keys = [k for k in well_filled(pa) if k in pb]
    w = np.array([pa[k][1] for k in keys], dtype=float)
    diff = np.array([pa[k][0] - pb[k][0] for k in keys])
    return float(np.sqrt(np.average(diff**2, weights=w)))


def rms_about_mean(points, direction, width):
    bins = profile(points, direction, width)
    kept = [bins[k] for k in well_filled(bins)]
    w = np.array([c for _, c in kept], dtype=float)
    dev = np.array([m for m, _ in kept]) - points["T"].mean()
    return float(np.sqrt(np.average(dev**2, weights=w)))


def main(rec_path, bin_d, extra_paths, each=False):
    dem, twins = dem_runs(rec_path)
    extras = [by_topic(p)["/tdex/snapshots"] for p in extra_paths]
    width = bin_d * diameter(dem)
    ks = [
        k
        for k in sorted(dem)
        if k >= 2 and all(k in e for e in extras) and all(k in t for t in twins)
    ]
    if not twins:
        print(f"bins of {bin_d:g} diameters; {rec_path} holds no DEM twin: distances to the")
        print("reference (K), then the reference profile's rms about the bed mean (K)")
        for direction in DIRECTIONS:
            print(direction)
            for k in ks:
                ref = dem[k]
                own = rms_about_mean(ref, direction, width)
                to = [distance(ref, e[k], direction, width) for e in extras]
                print(f"  t{k}: " + " ".join(f"{x:.4f}" for x in to) + f" | reference {own:.4f}")
        return
    print(f"bins of {bin_d:g} diameters; median over t{ks[0]}…t{ks[-1]} of the ratio")
    print("direction  " + "  ".join(extra_paths))
    for direction in DIRECTIONS:
        ratios = []
        for k in ks:
            runs = [dem[k]] + [t[k] for t in twins]
            def along(a, b):
                return distance(a, b, direction, width)

            pairs, to_runs = ratios_to_runs(runs, [e[k] for e in extras], along)
            ratios.append(to_runs)
            if each:
                print(
                    f"  {direction} t{k}: DEM pairs {pairs:.4f} K, ratio "
                    + " ".join(f"{x:.2f}" for x in ratios[-1])
                )
        medians = np.median(ratios, axis=0)
        print(f"{direction:<9}  " + "  ".join(f"{m:.3f}" for m in medians))


if __name__ == "__main__":
    args = sys.argv[1:]
    each = "--each" in args
    args = [a for a in args if a != "--each"]
    if len(args) < 3:
        sys.exit(__doc__)
    main(args[0], float(args[1]), args[2:], each)

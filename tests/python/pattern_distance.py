#!/usr/bin/env python3
"""Is an extrapolation's miss in its bed mean or in its pattern? (diagnostic,
docs/validation.md#fresh-boundary-maps; needs scipy)

usage: pattern_distance.py NAME REC.mcap EXTRA.mcap [REC.mcap EXTRA.mcap ...]
       (each REC recorded with --twins 2 or more, EXTRA an extrapolation of it)

At every t_k after the recorded stretch that every run holds, the bed is cut into 200 Voronoi
cells (seeds drawn in the reference's bed at that t_k, a function of k) and two runs' distance
is the mean absolute difference of their cell-mean temperatures, as `tdex compare` measures
it (its own cells, so the figures are near `tdex compare`'s, not equal). The same again on
the *pattern*: each run's temperatures less its own bed mean, so that a bed heating a little
too fast or too slowly, uniformly, costs nothing. Prints per bed the median over the t_k of
the extrapolation's mean distance to the DEM runs over their mean distance to each other, for
the field and for the pattern, beside a DEM run judged in the same seat (each run against the
others, its median over the t_k, the mean over the runs); then their mean ± standard error
over the beds.
"""
import sys

import numpy as np
from scipy.spatial import cKDTree

from spread import by_topic, dem_runs

CELLS = 200


def cells_of(points, k):
    """CELLS seeds uniform in the bed's bounding box, kept within a diameter of a particle."""
    xyz = np.stack([points["x"], points["y"], points["z"]], 1)
    reach = 2 * np.median(points["r"])
    tree = cKDTree(xyz)
    rng = np.random.default_rng(k)
    lo, hi = xyz.min(0), xyz.max(0)
    seeds = []
    while len(seeds) < CELLS:
        trial = lo + rng.random((4 * CELLS, 3)) * (hi - lo)
        near, _ = tree.query(trial)
        seeds.extend(trial[near <= reach][: CELLS - len(seeds)])
    return cKDTree(np.array(seeds))


def cell_means(cells, points, pattern):
    xyz = np.stack([points["x"], points["y"], points["z"]], 1)
    _, cell = cells.query(xyz)
    temp = points["T"] - (points["T"].mean() if pattern else 0.0)
    sums = np.bincount(cell, weights=temp, minlength=CELLS)
    counts = np.bincount(cell, minlength=CELLS)
    means = np.full(CELLS, np.nan)
    means[counts > 0] = sums[counts > 0] / counts[counts > 0]
    return means


def distance(a, b):
    both = ~np.isnan(a) & ~np.isnan(b)
    return float(np.abs(a[both] - b[both]).mean())


def ratios(runs, extra):
    """The extrapolation's ratio, then each DEM run's in its seat, at one t_k."""
    n = len(runs)
    pair = {(i, j): distance(runs[i], runs[j]) for i in range(n) for j in range(i + 1, n)}
    floor = np.mean(list(pair.values()))
    to_runs = np.mean([distance(r, extra) for r in runs])
    seats = []
    for c in range(n):
        others = [d for (i, j), d in pair.items() if c not in (i, j)]
        to_others = [d for (i, j), d in pair.items() if c in (i, j)]
        seats.append(np.mean(to_others) / np.mean(others))
    return [to_runs / floor] + seats


def bed(rec_path, extra_path):
    dem, twins = dem_runs(rec_path)
    extra = by_topic(extra_path)["/tdex/snapshots"]
    ks = [k for k in sorted(dem) if k in extra and all(k in t for t in twins)]
    ks = [k for k in ks if k >= 2]
    out = {}
    for pattern in (False, True):
        per_k = []
        for k in ks:
            cells = cells_of(dem[k], k)
            runs = [cell_means(cells, r[k], pattern) for r in [dem] + twins]
            per_k.append(ratios(runs, cell_means(cells, extra[k], pattern)))
        # the median over the t_k, per seat; a DEM run's figure is the mean over the seats,
        # as `tdex compare` has it
        medians = np.median(np.array(per_k), axis=0)
        out[pattern] = (medians[0], medians[1:].mean())
    return ks, out


def mean_se(values):
    values = np.array(values)
    se = values.std(ddof=1) / np.sqrt(len(values))
    decimals = 2 if se >= 0.005 else 3 if se >= 0.0005 else 4
    return f"{values.mean():.{decimals}f} ± {se:.{decimals}f}"


def main(name, paths):
    if len(paths) % 2 or not paths:
        sys.exit(__doc__)
    rows = []
    print(f"{name}: median over the t_k of the distance to the DEM runs over theirs to each other")
    print("bed                          field  DEM run   pattern  DEM run   t_k")
    for rec, extra in zip(paths[::2], paths[1::2]):
        ks, out = bed(rec, extra)
        rows.append((out[False][0], out[False][1], out[True][0], out[True][1]))
        print(f"{rec:<28} {out[False][0]:5.2f}  {out[False][1]:7.3f}   {out[True][0]:7.2f}"
              f"  {out[True][1]:7.3f}   t{ks[0]}…t{ks[-1]}")
    if len(rows) > 1:
        columns = list(zip(*rows))
        print(f"{'mean ± standard error':<28} " + "   ".join(mean_se(c) for c in columns))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])

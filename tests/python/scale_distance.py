#!/usr/bin/env python3
"""At which length scale does an extrapolation depart from the DEM more than the DEM runs
depart from each other? (diagnostic, docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6)

usage: scale_distance.py RECORDING.mcap EXTRA.mcap [EDGE_D ...]
       (RECORDING made with --reference K, and --twins M for the DEM runs' distances;
       EDGE_D: cubic cell edges in particle diameters, default 2.5 5 10 20)

At every t_k the extrapolation holds, for each cell edge: the bed is cut into cubic cells
(four grids shifted by a quarter cell, their figures averaged; cells holding fewer than half
the median count of the first field left out), and the distance of two runs is the mean over
the cells, weighted by the particles, of |difference of the cells' mean temperatures| (K).
Printed: the distance of each DEM pair (reference and twins), of the extrapolation to each
DEM run, the standard deviation of the cells' means about the bed mean for the reference
and the extrapolation (the field's own size: equal where the replay mixes like the DEM),
and the extrapolation's mean distance over the DEM pairs' mean. Where that ratio grows with
the cell edge, the replay departs from the DEM runs in its large-scale motion, where they
still agree. The cells are not `tdex compare`'s Voronoi cells, so the figures differ from
its ε_abs; all runs are measured alike here.
"""
import sys

import numpy as np

from spread import by_topic, dem_pairs, dem_runs, diameter, well_filled

SHIFTS = [np.array([0.37, 0.53, 0.71]) * o / 4 for o in range(4)]


def cell_keys(points, edge, shift):
    """Each particle's cubic cell of the given edge, the grid shifted by `shift` cells."""
    xyz = np.stack([points["x"], points["y"], points["z"]]).T
    return np.floor(xyz / edge - shift).astype(np.int64)


def field(points, keys):
    """Mean temperature and count of every cell key, as a dict key -> (mean, count)."""
    uniq, cell, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    sums = np.bincount(cell.ravel(), weights=points["T"])
    return {tuple(k): (s / c, c) for k, s, c in zip(uniq, sums, counts)}


def distance(a, b, edge):
    """Particle-weighted mean |ΔT| of the cell means, and each field's std, over SHIFTS."""
    dists, stds = [], []
    for shift in SHIFTS:
        fa = field(a, cell_keys(a, edge, shift))
        fb = field(b, cell_keys(b, edge, shift))
        common = [k for k in well_filled(fa) if k in fb]
        w = np.array([fa[k][1] for k in common], dtype=float)
        ta = np.array([fa[k][0] for k in common])
        tb = np.array([fb[k][0] for k in common])
        dists.append(np.average(np.abs(ta - tb), weights=w))
        stds.append(
            (
                np.sqrt(np.average((ta - a["T"].mean()) ** 2, weights=w)),
                np.sqrt(np.average((tb - b["T"].mean()) ** 2, weights=w)),
            )
        )
    return float(np.mean(dists)), np.mean(stds, axis=0)


def main(rec_path, extra_path, edges_d):
    dem, twins = dem_runs(rec_path)
    ex = by_topic(extra_path)["/tdex/snapshots"]
    d = diameter(dem)
    ks = sorted(k for k in ex if k in dem and k >= 2)
    print(f"cells in particle diameters (d = {d * 1e3:g} mm); distances in K")
    for edge_d in edges_d:
        print(f"cell edge {edge_d:g} d:")
        ratios = {}
        for k in ks:
            runs = [dem[k]] + [t[k] for t in twins if k in t]
            pairs = dem_pairs(runs, lambda a, b: distance(a, b, edge_d * d)[0])
            to_runs = []
            for i, r in enumerate(runs):
                dist, std = distance(r, ex[k], edge_d * d)
                to_runs.append(dist)
                if i == 0:
                    std_ref, std_ex = std
            line = f"  t{k}: extrapolation to the DEM runs " + " ".join(
                f"{x:.4f}" for x in to_runs
            )
            if pairs:
                ratio = np.mean(to_runs) / np.mean(pairs)
                ratios[k] = ratio
                line += " | DEM pairs " + " ".join(f"{x:.4f}" for x in pairs)
                line += f" | ratio {ratio:.3f}"
            line += f" | field std reference {std_ref:.4f}, extrapolation {std_ex:.4f}"
            print(line)
        if ratios:
            # over the t_k a twin holds (a recording still being written holds fewer)
            first, last = min(ratios), max(ratios)
            print(f"  median ratio over t{first}…t{last}: {np.median(list(ratios.values())):.3f}")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    edges = [float(e) for e in sys.argv[3:]] or [2.5, 5.0, 10.0, 20.0]
    main(sys.argv[1], sys.argv[2], edges)

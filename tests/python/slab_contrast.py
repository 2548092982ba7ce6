#!/usr/bin/env python3
"""Does the hot-cold contrast vary along the axis more in the extrapolation than in the DEM?
(diagnostic, docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6)

usage: slab_contrast.py RECORDING.mcap EXTRA.mcap SLAB_D   (RECORDING made with --reference
       K --twins M; the drum's axis is y; SLAB_D: the slabs' width in particle diameters)

The bed is cut into axial slabs; in each, the contrast is the mean temperature of the
particles hot at t0 less that of those cold at t0 (hot: above the bed mean at t0). Printed
per t_k: the bed's mean slab contrast, each run's rms of its slab contrasts about their mean
(how much the contrast varies along the axis), and each run's rms slab difference to the
reference. Slabs with fewer than half the median count are left out.
"""
import sys

import numpy as np

from spread import (axial_slab, by_topic, compared_ks, dem_runs, diameter, hot_at_t0, run_names,
                    well_filled)


def contrasts(points, hot_by_id, width):
    """{slab: hot mean − cold mean} over the well-filled slabs."""
    hot = hot_by_id[points["id"]]
    slab = axial_slab(points["y"], width)
    keys, index, counts = np.unique(slab, return_inverse=True, return_counts=True)
    index = index.ravel()
    n_hot = np.bincount(index, weights=hot)
    t_hot = np.bincount(index, weights=points["T"] * hot)
    t_all = np.bincount(index, weights=points["T"])
    contrast = t_hot / n_hot - (t_all - t_hot) / (counts - n_hot)
    cells = {b: (c_t, n) for b, c_t, n in zip(keys, contrast, counts)}
    return {b: cells[b][0] for b in well_filled(cells)}


def main(rec_path, extra_path, slab_d):
    dem, twins = dem_runs(rec_path)
    ex = by_topic(extra_path)["/tdex/snapshots"]
    width = slab_d * diameter(dem)
    hot_by_id = hot_at_t0(dem)
    names = run_names(twins)
    print(f"slabs of {slab_d:g} diameters; K")
    for k in compared_ks(dem, twins, ex):
        runs = [contrasts(r[k], hot_by_id, width) for r in [dem] + twins + [ex]]
        slabs = sorted(set.intersection(*(set(c) for c in runs)))
        v = np.array([[c[b] for b in slabs] for c in runs])
        spread = " ".join(f"{n} {row.std():.3f}" for n, row in zip(names, v))
        to_ref = " ".join(
            f"{n} {np.sqrt(np.mean((row - v[0]) ** 2)):.3f}" for n, row in zip(names[1:], v[1:])
        )
        print(f"t{k}: mean contrast {v[0].mean():.3f}; along the axis: {spread}; to the reference: {to_ref}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]))

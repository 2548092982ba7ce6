#!/usr/bin/env python3
"""In which plane does an extrapolation's large-scale excess lie? (diagnostic,
docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6)

usage: plane_distance.py RECORDING.mcap EXTRA.mcap EDGE_D   (RECORDING made with --reference
       K --twins M; the drum's axis is y; EDGE_D: the cells' edge in particle diameters)

As scale_distance.py, with cells of the given edge in two directions and the whole bed along
the third: the cross-section (x-z, averaged along the axis), y-z and x-y, and the 3-D cells
beside them. Per plane and t_k, the extrapolation's mean distance to the DEM runs over the DEM
pairs' mean distance, and the median over the t_k. A ratio near 1 in the cross-section and
above it in the planes that hold the axis says the replay's pattern across the drum is right
on average but varies along the axis more than the DEM's does.
"""
import sys

import numpy as np

from scale_distance import distance
from spread import by_topic, compared_ks, dem_runs, diameter, ratios_to_runs

PLANES = [("y", "x-z, whole axis"), ("x", "y-z, whole width"), ("z", "x-y, whole height"), (None, "3-D cells")]


def flattened(points, axis):
    """The points with one coordinate set to 0: their cells span the bed along it."""
    if axis is None:
        return points
    out = points.copy()
    out[axis] = 0.0
    return out


def main(rec_path, extra_path, edge_d):
    dem, twins = dem_runs(rec_path)
    if not twins:
        sys.exit(f"{rec_path} holds no DEM twin: record it with --twins 1 or more")
    ex = by_topic(extra_path)["/tdex/snapshots"]
    edge = edge_d * diameter(dem)
    ks = compared_ks(dem, twins, ex)
    print(f"cells of {edge_d:g} diameters in the plane, the whole bed across it; ratio per t_k")
    print(f"{'plane':<28} " + " ".join(f"t{k:<4}" for k in ks) + " median")
    for axis, name in PLANES:
        ratios = []
        for k in ks:
            runs = [flattened(r[k], axis) for r in [dem] + twins]
            e = flattened(ex[k], axis)
            ratios.append(ratios_to_runs(runs, [e], lambda a, b: distance(a, b, edge)[0])[1][0])
        print(f"{name:<28} " + " ".join(f"{r:<5.2f}" for r in ratios) + f" {np.median(ratios):.2f}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]))

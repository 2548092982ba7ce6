#!/usr/bin/env python3
"""How far apart are the particles of two DEM runs of one case? (diagnostic, docs/validation.md)

usage: run_distance.py RUN.mcap RUN2.mcap   (two recordings of the same case and particle count)

Prints, at every t_k both recordings hold, the mean distance between the positions of the
particle with the same id in the two runs, in diameters.
"""
import sys

import numpy as np

from period_map import snapshots


def main(first, second):
    a, b = snapshots(first), snapshots(second)
    d = 2 * a[0]["r"].mean()
    xyz = lambda s: np.stack([s["x"], s["y"], s["z"]], 1)[np.argsort(s["id"])]
    for k in sorted(set(a) & set(b)):
        apart = np.linalg.norm(xyz(a[k]) - xyz(b[k]), axis=1).mean() / d
        print(f"t_{k}: mean distance between the runs' particles {apart:.3f} d")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])

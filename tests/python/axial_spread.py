#!/usr/bin/env python3
"""How far do particles spread along the drum axis, in the DEM and in the extrapolation?
(diagnostic, docs/validation.md)

usage: axial_spread.py RECORDING.mcap EXTRAPOLATION.mcap   (recorded with --reference K)

Prints, at each extrapolated t_k with a DEM reference, the rms axial (y) displacement of the
particles since t1, in diameters: in the DEM, and in the extrapolation (where a particle is
at the position of the role it plays). A wider extrapolated spread carries more heat across
an axial hot/cold interface than the DEM does.
"""
import sys

import numpy as np

from period_map import snapshots
from spread import by_id


def axial_by_id(snap):
    return by_id(snap, "y")


def main(recording, extrapolation):
    dem, extra = snapshots(recording), snapshots(extrapolation)
    d = 2 * dem[0]["r"].mean()
    y1 = axial_by_id(dem[1])
    rms = lambda y: np.sqrt(((y - y1) ** 2).mean()) / d
    for k in sorted(set(dem) & set(extra)):
        if k >= 2:
            print(f"t_{k}: rms axial displacement since t1: DEM {rms(axial_by_id(dem[k])):.3f} d, "
                  f"extrapolation {rms(axial_by_id(extra[k])):.3f} d")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])

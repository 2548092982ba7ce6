#!/usr/bin/env python3
"""How far apart is the same particle in two runs? (diagnostic, docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6)

usage: separation.py RECORDING.mcap EXTRA.mcap   (RECORDING made with --reference K, and
       --twins M for the twins' figures)

At every t_k from t2 on, the mean |Δx|, |Δy|, |Δz| (diameters; y is the drum's axis) between
each particle in the DEM reference and the same particle in each twin, and in the
extrapolation (where a particle is at the position of the role it plays). A twin parts from
the reference at t1 by one unit in the last place of the drum's speed, the extrapolation at
t1 through the pairing: separations of the same size say the twins are as far parted from
the reference as the replay is, particle by particle.
"""
import sys

import numpy as np

from spread import by_topic, dem_runs, diameter, positions


def main(rec_path, extra_path):
    dem, twins = dem_runs(rec_path)
    extra = by_topic(extra_path)["/tdex/snapshots"]
    d = diameter(dem)
    print("mean |dx| |dy| |dz| of the same particle against the reference (diameters)")
    for k in (k for k in sorted(dem) if k >= 2 and k in extra):
        ref = positions(dem[k])
        parts = [
            f"twin {m + 1} " + " ".join(f"{v:.2f}" for v in np.abs(positions(t[k]) - ref).mean(axis=0) / d)
            for m, t in enumerate(twins)
            if k in t
        ]
        replay = np.abs(positions(extra[k]) - ref).mean(axis=0) / d
        parts.append("extrapolation " + " ".join(f"{v:.2f}" for v in replay))
        print(f"t{k}: " + " | ".join(parts))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])

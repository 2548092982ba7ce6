#!/usr/bin/env python3
"""Where in the bed is an extrapolation's excess distance to the DEM? (diagnostic,
docs/validation.md#long-horizons-100-periods-and-more)

usage: radial_profile.py RECORDING.mcap EXTRA.mcap K [K ...]
       (RECORDING made with --reference and --twins; the drum's axis is y)

At each t_k asked for, bins the particles by their distance to the drum's mantle (in
particle diameters: 0-1, 1-2, 2-4, 4-8, 8+) and prints each bin's mean temperature minus
the bed mean (K) for the DEM, each twin and the extrapolation, then the rms over the bins of
the extrapolation's difference to the DEM runs' mean profile beside the DEM runs' own rms
about it: a systematic radial profile error shows as an extrapolation rms well above the
DEM runs'.
"""
import sys

import numpy as np

from spread import by_topic, dem_runs

EDGES = [0, 1, 2, 4, 8, 1e9]


def profile(points, radius_drum, d):
    depth = (radius_drum - np.hypot(points["x"], points["z"])) / d
    dev = points["T"] - points["T"].mean()
    out = []
    for lo, hi in zip(EDGES, EDGES[1:]):
        sel = (depth >= lo) & (depth < hi)
        out.append(dev[sel].mean() if sel.any() else np.nan)
    return np.array(out)


def main():
    rec, extra, ks = sys.argv[1], sys.argv[2], [int(k) for k in sys.argv[3:]]
    reference, twins = dem_runs(rec)
    ext = by_topic(extra)["/tdex/snapshots"]
    runs = [reference] + twins
    first = runs[0][0]
    d = 2 * first["r"].mean()
    # the mantle's radius: the farthest particle centre from the axis plus a radius
    radius_drum = max(np.hypot(s["x"], s["z"]).max() for s in runs[0].values()) + d / 2
    names = ["DEM"] + [f"twin {m}" for m in range(1, len(runs))] + ["extrapolated"]
    bins = ", ".join(f"{lo}-{hi if hi < 1e8 else ''}" for lo, hi in zip(EDGES, EDGES[1:]))
    print(f"depth bins below the mantle (diameters): {bins}")
    for k in ks:
        profiles = [profile(r[k], radius_drum, d) for r in runs] + [profile(ext[k], radius_drum, d)]
        mean_dem = np.nanmean(profiles[:-1], axis=0)
        rms = lambda p: float(np.sqrt(np.nanmean((p - mean_dem) ** 2)))
        print(f"t_{k}:")
        for name, p in zip(names, profiles):
            print(f"  {name:>12}: " + "  ".join(f"{v:+8.4f}" for v in p) + f"   rms about the DEM runs' mean {rms(p):.4f} K")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Does the coarse axial drift repeat from one period to the next? (diagnostic,
docs/method.md#6-the-replay)

usage: cap_drift.py RECORDING.mcap [PERIODS]   (recorded with --reference K >= 2)

The drift `--boundary fresh-drift` moves along the axis: for each period t_k -> t_(k+1) of
the DEM (the recorded one and the reference), the mean axial step of the particles ending in
each 2-diameter bin of the axis within each 3-diameter square of the cross-section, less the
square's mean over the axis. Prints, bin by bin from one end cap to the other, the drift's
root mean square over the squares and periods, the root mean square of its mean over the
periods (what repeats), what that mean would be if each period's drift were fresh (the first
figure over the square root of the number of periods) and the ratio of the two (about 1
where the drift is fresh each period), and the correlation of a square's
drift with its drift a period later. Uses the first PERIODS periods (default 20).
"""
import sys

import numpy as np

from period_map import snapshots

BIN_DIAMETERS = 2.0
CELL_DIAMETERS = 3.0


def drift(start, end, diameter, lowest):
    """{(square, bin): drift in diameters} of one period, squares with 10 or more particles
    and bins with 3 or more."""
    step = (end["y"] - start["y"]) / diameter
    # one integer per square: its column and row, far apart
    square = (np.floor(end["x"] / diameter / CELL_DIAMETERS).astype(np.int64) * 1_000_000
              + np.floor(end["z"] / diameter / CELL_DIAMETERS).astype(np.int64))
    axial_bin = np.floor((end["y"] / diameter - lowest) / BIN_DIAMETERS).astype(int)
    out = {}
    for s in np.unique(square):
        in_square = square == s
        if in_square.sum() < 10:
            continue
        square_mean = step[in_square].mean()
        for b in np.unique(axial_bin[in_square]):
            members = in_square & (axial_bin == b)
            if members.sum() >= 3:
                out[(s, b)] = step[members].mean() - square_mean
    return out


def main(path, periods):
    snaps = snapshots(path)
    indices = sorted(snaps)[: periods + 1]
    if len(indices) < 3:
        sys.exit(f"{path}: {len(indices)} snapshots; record with --reference 2 or more")
    by_id = {k: np.sort(snaps[k], order="id") for k in indices}
    diameter = 2 * by_id[indices[0]]["r"].mean()
    axial = np.concatenate([by_id[k]["y"] for k in indices]) / diameter
    lowest, highest = axial.min(), axial.max()
    fields = [drift(by_id[a], by_id[b], diameter, lowest) for a, b in zip(indices, indices[1:])]
    n = len(fields)
    print(f"{path}: {len(by_id[indices[0]])} particles, the bed {highest - lowest:.1f} diameters "
          f"long, {n} periods")
    print("bin  from the nearer cap  drift rms  its mean over the periods  if fresh  repeats  "
          "lag-1 correlation")
    bins = int(np.ceil((highest - lowest) / BIN_DIAMETERS))
    for b in range(bins):
        keys = sorted({key for field in fields for key in field if key[1] == b})
        values = np.array([field[key] for field in fields for key in keys if key in field])
        means = np.array([np.mean([f[key] for f in fields if key in f]) for key in keys])
        lagged = np.array([(f[key], g[key]) for f, g in zip(fields, fields[1:])
                           for key in keys if key in f and key in g])
        centre = BIN_DIAMETERS * (b + 0.5)
        cap = max(min(centre, highest - lowest - centre), 0.0)
        rms = np.sqrt(np.mean(values ** 2))
        correlation = np.corrcoef(lagged.T)[0, 1] if len(lagged) > 5 else float("nan")
        repeated, fresh = np.sqrt(np.mean(means ** 2)), rms / np.sqrt(n)
        print(f"{b:3d}  {cap:8.1f} d  {rms:15.2f} d  {repeated:19.2f} d  {fresh:10.2f} d"
              f"  {repeated / fresh:6.1f}×  {correlation:12.2f}")


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 20)

#!/usr/bin/env python3
"""What does a genuine DEM run score on the "one more DEM run" bar? (diagnostic, docs/validation.md)

usage: run_as_candidate.py RECORDING.mcap [CELLS] [SEED]
       (recorded with --reference K --twins M, M >= 2: at least three DEM runs)

Each DEM run of the recording (the reference and its twins, which part at t1) is judged in
turn in the place of an extrapolation: at every t_k >= 2, its mean Voronoi-cell distance
eps_abs to the other runs over their mean distance to each other (`tdex compare`'s
ratio_to_floor, with one run fewer in the pool). Prints, for every start s, each run's median
of that ratio over t_{s+1} ... t_{s+6} (the windows of the draws in docs/validation.md), and
the mean and spread of those medians over all runs and starts: the yardstick a method
identical to the DEM in law would meet. The cells are drawn as `tdex compare` draws them
(CELLS seeds, default 200, uniform in the bed's box at t1 and kept within one radius of a
particle) but from numpy's generator (SEED, default 1), so they are not the same cells.
"""
import statistics
import sys

import numpy as np
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from period_map import POINT

WINDOW = 6


def runs_at(path):
    """{run: {k: snapshot}}, run 0 the reference, run m twin m."""
    runs = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, cloud in reader.iter_decoded_messages():
            if channel.topic == "/tdex/snapshots":
                run = 0
            elif channel.topic.startswith("/tdex/twins/"):
                run = int(channel.topic.rsplit("/", 1)[1])
            else:
                continue
            assert cloud.point_stride == POINT.itemsize
            runs.setdefault(run, {})[message.sequence] = np.frombuffer(cloud.data, dtype=POINT)
    return runs


def cells_inside_bed(bed, reach, count, seed):
    rng = np.random.default_rng(seed)
    lo, hi = bed.min(0), bed.max(0)
    seeds = []
    while len(seeds) < count:
        x = lo + rng.random(3) * (hi - lo)
        if (((bed - x) ** 2).sum(1)).min() <= reach * reach:
            seeds.append(x)
    return np.array(seeds)


def cell_means(seeds, snap):
    pos = np.stack([snap["x"], snap["y"], snap["z"]], 1)
    cell = np.argmin(((pos[:, None, :] - seeds[None, :, :]) ** 2).sum(2), 1)
    count = np.bincount(cell, minlength=len(seeds))
    total = np.bincount(cell, weights=snap["T"], minlength=len(seeds))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def eps_abs(a, b):
    both = ~np.isnan(a) & ~np.isnan(b)
    return np.abs(a[both] - b[both]).mean()


def ratios(path, cells=200, seed=1):
    """({(run, k): ratio of run c to the others' floor}, the runs, the t_k all runs hold,
    {k: mean eps_abs over all pairs of runs})."""
    runs = runs_at(path)
    assert len(runs) >= 3, f"{path}: {len(runs)} DEM runs; a candidate needs at least two others"
    ref = runs[0]
    bed1 = np.stack([ref[1]["x"], ref[1]["y"], ref[1]["z"]], 1)
    seeds = cells_inside_bed(bed1, ref[1]["r"].max(), cells, seed)
    ks = sorted(k for k in ref if k >= 2 and all(k in r for r in runs.values()))
    ratio = {}
    floors = {}
    for k in ks:
        means = {m: cell_means(seeds, runs[m][k]) for m in runs}
        dist = {(a, b): eps_abs(means[a], means[b]) for a in runs for b in runs if a < b}
        d = lambda a, b: dist[(min(a, b), max(a, b))]
        floors[k] = np.mean(list(dist.values()))
        for c in runs:
            others = [m for m in runs if m != c]
            to_others = np.mean([d(c, m) for m in others])
            floor = np.mean([d(a, b) for i, a in enumerate(others) for b in others[i + 1:]])
            ratio[(c, k)] = to_others / floor
    return ratio, sorted(runs), ks, floors


def window_medians(ratio, runs, ks):
    """[(start s, [each run's median ratio over t_{s+1} … t_{s+WINDOW}])] for every full window."""
    out = []
    for s in range(1, ks[-1] - WINDOW + 1):
        window = [k for k in range(s + 1, s + WINDOW + 1) if k in ks]
        if len(window) == WINDOW:
            out.append((s, [statistics.median(ratio[(c, k)] for k in window) for c in runs]))
    return out


def main(path, cells=200, seed=1):
    ratio, runs, ks, floors = ratios(path, cells, seed)
    print(f"{path}: {len(runs)} DEM runs, {cells} cells (numpy seed {seed}), t_k = {ks[0]}…{ks[-1]}")
    print("floor (mean eps_abs over all pairs of runs, K, to set beside tdex compare's floor_eps_abs): "
          + ", ".join(f"t{k} {floors[k]:.3f}" for k in ks))
    values = []
    for s, row in window_medians(ratio, runs, ks):
        values += row
        print(f"start t{s} (t{s + 1}…t{s + WINDOW}): median ratio per run "
              + ", ".join(f"{m:.2f}" for m in row))
    print(f"all windows: {len(values)} medians, mean {statistics.mean(values):.3f}, "
          f"standard deviation {statistics.stdev(values):.3f}, {min(values):.2f}–{max(values):.2f}, "
          f"{sum(v <= 1 for v in values)} at most 1")


if __name__ == "__main__":
    main(sys.argv[1], *(int(a) for a in sys.argv[2:3]), *(int(a) for a in sys.argv[3:4]))

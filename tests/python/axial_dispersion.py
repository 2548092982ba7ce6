#!/usr/bin/env python3
"""Does the replay spread the particles along the axis at the DEM's rate? (diagnostic,
docs/method.md#6-the-replay)

usage: axial_dispersion.py REC.mcap EXTRA.mcap [REC.mcap EXTRA.mcap ...]
       (each REC recorded with --reference K --twins M, K of 100 or more; EXTRA an
       extrapolation of it over the same periods)

The axial dispersion over a lag of L periods: the mean square axial displacement of the
particles over L periods (less the bed's mean displacement), over L, in diameters squared per
period, averaged over starts t_2, t_12, t_22, … (where the replay has left the recorded
stretch). A random walk's is the same at every lag; the DEM's falls with the lag (a
particle's axial steps in successive periods partly cancel). Prints per bed the first two
periods' own (t_0 → t_1, the one a replay of one recorded period repeats, and t_1 → t_2, the
second of two) beside the DEM reference's periods'
(t_k → t_k+1 after t_1: their mean and standard deviation, how much one period's varies),
then at lags of 20 and 100 periods the
DEM's (the mean over the reference and its twins) beside the extrapolation's and their
ratio; last, over all the beds, how much one DEM run's dispersion over a single window of the
lag (windows that do not overlap) scatters: what a rate measured on so many DEM periods could
be trusted to. In the extrapolation a particle stands where the role it plays stands.
"""
import sys

import numpy as np

from period_map import snapshots
from spread import by_topic, dem_runs

LAGS = (20, 100)
START_EVERY = 10


def by_id(run):
    """{t_k: points sorted by id}: a particle's row is the same at every t_k."""
    return {k: np.sort(points, order="id") for k, points in run.items()}


def window(run, first, last, lag, diameter):
    """Mean square axial displacement from t_first to t_last, over `lag` (d² per period)."""
    step = (run[last]["y"] - run[first]["y"]) / diameter
    return float(np.mean((step - step.mean()) ** 2)) / lag


def dispersion(run, ks, lag, diameter):
    """The mean over starts every START_EVERY t_k of the dispersion over `lag` periods."""
    values = [window(run, ks[i], ks[i + lag], lag, diameter)
              for i in range(0, len(ks) - lag, START_EVERY)]
    return float(np.mean(values)) if values else float("nan")


def windows(run, ks, lag, diameter):
    """The dispersion over each window of `lag` periods, windows end to end from the first t_k."""
    return [window(run, ks[i], ks[i + lag], lag, diameter) for i in range(0, len(ks) - lag, lag)]


def bed(rec_path, extra_path):
    recorded = by_id(snapshots(rec_path))
    dem, twins = dem_runs(rec_path)
    extra = by_id(by_topic(extra_path)["/tdex/snapshots"])
    runs = [by_id(dem)] + [by_id(t) for t in twins]
    ks = [k for k in sorted(extra) if k >= 2 and all(k in r for r in runs)]
    diameter = 2.0 * float(np.median(recorded[0]["r"]))
    own = [window(recorded, k, k + 1, 1, diameter) for k in (0, 1) if k + 1 in recorded]
    reference = by_id(dem)
    periods = [k for k in sorted(reference) if k >= 1 and k + 1 in reference]
    one_period = [window(reference, k, k + 1, 1, diameter) for k in periods]
    by_lag, single = {}, {}
    for lag in LAGS:
        if len(ks) > lag:
            dem_value = np.mean([dispersion(r, ks, lag, diameter) for r in runs])
            by_lag[lag] = (dem_value, dispersion(extra, ks, lag, diameter))
            single[lag] = [w for r in runs for w in windows(r, ks, lag, diameter)]
    return own, (np.mean(one_period), np.std(one_period, ddof=1)), by_lag, single


def main(paths):
    if len(paths) % 2 or not paths:
        sys.exit(__doc__)
    print("axial dispersion, d² per period: the first two periods'; per lag the DEM runs' mean, "
          "the extrapolation's, and their ratio")
    print("bed                          t0→t1  t1→t2  DEM period     " + "  ".join(
        f"lag {lag:3d}: DEM   extra  ratio" for lag in LAGS))
    ratios = {lag: [] for lag in LAGS}
    single = {lag: [] for lag in LAGS}
    for rec, extra in zip(paths[::2], paths[1::2]):
        own, (period_mean, period_sd), by_lag, bed_windows = bed(rec, extra)
        for lag, values in bed_windows.items():
            single[lag].extend(values)
        cells = []
        for lag in LAGS:
            if lag in by_lag:
                dem_value, extra_value = by_lag[lag]
                ratios[lag].append(extra_value / dem_value)
                cells.append(f"     {dem_value:6.3f}  {extra_value:6.3f}  {extra_value / dem_value:5.2f}")
            else:
                cells.append(f"{'(too few t_k)':>28}")
        firsts = "  ".join(f"{value:5.3f}" for value in own)
        print(f"{rec:<28} {firsts:<12}  {period_mean:5.3f} ± {period_sd:5.3f}  " + "  ".join(cells))
    for lag in LAGS:
        values = np.array(ratios[lag])
        if len(values) > 1:
            print(f"lag {lag}: the extrapolation's over the DEM's {values.min():.2f}–"
                  f"{values.max():.2f}, its rms distance from 1 "
                  f"{np.sqrt(np.mean((values - 1) ** 2)):.2f}")
        values = np.array(single[lag])
        if len(values) > 1:
            print(f"lag {lag}: one DEM run over one window of {lag} periods: {values.mean():.3f} d² "
                  f"per period, standard deviation {values.std(ddof=1):.3f} "
                  f"({100 * values.std(ddof=1) / values.mean():.0f} %, {len(values)} windows)")


if __name__ == "__main__":
    main(sys.argv[1:])

#!/usr/bin/env python3
"""Does the replay's excess follow how often its periods are replayed, or the horizon?
(diagnostic, docs/validation.md#repetition-or-horizon)

usage: repetition_windows.py --periods K [--recorded-periods 4,8,12,16] [--seeds 1,2,3,4]
                             [--tables DIR] [--out DIR] REC.mcap [REC.mcap ...]
       (each REC recorded with --reference K and --twins 2 or more, and with --recorded-periods
       at least the largest P, or a P beyond its own replayed from DIR/REC, a recording of the
       same DEM run with more recorded periods and no reference; `tdex` is
       target/release/tdex unless TDEX names another)

By t_k a replay of P recorded periods has run each of them about r = k / P times. For each
recording, each P and each path seed, the script extrapolates K periods
(`tdex extrapolate --recorded-periods P --seed S`, uniform jumps, the exact pairing; kept in
DIR and reused), compares it with the DEM runs (`tdex compare --json`) and takes the median
ratio to the floor over windows of r and over windows of k (the seeds pooled, the t_k of the
recorded stretch left out). If the excess follows the repetition, the rows of several P
agree in windows of r and part in windows of k. Printed: per recording, then the mean over
the recordings ± its standard error; beside them a DEM run in the seat (each DEM run's
median over the same t_k, judged against the other runs as the replay is, their mean).
"""
import argparse
import functools
import json
import os
import statistics
import subprocess
import sys

from beds_summary import mean_se

R_WINDOWS = [(1, 3), (3, 6), (6, 9), (9, 12), (12, 18), (18, 25), (25, 40), (40, 80)]


def tdex():
    return os.environ.get("TDEX", "target/release/tdex")


@functools.lru_cache(maxsize=None)
def recorded_periods(rec):
    inspected = subprocess.run([tdex(), "inspect", rec, "--json"], check=True,
                               capture_output=True, text=True).stdout
    return json.loads(inspected)["recorded_periods"]


def extrapolated(rec, periods, p, seed, out, tables):
    """The compare JSON's periods of one replay, extrapolating it first unless kept. The
    replay runs the recording's own tables, or with P beyond them those of its namesake in
    `tables` (`tdex compare` judges a replay of another recording of the same DEM run)."""
    name = os.path.splitext(os.path.basename(rec))[0]
    path = os.path.join(out, f"p{p}_s{seed}_{name}.extra.mcap")
    if not os.path.exists(path):
        source = rec
        if tables and p > recorded_periods(rec):
            source = os.path.join(tables, os.path.basename(rec))
        subprocess.run([tdex(), "extrapolate", source, "--recorded-periods", str(p), "--periods",
                        str(periods), "--seed", str(seed), "--threads", "1", "-o", path],
                       check=True, capture_output=True)
    compared = subprocess.run([tdex(), "compare", rec, path, "--json"], check=True,
                              capture_output=True, text=True).stdout
    return json.loads(compared)["periods"]


def k_windows(first, last):
    """Five windows of k of about equal length from t_first to t_last."""
    edges = [round(first + i * (last + 1 - first) / 5) for i in range(6)]
    return list(zip(edges[:-1], edges[1:]))


def mean_se_text(xs):
    if len(xs) < 2:
        return f"{xs[0]:.2f}" if xs else "-"
    return "%.2f ± %.2f" % mean_se(xs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("recordings", nargs="+")
    ap.add_argument("--periods", type=int, required=True)
    ap.add_argument("--recorded-periods", default="4,8,12,16")
    ap.add_argument("--seeds", default="1,2,3,4")
    ap.add_argument("--tables", help="recordings of the same DEM runs with more recorded periods")
    ap.add_argument("--out", default="repetition")
    a = ap.parse_args()
    ps = [int(p) for p in a.recorded_periods.split(",")]
    seeds = [int(s) for s in a.seeds.split(",")]
    os.makedirs(a.out, exist_ok=True)
    ratio = {}  # (recording, P) -> [(k, ratio)] over the seeds
    dem = {}  # recording -> {k: each DEM run's ratio to the others}
    for rec in a.recordings:
        for p in ps:
            ratio[rec, p] = []
            for seed in seeds:
                for c in extrapolated(rec, a.periods, p, seed, a.out, a.tables):
                    if c["k"] > p and c["ratio_to_floor"] is not None:
                        ratio[rec, p].append((c["k"], c["ratio_to_floor"]))
                    if c.get("dem_runs_ratio_to_others"):
                        dem.setdefault(rec, {})[c["k"]] = c["dem_runs_ratio_to_others"]
        if rec not in dem:
            sys.exit(f"{rec}: no DEM run judged against the others; record it with --twins 2 or more")
    last = a.periods + 1

    def covered(p, lo, hi):
        """Whether the horizon holds at least half of the r window's t_k."""
        return min(hi * p, last + 1) - max(lo * p, p + 1) >= (hi - lo) * p / 2

    def replay(rec, p, lo, hi, by_r):
        if by_r and not covered(p, lo, hi):
            return None
        xs = [v for k, v in ratio[rec, p] if lo <= (k / p if by_r else k) < hi]
        return statistics.median(xs) if xs else None

    def dem_run(rec, lo, hi):
        ks = [k for k in dem[rec] if lo <= k < hi]
        if not ks:
            return None
        runs = len(dem[rec][ks[0]])
        return statistics.mean(statistics.median(dem[rec][k][i] for k in ks) for i in range(runs))

    kw = k_windows(max(ps) + 1, last)
    for by_r, windows, name in [(True, R_WINDOWS, "r = k/P"), (False, kw, "k")]:
        windows = [(lo, hi) for lo, hi in windows if not by_r or covered(min(ps), lo, hi)]
        head = " ".join(f"{lo}-{hi - 1 if not by_r else hi}".rjust(12) for lo, hi in windows)
        print(f"\nmedian ratio to the floor in windows of {name} ({len(seeds)} path seeds pooled)")
        print(f"{'recording':<16} {'P':>3} {head}")
        for rec in a.recordings:
            for p in ps:
                cells = [replay(rec, p, lo, hi, by_r) for lo, hi in windows]
                print(f"{os.path.basename(rec):<16} {p:>3} "
                      + " ".join(("-" if x is None else f"{x:.2f}").rjust(12) for x in cells))
        print(f"{'mean ± s.e.':<16}")
        for p in ps:
            cells = []
            for lo, hi in windows:
                xs = [replay(rec, p, lo, hi, by_r) for rec in a.recordings]
                cells.append(mean_se_text(xs) if None not in xs else "-")
            print(f"{'':<16} {p:>3} " + " ".join(c.rjust(12) for c in cells))
        print(f"{'a DEM run':<16}")
        for p in ps if by_r else [None]:
            cells = []
            for lo, hi in windows:
                k_lo, k_hi = (max(lo * p, p + 1), hi * p) if by_r else (lo, hi)
                xs = [dem_run(rec, k_lo, k_hi) for rec in a.recordings]
                cells.append(mean_se_text(xs) if None not in xs and (not by_r or covered(p, lo, hi)) else "-")
            print(f"{'':<16} {p if p else '':>3} " + " ".join(c.rjust(12) for c in cells))


if __name__ == "__main__":
    main()

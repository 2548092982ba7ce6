#!/usr/bin/env python3
"""One case on several beds over a long horizon (diagnostic, docs/validation.md): the paper's
method (P = 1) and two recorded periods (P = 2) against each bed's three DEM runs, beside each
DEM run judged in the extrapolation's seat, averaged over the beds with standard errors.

usage: beds_summary.py PREFIX SEED [SEED ...]
       (PREFIX_SEED.mcap recorded with --recorded-periods 2 --reference K --twins 2; tdex on
       the PATH or in TDEX; writes PREFIX_SEED.horizon/ with the study of each bed)

Per bed: `tdex study horizon --recorded-periods 1,2`, then `tdex compare --json` of each
extrapolation for its verdict: the median ratio to the floor, the share of the compared t_k
outside the DEM runs' range, the bed-mean error, and `dem_runs_median_ratio` (each DEM run in
the seat against the others). The three runs of a bed are not independent, so the DEM runs'
standard error is taken over the beds' means.
"""
import json
import os
import statistics as st
import subprocess
import sys

TDEX = os.environ.get("TDEX", "tdex")


def tdex(*args):
    return subprocess.run([TDEX, *args], check=True, capture_output=True, text=True).stdout


def mean_se(xs):
    return st.mean(xs), (st.stdev(xs) / len(xs) ** 0.5 if len(xs) > 1 else float("nan"))


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    prefix, seeds = sys.argv[1], sys.argv[2:]
    rows, seat = {1: [], 2: []}, []
    for s in seeds:
        rec, out = f"{prefix}_{s}.mcap", f"{prefix}_{s}.horizon"
        tdex("study", "horizon", rec, "--recorded-periods", "1,2", "-o", out, "--json")
        for p in (1, 2):
            v = json.loads(tdex("compare", rec, f"{out}/horizon_p{p}.extra.mcap", "--json"))["verdict"]
            outside = len(v["outside_range"]) / len(v["compared"])
            rows[p].append((v["median_ratio"], outside, v["means_error_max"], v["means_spread_max"]))
            if p == 1:
                seat.append(v["dem_runs_median_ratio"])
    print("seed  P = 1: median (outside)  P = 2: median (outside)  DEM runs in the seat")
    for k, s in enumerate(seeds):
        a, b = rows[1][k], rows[2][k]
        runs = ", ".join(f"{x:.3f}" for x in seat[k])
        print(f"{s:>4}  {a[0]:.3f} ({100 * a[1]:.0f} %)  {b[0]:.3f} ({100 * b[1]:.0f} %)  {runs}")
    for p in (1, 2):
        m, e = mean_se([r[0] for r in rows[p]])
        o, oe = mean_se([100 * r[1] for r in rows[p]])
        print(f"P = {p}: mean median {m:.3f} ± {e:.3f}; outside {o:.0f} ± {oe:.0f} %; bed-mean error "
              f"up to {max(r[2] for r in rows[p]):.3f} K (DEM runs apart by up to {max(r[3] for r in rows[p]):.3f} K)")
    every = [x for runs in seat for x in runs]
    m, e = mean_se([st.mean(runs) for runs in seat])
    print(f"a DEM run in the seat: mean median {m:.3f} ± {e:.3f} (over the beds' means); {len(every)} runs, "
          f"≤ 1 in {sum(x <= 1 for x in every)}, {min(every):.3f}–{max(every):.3f}")


if __name__ == "__main__":
    main()

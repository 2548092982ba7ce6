#!/usr/bin/env python3
"""Draws from t2 judged against twins that part at t2 (docs/validation.md#the-extrapolation-at-short-horizons). (diagnostic)

usage: fair_start_summary.py DIR BED [BED ...]
       DIR holds, for every BED (a seed), `tdex compare --json` outputs of the recording fBED.mcap
       (`--recorded-periods 2 --reference 7 --twins 3 --twins-from 2`): fBED_c.json (the second
       revolution repeated, `--jump-to 2`), fBED_d.json and fBED_e.json (two revolutions, the
       default path and `--seed 1`'s), fBED_b.json (one revolution from t1, `--recorded-periods 1`);
       and where present oBED_x.json: the paper's method, `tdex compare oBED.mcap` of a recording
       `--reference 7 --twins 3` (twins from t1) and its extrapolation over 7 periods.

Prints each draw's median ratio over t3…t8, each DEM run's own median judged against the
other three over the same t_k (compare's verdict.dem_runs_median_ratio), the means, and how
often a draw scores above a DEM run in the seat.
"""
import json
import statistics as st
import sys

DRAWS = {"b": "one revolution from t1", "c": "the second revolution repeated",
         "d": "two revolutions, default path", "e": "two revolutions, seed 1's path"}


def above(draws, runs):
    """How often a draw's median exceeds a DEM run's in the seat, over all pairs (ties count
    half): 0.5 where the draws score like DEM runs. The pairs are not independent (a bed's
    draws and runs share its DEM), so no p-value is given."""
    wins = sum((d > r) + 0.5 * (d == r) for d in draws for r in runs)
    return wins / (len(draws) * len(runs))


def main(folder, beds):
    draws = {m: [] for m in DRAWS}
    runs = []
    for b in beds:
        line = []
        for m in DRAWS:
            v = json.load(open(f"{folder}/f{b}_{m}.json"))["verdict"]
            draws[m].append(v["median_ratio"])
            line.append(f"{m} {v['median_ratio']:.2f}")
        seat = v["dem_runs_median_ratio"]
        runs += seat
        print(f"bed {b}: " + ", ".join(line) + "; DEM runs in the seat " + " ".join(f"{x:.2f}" for x in seat))
    for m, name in DRAWS.items():
        xs = draws[m]
        print(f"{name}: mean {st.mean(xs):.3f}, {min(xs):.2f}–{max(xs):.2f}, {sum(x <= 1 for x in xs)} of {len(xs)} at most 1, "
              f"above a DEM run in the seat with probability {above(xs, runs):.2f}")
    print(f"a DEM run in the seat: mean {st.mean(runs):.3f}, median {st.median(runs):.3f}, "
          f"{min(runs):.2f}–{max(runs):.2f}, {sum(x <= 1 for x in runs)} of {len(runs)} at most 1")
    paper_method(folder, beds)


def paper_method(folder, beds):
    """The paper's method on the same beds where recorded: oBED.mcap (`--reference 7 --twins 3`,
    twins from t1) extrapolated over 7 periods from t1 (oBED_x.json), medians over t2…t8."""
    draws, runs = [], []
    for b in beds:
        try:
            v = json.load(open(f"{folder}/o{b}_x.json"))["verdict"]
        except FileNotFoundError:
            continue
        draws.append(v["median_ratio"])
        runs += v["dem_runs_median_ratio"]
        print(f"bed {b}, one revolution from t1, twins from t1: {v['median_ratio']:.2f}; DEM runs in the seat "
              + " ".join(f"{x:.2f}" for x in v["dem_runs_median_ratio"]))
    if draws:
        print(f"one revolution from t1 (the paper's method, twins from t1): mean {st.mean(draws):.3f}, "
              f"{min(draws):.2f}–{max(draws):.2f}, {sum(x <= 1 for x in draws)} of {len(draws)} at most 1, "
              f"above a DEM run in the seat with probability {above(draws, runs):.2f}; the runs in the seat: "
              f"mean {st.mean(runs):.3f}, median {st.median(runs):.3f}, {sum(x <= 1 for x in runs)} of {len(runs)} at most 1")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])

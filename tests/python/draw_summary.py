#!/usr/bin/env python3
"""The small_drum draws of docs/validation.md#the-extrapolation-at-short-horizons,
summarised: per method, the medians of ratio_to_floor over the six t_k after each start, their
mean, standard error and count at most 1; the paired differences of two recorded revolutions
against one from the same start; and a rank comparison with a genuine DEM run judged in the
extrapolation's seat (run_as_candidate.py). (diagnostic)

usage: draw_summary.py DIR BED [BED ...]
       DIR holds, for every BED (a seed), the recording sBED.mcap and `tdex compare --json`
       outputs sBED_cK.json (one revolution, start tK, K = 1…8), sBED_dK.json (two revolutions,
       default path, K = 2…8) and sBED_eK.json (two revolutions, --seed 1, K = 2…8).
"""
import json
import math
import statistics as st
import sys

import run_as_candidate

WINDOW = 6


def draw_median(path, start):
    periods = json.load(open(path))["periods"]
    return st.median(p["ratio_to_floor"] for p in periods
                     if start + 1 <= p["k"] <= start + WINDOW and p["ratio_to_floor"] is not None)


def describe(name, xs):
    sd = st.stdev(xs)
    print(f"{name}: n {len(xs)}, {min(xs):.2f}–{max(xs):.2f}, mean {st.mean(xs):.3f} "
          f"(standard error {sd / math.sqrt(len(xs)):.3f}, sd {sd:.3f}), median {st.median(xs):.3f}, "
          f"{sum(x <= 1 for x in xs)} at most 1")


def above(a, b):
    """P(a draw of a > one of b), ties half, and a one-sided normal-approximation p-value that
    treats every value as independent (they are not: see docs/validation.md)."""
    u = sum((x > y) + 0.5 * (x == y) for x in a for y in b)
    n1, n2 = len(a), len(b)
    z = (u - n1 * n2 / 2) / math.sqrt(n1 * n2 * (n1 + n2 + 1) / 12)
    return u / (n1 * n2), 0.5 * math.erfc(z / math.sqrt(2))


def main(folder, beds):
    med = {m: {(b, k): draw_median(f"{folder}/s{b}_{m}{k}.json", k)
               for b in beds for k in range(1 if m == "c" else 2, 9)} for m in "cde"}
    dem = {}
    for b in beds:
        ratio, runs, ks, _ = run_as_candidate.ratios(f"{folder}/s{b}.mcap")
        for s, row in run_as_candidate.window_medians(ratio, runs, ks):
            dem[(b, s)] = row
    for lo, hi in [(1, 4), (2, 4), (2, 5)]:
        print(f"starts t{lo}…t{hi}")
        one = [med["c"][(b, k)] for b in beds for k in range(lo, hi + 1)]
        describe("  one revolution", one)
        runs = [x for b in beds for k in range(lo, hi + 1) for x in dem[(b, k)]]
        describe("  a DEM run in the seat", runs)
        print("  one revolution above a DEM run: P {:.2f}, p {:.3f}".format(*above(one, runs)))
        if lo < 2:
            continue
        for m, path in [("d", "default path"), ("e", "path of seed 1")]:
            two = [med[m][(b, k)] for b in beds for k in range(lo, hi + 1)]
            describe(f"  two revolutions, {path}", two)
            diff = [med[m][(b, k)] - med["c"][(b, k)] for b in beds for k in range(lo, hi + 1)]
            describe(f"    minus one revolution", diff)
            print(f"    lower in {sum(x < -0.005 for x in diff)}, equal in {sum(abs(x) <= 0.005 for x in diff)}")
            print("    above a DEM run: P {:.2f}, p {:.3f}".format(*above(two, runs)))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])

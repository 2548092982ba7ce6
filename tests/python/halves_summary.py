#!/usr/bin/env python3
"""Half-revolution periods on small_drum (docs/validation.md#the-extrapolation-at-short-horizons): does a third recorded half revolution bring one revolution's draws to two's? (diagnostic)

usage: halves_summary.py DIR BED [BED ...]
       DIR holds, for every BED (a seed), the recording hBED.mcap (`--tau-rev 0.5
       --recorded-periods 8 --reference 19 --twins 3`) and `tdex compare --json` outputs
       hBED_NPH.json: N = 2, 3, 4 half-revolution periods (`--jump-to H-N+1,…,H`), P = d (the
       default path) or e (`--seed 1`), start H = 4, 6, 8 half revolutions (t2, t3, t4 in
       revolutions).

Each draw's median ratio_to_floor is over the six whole revolutions after its start
(k = H+2, H+4, …, H+12 in half revolutions), the instants of the one-revolution draws; a
genuine DEM run judged in the extrapolation's seat (run_as_candidate.py) over the same k.
Then, per bed, how far the reference and the twins part (mean particle distance, diameters,
and mean cell distance, K, reference to twins against twin to twin), and, where DIR holds
vBED.mcap (`tdex record small_drum_seedBED.toml -o vBED.mcap`, τ = one revolution), whether
its t1 is hBED.mcap's t2 bit for bit: the same DEM run, whatever τ.
"""
import json
import os
import statistics as st
import sys

import numpy as np

import run_as_candidate
from draw_summary import above, describe

STARTS = (4, 6, 8)
WINDOW = [2 * i for i in range(1, 7)]


def draw_median(path, start):
    ratio = {p["k"]: p["ratio_to_floor"] for p in json.load(open(path))["periods"]}
    return st.median(ratio[start + w] for w in WINDOW)


def main(folder, beds):
    med = {(n, p, b, h): draw_median(f"{folder}/h{b}_{n}{p}{h}.json", h)
           for n in (2, 3, 4) for p in "de" for b in beds for h in STARTS}
    dem, seat = [], {}
    for b in beds:
        ratio, runs, ks, _ = run_as_candidate.ratios(f"{folder}/h{b}.mcap")
        for h in STARTS:
            seat[(b, h)] = [st.median(ratio[(c, h + w)] for w in WINDOW) for c in runs]
            dem += seat[(b, h)]
    describe("a DEM run in the seat", dem)
    # A draw from t_H is the reference until t_H and is judged against the twins alone, which
    # parted at t1: set its score beside the reference's own score in the seat at that start.
    print("per start: the reference's score in the seat, the twins', and the mean of the six draws")
    refs, draws = [], []
    for b in beds:
        for h in STARTS:
            mean_draw = st.mean(med[(n, p, b, h)] for n in (2, 3, 4) for p in "de")
            refs.append(seat[(b, h)][0])
            draws.append(mean_draw)
            print(f"  bed {b}, start t{h}: reference {seat[(b, h)][0]:.2f}, twins "
                  + " ".join(f"{x:.2f}" for x in seat[(b, h)][1:]) + f", draws {mean_draw:.2f}")
    print(f"  correlation of the draws' mean with the reference's score: "
          f"{st.correlation(refs, draws):.2f} over {len(refs)} starts")
    for b in beds:
        print(f"bed {b}: " + "; ".join(
            f"{n} halves " + " ".join(f"{med[(n, p, b, h)]:.2f}" for p in "de" for h in STARTS)
            for n in (2, 3, 4)))
    for n in (2, 3, 4):
        xs = [med[(n, p, b, h)] for p in "de" for b in beds for h in STARTS]
        describe(f"{n} half revolutions (both paths)", xs)
        print("  above a DEM run: P {:.2f}, p {:.3f}".format(*above(xs, dem)))
        if n > 2:
            diff = [med[(n, p, b, h)] - med[(2, p, b, h)] for p in "de" for b in beds for h in STARTS]
            print(f"  minus 2 halves, same start and path: mean {st.mean(diff):+.3f} (standard error "
                  f"{st.stdev(diff) / len(diff) ** 0.5:.3f}), {min(diff):+.2f}…{max(diff):+.2f}, "
                  f"lower in {sum(d < -0.005 for d in diff)} of {len(diff)}")


def parting(folder, beds):
    for b in beds:
        runs = run_as_candidate.runs_at(f"{folder}/h{b}.mcap")
        ref = runs[0]
        bed1 = np.stack([ref[1][f] for f in "xyz"], 1)
        seeds = run_as_candidate.cells_inside_bed(bed1, ref[1]["r"].max(), 200, 1)
        diameter = 2 * ref[1]["r"].max()
        twins = [m for m in runs if m != 0]
        pairs = [(a, c) for i, a in enumerate(twins) for c in twins[i + 1:]]
        line = []
        for k in (2, 16, 20):
            pos = {m: np.stack([runs[m][k][f] for f in "xyz"], 1) for m in runs}
            apart = lambda a, c: np.sqrt(((pos[a] - pos[c]) ** 2).sum(1)).mean() / diameter
            means = {m: run_as_candidate.cell_means(seeds, runs[m][k]) for m in runs}
            cell = lambda a, c: run_as_candidate.eps_abs(means[a], means[c])
            line.append(f"t{k}: {st.mean(apart(0, m) for m in twins):.2f} / "
                        f"{st.mean(apart(a, c) for a, c in pairs):.2f} d, "
                        f"{st.mean(cell(0, m) for m in twins):.3f} / {st.mean(cell(a, c) for a, c in pairs):.3f} K")
        print(f"bed {b}, reference to twins / twin to twin: " + "; ".join(line))
        whole = f"{folder}/v{b}.mcap"
        if os.path.exists(whole):
            one = run_as_candidate.runs_at(whole)[0][1]
            same = all(np.array_equal(one[f], ref[2][f]) for f in ("x", "y", "z", "T"))
            print(f"  {whole}'s t1 is h{b}.mcap's t2 bit for bit: {same}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
    parting(sys.argv[1], sys.argv[2:])

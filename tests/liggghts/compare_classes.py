#!/usr/bin/env python3
"""Compare the size classes of LIGGGHTS runs and tdex runs of one case, seed against seed.

usage: compare_classes.py CASE.toml --liggghts OUTDIR... --tdex VTKDIR... [--json]

OUTDIR: a run of run_case.sh (its dump_classes files); VTKDIR: `tdex export vtk` of a
recording (see tdex_classes.py).  For each time since t0 that every run has (in drum
revolutions) and each quantity (the bed mean's rise since t0, each class's mean
temperature, the segregation index) it prints every run's value, the min..max of each
engine's runs, whether the two ranges overlap, and the gap between them (0 when they
overlap) next to the larger of the two engines' own spreads (max - min).
Python stdlib only.
"""
import json
import sys
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from summarize import liggghts_classes  # noqa: E402
from tdex_classes import tdex_classes  # noqa: E402


def quantities(row, t0_row, radii):
    q = {"bed_mean_rise": row["bed_mean"] - t0_row["bed_mean"]}
    for r, T in zip(radii, row["class_mean"]):
        q["T_%gmm" % (r * 1e3)] = T
    q["segregation_index"] = row["segregation_index"]
    return q


def main():
    argv = sys.argv[1:]
    as_json = "--json" in argv
    argv = [a for a in argv if a != "--json"]
    if len(argv) < 5 or "--liggghts" not in argv or "--tdex" not in argv:
        sys.exit(__doc__)
    case = tomllib.loads(Path(argv[0]).read_text())
    il, it = argv.index("--liggghts"), argv.index("--tdex")
    ldirs = argv[il + 1:it] if il < it else argv[il + 1:]
    tdirs = argv[it + 1:il] if it < il else argv[it + 1:]
    runs = [("liggghts", d, liggghts_classes(Path(d), case)) for d in ldirs]
    runs += [("tdex", d, tdex_classes(case, Path(d))) for d in tdirs]
    radii = runs[0][2]["radii"]
    times = sorted(set.intersection(*[{row["revolutions"] for row in c["series"]} for _, _, c in runs]))
    table = []
    for rev in times:
        vals = []
        for engine, d, c in runs:
            row = next(r for r in c["series"] if r["revolutions"] == rev)
            vals.append((engine, d, quantities(row, c["series"][0], radii)))
        for name in vals[0][2]:
            lv = [v[name] for e, _, v in vals if e == "liggghts"]
            tv = [v[name] for e, _, v in vals if e == "tdex"]
            lo_l, hi_l, lo_t, hi_t = min(lv), max(lv), min(tv), max(tv)
            gap = max(0.0, lo_t - hi_l, lo_l - hi_t)
            table.append({"revolutions": rev, "quantity": name,
                          "liggghts": lv, "tdex": tv,
                          "liggghts_range": [lo_l, hi_l], "tdex_range": [lo_t, hi_t],
                          "overlap": gap == 0.0, "gap": gap,
                          "largest_seed_spread": max(hi_l - lo_l, hi_t - lo_t)})
    if as_json:
        print(json.dumps({"runs": [[e, d] for e, d, _ in runs], "rows": table}, indent=1))
        return
    print("# runs: " + "; ".join(f"{e} {d}" for e, d, _ in runs))
    print("# rev quantity | liggghts values | tdex values | overlap gap largest_seed_spread")
    for r in table:
        f = "%.5f" if r["quantity"] == "segregation_index" else "%.3f"
        print("%-4g %-18s | %s | %s | %-5s %s %s" % (
            r["revolutions"], r["quantity"], " ".join(f % x for x in r["liggghts"]),
            " ".join(f % x for x in r["tdex"]), "yes" if r["overlap"] else "no",
            f % r["gap"], f % r["largest_seed_spread"]))


if __name__ == "__main__":
    main()

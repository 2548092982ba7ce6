#!/usr/bin/env python3
"""Markdown tables of a long-horizon comparison (docs/validation.md#long-horizons-100-periods-and-more).

    python3 tests/python/horizon_table.py CAPACITY K1,K2,... LABEL=compare.json [...]

Each compare.json is `tdex compare REC EXTRA --json` of one extrapolation against a recording
with DEM twins. CAPACITY is one particle's heat capacity m c (J/K; equal particles), which
turns the change of a bed mean over a period into the heat the walls gave in it. Prints, per
LABEL, a row for each k asked for, then the verdict's summary over every compared t_k.
"""
import json
import sys


def f(x, digits=2):
    return "–" if x is None else f"{x:.{digits}f}"


def main():
    capacity = float(sys.argv[1])
    ks = [int(k) for k in sys.argv[2].split(",")]
    for arg in sys.argv[3:]:
        label, path = arg.rsplit("=", 1)
        c = json.load(open(path))
        n = c["particles"]
        periods = {p["k"]: p for p in c["periods"]}
        dem = {g["k"]: g for g in c["dem_series"]}
        runs = [{g["k"]: g for g in s} for s in c["dem_runs_series"]]
        groups = c["hot_particles"] > 0
        print(f"\n**{label}**\n")
        if groups:
            print("| k | t (s) | hot / cold DEM (K) | twins | extrapolated | ε_abs (K) | floor mean (min–max) | ratio | ε_rel | floor ε_rel | Eq. 10 |")
            print("|---|---|---|---|---|---|---|---|---|---|---|")
        else:
            print("| k | t (s) | bed DEM (K) | bed twins (K) | bed extrapolated (K) | ε_abs (K) | floor mean (min–max) | ratio | ε_rel | Eq. 10 | wall heat per period (J): DEM / twins / extrapolated |")
            print("|---|---|---|---|---|---|---|---|---|---|---|")
        for k in ks:
            p = periods.get(k)
            if p is None:
                continue
            pct = lambda x: "–" if x is None else f"{100 * x:.1f} %"
            floor = f"{f(p['floor_eps_abs'], 3)} ({f(p['floor_eps_abs_min'], 3)}–{f(p['floor_eps_abs_max'], 3)})"
            if groups:
                twins = " ; ".join(f"{h:.2f} / {cd:.2f}" for h, cd in zip(p["dem_runs_hot_mean"], p["dem_runs_cold_mean"]))
                print(f"| {k} | {p['t']:.0f} | {p['hot_mean_dem']:.2f} / {p['cold_mean_dem']:.2f} | {twins} | "
                      f"{p['hot_mean_extra']:.2f} / {p['cold_mean_extra']:.2f} | {p['eps_abs']:.3f} | {floor} | "
                      f"{f(p['ratio_to_floor'])} | {pct(p['eps_rel'])} | {pct(p['floor_eps_rel'])} | {pct(p['energy_error'])} |")
            else:
                heat = lambda now, before: n * capacity * (now - before)
                prev = periods.get(k - 1)
                dem_heat = heat(dem[k]["bed"], dem[k - 1]["bed"])
                # a twin parts from the DEM at t1: its t1 is the DEM's
                twin_heat = [heat(r[k]["bed"], r.get(k - 1, dem[k - 1])["bed"]) for r in runs]
                extra_before = prev["bed_mean_extra"] if prev else dem[k - 1]["bed"]
                extra_heat = heat(p["bed_mean_extra"], extra_before)
                twins = " / ".join(f"{b:.2f}" for b in p["dem_runs_bed_mean"])
                heats = " / ".join(f"{h:.0f}" for h in [dem_heat, *twin_heat, extra_heat])
                print(f"| {k} | {p['t']:.0f} | {p['bed_mean_dem']:.2f} | {twins} | {p['bed_mean_extra']:.2f} | "
                      f"{p['eps_abs']:.3f} | {floor} | {f(p['ratio_to_floor'])} | {pct(p['eps_rel'])} | "
                      f"{pct(p['energy_error'])} | {heats} |")
        v = c["verdict"]
        print(f"\nover t2…t{max(periods)}: median ratio {f(v['median_ratio'])}, range "
              f"{f(v['ratio_min'])}–{f(v['ratio_max'])}, outside the DEM runs' range at "
              f"{len(v['outside_range'])} of {len(v['compared'])} t_k; largest mean error "
              f"{f(v['means_error_max'], 3)} K against a DEM spread of {f(v['means_spread_max'], 3)} K")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Print one JSON object summarising a LIGGGHTS peer run made by run_case.sh.

usage: summarize.py OUTDIR [--bed-mean]

With --bed-mean it prints instead one row per `temps.txt` row of the heating run: step,
time since t0 (s) and the bed mean temperature (K), the count-weighted mean of the hot and
cold means.

Reads OUTDIR/case.toml, log.liggghts, screen.txt, marks.txt, temps.txt and
dump_T.{start,end}.txt.  Temperatures and heat come from the deck's prints (15
significant digits); `from_dumps` recomputes them from the 17-digit dumps as a check.
Heating wall time is LIGGGHTS' own "Loop time" of the heating run; CPU time is the
user+system time of the liggghts process between the marks around that run.
"""
import json
import math
import os
import re
import sys
import tomllib
from pathlib import Path


def kv(line):
    return {k: float(v) for k, v in re.findall(r"(\w+)=(\S+)", line)}


def read_dump(path):
    lines = path.read_text().splitlines()
    i = lines.index(next(l for l in lines if l.startswith("ITEM: ATOMS")))
    return {int(r.split()[0]): float(r.split()[4]) for r in lines[i + 1:] if r.strip()}


def main():
    out = Path(sys.argv[1])
    case = tomllib.loads((out / "case.toml").read_text())
    N, rp = case["particles"]["count"], case["particles"]["radius"]
    mc = case["material"]["density"] * 4 / 3 * math.pi * rp ** 3 * case["material"]["heat_capacity"]
    split = case["temperature"]["mode"] == "split"

    log = (out / "log.liggghts").read_text().splitlines()
    screen = (out / "screen.txt").read_text().splitlines()
    version = next(l for l in screen if l.startswith("LIGGGHTS (Version"))
    inserted = int(re.search(r"INSERTED (\d+)", "\n".join(log)).group(1))
    start = kv(next(l for l in log if l.startswith("HEATING_START")))
    end = kv(next(l for l in log if l.startswith("HEATING_END")))
    nheat = int(end["step"] - start["step"])
    loops = [re.match(r"Loop time of (\S+) on \d+ procs for (\d+) steps", l) for l in log]
    wall = [float(m.group(1)) for m in loops if m and int(m.group(2)) == nheat][-1]

    marks = {l.split()[0]: l.split() for l in (out / "marks.txt").read_text().splitlines()}
    tck = os.sysconf("SC_CLK_TCK")
    cpu = (sum(map(int, marks["end_heat"][3:5])) - sum(map(int, marks["start_heat"][3:5]))) / tck

    rows = [list(map(float, l.split())) for l in (out / "temps.txt").read_text().splitlines()
            if l.strip() and not l.startswith("#")]
    rows = {int(r[0]): r for r in rows if start["step"] < r[0] <= end["step"]}
    z_mean = sum(r[4] for r in rows.values()) / len(rows)
    nh, nc = start["hot"], start["cold"]
    bed = lambda Th, Tc: (nh * Th + nc * Tc) / (nh + nc)
    if sys.argv[2:] == ["--bed-mean"]:
        dt = case["time"]["dt"]
        print("# step t_since_t0(s) bed_mean_T(K)")
        print("%d %.6g %.15g" % (start["step"], 0.0, bed(start["Thot"], start["Tcold"])))
        for k, r in sorted(rows.items()):
            print("%d %.6g %.15g" % (k, (k - start["step"]) * dt, bed(r[1], r[2])))
        return

    warnings = {}
    for i, l in enumerate(screen):
        if l.startswith("WARNING:"):
            w = l[8:].strip() or screen[i + 1].strip()
            warnings[w] = warnings.get(w, 0) + 1

    d0, d1 = read_dump(out / "dump_T.start.txt"), read_dump(out / "dump_T.end.txt")
    hot_ids = [i for i, T in d0.items() if T == case["temperature"]["hot"]] if split else []
    cold_ids = [i for i in d0 if i not in set(hot_ids)] if split else []
    mean = lambda d, ids: sum(d[i] for i in ids) / len(ids) if ids else None

    print(json.dumps({
        "case": case.get("name", ""),
        "liggghts_version": version,
        "particles": inserted,
        "particles_requested": N,
        "hot_particles": int(start["hot"]),
        "cold_particles": int(start["cold"]),
        "dt": case["time"]["dt"],
        "heating_steps": nheat,
        "heating_first_step": int(start["step"]),
        "hot_mean_start": start["Thot"],
        "cold_mean_start": start["Tcold"],
        "hot_mean_end": end["Thot"],
        "cold_mean_end": end["Tcold"],
        "bed_mean_start": bed(start["Thot"], start["Tcold"]),
        "bed_mean_end": bed(end["Thot"], end["Tcold"]),
        "wall_temperature": case["drum"].get("wall_temperature"),
        "total_heat_start": start["Q"],
        "total_heat_end": end["Q"],
        "total_heat_rel_change": (end["Q"] - start["Q"]) / start["Q"],
        "contacts_per_particle_start": start["Z"],
        "contacts_per_particle_mean": z_mean,
        "contacts_per_particle_end": end["Z"],
        "contacts_rows": len(rows),
        "heating_wall_s": wall,
        "heating_cpu_s": cpu,
        "particle_steps_per_s": inserted * nheat / wall,
        "particle_steps_per_cpu_s": inserted * nheat / cpu if cpu > 0 else None,
        "from_dumps": {
            "particles_start": len(d0), "particles_end": len(d1),
            "hot_mean_end": mean(d1, hot_ids), "cold_mean_end": mean(d1, cold_ids),
            "bed_mean_start": mean(d0, list(d0)), "bed_mean_end": mean(d1, list(d1)),
            "total_heat_start": mc * sum(d0.values()), "total_heat_end": mc * sum(d1.values()),
        },
        "warnings": warnings,
    }, indent=1))


if __name__ == "__main__":
    main()

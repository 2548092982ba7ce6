#!/usr/bin/env python3
"""Print one JSON object summarising a LIGGGHTS peer run made by run_case.sh.

usage: summarize.py OUTDIR [--bed-mean | --classes]

With --bed-mean it prints instead one row per `temps.txt` row of the heating run: step,
time since t0 (s) and the bed mean temperature (K), the count-weighted mean of the hot and
cold means.

A bed of several sizes also gets `classes`, from the deck's dump_classes.STEP files (t0 and
every half revolution of heating): per dump the bed mean (r^3-weighted, as tdex's), each size
class's mean temperature and relative distance, and the radial segregation index, as
src/compare/classes.rs defines them.  With --classes only that object is printed.

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


def read_class_dump(path):
    """(step, ids, radius, [x, y, z], T) of a dump_classes.STEP file (id radius x y z T)."""
    lines = path.read_text().splitlines()
    step = int(lines[lines.index("ITEM: TIMESTEP") + 1])
    i = lines.index(next(l for l in lines if l.startswith("ITEM: ATOMS")))
    rows = [r.split() for r in lines[i + 1:] if r.strip()]
    return (step, [int(r[0]) for r in rows], [float(r[1]) for r in rows],
            [(float(r[2]), float(r[3]), float(r[4])) for r in rows], [float(r[5]) for r in rows])


def class_state(radius, pos, temp):
    """The size classes' state in one snapshot, as src/compare/classes.rs: classes are the
    distinct radii, smallest first; a class mean is the plain mean of its particles; a class's
    relative distance is the mean distance of its centres from the bed's centroid in (x, z)
    over the same mean for all particles; the index is the largest class's minus the
    smallest's.  The bed mean is weighted by r^3 (src/compare/metrics.rs `bed_mean`)."""
    radii = sorted(set(radius))
    cls = {r: k for k, r in enumerate(radii)}
    n = max(len(pos), 1)
    cx = cz = 0.0
    for p in pos:
        cx += p[0] / n
        cz += p[2] / n
    dist = [math.hypot(p[0] - cx, p[2] - cz) for p in pos]
    mean_all = sum(dist) / n
    count, tsum, dsum = [0] * len(radii), [0.0] * len(radii), [0.0] * len(radii)
    for r, d, t in zip(radius, dist, temp):
        k = cls[r]
        count[k] += 1
        tsum[k] += t
        dsum[k] += d
    rel = [ds / k / mean_all if k and mean_all > 0 else float("nan") for ds, k in zip(dsum, count)]
    heat = sum(r ** 3 * t for r, t in zip(radius, temp))
    return {
        "radii": radii,
        "counts": count,
        "bed_mean": heat / sum(r ** 3 for r in radius),
        "bed_mean_number": sum(temp) / len(temp),
        "class_mean": [ts / k for ts, k in zip(tsum, count)],
        "relative_distance": rel,
        "segregation_index": rel[-1] - rel[0],
    }


def class_series(snaps, t0, period):
    """`class_state` of each (time, radius, pos, temp), with the time since t0 and in revolutions."""
    out = []
    for t, radius, pos, temp in snaps:
        st = class_state(radius, pos, temp)
        out.append({"t": t - t0, "revolutions": round((t - t0) / period, 9), **st})
    return out


def liggghts_classes(out, case):
    """The `classes` object of a LIGGGHTS run (None without dump_classes files)."""
    files = sorted(out.glob("dump_classes.*"), key=lambda f: int(f.suffix[1:]))
    if not files:
        return None
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from deck_from_case import size_classes
    radii, counts = size_classes(case["particles"])
    dt, period = case["time"]["dt"], case["drum"]["rotation_period"]
    dumps = [read_class_dump(f) for f in files]
    t0 = dumps[0][0] * dt
    series = class_series([(d[0] * dt, d[2], d[3], d[4]) for d in dumps], t0, period)
    for row, d in zip(series, dumps):
        row["step"] = d[0]
    return {"radii": radii, "requested": counts, "inserted": series[0]["counts"],
            "series": series}


def print_classes(c, label=""):
    """The per-class table as text."""
    print(f"# {label}radii (mm) " + " ".join("%g" % (r * 1e3) for r in c["radii"])
          + "; requested " + " ".join(map(str, c["requested"]))
          + "; in the bed " + " ".join(map(str, c["inserted"])))
    print("# rev  bed_mean(K)  " + "  ".join("T_%gmm" % (r * 1e3) for r in c["radii"])
          + "  " + "  ".join("d_%gmm" % (r * 1e3) for r in c["radii"]) + "  seg_index")
    for row in c["series"]:
        print("%.3g %.4f " % (row["revolutions"], row["bed_mean"])
              + " ".join("%.4f" % x for x in row["class_mean"]) + " "
              + " ".join("%.5f" % x for x in row["relative_distance"])
              + " %.5f" % row["segregation_index"])


def main():
    out = Path(sys.argv[1])
    case = tomllib.loads((out / "case.toml").read_text())
    N, rp = case["particles"]["count"], case["particles"].get("radius")
    rho_c = case["material"]["density"] * case["material"]["heat_capacity"]
    mc = rho_c * 4 / 3 * math.pi * rp ** 3 if rp is not None else None
    split = case["temperature"]["mode"] == "split"
    classes = liggghts_classes(out, case)
    if sys.argv[2:] == ["--classes"]:
        if classes is None:
            sys.exit(f"{out}: no dump_classes files (a bed of one size)")
        print_classes(classes)
        return

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
    if mc is None:  # several sizes: each particle's m c from its radius in the class dumps
        f = next(iter(sorted(out.glob("dump_classes.*"))), None)
        rad = dict(zip(*read_class_dump(f)[1:3])) if f else {}
        heat = lambda d: (sum(rho_c * 4 / 3 * math.pi * rad[i] ** 3 * T for i, T in d.items())
                          if rad else None)
    else:
        heat = lambda d: mc * sum(d.values())

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
            "total_heat_start": heat(d0), "total_heat_end": heat(d1),
        },
        "warnings": warnings,
        **({"classes": classes} if classes else {}),
    }, indent=1))


if __name__ == "__main__":
    main()

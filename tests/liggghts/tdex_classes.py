#!/usr/bin/env python3
"""The size classes' numbers of a tdex run, as summarize.py gives them for a LIGGGHTS run.

usage: tdex_classes.py CASE.toml VTKDIR [--json]

VTKDIR is `tdex export vtk REC.mcap -o VTKDIR` of a recording: its REC.pvd lists the
snapshots (t0, t1, then the reference snapshots) with their simulated times, and each
REC_NNNN.vtp holds the arrays temperature, radius, id and position (ASCII, Rust's
shortest round-trip numbers).  Prints for each snapshot the time since t0 in drum
revolutions, the bed mean (r^3-weighted), each size class's mean temperature and relative
distance, and the segregation index (`class_state` of summarize.py); with --json the same
as one JSON object (the `classes` object of summarize.py's summary).  Twins' series
(REC_twinM.pvd) are left out.  Python stdlib only.
"""
import json
import re
import sys
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from deck_from_case import size_classes  # noqa: E402
from summarize import class_series, print_classes  # noqa: E402


def read_vtp(path):
    """{array name: [floats]} of a tdex .vtp file (ASCII DataArrays)."""
    text = path.read_text()
    arrays = {}
    for m in re.finditer(r'<DataArray [^>]*Name="(\w+)"[^>]*>(.*?)</DataArray>', text, re.S):
        arrays[m.group(1)] = [float(x) for x in m.group(2).split()]
    return arrays


def tdex_classes(case, vtkdir):
    pvds = [p for p in sorted(vtkdir.glob("*.pvd")) if "_twin" not in p.stem]
    if len(pvds) != 1:
        sys.exit(f"{vtkdir}: expected one .pvd series (besides twins), found {len(pvds)}")
    series = re.findall(r'<DataSet timestep="([^"]+)"[^>]*file="([^"]+)"', pvds[0].read_text())
    snaps = []
    for t, name in series:
        a = read_vtp(vtkdir / name)
        xyz = a["position"]
        pos = [tuple(xyz[3 * i:3 * i + 3]) for i in range(len(xyz) // 3)]
        snaps.append((float(t), a["radius"], pos, a["temperature"]))
    radii, counts = size_classes(case["particles"])
    out = class_series(snaps, snaps[0][0], case["drum"]["rotation_period"])
    return {"radii": radii, "requested": counts, "inserted": out[0]["counts"], "series": out}


def main():
    args = [a for a in sys.argv[1:] if a != "--json"]
    if len(args) != 2:
        sys.exit(__doc__)
    case = tomllib.loads(Path(args[0]).read_text())
    c = tdex_classes(case, Path(args[1]))
    if "--json" in sys.argv:
        print(json.dumps(c, indent=1))
    else:
        print_classes(c)


if __name__ == "__main__":
    main()

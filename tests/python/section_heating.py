#!/usr/bin/env python3
"""Heat-up of a bed, or of the middle of a long one, from `tdex export vtk` series
(docs/validation.md#a-periodic-section-against-a-long-drum).

usage: section_heating.py [--middle HALF_WIDTH_M] DIR [DIR ...]
       (each DIR the output of `tdex export vtk RECORDING -o DIR`)

For each series, the mean temperature (K) at every snapshot of the particles whose centre
lies within HALF_WIDTH_M of the drum's mid-plane y = 0 (all particles without --middle):
a drum with end caps long enough that the caps do not reach its middle heats there as an
endless drum would, which is what a periodic section stands for. Python stdlib only.
"""
import sys
import xml.etree.ElementTree as ET
from pathlib import Path


def arrays(vtp):
    """The point arrays of one .vtp file written by tdex (ASCII, one tuple per line)."""
    root = ET.parse(vtp).getroot()
    found = {}
    for a in root.iter("DataArray"):
        values = [float(x) for x in a.text.split()]
        k = int(a.get("NumberOfComponents", "1"))
        found[a.get("Name")] = [values[i:i + k] for i in range(0, len(values), k)] if k > 1 else values
    return found


def series(directory):
    """(time, file) of every snapshot of the series, in its order."""
    pvd = next(Path(directory).glob("*.pvd"))
    root = ET.parse(pvd).getroot()
    return [(float(d.get("timestep")), pvd.parent / d.get("file")) for d in root.iter("DataSet")]


def main(argv):
    middle = None
    if argv[:1] == ["--middle"]:
        middle, argv = float(argv[1]), argv[2:]
    if not argv:
        sys.exit(__doc__)
    columns = []
    for directory in argv:
        rows = []
        for time, vtp in series(directory):
            a = arrays(vtp)
            temps = [t for t, p in zip(a["temperature"], a["position"]) if middle is None or abs(p[1]) <= middle]
            rows.append((time, sum(temps) / len(temps), len(temps)))
        columns.append(rows)
    t0 = columns[0][0][0]
    print("time after t0 (s) | " + " | ".join(Path(d).name for d in argv))
    for k in range(min(len(c) for c in columns)):
        cells = [f"{c[k][1]:.3f} ({c[k][2]})" for c in columns]
        print(f"{columns[0][k][0] - t0:.2f} | " + " | ".join(cells))


if __name__ == "__main__":
    main(sys.argv[1:])

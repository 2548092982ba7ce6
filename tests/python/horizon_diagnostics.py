#!/usr/bin/env python3
"""Where the long-horizon excess comes from (diagnostic, docs/validation.md#long-horizons-100-periods-and-more).

usage:
  horizon_diagnostics.py jumps COMPARE.json INSPECT.json
      COMPARE.json: `tdex compare REC EXTRA --json`; INSPECT.json: `tdex inspect EXTRA --json`
      (an extrapolation of several recorded periods). Prints the median ratio to the DEM
      runs' spread and the t_k outside their range after the recorded stretch (t_k > tP),
      and the mean ratio from t10 on grouped by the periods since the last jump (0: the
      period entered through a pairing).
  horizon_diagnostics.py drift RECORDING.mcap LENGTH K [K ...]
      The particles in six equal axial (y) slices of the drum, LENGTH metres long and
      centred on y = 0, and the bed's mean y and z (mm) at each snapshot t_k: a slow axial
      drift of the bed.
  horizon_diagnostics.py shift RECORDING.mcap END START
      The mean |dx|, |dy|, |dz| and the mean dy (diameters) by which the pairing of t_END
      to t_START moves the particles (its sidecar, written by `tdex pair` or `tdex
      extrapolate`, beside the recording).
"""
import collections
import json
import statistics
import sys

import numpy as np

from period_map import snapshots


def jumps(compare_path, inspect_path):
    c = json.load(open(compare_path))
    path = json.load(open(inspect_path))["path"]
    recorded, replayed = path["recorded_periods"], path["replayed"]
    after = [p for p in c["periods"] if p["k"] > recorded]
    ratios = [p["ratio_to_floor"] for p in after]
    outside = [p["k"] for p in after if p["eps_abs_to_dem_runs"] > p["floor_eps_abs_max"]]
    print(f"after t{recorded}: median ratio {statistics.median(ratios):.3f}, "
          f"outside the DEM runs' range at {len(outside)} of {len(after)} t_k")
    ratio = {p["k"]: p["ratio_to_floor"] for p in c["periods"]}
    since, at_end_of, groups = None, 1, collections.defaultdict(list)
    for i, period in enumerate(replayed):
        k = i + 2  # replayed[i] is the period that ends at t_(i+2)
        if at_end_of == recorded:
            since = 0  # entered through a pairing
        elif since is not None:
            since += 1
        at_end_of = period
        if since is not None and k >= 10:
            groups[since].append(ratio[k])
    for s, values in sorted(groups.items()):
        print(f"{s} periods after a jump: mean ratio {sum(values) / len(values):.3f} ({len(values)} t_k)")


def drift(recording, length, ks):
    snaps = snapshots(recording)
    edges = np.linspace(-length / 2, length / 2, 7)
    for k in ks:
        s = snaps[k]
        counts, _ = np.histogram(s["y"], bins=edges)
        print(f"t{k}: particles per axial slice {counts.tolist()}, mean y {1e3 * s['y'].mean():+.1f} mm, "
              f"mean z {1e3 * s['z'].mean():+.1f} mm")


def shift(recording, end, start):
    name = (f"{recording}.pairing.json" if (end, start) == (1, 0)
            else f"{recording}.pairing.t{end}-t{start}.json")
    g = np.array(json.load(open(name))["g"])
    snaps = snapshots(recording)
    a, b = snaps[end], snaps[start]
    d = 2 * a["r"].mean()
    # g[p]: the role particle p (at t_end) takes at t_start
    delta = np.stack([b[c][g] - a[c] for c in "xyz"]) / d
    mean_abs = np.abs(delta).mean(axis=1)
    print(f"t{end} -> t{start}: mean |dx| {mean_abs[0]:.2f} d, |dy| {mean_abs[1]:.2f} d, "
          f"|dz| {mean_abs[2]:.2f} d, mean dy {delta[1].mean():+.3f} d")


if __name__ == "__main__":
    what = sys.argv[1]
    if what == "jumps":
        jumps(sys.argv[2], sys.argv[3])
    elif what == "drift":
        drift(sys.argv[2], float(sys.argv[3]), [int(k) for k in sys.argv[4:]])
    elif what == "shift":
        shift(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
    else:
        sys.exit(__doc__)

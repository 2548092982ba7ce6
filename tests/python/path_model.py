#!/usr/bin/env python3
"""Which replay path through a recording's periods (the sub-periods of one revolution, or whole
revolutions) keeps the slabs' tilts as a DEM run does? A model without conduction
(diagnostic, docs/validation.md#long-horizons-100-periods-and-more).

usage: path_model.py REFERENCE.mcap RECORDING.mcap [EXTRA.mcap ...]
       REFERENCE: the run recorded with one period and --reference K --twins 1 or more;
       RECORDING: the same run recorded from t0 as P periods without a reference, either its
       first revolution in P sub-periods (--tau-rev 1/P --recorded-periods P) or P whole
       revolutions (--recorded-periods P), with the pairings the paths below use stored
       beside it (`tdex pair` stores those from t_P; any other, t_e to t_s:
       `cargo run --release -p extrapolate --example pair_snapshots -- RECORDING e s`);
       EXTRA: `tdex extrapolate RECORDING` runs, measured at the revolutions after t1.

Every particle keeps the temperature it had at the end of the first revolution (t1 of
REFERENCE, the same instant of RECORDING: the same run): the reference's and the twin's
particles carry it along their own motion, the replay's roles along a path of the recorded
periods (the DEM's own continuation to the end of the recording, then as drawn), through a
pairing at every jump (the particle at the end of one period takes the role it is paired
with at the start of the next), as `tdex extrapolate` moves temperatures, with no heat
exchanged. Printed at each revolution after t1: the rms over the 10-diameter axial slabs of
the difference between each run's tilt across the drum (the x and z slopes of the least-squares
fit of the temperature on [1, x, z], K per 10 diameters) and the reference's, for the twin, for
the paper's method (the first revolution as one period, replayed again and again), and for
random paths (DRAWS paths each, numpy's generator seeded 1): tdex's path (jumps only from the
recording's end, to a start drawn uniformly), the half periods (a revolution in P sub-periods,
P even: as tdex replays a revolution recorded as two) and jumps from the end of any period.
Without conduction the tilts stray further than the real runs' (conduction damps them), alike
for every run; compare the paths with each other and with the twin.
"""
import json
import sys

import numpy as np

from slab_affine import plain_tilts, row
from slab_corrected import MIN_FIT, tilt_distance
from spread import axial_slab, by_id, by_topic, dem_runs, diameter, positions

# random paths per policy: enough for a mean, a min and a max
DRAWS = 20
# tilts per 10 diameters, on slabs 10 diameters wide, as slab_corrected.py's
SLAB_D = 10


def sidecar(recording, end, start):
    """The stored pairing of snapshot t_end to t_start (tdex's sidecar names)."""
    if (end, start) == (1, 0):
        return f"{recording}.pairing.json"
    return f"{recording}.pairing.t{end}-t{start}.json"


def main(ref_path, rec_path, extra_paths):
    dem, twins = dem_runs(ref_path)
    if not twins:
        sys.exit(f"{ref_path}: no DEM twins (record with --twins 1 or more)")
    recorded = by_topic(rec_path)["/tdex/snapshots"]
    P = max(recorded)
    ref = {k: positions(dem[k]) for k in dem}
    sub = {k: positions(recorded[k]) for k in recorded}
    # the recorded periods per revolution: the snapshot that is the reference's t1
    per_revolution = next((k for k in sorted(sub) if k > 0 and np.array_equal(sub[k], ref[1])),
                          None)
    if not np.array_equal(sub[0], ref[0]) or per_revolution is None:
        sys.exit(f"{rec_path}: its t0 and none of its snapshots are {ref_path}'s t0 and t1 "
                 "(not the same run)")
    d = diameter(dem)
    width = per = SLAB_D * d
    t1_temp = by_id(dem[1], "T")
    slabs = [s for s, c in zip(*np.unique(axial_slab(ref[1][:, 1], width), return_counts=True))
             if c >= MIN_FIT]
    ks = sorted(k for k in dem if k > 1)

    def tilt(at, values):
        return plain_tilts(at, values, width, slabs, per)

    reference = [tilt(ref[k], t1_temp) for k in ks]

    def to_reference(tilts):
        return [tilt_distance(a, b) for a, b in zip(tilts, reference)]

    pairings = {}

    def pairing(end, start):
        """By particle id: the id at t_start whose role the particle `id` at t_end takes."""
        if (end, start) not in pairings:
            try:
                with open(sidecar(rec_path, end, start)) as f:
                    g = np.asarray(json.load(f)["g"])
            except FileNotFoundError:
                sys.exit(f"{sidecar(rec_path, end, start)}: missing; store it with "
                         f"`cargo run --release -p extrapolate --example pair_snapshots -- "
                         f"{rec_path} {end} {start}`")
            by = np.empty(len(g), dtype=np.int64)
            by[recorded[end]["id"]] = recorded[start]["id"][g]
            pairings[(end, start)] = by
        return pairings[(end, start)]

    def play(policy, rng):
        """The tilts at each revolution after t1 along the path `policy(at_end_of, rng)` gives
        (the next recorded period, 1-based: the next one is the DEM's own continuation, any
        other a jump), and the number of jumps."""
        values, at, out, jumps = t1_temp.copy(), per_revolution, [], 0
        for step in range(per_revolution * len(ks)):
            m = policy(at, rng)
            if m != at + 1:
                moved = np.empty_like(values)
                moved[pairing(at, m - 1)] = values
                values, jumps = moved, jumps + 1
            at = m
            if (step + 1) % per_revolution == 0:
                out.append(tilt(sub[at], values))
        return to_reference(out), jumps

    print(f"{ref_path}, {rec_path} ({P} recorded periods, {per_revolution} per revolution); the t1 "
          "temperatures carried without "
          f"conduction; slab tilts' distance to the reference's at t{ks[0]}…t{ks[-1]} "
          f"(K per {SLAB_D} d)")
    for m, twin in enumerate(twins):
        tilts = [tilt(positions(twin[k]), t1_temp) for k in ks]
        print(f"  twin {m + 1}: {row(to_reference(tilts))}")
    out, jumps = play(lambda at, rng: 1 if at == per_revolution else at + 1, None)
    print(f"  the revolution as one period (the paper's method): {row(out)}; {jumps} jumps")
    policies = [("tdex's path: jumps from the recording's end only",
                 lambda at, rng: int(rng.integers(1, P + 1)) if at == P else at + 1)]
    if per_revolution == P and P % 2 == 0 and P > 2:
        policies.append(("half periods, jumps from the end only",
                         lambda at, rng: 1 + (P // 2) * int(rng.integers(0, 2)) if at == P
                         else at + 1))
    policies.append(("jumps from the end of any recorded period",
                     lambda at, rng: int(rng.integers(1, P + 1))))
    for name, policy in policies:
        rng = np.random.default_rng(1)
        runs = [play(policy, rng) for _ in range(DRAWS)]
        dist = np.array([r for r, _ in runs])
        print(f"  {name}, {DRAWS} paths: mean {row(dist.mean(0))}; min {row(dist.min(0))}; "
              f"max {row(dist.max(0))}; {np.mean([j for _, j in runs]):.1f} jumps")
    # the real extrapolations (with conduction) at the same instants: their snapshot
    # per_revolution·k is the revolution k after t0, the reference's t_k
    def own_tilt(points):
        """A run's tilts with its own temperatures (conduction and all)."""
        return tilt(positions(points), by_id(points, "T"))

    if extra_paths:
        measured_ref = {k: own_tilt(dem[k]) for k in ks}
        measured_twin = {k: tilt_distance(own_tilt(twins[0][k]), measured_ref[k]) for k in ks}
    for path in extra_paths:
        extra = by_topic(path)["/tdex/snapshots"]
        at_k = {k: extra[per_revolution * k] for k in ks if per_revolution * k in extra}
        measured = [tilt_distance(own_tilt(p), measured_ref[k]) for k, p in at_k.items()]
        print(f"  measured, with conduction, at t{min(at_k)}…t{max(at_k)}: {path} "
              f"{row(measured)}; twin 1 {row(measured_twin[k] for k in at_k)}")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3:])

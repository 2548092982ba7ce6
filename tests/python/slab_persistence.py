#!/usr/bin/env python3
"""Do the axial slabs keep their own mixing rate from one revolution to the next? (diagnostic,
docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6)

usage: slab_persistence.py [--each] RECORDING.mcap EXTRA.mcap SLAB_D   (RECORDING made with
       --reference K [--twins M]; the drum's axis is y; SLAB_D: the slabs' width in particle
       diameters; --each also prints every slab's anomaly per period)

Per axial slab and snapshot, the hot-cold contrast of slab_contrast.py (the mean temperature of
the particles hot at t0 less that of those cold at t0). Over each period, a slab's decay is the
log of its contrast at the end over that at the start; less the bed's mean decay over that
period, it is the slab's anomaly: how much faster or slower than the bed it mixed. Printed, for
the DEM reference and the extrapolation: the anomalies' rms per period, and the correlation
across slabs of the anomalies of consecutive periods, over all slabs and without the
INNER_DROP slabs at each end; then, over each replayed period, the correlation of the
extrapolation's anomalies with the DEM's and their least-squares ratio (how much larger the
replay's pattern is), and the rms of their difference. With twins (DEM runs that leave the
reference at t1), the same three figures for each twin against the reference: the DEM's own
spread, the yardstick for the extrapolation's (without twins it is not measured). The replay
applies the recorded
period's contacts every period, so where a slab's rate is set by its contacts rather than by
the temperature pattern it holds, the replay's correlations are high. If they are and the
DEM's are low, each DEM revolution draws its slabs' rates anew and the replay's repetition
adds up along the axis where the DEM's averages out (the candidate mechanism of the pilot
drum's excess); if the DEM's are as high, the slabs' rates are a property of the drum (its
ends, its fill) and the repetition is faithful; if both are low, the slabs' rates follow the
temperature pattern and this test cannot tell.
"""
import sys

import numpy as np

from slab_contrast import contrasts
from spread import by_topic, dem_runs, diameter, hot_at_t0

# The "inner" correlation leaves out this many slabs at each end: the end caps' drag makes
# the slabs beside them mix faster in every revolution, a drum property that would
# correlate on its own.
INNER_DROP = 2


def decays(snaps, ks, hot_by_id, width):
    """{(k0, k1): {slab: log(C(k1) / C(k0)) less the bed's mean}} over consecutive ks."""
    per_k = {k: contrasts(snaps[k], hot_by_id, width) for k in ks}
    out = {}
    for k0, k1 in zip(ks, ks[1:]):
        slabs = sorted(set(per_k[k0]) & set(per_k[k1]))
        d = np.array([np.log(per_k[k1][s] / per_k[k0][s]) for s in slabs])
        out[(k0, k1)] = dict(zip(slabs, d - d.mean()))
    return out


def against(dem_an, other_an, start):
    """Per period from `start` on: the correlation across slabs of `other_an` with `dem_an`, the
    least-squares ratio of the first to the second, and the rms of their difference."""
    out = []
    for p in dem_an:
        if p[0] < start or p not in other_an:
            continue
        slabs = sorted(set(dem_an[p]) & set(other_an[p]))
        x = np.array([dem_an[p][s] for s in slabs])
        y = np.array([other_an[p][s] for s in slabs])
        out.append(f"t{p[0]}-t{p[1]} correlation {np.corrcoef(x, y)[0, 1]:+.2f}, "
                   f"{(x @ y) / (x @ x):.2f} times the DEM's, rms difference "
                   f"{np.sqrt(np.mean((y - x) ** 2)):.3f}")
    return out


def main(rec_path, extra_path, slab_d, each=False):
    dem, twin_runs = dem_runs(rec_path)
    ex = by_topic(extra_path)["/tdex/snapshots"]
    # the extrapolation starts from the DEM's last recorded snapshot (its first one, t1 with one
    # recorded period); the periods up to it are the recorded ones
    start = min(ex)
    ex = {**{k: dem[k] for k in dem if k <= start}, **{k: v for k, v in ex.items() if k > start}}
    # a twin leaves the reference at t1: its periods up to t1 are the reference's
    twins = [{**{k: dem[k] for k in dem if k <= 1}, **twin} for twin in twin_runs]
    width = slab_d * diameter(dem)
    hot_by_id = hot_at_t0(dem)
    ks = [k for k in sorted(dem) if k in ex]
    print(f"slabs of {slab_d:g} diameters; decay = ln(contrast at the end / at the start), "
          "less the bed's mean")
    anomalies = {}
    for name, snaps in [("DEM reference", dem), ("extrapolation", ex)]:
        an = anomalies[name] = decays(snaps, ks, hot_by_id, width)
        periods = list(an)
        rms = " ".join(
            f"t{a}-t{b} {np.sqrt(np.mean(np.square(list(an[(a, b)].values())))):.3f}"
            for a, b in periods
        )
        print(f"{name}: anomaly rms {rms}")
        for label, ends in [("all", 0), ("inner", INNER_DROP)]:
            corr = []
            for p, q in zip(periods, periods[1:]):
                slabs = sorted(set(an[p]) & set(an[q]))
                slabs = slabs[ends:len(slabs) - ends]
                x = np.array([an[p][s] for s in slabs])
                y = np.array([an[q][s] for s in slabs])
                corr.append(f"t{p[0]}-t{p[1]} with t{q[0]}-t{q[1]} {np.corrcoef(x, y)[0, 1]:+.2f}")
            print(f"  correlation across {label} {len(slabs)} slabs: " + ", ".join(corr))
        if each:
            every = sorted(set.union(*(set(a) for a in an.values())))
            print("  per slab (its middle in diameters along the axis): " + " ".join(
                f"{(b + 0.5) * slab_d:+.0f}" for b in every))
            for a, b in periods:
                print(f"    t{a}-t{b} " + " ".join(
                    f"{an[(a, b)][s]:+.3f}" if s in an[(a, b)] else "   –  " for s in every))
    # Over the periods the extrapolation replays: is its pattern the DEM's, and how large? And
    # how far does a second DEM run's pattern stray from the reference's over the same periods?
    dem_an = anomalies["DEM reference"]
    for m, twin in enumerate(twins):
        tks = [k for k in ks if k in twin]
        print(f"twin {m + 1} against the DEM, least squares: " + "; ".join(
            against(dem_an, decays(twin, tks, hot_by_id, width), 1)))
    print("extrapolation against the DEM, least squares: " + "; ".join(
        against(dem_an, anomalies["extrapolation"], start)))


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--each"]
    if len(args) != 3:
        sys.exit(__doc__)
    main(args[0], args[1], float(args[2]), "--each" in sys.argv)

#!/usr/bin/env python3
"""How fast does each axial slab mix at the particle scale, in the DEM runs and in the
replay? (diagnostic, docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6; needs scipy)

usage: slab_mixing.py RECORDING.mcap EXTRA.mcap SLAB_D   (RECORDING made with --reference K
       [--twins M]; the drum's axis is y; SLAB_D: the slabs' width in particle diameters)

Two measures, per axial slab and t_k, for the DEM reference, each twin and the extrapolation:
- separation: the particles in contact at t1 (centres within 1.05 diameters; the state all
  the runs share), and the mean over those pairs of log2(their distance at t_k / d), in the
  slab the pair held at t1. How fast neighbours part: the stretching of the flow.
- hot-cold contacts: of the contacts at t_k in the slab, the share between a particle hot at
  t0 and one cold at t0 (hot: above the bed mean at t0). How far the two groups are mixed
  at the particle scale, where conduction acts: a slab's hot-cold contrast decays with it.
Then, per t_k, each run's difference to the reference over the slabs (mean and rms): the
twins' is the DEM's own spread, against which the extrapolation's is judged. If the pairing
the extrapolation used is stored beside the recording (RECORDING.pairing.json, one recorded
period), the separation's difference to the reference is also given by the pair's jump (the
larger of its two particles' |x1[p] − x0[g(p)]|), and by its velocity mismatch (the larger
|v1[p] − v0[g(p)]|), in fifths of the pairs.
"""
import json
import os
import sys

import numpy as np
from scipy.spatial import cKDTree

from spread import (axial_slab, by_id, by_topic, compared_ks, dem_runs, diameter, hot_at_t0,
                    positions, run_names)

TOUCH = 1.05  # contact: centres within this many diameters


def main(rec_path, extra_path, slab_d):
    dem, twins = dem_runs(rec_path)
    ex = by_topic(extra_path)["/tdex/snapshots"]
    d = diameter(dem)
    hot = hot_at_t0(dem)
    x1 = positions(dem[1])
    pairs = cKDTree(x1).query_pairs(TOUCH * d, output_type="ndarray")
    slab_t1 = axial_slab(x1[pairs[:, 0], 1], slab_d * d)
    keys, counts = np.unique(slab_t1, return_counts=True)
    slabs = keys[counts >= 0.5 * np.median(counts)]  # thin end slabs left out

    def pair_separation(points):
        x = positions(points)
        return np.log2(np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1) / d)

    def separation(points):
        s = pair_separation(points)
        return np.array([s[slab_t1 == b].mean() for b in slabs])

    def hot_cold(points):
        x = positions(points)
        touching = cKDTree(x).query_pairs(TOUCH * d, output_type="ndarray")
        mixed = hot[touching[:, 0]] != hot[touching[:, 1]]
        slab = axial_slab(x[touching[:, 0], 1], slab_d * d)
        return np.array([mixed[slab == b].mean() for b in slabs])

    print(f"{len(pairs)} pairs in contact at t1; {len(slabs)} slabs of {slab_d:g} diameters, "
          f"middles {(slabs[0] + 0.5) * slab_d:+.1f} … {(slabs[-1] + 0.5) * slab_d:+.1f} d")
    names = run_names(twins)
    ks = compared_ks(dem, twins, ex)
    for label, measure in [("separation, mean log2(distance / d)", separation),
                           ("hot-cold share of the contacts", hot_cold)]:
        print(label)
        for k in ks:
            rows = [measure(r[k]) for r in [dem] + twins + [ex]]
            for name, row in zip(names, rows):
                print(f"  t{k} {name:13s} " + " ".join(f"{v:.3f}" for v in row)
                      + f"  mean {row.mean():.4f}")
            diff = "; ".join(
                f"{name} mean {(row - rows[0]).mean():+.4f} rms {np.sqrt(np.mean((row - rows[0]) ** 2)):.4f}"
                for name, row in zip(names[1:], rows[1:]))
            print(f"  t{k} less the reference: {diff}")
    sidecar = rec_path + ".pairing.json"
    if os.path.exists(sidecar) and min(ex) == 1:
        g = np.array(json.load(open(sidecar))["g"])
        v0, v1 = (by_id(dem[k], "vx", "vy", "vz") for k in (0, 1))
        per_particle = [
            ("jump through the pairing (d)",
             np.linalg.norm(x1 - positions(dem[0])[g], axis=1) / d, 2),
            ("velocity mismatch through the pairing (m/s)",
             np.linalg.norm(v1 - v0[g], axis=1), 3),
        ]
        for label, value, digits in per_particle:
            key = np.maximum(value[pairs[:, 0]], value[pairs[:, 1]])
            edges = np.quantile(key, np.linspace(0.0, 1.0, 6))
            fifth = np.clip(np.searchsorted(edges, key, side="right") - 1, 0, 4)
            print(f"separation less the reference's, by the pair's {label}")
            for k in ks:
                ref = pair_separation(dem[k])
                for name, run in zip(names[1:], twins + [ex]):
                    diff = pair_separation(run[k]) - ref
                    print(f"  t{k} {name:13s} " + "; ".join(
                        f"{edges[i]:.{digits}f}–{edges[i + 1]:.{digits}f} {diff[fifth == i].mean():+.3f}"
                        for i in range(5)))


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]))

#!/usr/bin/env python3
"""How much of an extrapolation's excess over the DEM runs' spread do the axial slabs' hot and
cold means carry, and how much the tilt of each slab's field across the drum? (diagnostic, docs/validation.md#the-papers-drum-at-80-000-particles-tables-5-and-6)

usage: slab_corrected.py RECORDING.mcap EXTRA.mcap SLAB_D EDGE_D
       (RECORDING made with --reference K --twins M; the drum's axis is y; SLAB_D: the axial
       slabs' width, EDGE_D: the cubic cells' edge, both in particle diameters)

At every t_k the extrapolation holds, each run other than the reference (the twins and the
extrapolation) is compared with the reference by scale_distance.py's cell distance, three
times: as it is; "corrected": every particle's temperature shifted by the reference's mean
less the run's mean over the particles of its axial slab and its group (hot or cold at t0,
as in slab_contrast.py), so that every slab's hot and cold means are the reference's; and
"tilted": in every slab, the run's least-squares fit of the temperatures on [1, hot, x, z]
(the slab's cold mean, its hot-cold contrast and the tilt of its field across the drum)
replaced by the reference's, evaluated at the run's particles. Each correction takes from
each run what lies in those few numbers per slab and leaves the rest. Printed per t_k: the
distances and the extrapolation's ratio to the twins' mean, three times; then each run's
slab tilts (the x and z slopes, in K per 10 diameters): the size of their mean over the
slabs, their rms about it along the axis and their rms difference to the reference's slab
tilts; last, the median ratios. Where a corrected ratio falls to the DEM runs' own (about
1), the numbers that correction replaced carry the excess; where it stays, the excess lies
elsewhere.
"""
import sys

import numpy as np

from scale_distance import distance
from spread import axial_slab, by_topic, compared_ks, dem_runs, diameter, hot_at_t0, run_names

MIN_FIT = 100


def group_slab_keys(points, hot_by_id, width):
    """Each particle's (slab, group) key as one integer: 2 × slab + hot."""
    return 2 * axial_slab(points["y"], width) + hot_by_id[points["id"]].astype(np.int64)


def with_slab_means(run, reference, hot_by_id, width):
    """`run` with each particle's temperature moved by its (slab, group)'s mean difference to
    the reference's; a (slab, group) the reference lacks is left as it is."""
    def means(points):
        keys = group_slab_keys(points, hot_by_id, width)
        uniq, index = np.unique(keys, return_inverse=True)
        index = index.ravel()
        sums = np.bincount(index, weights=points["T"])
        counts = np.bincount(index)
        return keys, dict(zip(uniq, sums / counts))

    keys, run_means = means(run)
    _, ref_means = means(reference)
    shift = np.array([ref_means.get(k, run_means[k]) - run_means[k] for k in keys])
    out = run.copy()
    out["T"] = run["T"] + shift
    return out


def fits_per_slab(slab, basis, values, slabs=None):
    """{slab: least-squares coefficients of `values` on the `basis` rows of its particles}, for
    the given slabs, or for every slab of at least MIN_FIT particles (the end caps' slivers
    left out)."""
    if slabs is None:
        found, counts = np.unique(slab, return_counts=True)
        slabs = found[counts >= MIN_FIT]
    return {s: np.linalg.lstsq(basis[slab == s], values[slab == s], rcond=None)[0]
            for s in slabs}


def slab_fits(points, hot_by_id, width):
    """Per axial slab, the least-squares fit of the temperatures on [1, hot, x, z]: the slab's
    cold mean, its hot-cold contrast and the tilt of its field across the drum (K/m along x
    and z: the direction and strength of what is left of the hot-cold split in that slab).
    Returns the particles' slabs, their basis rows and {slab: coefficients}; slabs of fewer
    than MIN_FIT particles (the end caps' slivers) are left out."""
    slab = axial_slab(points["y"], width)
    basis = np.stack([np.ones(len(points)), hot_by_id[points["id"]].astype(float),
                      points["x"], points["z"]]).T
    return slab, basis, fits_per_slab(slab, basis, points["T"])


def tilt_distance(a, b):
    """The rms over the slabs of the difference of two runs' slab tilts (one x, z vector per
    slab, the slabs in the same order)."""
    return float(np.sqrt(np.mean(np.sum((np.asarray(a) - np.asarray(b)) ** 2, axis=-1))))


def with_slab_fits(run, reference, hot_by_id, width):
    """`run` with each slab's fitted field (slab_fits) replaced by the reference's fit over
    the same slab, evaluated at the run's particles."""
    slab, basis, fits = slab_fits(run, hot_by_id, width)
    _, _, ref_fits = slab_fits(reference, hot_by_id, width)
    shift = np.zeros(len(run))
    for s, coef in fits.items():
        if s in ref_fits:
            rows = slab == s
            shift[rows] = basis[rows] @ (ref_fits[s] - coef)
    out = run.copy()
    out["T"] = run["T"] + shift
    return out


def tilts(runs, hot_by_id, width, d):
    """Per run, its slabs' tilts (K per 10 diameters, x and z): the bed's mean tilt's size,
    their rms about it along the axis, and their rms difference to the first run's."""
    per_run = [slab_fits(r, hot_by_id, width)[2] for r in runs]
    slabs = sorted(set.intersection(*(set(f) for f in per_run)))
    vecs = [np.array([f[s][2:] for s in slabs]) * 10 * d for f in per_run]
    return [(np.linalg.norm(v.mean(axis=0)), tilt_distance(v, v.mean(axis=0)),
             tilt_distance(v, vecs[0])) for v in vecs]


def main(rec_path, extra_path, slab_d, edge_d):
    dem, twins = dem_runs(rec_path)
    if not twins:
        sys.exit(f"{rec_path}: no DEM twins (record with --twins 1 or more)")
    ex = by_topic(extra_path)["/tdex/snapshots"]
    d = diameter(dem)
    width, edge = slab_d * d, edge_d * d
    hot_by_id = hot_at_t0(dem)
    ks = compared_ks(dem, twins, ex)
    names = run_names(twins)
    print(f"slabs of {slab_d:g} d, cubic cells of {edge_d:g} d; distances to the reference in K")
    corrections = {"as it is": None, "corrected": with_slab_means, "tilted": with_slab_fits}
    ratios = {label: [] for label in corrections}
    for k in ks:
        ref = dem[k]
        line = f"  t{k}:"
        for label, correct in corrections.items():
            runs = [t[k] for t in twins] + [ex[k]]
            if correct:
                runs = [correct(r, ref, hot_by_id, width) for r in runs]
            *twin_d, ex_d = [distance(ref, r, edge)[0] for r in runs]
            ratio = ex_d / np.mean(twin_d)
            ratios[label].append(ratio)
            line += (f" {label}: twins " + " ".join(f"{x:.4f}" for x in twin_d)
                     + f", extrapolation {ex_d:.4f}, ratio {ratio:.2f};")
        print(line.rstrip(";"))
        print("      tilt (K per 10 d): mean size, rms along the axis, rms to the reference's: "
              + "; ".join(f"{n} {a:.3f} {b:.3f} {c:.3f}" for n, (a, b, c) in zip(
                  names, tilts([ref] + [t[k] for t in twins] + [ex[k]], hot_by_id, width, d))))
    print(f"  median ratio over t{ks[0]}…t{ks[-1]}: " + ", ".join(
        f"{label} {np.median(r):.2f}" for label, r in ratios.items()))


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]))

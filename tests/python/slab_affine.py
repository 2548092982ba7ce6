#!/usr/bin/env python3
"""Does the replay's excess in the slabs' tilts come from repeating the recorded revolution's
map of each slab's cross-section? (diagnostic, docs/validation.md#long-horizons-100-periods-and-more)

usage: slab_affine.py RECORDING.mcap EXTRA.mcap [SLAB_D [CELL_D]]
       (RECORDING made with --reference K --twins M and one recorded period; EXTRA its
       extrapolation from t1; the drum's axis is y; SLAB_D: the axial slabs' width, default 10,
       CELL_D: the transport model's cubic cells' edge, default 2.5, both in particle diameters)

The replay applies the same one-revolution particle map every period (the recorded revolution
t0 -> t1 closed by the pairing); the DEM applies a new one every revolution. The candidate: the
recorded map's linear part per slab is off the DEM's typical revolution, the replay repeats
that offset so it adds up, and the slabs' temperature tilts stray. Each revolution's map is
measured by particle id between consecutive snapshots of a run (the reference t0…t7, each twin
from t1, the extrapolation from t1: its positions are the roles' t1 places). Tilts are in K
(or, for the hot-at-t0 indicator, 1) per 10 diameters; distances are the rms over the slabs of
the tilt vectors' difference, as slab_corrected.py's. Printed, in four parts:

1. Per revolution, each slab's back-map (where its particles were at t_k, fitted on [1, x, z]
   at t_{k+1}): its linear part A (a field's tilt g becomes A^T g), the A's variation along
   the axis and its correlation with the recorded revolution's, each A's offset from the DEM's
   mean over its other revolutions (rms, and in units of the revolutions' spread), and the
   share of particles that change slab.
2. The linear model: from the reference's tilts at t1, g -> A^T g every revolution with (a)
   the replay's map, (b) the reference's own maps, (c) each twin's; its error in one step and
   over t2…t7, beside the measured distances.
3. A transport model one level finer (the mapping method): cell-mean fields carried by each
   revolution's cell-to-cell particle counts, the same three sequences; plain tilts of T and of
   the hot indicator, and the tilt of slab_corrected.py's [1, hot, x, z] fit (the docs' number),
   recovered as the plain T tilt less the slab's hot-cold coefficient times the hot tilt; and
   where along the axis the measured tilt errors lie (common to every slab, or alike in
   slabs mirrored about the mid-plane).
4. With the transport model: each DEM revolution repeated as the replay repeats the recorded
   one, random orders of distinct DEM revolutions, two alternating; every map with its axial
   moves taken out, or with only them; and the replay's map with each slab's linear (and cubic)
   back-map set to the DEM's mean, and the twins' maps with the recorded revolution's imposed:
   whether the repetition carries the excess, across the drum or along it, and whether the
   linear part does.

Conduction is left out of both models (each prints how much the measured plain tilt differs
from the purely advected one in one revolution); the plain tilts are the ones they carry.
"""
import sys

import numpy as np
import scipy.sparse as sp

from slab_corrected import MIN_FIT, fits_per_slab, slab_fits, tilt_distance as distance
from spread import (axial_slab, by_id, by_topic, dem_runs, diameter, hot_at_t0, positions,
                    run_names)

# tilts are printed per 10 diameters whatever the slab width, as slab_corrected.py's
TILT_D = 10
# random orders of distinct DEM revolutions: enough draws for a mean and a max
DRAWS = 20


def poly_basis(xz, scale, degree):
    """The monomials of (x, z) up to `degree` (1, x, z, x², xz, z², …), the coordinates in
    units of `scale` so the fits stay well conditioned."""
    x, z = xz[:, 0] / scale, xz[:, 1] / scale
    cols = [np.ones(len(xz))]
    for d in range(1, degree + 1):
        cols += [x ** (d - i) * z ** i for i in range(d + 1)]
    return np.stack(cols, 1)


def back_map(start, end, slab_of_end, slabs, scale, degree=1):
    """Per slab (the particles' slab at the revolution's end), the least-squares fit of where
    they were across the drum (x, z at t_k) on the polynomial of where they are (t_{k+1}). The
    back-map and not the forward one: a field carried by the particles has at t_{k+1} the value
    it had where they came from, so for degree 1 a tilt g becomes A^T g, A the coefficient
    block of x and z ({slab: coefficients, rows the basis, columns x_k, z_k; both sides in
    units of `scale`})."""
    return fits_per_slab(slab_of_end, poly_basis(end[:, [0, 2]], scale, degree),
                         start[:, [0, 2]] / scale, slabs)


def linear_part(coefs):
    """{slab: A (2×2)}: rows x_k, z_k, columns x_{k+1}, z_{k+1}."""
    return {s: c[1:3].T for s, c in coefs.items()}


def plain_tilts(pos, values, width, slabs, per):
    """Per slab, the x and z slopes of the least-squares fit of `values` on [1, x, z], per `per`
    metres (the temperature field's tilt with no group term: the one advection carries)."""
    basis = np.stack([np.ones(len(pos)), pos[:, 0], pos[:, 2]], 1)
    fits = fits_per_slab(axial_slab(pos[:, 1], width), basis, values, slabs)
    return np.array([fits[s][1:] * per for s in slabs])


def hot_cold_tilts(points, hot_by_id, width, slabs, per):
    """Per slab, slab_corrected.py's [1, hot, x, z] fit: the hot coefficient and the x, z
    slopes per `per` metres (the tilt the docs' table gives)."""
    fits = slab_fits(points, hot_by_id, width)[2]
    return np.array([fits[s][1] for s in slabs]), np.array([fits[s][2:] * per for s in slabs])


def row(values, fmt="{:.3f}"):
    return " ".join(fmt.format(v) for v in values)


class Cells:
    """Cubic cells over the bed (the grid's origin on a multiple of the edge, so that with a
    slab width a multiple of the edge each cell lies in one slab)."""

    def __init__(self, all_positions, edge):
        lo = np.min([p.min(0) for p in all_positions], 0)
        hi = np.max([p.max(0) for p in all_positions], 0)
        self.edge = edge
        self.lo = np.floor(lo / edge) * edge
        self.shape = (np.floor((hi - self.lo) / edge).astype(int) + 1)
        self.n = int(np.prod(self.shape))

    def of(self, pos):
        c = np.floor((pos - self.lo) / self.edge).astype(int)
        # a corrected start position (part 4) may leave the grid: its nearest cell
        c = np.clip(c, 0, self.shape - 1)
        return (c[:, 0] * self.shape[1] + c[:, 1]) * self.shape[2] + c[:, 2]

    def means(self, pos, values):
        """Each cell's mean of `values` (NaN where the cell is empty)."""
        c = self.of(pos)
        count = np.bincount(c, minlength=self.n)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.bincount(c, weights=values, minlength=self.n) / count

    def transport(self, start, end):
        """The revolution's particle counts from each cell at its start to each at its end:
        the field's cell means at the end are these rows' averages of the start's (the mapping
        method; exact for a field uniform within cells)."""
        return sp.csr_matrix((np.ones(len(start)), (self.of(end), self.of(start))),
                             shape=(self.n, self.n))

    def geometry(self, pos, width):
        """Per cell: particle count, centroid x and z, and slab (of its centroid)."""
        c = self.of(pos)
        count = np.bincount(c, minlength=self.n).astype(float)
        with np.errstate(invalid="ignore", divide="ignore"):
            cen = [np.bincount(c, weights=pos[:, i], minlength=self.n) / count for i in range(3)]
        return count, cen[0], cen[2], axial_slab(np.nan_to_num(cen[1]), width)


def advect(matrix, field):
    """The cell means after one revolution; start cells with no value (empty in the field's
    configuration) are left out of each end cell's average."""
    ok = np.isfinite(field)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (matrix @ np.where(ok, field, 0.0)) / (matrix @ ok.astype(float))


def cell_tilts(field, geometry, slabs, per):
    """Per slab, the count-weighted least-squares fit of the cell means on [1, x, z] at the
    cells' centroids (the plain tilt's cell estimate), per `per` metres."""
    count, xc, zc, slab = geometry
    out = []
    for s in slabs:
        m = (count > 0) & (slab == s) & np.isfinite(field)
        w = np.sqrt(count[m])
        basis = np.stack([np.ones(m.sum()), xc[m], zc[m]], 1) * w[:, None]
        out.append(np.linalg.lstsq(basis, field[m] * w, rcond=None)[0][1:] * per)
    return np.array(out)


def main(rec_path, extra_path, slab_d, cell_d):
    dem, twin_runs = dem_runs(rec_path)
    if not twin_runs:
        sys.exit(f"{rec_path}: no DEM twins (record with --twins 1 or more)")
    ex = by_topic(extra_path)["/tdex/snapshots"]
    if min(ex) != 1:
        sys.exit(f"{extra_path}: starts at t{min(ex)}; this compares from t1 (one recorded period)")
    d = diameter(dem)
    width, per = slab_d * d, TILT_D * d
    hot_by_id = hot_at_t0(dem)
    hot = hot_by_id.astype(float)
    names = run_names(twin_runs)
    twin_names = names[1:-1]
    # every run from t1, where the twins and the extrapolation leave the reference
    runs = {"reference": dem, "extrapolation": {**{1: dem[1]}, **ex}}
    runs.update({n: {**{1: dem[1]}, **t} for n, t in zip(twin_names, twin_runs)})
    ks = sorted(k for k in dem if k >= 1 and all(k in r for r in runs.values()))
    pos = {(n, k): positions(r[k]) for n, r in runs.items() for k in r}
    temp = {(n, k): by_id(r[k], "T") for n, r in runs.items() for k in r}
    slabs = [s for s, c in zip(*np.unique(axial_slab(pos[("reference", 1)][:, 1], width),
                                           return_counts=True)) if c >= MIN_FIT]

    # the revolutions (run, k): t_k -> t_{k+1}; (reference, 0) is the recorded one
    steps = [(n, k) for n, r in runs.items() for k in sorted(r) if k + 1 in r]
    steps.append(("reference", 0))
    recorded, replay = ("reference", 0), ("extrapolation", 1)
    # the DEM's revolutions other than the recorded one: its "typical revolution"
    others = [s for s in steps if s[0] != "extrapolation" and s != recorded]
    dem_steps = [recorded] + others
    ends = {s: (pos[(s[0], s[1])], pos[(s[0], s[1] + 1)]) for s in steps}
    end_slab = {s: axial_slab(e[:, 1], width) for s, (_, e) in ends.items()}

    def fits(step, degree=1):
        start, end = ends[step]
        return back_map(start, end, end_slab[step], slabs, width, degree)

    def label(s):
        return f"{s[0]} t{s[1]}-t{s[1] + 1}"

    print(f"{len(slabs)} slabs of {slab_d:g} d; tilts per {TILT_D} d; revolutions: the recorded "
          f"{label(recorded)}, {len(others)} other DEM ones, the replay's")

    # ---- 1. the per-slab linear parts
    A = {s: linear_part(fits(s)) for s in steps}
    stack = {s: np.array([A[s][b] for b in slabs]) for s in steps}
    # the replay applies one map every period: its A must not change from period to period
    rep = [s for s in steps if s[0] == "extrapolation"]
    print("\n1. back-map linear parts A per slab (rows x_k, z_k; columns x_k+1, z_k+1)")
    print(f"  the replay's A over its {len(rep)} periods differ by at most "
          f"{max(np.abs(stack[s] - stack[replay]).max() for s in rep):.1e}; "
          f"from the recorded revolution's by {np.abs(stack[replay] - stack[recorded]).max():.4f}")
    anomaly = {s: stack[s] - stack[s].mean(0) for s in steps}
    print("  revolution: bed mean A (xx xz zx zz); slab anomaly rms (same order); correlation of "
          "its slab anomalies with the recorded's; offset from the DEM's mean over its other "
          "revolutions, rms over slabs (same order) and in units of their spread; share "
          "changing slab")
    offset_spread = np.std([stack[s] for s in others], 0, ddof=1)
    offset = {}
    for s in dem_steps + [replay]:
        pool = [o for o in others if o != s]
        offset[s] = stack[s] - np.mean([stack[o] for o in pool], 0)
        exchange = np.mean(axial_slab(ends[s][0][:, 1], width) != end_slab[s])
        print(f"    {label(s):24s} {row(stack[s].mean(0).ravel(), '{:+.3f}')}; "
              f"{row(np.sqrt((anomaly[s] ** 2).mean(0)).ravel())}; "
              f"{np.corrcoef(anomaly[s].ravel(), anomaly[recorded].ravel())[0, 1]:+.2f}; "
              f"{row(np.sqrt((offset[s] ** 2).mean(0)).ravel())} "
              f"({np.sqrt(np.mean((offset[s] / offset_spread) ** 2)):.2f}); {exchange:.3f}")
    pairs = [np.corrcoef(offset[a].ravel(), offset[b].ravel())[0, 1]
             for i, a in enumerate(dem_steps) for b in dem_steps[i + 1:]]
    print(f"  offsets' correlation between two DEM revolutions: mean {np.mean(pairs):+.2f}, "
          f"range {min(pairs):+.2f} … {max(pairs):+.2f} ({len(pairs)} pairs)")

    # ---- 2. the linear model on the plain T tilt: the one conduction hardly changes, while
    # the [1, hot, x, z] tilt is made in good part by conduction out of the hot-cold split
    # (both printed below), so the models carry plain tilts (part 3 recombines them)
    measured = {(n, k): plain_tilts(pos[(n, k)], temp[(n, k)], width, slabs, per)
                for n in runs for k in ks}
    print("\n2. the linear model g -> A^T g per slab, plain tilt of T on [1, x, z] (K per "
          f"{TILT_D} d); one revolution from each run's own t_k:")
    for n in runs:
        lin, adv, adv_docs = [], [], []
        for k in ks[:-1]:
            g = measured[(n, k)]
            carried = plain_tilts(pos[(n, k + 1)], temp[(n, k)], width, slabs, per)
            lin.append(distance(np.einsum("sji,sj->si", stack[(n, k)], g), carried))
            adv.append(distance(carried, measured[(n, k + 1)]))
            moved = runs[n][k + 1].copy()
            moved["T"] = temp[(n, k)][moved["id"]]
            adv_docs.append(distance(hot_cold_tilts(moved, hot_by_id, width, slabs, per)[1],
                                     hot_cold_tilts(runs[n][k + 1], hot_by_id, width, slabs,
                                                    per)[1]))
        print(f"  {n:14s} linear model to the advected tilt (T_k at the particles' t_k+1 "
              f"places) {row(lin)}; advected to measured (conduction) {row(adv)}; the same for "
              f"the [1, hot, x, z] tilt {row(adv_docs)}")

    def linear(sequence):
        g, out = measured[("reference", 1)], []
        for s in sequence:
            g = np.einsum("sji,sj->si", stack[s], g)
            out.append(g)
        return out

    n_per = len(ks) - 1
    a = linear([replay] * n_per)
    b = linear([("reference", k) for k in ks[:-1]])
    cs = {n: linear([(n, k) for k in ks[:-1]]) for n in twin_names}
    print_compare(ks, measured, a, b, cs, twin_names)

    # ---- 3. the cell transport model
    cells = Cells(list(pos.values()), cell_d * d)
    matrix = {s: cells.transport(*ends[s]) for s in steps}
    geom = {s: cells.geometry(ends[s][1], width) for s in steps}
    h_ref = {k: hot_cold_tilts(dem[k], hot_by_id, width, slabs, per)[0] for k in ks}
    filled = len(np.unique(cells.of(pos[("reference", 1)])))
    print(f"\n3. cell transport ({cell_d:g}-d cells, {filled} filled at t1), no conduction; the "
          "model's errors are mostly common to its sequences, so its a-b and c-b are what to set "
          "against the measured distances")

    def cells_from_t1(sequence, values, mats=None, geoms=None):
        """The plain tilts after each revolution of `sequence` from the reference's t1 field
        (`mats`, `geoms`: the revolutions' transports and their end cells' geometry, by
        default their own)."""
        f, out = cells.means(pos[("reference", 1)], values), []
        for i, s in enumerate(sequence):
            f = advect(matrix[s] if mats is None else mats[i], f)
            out.append(cell_tilts(f, geom[s] if geoms is None else geoms[i], slabs, per))
        return out

    sequences = {"a": [replay] * n_per, "b": [("reference", k) for k in ks[:-1]]}
    sequences.update({n: [(n, k) for k in ks[:-1]] for n in twin_names})
    model = {}
    for field, values in [("T", temp[("reference", 1)]), ("hot", hot)]:
        model[field] = {key: cells_from_t1(seq, values) for key, seq in sequences.items()}
        meas = {(n, k): cell_tilts(cells.means(pos[(n, k)], temp[(n, k)] if field == "T" else hot),
                                   cells.geometry(pos[(n, k)], width), slabs, per)
                for n in runs for k in ks}
        own = {(n, k): plain_tilts(pos[(n, k)], temp[(n, k)] if field == "T" else hot, width,
                                   slabs, per) for n in runs for k in ks}
        if field == "T":
            own_t = own
        check = [distance(meas[("reference", k)], own[("reference", k)]) for k in ks]
        print(f"  plain tilt of {field}: the cells' estimate against the particles' (reference, "
              f"t{ks[0]}…t{ks[-1]}) {row(check)}")
        print_compare(ks, own, model[field]["a"], model[field]["b"],
                      {n: model[field][n] for n in twin_names}, twin_names)
    # the docs' tilt: T on [1, hot, x, z]; by least squares its x, z slopes are the plain T
    # slopes less the hot coefficient times the hot indicator's plain slopes (exact for the
    # measured fits); the models carry T and hot, the hot coefficient is the reference's
    docs = {(n, k): hot_cold_tilts(runs[n][k], hot_by_id, width, slabs, per)[1]
            for n in runs for k in ks}
    combined = {key: [model["T"][key][i] - h_ref[k][:, None] * model["hot"][key][i]
                      for i, k in enumerate(ks[1:])] for key in sequences}
    print("  tilt of the [1, hot, x, z] fit (slab_corrected.py's), models' hot coefficient "
          "the reference's:")
    print_compare(ks, docs, combined["a"], combined["b"], {n: combined[n] for n in twin_names},
                  twin_names)

    # where along the axis the measured tilt errors lie: the same in every slab (a structure
    # along the whole drum), or alike in slabs mirrored about the mid-plane (a structure that
    # the mirror image repeats rather than cancels); a random pattern has half its squares
    # even in y and 1/len(slabs) common
    print("  the measured plain T tilts' errors (run less reference) along the axis: share of "
          "their squares common to every slab / even in y (slab s with its mirror -s-1)")
    for n in [r for r in runs if r != "reference"]:
        shares = [error_shares(own_t[(n, k)] - own_t[("reference", k)], slabs) for k in ks[1:]]
        print(f"    {n:14s} " + " ".join(f"t{k} {c:.2f}/{e:.2f}" for k, (c, e) in
                                         zip(ks[1:], shares)))

    # ---- 4. repetition and the linear part, plain T tilt, against the model's (b)
    ref_path = model["T"]["b"]

    def to_b(out):
        return [distance(o, r) for o, r in zip(out, ref_path)]

    t_values = temp[("reference", 1)]
    print(f"\n4. cell transport from t1, plain T tilt: distance to the reference's own maps' "
          f"(model b) at t{ks[1]}…t{ks[-1]}; 'linear offset': rms over slabs of "
          f"(A - DEM mean)^T g(t1), K per {TILT_D} d")
    g1 = measured[("reference", 1)]
    rows_, lin_size, rep_size = [], [], []
    for s in [replay] + dem_steps:
        dist = to_b(cells_from_t1([s] * n_per, t_values))
        size = distance(np.einsum("sji,sj->si", offset[s], g1), 0)
        rows_.append(f"    {label(s) if s != replay else 'the replay':24s} {row(dist)}   "
                     f"linear offset {size:.3f}")
        if s in dem_steps:
            lin_size.append(size)
            rep_size.append(np.mean(dist[1:]))
    print("  one revolution repeated:")
    print("\n".join(rows_))
    print(f"  across the {len(dem_steps)} DEM revolutions, correlation of the linear offset with "
          f"the repeat's mean distance over t{ks[2]}…t{ks[-1]}: "
          f"{np.corrcoef(lin_size, rep_size)[0, 1]:+.2f}")
    rng = np.random.default_rng(0)
    # sequences without repetition, from revolutions that are not the reference's own t1…t7
    # ones (which would share steps with model b): the DEM's way, drawn from other runs
    pool = [s for s in dem_steps if s[0] != "reference" or s == recorded]
    if len(pool) >= n_per:
        draws = np.array([to_b(cells_from_t1([pool[i] for i in rng.permutation(len(pool))[:n_per]],
                                             t_values))
                          for _ in range(DRAWS)])
        print(f"  {DRAWS} random orders of {n_per} distinct revolutions (of the recorded and the "
              f"twins'): mean {row(draws.mean(0))}, max {row(draws.max(0))}")
    alternating = []
    for _ in range(DRAWS):
        two = [pool[i] for i in rng.permutation(len(pool))[:2]]
        alternating.append(to_b(cells_from_t1((two * n_per)[:n_per], t_values)))
    print(f"  {DRAWS} pairs of them alternating: mean {row(np.mean(alternating, 0))}")
    # `--mirror` replays the recorded revolution and its mirror image y -> -y in turn, the
    # image first (every jump enters it): two distinct maps, but in a drum whose flow is its
    # own mirror image they may share the structure that adds up. The cells are symmetric
    # about y = 0 (their edges on multiples of the cell edge), so the image's transport is
    # the revolution's with both ends mirrored.
    flip = np.array([1.0, -1.0, 1.0])
    image = cells.transport(ends[recorded][0] * flip, ends[recorded][1] * flip)
    image_geometry = cells.geometry(ends[recorded][1] * flip, width)
    mirrored = [image if i % 2 == 0 else matrix[recorded] for i in range(n_per)]
    mirrored_geometry = [image_geometry if i % 2 == 0 else geom[recorded] for i in range(n_per)]
    print("  the recorded revolution and its mirror image in turn (--mirror): "
          f"{row(to_b(cells_from_t1([recorded] * n_per, t_values, mirrored, mirrored_geometry)))}")

    def corrected(step, degree, own, target):
        """The step's transport with each slab's back-map polynomial (up to `degree`, `own` the
        step's fit) replaced by `target`'s, the particles' departures from it kept: start +
        basis (target - own)."""
        start, end = ends[step]
        moved = start.copy()
        for s in slabs:
            rows = end_slab[step] == s
            moved[np.ix_(rows, [0, 2])] += width * (
                poly_basis(end[rows][:, [0, 2]], width, degree) @ (target[s] - own[s]))
        return cells.transport(moved, end)

    # where the coherent part lives: across the drum or along it. Each revolution's transport
    # with the particles' axial moves taken out (start y set to end y), then with only them
    def split(step, keep):
        start, end = ends[step]
        moved = end.copy()
        moved[:, keep] = start[:, keep]
        return cells.transport(moved, end)

    for what, keep in [("across the drum only (no axial moves)", [0, 2]),
                       ("along the axis only (x, z frozen)", [1])]:
        out = {key: cells_from_t1(seq, t_values, [split(s, keep) for s in seq])
               for key, seq in sequences.items()}
        print(f"  {what}: a-b {row(distance(x, y) for x, y in zip(out['a'], out['b']))}; "
              + "; ".join(f"{n}-b {row(distance(x, y) for x, y in zip(out[n], out['b']))}"
                          for n in twin_names))
    print("  the back-map's polynomial per slab (degree 1: the linear part, with the offset; "
          "3: cubic) replaced:")
    for degree in (1, 3):
        per_step = {s: fits(s, degree) for s in others + [recorded, replay]}
        mean_fit = {b: np.mean([per_step[o][b] for o in others], 0) for b in slabs}

        def with_fit(sequence, target):
            # each distinct revolution's corrected transport once (the replay's repeats one)
            mats = {s: corrected(s, degree, per_step[s], target) for s in set(sequence)}
            return to_b(cells_from_t1(sequence, t_values, [mats[s] for s in sequence]))

        print(f"    degree {degree}: the replay's map set to the DEM mean, repeated "
              f"{row(with_fit([replay] * n_per, mean_fit))}")
        # the control: the same replacement in maps that are not repeated, to tell its own
        # disturbance from what it removes
        print(f"    degree {degree}: control, the reference's maps set to the DEM mean      "
              f"{row(with_fit(sequences['b'], mean_fit))}")
        for n in twin_names:
            print(f"    degree {degree}: {n}'s maps as they are / with the recorded's         "
                  f"{row(to_b(cells_from_t1(sequences[n], t_values)))} / "
                  f"{row(with_fit(sequences[n], per_step[recorded]))}")


def error_shares(errors, slabs):
    """Of the squared tilt errors (one x, z vector per slab), the share common to all slabs
    (their mean vector) and the share even in y (each slab's averaged with its mirror image's,
    slab -s-1; slabs without their mirror are left out of that share)."""
    errors = np.asarray(errors)
    total = np.sum(errors ** 2, axis=1).mean()
    common = np.sum(errors.mean(0) ** 2) / total
    where = {s: i for i, s in enumerate(slabs)}
    pairs = [(where[s], where[-s - 1]) for s in slabs if -s - 1 in where]
    even = np.mean([np.sum(((errors[i] + errors[j]) / 2) ** 2) for i, j in pairs])
    mirrored = np.mean([np.sum(errors[i] ** 2) for i, _ in pairs])
    return common, even / mirrored


def print_compare(ks, measured, a, b, cs, twin_names):
    """Per t_k after t1: the measured distances of the replay and each twin to the reference;
    the model's replay-sequence (a) and twin-sequence (c) tilts' distances to its reference-
    sequence (b); and the model's errors (b to the measured reference, a to the measured
    replay)."""
    for i, k in enumerate(ks[1:]):
        ref = measured[("reference", k)]
        twins = " ".join(f"{distance(measured[(n, k)], ref):.3f}" for n in twin_names)
        model_c = " ".join(f"{distance(cs[n][i], b[i]):.3f}" for n in twin_names)
        replay = measured[("extrapolation", k)]
        print(f"    t{k}: measured replay {distance(replay, ref):.3f}, twin {twins} | model a-b "
              f"{distance(a[i], b[i]):.3f}, c-b {model_c} | model error b "
              f"{distance(b[i], ref):.3f}, a {distance(a[i], replay):.3f}")


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4, 5):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else 10.0,
         float(sys.argv[4]) if len(sys.argv) > 4 else 2.5)

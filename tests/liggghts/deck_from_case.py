#!/usr/bin/env python3
"""Write a LIGGGHTS 3.8 deck and the drum STL for a tdex case file.

usage: deck_from_case.py CASE.toml OUTDIR [--facets F] [--default-curvature]
                         [--dumps N PERIODS [--per-proc] [--from-t1-period P]]

Writes OUTDIR/in.drum (every value of the case substituted, paths relative to
OUTDIR: run it from there) and the drum mesh: OUTDIR/drum.stl (mantle + both end
caps, one rotating mesh) or, with `end_caps = "fixed"`, drum_mantle.stl and
drum_caps.stl.  Drum axis y through the origin, gravity -z, type 1 = particles,
type 2 = wall (same E, nu, k, c as the particles).  Python stdlib only.

--facets F sets the number of facets around the mantle (default 96).

A bed of several sizes (particles.classes or particles.distribution) is resolved into classes
as tdex does (size_classes(), after recorder/src/case/sizes.rs); each class is a
particletemplate/sphere and one particledistribution/discrete takes them with their mass
fractions (count x r^3).  The deck then also dumps `id radius x y z f_Temp` at t0 and every
half revolution of heating (dump_classes.STEP).  With `end_caps = "periodic"` the box is
periodic along y with the period L (boundary f p f) and the mesh is the mantle alone,
drum_mantle.stl.  A Young's modulus below 5 MPa gets `soft_particles yes`.

A heated mantle (`drum.wall_temperature`) is its own mesh, drum_mantle.stl, with
`temperature Tw` (fix heat/gran/conduction then conducts between it and the particles
touching it, with the wall's conductivity `drum.wall_conductivity`), and the end caps
are a second mesh, drum_caps.stl, without temperature (adiabatic, as in tdex); with
rotating end caps both meshes turn.  The mantle's `curvature` is 1.5 x the angle
between neighbouring facets (360/F degrees), so that a sphere touching several mantle
facets at once makes one contact with it; --default-curvature leaves LIGGGHTS' default
(0.256 degrees), with which such a sphere makes a contact with each facet.

With --dumps N PERIODS the heating phase is 1 + PERIODS drum revolutions and the deck
writes the dumps `tdex import liggghts` reads (docs/liggghts.md): the atoms at t0 and
after every revolution (dump_atoms.STEP), for a heated mantle the wall contacts
(dump_walls.STEP: mesh 0 the mantle, 1 the end caps) and the contacts every N steps during the
first revolution (dump_pairs.STEP); with --per-proc the atoms go to one file per MPI
process and timestep (dump_atoms.STEP.PROC; LIGGGHTS 3.8 writes no header in the `dump local`
files of processes other than 0, so the contacts are always gathered into one file).  t0 must then be a whole number of revolutions and
of N steps (choose time.settle + time.spin_up accordingly).

With --from-t1-period P the drum's rotation is defined anew at t1 (after the recorded
revolution) with the period P s: run once with the case's own period and once per twin with
P changed in its last digits, and the runs are the same to t1 (LIGGGHTS is reproducible to the
last digit) and part from t1 on, as `tdex record --twins` does (docs/validation.md).
"""
import math
import re
import sys
import tomllib
from pathlib import Path

N_THETA = 96      # facets around the circumference (default of --facets)
CURVATURE_FACTOR = 1.5  # mantle curvature (deg) = this x 360 / facets, unless --default-curvature
AXIAL_SEG = 0.02  # target length (m) of one mantle facet along the axis


def facet(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    s = math.sqrt(sum(x * x for x in n)) or 1.0
    lines = ["facet normal %.9e %.9e %.9e" % tuple(x / s for x in n), " outer loop"]
    lines += [" vertex %.12e %.12e %.12e" % p for p in (a, b, c)]
    return lines + [" endloop", "endfacet"]


def write_stl(path, R, L, mantle=True, caps=True, n_theta=N_THETA):
    """ASCII STL, normals pointing into the drum (LIGGGHTS does not need them)."""
    ring = [(R * math.cos(2 * math.pi * k / n_theta), R * math.sin(2 * math.pi * k / n_theta))
            for k in range(n_theta)]
    ny = max(1, math.ceil(L / AXIAL_SEG))
    ys = [-L / 2 + L * j / ny for j in range(ny + 1)]
    out = ["solid drum"]
    for k in range(n_theta):
        (x0, z0), (x1, z1) = ring[k], ring[(k + 1) % n_theta]
        if mantle:
            for y0, y1 in zip(ys, ys[1:]):
                out += facet((x0, y0, z0), (x1, y0, z1), (x1, y1, z1))
                out += facet((x0, y0, z0), (x1, y1, z1), (x0, y1, z0))
        if caps:  # triangle fans around the axis
            out += facet((0.0, -L / 2, 0.0), (x1, -L / 2, z1), (x0, -L / 2, z0))
            out += facet((0.0, L / 2, 0.0), (x0, L / 2, z0), (x1, L / 2, z1))
    Path(path).write_text("\n".join(out + ["endsolid drum", ""]))


def next_prime(n):
    """LIGGGHTS wants random seeds that are primes > 10000."""
    while n < 3 or any(n % d == 0 for d in range(2, math.isqrt(n) + 1)):
        n += 1
    return n


def size_classes(p):
    """The bed's sizes as recorder/src/case/sizes.rs resolves them: (radii, counts), radii
    increasing, counts summing to particles.count."""
    N = p["count"]
    if "radius" in p:
        return [p["radius"]], [N]
    if "classes" in p:
        cl = sorted(p["classes"], key=lambda c: c["radius"])
        radius, fraction = [c["radius"] for c in cl], [c["fraction"] for c in cl]
    else:
        d = p["distribution"]
        lo, hi, k = d["min_radius"], d["max_radius"], d["classes"]
        m, sd = d["mean_radius"], d["std_radius"]
        if d["shape"] == "normal":
            cdf = lambda r: 0.5 * math.erfc(-((r - m) / sd) / math.sqrt(2.0))
        elif d["shape"] == "lognormal":
            s2 = math.log(1.0 + (sd / m) ** 2)
            mu = math.log(m) - 0.5 * s2
            cdf = lambda r: 0.5 * math.erfc(-((math.log(r) - mu) / math.sqrt(s2)) / math.sqrt(2.0))
        else:
            sys.exit(f"particles.distribution.shape = {d['shape']!r} is not supported")
        width = (hi - lo) / k
        edge = lambda b: lo + b * width
        prob = [cdf(edge(b + 1)) - cdf(edge(b)) for b in range(k)]
        total = sum(prob)
        radius = [edge(b) + 0.5 * width for b in range(k)]
        fraction = [q / total for q in prob]
    if p.get("fractions", "number") == "mass":
        w = [f / r ** 3 for r, f in zip(radius, fraction)]
    elif p.get("fractions", "number") == "number":
        w = list(fraction)
    else:
        sys.exit(f"particles.fractions = {p['fractions']!r} is not supported")
    shares = [x / sum(w) for x in w]
    # floors, then one each to the largest remainders (ties to the smaller radius)
    exact = [s * N for s in shares]
    counts = [math.floor(x) for x in exact]
    order = sorted(range(len(exact)), key=lambda c: (-(exact[c] - math.floor(exact[c])), c))
    for c in order[:max(0, N - sum(counts))]:
        counts[c] += 1
    kept = [(r, n) for r, n in zip(radius, counts) if n > 0]
    return [r for r, _ in kept], [n for _, n in kept]


def steps(seconds, dt, what):
    n = round(seconds / dt)
    if abs(n * dt - seconds) > 1e-9 * max(1.0, seconds):
        sys.exit(f"{what} = {seconds} s is not a whole number of steps of {dt} s")
    return n


BENCH = Path(__file__).resolve().parents[2] / "src" / "bench"
DECK = (BENCH / "liggghts_deck.in").read_text()
# the deck's @start@: LIGGGHTS inserts, settles and spins up the bed itself
START = (BENCH / "liggghts_start_settle.in").read_text()


IMPORT_DUMPS = """\
# the dumps of `tdex import liggghts` (docs/liggghts.md): atoms at t0 and every revolution,
# contacts every @n@ steps during the recorded revolution, then @periods@ revolutions of reference
dump da all custom @nper@ dump_atoms.*@proc@ id type x y z vx vy vz radius f_Temp
dump_modify da format "%d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g"
dump dc all local @n@ dump_pairs.* c_pc[1] c_pc[2] c_pc[3] c_pc[4]
dump_modify dc format "%.0f %.0f %.0f %.17g"
@wall_dump@run @nper@
undump dc
@wall_undump@@restart_rotation@
run @nrest@"""


CLASS_DUMPS = """\
# a bed of several sizes: the atoms at t0 and every half revolution of heating (steps
# @nstart@ + k @nhalf@), for the size classes' mean temperatures and segregation
variable clnext equal @nstart@+@nhalf@*(floor((step-@nstart@)/@nhalf@)+1)
dump dcl all custom 1 dump_classes.* id radius x y z f_Temp
dump_modify dcl every v_clnext first yes sort id format "%d %.17g %.17g %.17g %.17g %.17g"
"""


def several_sizes(start, v, radii, counts, rho):
    """The start's insertion for a bed of several sizes: a particletemplate/sphere per class
    and a particledistribution/discrete of the classes' mass fractions (count x r^3)."""
    mass = [n * r ** 3 for r, n in zip(radii, counts)]
    seeds = [v["seed1"]] + [None] * (len(radii) - 1)
    q = v["seed3"]
    for k in range(1, len(radii)):  # the further templates' seeds: the primes after seed3
        q = next_prime(q + 1)
        seeds[k] = q
    templates = "\n".join(
        f"fix pts{k + 1} all particletemplate/sphere {seeds[k]} atom_type 1 density constant {rho} "
        f"radius constant {r!r}" for k, r in enumerate(radii))
    dist = " ".join(f"pts{k + 1} {m / sum(mass)!r}" for k, m in enumerate(mass))
    start = replace_once(start, f"fix pts all particletemplate/sphere {v['seed1']} atom_type 1 "
                         f"density constant {rho} radius constant {v['rp']}\n", templates + "\n")
    return replace_once(start, f"fix pdd all particledistribution/discrete {v['seed2']} 1 pts 1.0\n",
                        f"fix pdd all particledistribution/discrete {v['seed2']} {len(radii)} {dist}\n")


def import_dumps(argv, nper, nstart, rotating, heated, caps_turn):
    """The heating runs of a deck that writes the import dumps
    (--dumps N PERIODS [--per-proc] [--from-t1-period P]); with a heated mantle also the wall
    contacts (mesh 0 the mantle, mesh 1 the end caps) every N steps of the recorded revolution."""
    restart = ""
    if len(argv) >= 2 and argv[-2] == "--from-t1-period":
        restart = (f"unfix rot\nfix rot all move/mesh mesh {rotating} rotate origin 0. 0. 0. "
                   f"axis 0. 1. 0. period {float(argv[-1])!r}")
        if heated and caps_turn:  # the caps turn with the mantle, by their own move/mesh
            restart += ("\nunfix rotcaps\nfix rotcaps all move/mesh mesh caps rotate origin 0. 0. 0. "
                        f"axis 0. 1. 0. period {float(argv[-1])!r}")
        argv = argv[:-2]
    if len(argv) not in (3, 4) or argv[0] != "--dumps" or argv[3:] not in ([], ["--per-proc"]):
        sys.exit(__doc__)
    n, periods = int(argv[1]), int(argv[2])
    if n < 1 or periods < 0 or nper % n or nstart % nper:
        sys.exit(f"--dumps {n} {periods}: t0 = step {nstart} must be a multiple of one revolution "
                 f"({nper} steps), itself a multiple of n = {n}")
    wall_dump = (f"dump dw all local {n} dump_walls.* c_wc[1] c_wc[2] c_wc[3] c_wc[4]\n"
                 'dump_modify dw format "%.0f %.0f %.0f %.17g"\n') if heated else ""
    v = dict(n=n, periods=periods, nper=nper, nrest=periods * nper,
             proc=".%" if argv[3:] else "", restart_rotation=restart,
             wall_dump=wall_dump, wall_undump="undump dw\n" if heated else "")
    return re.sub(r"@(\w+)@", lambda m: str(v[m.group(1)]), IMPORT_DUMPS)


def mesh_options(argv):
    """Take --facets F and --default-curvature out of argv; return (facets, default_curvature)."""
    facets, default_curv = N_THETA, False
    while "--default-curvature" in argv:
        argv.remove("--default-curvature")
        default_curv = True
    while "--facets" in argv:
        i = argv.index("--facets")
        if i + 1 >= len(argv) or not argv[i + 1].isdigit() or int(argv[i + 1]) < 3:
            sys.exit("--facets wants a whole number >= 3")
        facets = int(argv[i + 1])
        del argv[i:i + 2]
    return facets, default_curv


def replace_once(text, old, new):
    if text.count(old) != 1:
        sys.exit(f"the deck template has {text.count(old)} lines `{old}` where 1 was expected")
    return text.replace(old, new)


def heated_mantle(deck, v, caps_turn, Kw, periodic=False):
    """The heated mantle's edits of the filled-in deck: the wall's conductivity (type 2) and,
    with rotating end caps, a second move/mesh for the caps mesh."""
    if Kw is not None and float(Kw) != float(v["k"]):
        deck = replace_once(deck, f"thermalConductivity peratomtype {v['k']} {v['k']}\n",
                            f"thermalConductivity peratomtype {v['k']} {float(Kw)!r}\n")
    deck = replace_once(deck, "# drum (adiabatic: no 'temperature' on the meshes)\n",
                        "# drum: the mantle held at its 'temperature' (conducts to the particles touching it),"
                        + (" no end caps (periodic along y)\n" if periodic else " the end caps adiabatic\n"))
    if caps_turn:
        rot = (f"fix rot all move/mesh mesh mantle rotate origin 0. 0. 0. axis 0. 1. 0. "
               f"period {v['period']}\n")
        if rot not in deck:
            sys.exit(f"the deck template has no line `{rot.strip()}`")
        # the spin-up's; a restart at t1 (--from-t1-period) moves the caps itself
        deck = deck.replace(rot, rot + rot.replace("fix rot all", "fix rotcaps all")
                            .replace("mesh mantle", "mesh caps"), 1)
    return deck


def main():
    facets, default_curv = mesh_options(sys.argv)
    if len(sys.argv) < 3 or (len(sys.argv) > 3 and sys.argv[3] != "--dumps"):
        sys.exit(__doc__)
    case_path, out = Path(sys.argv[1]), Path(sys.argv[2])
    c = tomllib.loads(case_path.read_text())
    p, mat, con, drum, t, temp = (c["particles"], c["material"], c["contact"], c["drum"],
                                  c["time"], c["temperature"])
    cond = c.get("conduction", {})
    # refuse what this deck cannot reproduce rather than run something else
    if temp["mode"] not in ("split", "uniform"):
        sys.exit(f"temperature.mode = {temp['mode']!r} is not supported")
    if cond.get("contact_area", "overlap") != "overlap":
        sys.exit("LIGGGHTS 3.8 heat/gran/conduction has no Hertz contact area")
    Tw = drum.get("wall_temperature")
    if temp["mode"] == "uniform":  # the deck's hot/cold groups, both at the one value
        T_hot = T_cold = temp["value"]
    else:
        T_hot, T_cold = temp["hot"], temp["cold"]

    out.mkdir(parents=True, exist_ok=True)
    radii, counts = size_classes(p)
    # one size: the radius; several: the largest sets the skin and the insertion region
    R, L, rp, dt = drum["radius"], drum["length"], p.get("radius", radii[-1]), t["dt"]
    periodic = drum.get("end_caps", "rotating") == "periodic"
    caps_turn = drum.get("end_caps", "rotating") == "rotating"
    if periodic:
        # no end caps: the mantle alone, the box periodic along y with the period L
        write_stl(out / "drum_mantle.stl", R, L, caps=False, n_theta=facets)
        curv = "" if default_curv or Tw is None else f" curvature {CURVATURE_FACTOR * 360.0 / facets!r}"
        temp_kw = "" if Tw is None else f" temperature {float(Tw)!r}"
        mesh_fixes = f"fix mantle all mesh/surface file drum_mantle.stl type 2{temp_kw}{curv}"
        n_meshes, meshes, rotating = 1, "mantle", "mantle"
    elif Tw is not None:
        # the heated mantle and the adiabatic end caps as two meshes; only the mantle has a temperature
        write_stl(out / "drum_mantle.stl", R, L, caps=False, n_theta=facets)
        write_stl(out / "drum_caps.stl", R, L, mantle=False, n_theta=facets)
        curv = "" if default_curv else f" curvature {CURVATURE_FACTOR * 360.0 / facets!r}"
        mesh_fixes = (f"fix mantle all mesh/surface file drum_mantle.stl type 2 temperature {float(Tw)!r}{curv}\n"
                      "fix caps all mesh/surface file drum_caps.stl type 2")
        n_meshes, meshes, rotating = 2, "mantle caps", "mantle"
    elif not caps_turn:
        write_stl(out / "drum_mantle.stl", R, L, caps=False, n_theta=facets)
        write_stl(out / "drum_caps.stl", R, L, mantle=False, n_theta=facets)
        mesh_fixes = ("fix mantle all mesh/surface file drum_mantle.stl type 2\n"
                      "fix caps all mesh/surface file drum_caps.stl type 2")
        n_meshes, meshes, rotating = 2, "mantle caps", "mantle"
    else:
        write_stl(out / "drum.stl", R, L, n_theta=facets)
        mesh_fixes, n_meshes, meshes, rotating = "fix drum all mesh/surface file drum.stl type 2", 1, "drum", "drum"

    ax = temp.get("split_axis", "x")
    ext = R + 0.01 if ax in "xz" else L / 2 + 0.01
    blocks = {k: ["INF", "INF", "INF", "INF", "INF", "INF"] for k in ("tmp", "hot")}
    i = "xyz".index(ax)
    blocks["tmp"][2 * i + 1], blocks["hot"][2 * i + 1] = "${mid}", "${split}"

    E_real = cond.get("youngs_modulus_real")
    s1 = next_prime(10001 + c["seed"] % 1_000_000_000)
    s2 = next_prime(s1 + 1)
    s3 = next_prime(s2 + 1)
    pp, pw = con["particle_particle"], con["particle_wall"]
    v = dict(
        case=case_path.name, name=c.get("name", ""), seed=c["seed"],
        bx=R + 0.01, by=L / 2 + 0.01, skin=0.4 * rp,
        E=mat["youngs_modulus"], nu=mat["poisson_ratio"], k=mat["conductivity"], cp=mat["heat_capacity"],
        rho=mat["density"], rp=rp, N=p["count"], dt=dt,
        e_pp=pp["restitution"], e_pw=pw["restitution"], mu_pp=pp["friction"], mu_pw=pw["friction"],
        mur_pp=pp.get("rolling_friction", 0.0), mur_pw=pw.get("rolling_friction", 0.0),
        rolling=con.get("rolling_model", "epsd2"),
        E_real_fix=(f"fix m8 all property/global youngsModulusOriginal peratomtype {E_real!r} {E_real!r}"
                    if E_real else ""),
        area_corr="yes" if E_real else "no",
        mesh_fixes=mesh_fixes, n_meshes=n_meshes, meshes=meshes, rotating=rotating,
        T_init=0.5 * (T_hot + T_cold), T_hot=T_hot, T_cold=T_cold,
        rins=R - 1.5 * rp, yins=L / 2 - 1.5 * rp, seed1=s1, seed2=s2, seed3=s3,
        nsettle=steps(t["settle"], dt, "time.settle"),
        nsettle_rest=steps(t["settle"], dt, "time.settle") - 1,
        period=drum["rotation_period"], nspin=steps(t["spin_up"], dt, "time.spin_up"),
        nheat=steps(t.get("heating") or drum["rotation_period"], dt, "time.heating"),
        ax=ax, ext=ext, tmp_block=" ".join(blocks["tmp"]), hot_block=" ".join(blocks["hot"]),
    )
    nper = steps(drum["rotation_period"], dt, "drum.rotation_period")
    # LIGGGHTS wants compute pair/gran/local defined before the first run
    v["pair_compute"] = "compute pc all pair/gran/local id contactArea" if len(sys.argv) > 3 else ""
    if len(sys.argv) > 3 and Tw is not None:
        v["pair_compute"] += "\ncompute wc all wall/gran/local id contactArea"
    v["heat_runs"] = (import_dumps(sys.argv[3:], nper, v["nsettle"] + v["nspin"], rotating,
                                   Tw is not None, caps_turn)
                      if len(sys.argv) > 3 else f"run {v['nheat']}")
    if periodic:  # the box spans exactly one period along y
        v["by"] = L / 2
    v["box"] = f"region          domain block -{v['bx']} {v['bx']} -{v['by']} {v['by']} -{v['bx']} {v['bx']} units box\ncreate_box      2 domain"
    v["start"] = re.sub(r"@(\w+)@", lambda m: str(v[m.group(1)]), START)
    if len(radii) > 1:
        v["start"] = several_sizes(v["start"], v, radii, counts, mat["density"])
        cl = dict(nstart=v["nsettle"] + v["nspin"],
                  nhalf=steps(drum["rotation_period"] / 2, dt, "half of drum.rotation_period"))
        v["heat_runs"] = re.sub(r"@(\w+)@", lambda m: str(cl[m.group(1)]), CLASS_DUMPS) + v["heat_runs"]
    deck = re.sub(r"@(\w+)@", lambda m: str(v[m.group(1)]), DECK)
    if periodic:
        deck = replace_once(deck, "boundary        f f f\n", "boundary        f p f\n")
    if float(mat["youngs_modulus"]) < 5e6:  # LIGGGHTS refuses a softer E in SI units without it
        deck = replace_once(deck, "units           si\n", "units           si\nsoft_particles  yes\n")
    if Tw is not None:
        deck = heated_mantle(deck, v, caps_turn, drum.get("wall_conductivity"), periodic)
    (out / "in.drum").write_text(deck)
    sizes = "" if len(radii) == 1 else " classes " + " ".join(f"{r!r}:{n}" for r, n in zip(radii, counts))
    print(f"wrote {out}/in.drum: N={v['N']} R={R} L={L} settle={v['nsettle']} spin={v['nspin']} "
          f"heat={v['nheat']} steps, rolling={v['rolling']}, seeds {s1} {s2} {s3}{sizes}"
          + (", periodic along y" if periodic else ""))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""How unmixed is the bed at the particle scale? (diagnostic, docs/validation.md)

usage: spread.py RECORDING.mcap EXTRA.mcap   (RECORDING made with --reference K --twins M)

Prints, at every t_k the extrapolation holds, the standard deviation of the particle
temperatures (K) of the DEM reference, of each DEM twin and of the extrapolation, and the
extrapolation's over the DEM runs' mean: where it grows above 1, the replay leaves
particle-scale temperature differences that the DEM has already mixed away.
"""
import sys

import numpy as np
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from period_map import POINT


def by_topic(path):
    out = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, cloud in reader.iter_decoded_messages():
            if channel.topic == "/tdex/snapshots" or channel.topic.startswith("/tdex/twins/"):
                out.setdefault(channel.topic, {})[message.sequence] = np.frombuffer(
                    cloud.data, dtype=POINT)
    return out


def dem_runs(path):
    """The DEM runs of a recording: the reference's snapshots and each twin's, in the order of
    their topics ({t_k: points} each; a twin holds the t_k after t1, where it left the
    reference)."""
    rec = by_topic(path)
    reference = rec.pop("/tdex/snapshots")
    return reference, [rec[t] for t in sorted(rec)]


def diameter(dem):
    """The particle diameter of a run ({t_k: points}): twice the median radius at its first t_k."""
    return 2.0 * float(np.median(dem[min(dem)]["r"]))


def hot_at_t0(dem):
    """Per particle id, whether it was hot at t0 (above the bed's mean temperature there): the
    two groups the hot/cold drums start from."""
    at_t0 = by_id(dem[min(dem)], "T")
    return at_t0 > at_t0.mean()


def axial_slab(y, width):
    """The axial slab of each axial coordinate (the drum's axis is y), slabs `width` wide."""
    return np.floor(y / width).astype(np.int64)


def run_names(twins):
    """The printed names of the reference, each twin and the extrapolation, in that order."""
    return ["reference"] + [f"twin {m + 1}" for m in range(len(twins))] + ["extrapolation"]


def compared_ks(dem, twins, extra):
    """The t_k after the recorded period (k >= 2) that the reference, every twin and the
    extrapolation all hold, in order."""
    return sorted(k for k in dem if k >= 2 and k in extra and all(k in t for t in twins))


def by_id(points, *fields):
    """The named fields in particle-id order: a vector for one field, one column per field."""
    out = np.empty((len(points), len(fields)))
    out[points["id"]] = np.stack([points[f] for f in fields]).T
    return out[:, 0] if len(fields) == 1 else out


def positions(points):
    """x, y, z in particle-id order (one row per id)."""
    return by_id(points, "x", "y", "z")


def well_filled(cells):
    """The keys of a {key: (mean, count)} map whose cells hold at least half the median count:
    the thin cells at the bed's surface and walls are mostly sampling noise."""
    floor = 0.5 * np.median([c for _, c in cells.values()])
    return [k for k, (_, c) in cells.items() if c >= floor]


def dem_pairs(runs, distance):
    """The distance of every pair of DEM runs (reference and twins), each pair once, in order:
    the yardstick an extrapolation's distance to the runs is measured against."""
    return [distance(runs[i], runs[j]) for i in range(len(runs)) for j in range(i + 1, len(runs))]


def ratios_to_runs(runs, extras, distance):
    """The DEM pairs' mean distance, and per extrapolation its mean distance to the DEM runs
    over it (`distance(a, b)`, a float; the run first, as its cells choose what is compared)."""
    pairs = np.mean(dem_pairs(runs, distance))
    return pairs, [float(np.mean([distance(r, e) for r in runs]) / pairs) for e in extras]


def main(recording, extra):
    dem, twins = dem_runs(recording)
    ex = by_topic(extra)["/tdex/snapshots"]
    for k in sorted(ex):
        if k not in dem:
            continue
        stds = [dem[k]["T"].std()] + [t[k]["T"].std() for t in twins if k in t]
        e = ex[k]["T"].std()
        print(f"t_{k}: std DEM runs " + ", ".join(f"{s:.4f}" for s in stds)
              + f" K, extrapolated {e:.4f} K, ratio {e / np.mean(stds):.2f}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])

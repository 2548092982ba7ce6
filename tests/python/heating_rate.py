#!/usr/bin/env python3
"""How fast does the bed heat in an extrapolation, against the DEM runs? (diagnostic,
docs/validation.md#fresh-boundary-maps)

usage: heating_rate.py WALL_K COMPARE.json [COMPARE.json ...]
       (each the output of `tdex compare RECORDING EXTRAPOLATION --json` on a bed heated by a
       mantle held at WALL_K kelvin, recorded with --twins 2)

For each comparison, the bed's mean heating rate per period relative to what is left to
gain, (T(t_k+1) - T(t_k)) / (WALL_K - T(t_k)), averaged over the first 60 compared t_k, for
the extrapolation and for each twin, each as a relative difference to the reference's. A
recorded period whose mantle contacts happened to conduct more than the DEM's average heats
the replay faster at every period, where a twin averages over fresh periods. Last, how
much the DEM reference's own rate changes from one period to the next (its standard
deviation over the periods, relative to its mean, and the lag-1 autocorrelation).
"""
import json
import statistics
import sys


def rates(periods, mean_of):
    """The rate of each period, t_k to t_(k+1)."""
    pairs = zip(periods, periods[1:])
    return [(mean_of(b) - mean_of(a)) / (WALL - mean_of(a)) for a, b in pairs]


def rate(periods, mean_of):
    return statistics.mean(rates(periods, mean_of))


def per_period(periods):
    """The reference's rate of each period relative to its mean, and their lag-1
    autocorrelation: how much the DEM's own rate changes from one period to the next."""
    own = rates(periods, lambda p: p["bed_mean_dem"])
    relative = [r / statistics.mean(own) - 1 for r in own]
    lag1 = sum(a * b for a, b in zip(relative, relative[1:])) / sum(a * a for a in relative)
    return relative, lag1


def main():
    global WALL
    WALL = float(sys.argv[1])
    extra, twins, relative, lag1 = [], [], [], []
    for path in sys.argv[2:]:
        with open(path, encoding="utf-8") as f:
            periods = json.load(f)["periods"][:60]
        reference = rate(periods, lambda p: p["bed_mean_dem"])
        e = rate(periods, lambda p: p["bed_mean_extra"]) / reference - 1
        t = [
            rate(periods, lambda p, j=j: p["dem_runs_bed_mean"][j]) / reference - 1
            for j in range(len(periods[0]["dem_runs_bed_mean"]))
        ]
        extra.append(e)
        twins.extend(t)
        own, own_lag1 = per_period(periods)
        relative.extend(own)
        lag1.append(own_lag1)
        print(f"{path}: extrapolation {100 * e:+.2f} %, twins "
              + ", ".join(f"{100 * x:+.2f} %" for x in t))
    print(f"extrapolations {100 * min(extra):+.2f} to {100 * max(extra):+.2f} % "
          f"(mean {100 * statistics.mean(extra):+.2f} %); twins {100 * min(twins):+.2f} to "
          f"{100 * max(twins):+.2f} %")
    if len(extra) > 1:
        print(f"extrapolations' standard deviation {100 * statistics.stdev(extra):.2f} %")
    print(f"the DEM reference's own rate, period by period: standard deviation "
          f"{100 * statistics.stdev(relative):.2f} % ({len(relative)} periods), lag-1 "
          f"autocorrelation {statistics.mean(lag1):.2f}")


if __name__ == "__main__":
    main()

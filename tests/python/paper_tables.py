#!/usr/bin/env python3
"""The paper's Table 5 beside tdex's: ε_abs and ε_rel at t2…t7 of an extrapolation against
its DEM, with the DEM-against-DEM floor and their ratio, and the DEM's hot−cold difference
(the calibration's measure), from `tdex compare REC EXTRA --json` (docs/validation.md,
"The paper's tables at 80 000 particles").

    tdex compare paper.mcap paper.extra.mcap --json > compare.json
    python3 tests/python/paper_tables.py compare.json

Prints Markdown tables on stdout. Figures are printed with three significant digits.
"""

import json
import sys

# Haydar et al. 2023, Table 5 (80 000 particles, 200 Voronoi cells): ε_abs (K) and ε_rel (%)
# at t2…t7; their ratio is the DEM's hot−cold difference.
PAPER_EPS_ABS = [0.241, 0.126, 0.083, 0.062, 0.042, 0.030]
PAPER_EPS_REL = [1.84, 1.275, 1.27, 1.69, 2.25, 3.09]
PAPER_CONTRAST = [13.1, 9.9, 6.5, 3.7, 1.9, 0.97]


def sig(x, digits=3):
    """Three significant digits, no exponent for the magnitudes of these tables."""
    if x is None:
        return "–"
    if x == 0:
        return "0"
    return f"{x:.{digits}g}" if abs(x) >= 1e-3 else f"{x:.2e}"


def main(path):
    with open(path) as f:
        c = json.load(f)
    periods = {p["k"]: p for p in c["periods"]}
    dem_series = {p["k"]: p for p in c["dem_series"]}
    ks = [k for k in range(2, 8) if k in periods]
    if not ks:
        sys.exit(f"{path}: no compared t_k among t2…t7")
    head = "| | " + " | ".join(f"t{k}" for k in ks) + " |"
    rule = "|---|" + "---|" * len(ks)
    print(head)
    print(rule)

    def row(label, values):
        print(f"| {label} | " + " | ".join(values) + " |")

    pick = lambda key, scale=1.0: [  # noqa: E731
        sig(periods[k][key] * scale) if periods[k].get(key) is not None else "–" for k in ks
    ]
    row("paper ε_abs (K)", [sig(PAPER_EPS_ABS[k - 2]) for k in ks])
    row("tdex ε_abs (K)", pick("eps_abs"))
    row("floor ε_abs (K), DEM against its twin(s)", pick("floor_eps_abs"))
    row("paper ε_rel (%)", [sig(PAPER_EPS_REL[k - 2]) for k in ks])
    row("tdex ε_rel (%)", pick("eps_rel", 100.0))
    row("floor ε_rel (%)", pick("floor_eps_rel", 100.0))
    row("ratio to the floor", pick("ratio_to_floor"))
    row("paper hot − cold (K)", [sig(PAPER_CONTRAST[k - 2]) for k in ks])
    row(
        "tdex DEM hot − cold (K)",
        [sig(dem_series[k]["hot"] - dem_series[k]["cold"]) for k in ks],
    )
    v = c.get("verdict") or {}
    if v:
        print()
        print(f"Verdict: {v.get('text', '')}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])

#!/usr/bin/env bash
# Run the LIGGGHTS 3.8 peer of a tdex case on one process and print its summary.
# usage: tests/liggghts/run_case.sh CASE.toml OUTDIR [--facets F] [--default-curvature]
#   (the options go to deck_from_case.py)
# OUTDIR gets: case.toml (copy), in.drum + drum STL (generated), log.liggghts, screen.txt,
# marks.txt (per-phase wall/CPU marks), temps.txt (every 100 heating steps), dump_T.{start,end}.txt,
# dump_classes.STEP for a bed of several sizes (t0 and every half revolution of heating),
# summary.json.  Prefix with `nice -n 5` on a shared machine.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
case_file="${1:?usage: run_case.sh CASE.toml OUTDIR}"
out="${2:?usage: run_case.sh CASE.toml OUTDIR}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
rm -f "$out"/{marks.txt,temps.txt,dump_T.start.txt,dump_T.end.txt,summary.json} "$out"/dump_classes.*
cp "$case_file" "$out/case.toml"
python3 "$here/deck_from_case.py" "$out/case.toml" "$out" "${@:3}"
cd "$out"
echo "loadavg before: $(cat /proc/loadavg)" > load.txt
start=$(date +%s.%N)
liggghts -in in.drum -log log.liggghts -echo none > screen.txt 2>&1 || {
  echo "liggghts failed, see $out/screen.txt" >&2; tail -5 screen.txt >&2; exit 1; }
end=$(date +%s.%N)
echo "loadavg after: $(cat /proc/loadavg)" >> load.txt
python3 -c "print('total wall time %.1f s' % ($end - $start))" | tee -a load.txt
python3 "$here/summarize.py" "$out" | tee summary.json

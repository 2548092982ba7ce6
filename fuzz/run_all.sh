#!/usr/bin/env bash
# Fuzzes the given targets one after another, one process each on one core, niced:
#   fuzz/run_all.sh TAG SECONDS TARGET...
# Corpus: fuzz/corpus/TARGET (grown) seeded from tests/corpus/TARGET; crashes go to
# fuzz/artifacts/TARGET; each run's log to fuzz/logs/TARGET-TAG.log.
set -u
cd "$(dirname "$0")"
tag=$1 seconds=$2
shift 2
mkdir -p logs
for target in "$@"; do
    mkdir -p "corpus/$target"
    log="logs/$target-$tag.log"
    date -u +%s >"logs/$target-$tag.start"
    nice -n 10 cargo +nightly fuzz run -s none "$target" "corpus/$target" "../tests/corpus/$target" -- \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=65536 \
        -print_final_stats=1 >"$log" 2>&1
    echo "EXIT $?" >>"$log"
    date -u +%s >"logs/$target-$tag.end"
done

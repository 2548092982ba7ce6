#!/bin/bash
# Byte-identity check of a refactoring: run.sh TDEX OUTDIR makes a fixed set of outputs
# (recordings with reference periods and a twin, a heated mantle, another sampling; pairing
# sidecars; an extrapolation with each scheme, streamed and in memory; compare and inspect
# JSON) with the binary TDEX, all reproducible, and lists their SHA-256 sums in
# OUTDIR/SHA256. Run it with the binary before and after a change and diff the two lists
# (docs/architecture.md).
set -e
BIN=$(realpath "$1"); OUT=$2; HERE=$(dirname "$(realpath "$0")")
mkdir -p "$OUT"; cd "$OUT"
cp "$HERE/tiny.toml" "$HERE/heated.toml" .
$BIN record tiny.toml -o tiny.mcap --reference 3 --twins 1 --reproducible --threads 2 > /dev/null
$BIN record heated.toml -o heated.mcap --reference 2 --reproducible --threads 1 > /dev/null
$BIN record tiny.toml -o tinyn.mcap --n 5 --dtc-max 40 --reproducible --threads 2 > /dev/null
$BIN pair tiny.mcap --reproducible --json > pair_tiny.json
$BIN pair heated.mcap --reproducible > /dev/null
for s in explicit exact synchronous; do
    $BIN extrapolate tiny.mcap --periods 4 --scheme $s --reproducible -o tiny_$s.extra.mcap --threads 2 > /dev/null 2>&1
done
$BIN extrapolate heated.mcap --periods 3 --reproducible -o heated.extra.mcap --stream --threads 1 > /dev/null 2>&1
$BIN extrapolate tinyn.mcap --periods 2 --reproducible -o tinyn.extra.mcap > /dev/null 2>&1
$BIN compare tiny.mcap tiny_explicit.extra.mcap --json > compare_tiny.json
$BIN compare heated.mcap heated.extra.mcap --json > compare_heated.json
$BIN inspect tiny.mcap --json > inspect_tiny.json
# pair_tiny.json holds the solve's time: left out
sha256sum *.mcap *.json | grep -v pair_tiny > SHA256

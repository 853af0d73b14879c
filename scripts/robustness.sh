#!/bin/sh
# The robustness benchmark end to end (docs/guide/evaluating.md, "Robustness"): seeded,
# corrupted copies of held-out scenes; the classical baseline and every trained run given
# predicted on each copy; all scored into one table and one plot.
#
# Usage: scripts/robustness.sh HELD_OUT OUT [RUN...]
#   HELD_OUT  dataset, split or scene folder (e.g. datasets/lfgen/val)
#   OUT       new folder: OUT/corrupted, OUT/pred/<method>/<copy>, OUT/report
#   RUN       lftrain run folders (the method is named by the folder)
# lfgen's binaries must be on PATH (export PATH="$PWD/target/release:$PATH").
set -eu
[ $# -ge 2 ] || { sed -n '6,10p' "$0"; exit 2; }
data=$1
out=$2
shift 2
lfeval corrupt "$data" --out "$out/corrupted"
methods="$out/pred/baseline"
for run in "$@"; do
    methods="$methods $out/pred/$(basename "$run")"
done
for copy in "$out"/corrupted/*/; do
    name=$(basename "$copy")
    lfeval -q baseline "$copy" --out "$out/pred/baseline/$name" --no-posterior
    for run in "$@"; do
        lftrain -q predict "$run" "$copy" --out "$out/pred/$(basename "$run")/$name"
    done
done
# shellcheck disable=SC2086 # one word per method folder
lfeval robustness "$out/corrupted" $methods --out "$out/report"

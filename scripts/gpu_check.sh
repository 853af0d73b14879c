#!/usr/bin/env bash
# Issue 15's GPU check, one script of at most 10 minutes on a GPU machine: the thesis-size BASE
# and DPP at batch 64 (crates/lftrain/configs/gpu_thesis.toml), each timed on random input
# (`lftrain bench`), trained for 200 steps on DATA/train and applied once to DATA/val. With
# BUDGET seconds given, BASE then trains on until about BUDGET seconds after the start, at the
# pace measured, and predicts DATA/val again (pred/base_long).
# Needs an lftrain built with `cargo build --release -p lftrain --features wgpu` (BIN) and a
# Vulkan driver; scripts/gpu_carry.py packs binary and data for a device machine. CFG and
# STEPS override the config and the 200 steps (a CPU dry run: BURN_DEVICE=flex, a small CFG).
# Writes OUT_DIR/{log.txt,runs/,pred/}; docs/design/training-models.md, "GPU training", has the rest.
# Use: DATA=datasets/lfgen BIN=target/release/lftrain OUT_DIR=gpu BUDGET=470 scripts/gpu_check.sh
set -uo pipefail
: "${DATA:?DATA must name a dataset root with train/ and val/}"
BIN=${BIN:-target/release/lftrain}
OUT_DIR=${OUT_DIR:-gpu}
BUDGET=${BUDGET:-0}
CFG=${CFG:-crates/lftrain/configs/gpu_thesis.toml}
export BURN_DEVICE=${BURN_DEVICE:-wgpu}
mkdir -p "$OUT_DIR/runs" "$OUT_DIR/pred"
exec > >(tee -a "$OUT_DIR/log.txt") 2>&1

stage() { # name, command...: runs, times and reports one stage; a failure stops the script
    local name=$1 start=$SECONDS rc
    shift
    echo "== $name (t = $SECONDS s): $*"
    "$@"
    rc=$?
    echo "== $name: rc $rc after $((SECONDS - start)) s"
    [ $rc -eq 0 ] || exit $rc
}
# The seconds per step of the last "s per step" line printed.
pace() { grep -o '[0-9.]* s per step' "$OUT_DIR/log.txt" | tail -1 | cut -d' ' -f1; }

nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader || true
stage bench-base "$BIN" -q bench --config "$CFG" --model base --steps 20
# 200 steps each, unless the pace says that would not leave the script a third of its budget.
steps=$(awk -v s="${STEPS:-200}" -v p="$(pace)" -v b="$BUDGET" 'BEGIN { if (b > 0 && 2.2 * s * p > b / 1.5) s = int(b / 3.3 / p); print s }')
stage bench-dpp "$BIN" -q bench --config "$CFG" --model dpp --steps 20
stage train-base "$BIN" -q train --config "$CFG" --model base --steps "$steps" --train "$DATA/train" --out "$OUT_DIR/runs/base"
base_pace=$(pace)
stage train-dpp "$BIN" -q train --config "$CFG" --model dpp --multimodal --steps "$steps" --train "$DATA/train" --out "$OUT_DIR/runs/dpp"
stage predict-base "$BIN" -q predict "$OUT_DIR/runs/base" "$DATA/val" --out "$OUT_DIR/pred/base"
stage predict-dpp "$BIN" -q predict "$OUT_DIR/runs/dpp" "$DATA/val" --out "$OUT_DIR/pred/dpp"
left=$((BUDGET - SECONDS - 30))
if [ "$left" -gt 30 ]; then
    total=$(awk -v s="$steps" -v l="$left" -v p="$base_pace" 'BEGIN { printf "%d", s + l / p }')
    stage train-base-long "$BIN" -q train --resume --steps "$total" --train "$DATA/train" --out "$OUT_DIR/runs/base"
    stage predict-base-long "$BIN" -q predict "$OUT_DIR/runs/base" "$DATA/val" --out "$OUT_DIR/pred/base_long"
fi
echo "== done after $SECONDS s"

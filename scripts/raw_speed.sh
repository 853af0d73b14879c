#!/usr/bin/env bash
# Raw speed at equal spp (docs/validation.md, "Speed at equal spp"): on scripts/validate.sh's
# matched scenes, lfgen without sharing (independent shading, no adaptive samples, Russian
# roulette off, max_depth 5) against Mitsuba 3's scalar_rgb and llvm_ad_rgb, back to back,
# each at SPP samples per pixel; prints wall and CPU seconds (user + system) per render.
#
#   OUT=target/validation scripts/raw_speed.sh [LFGEN...]
#
# OUT: the folder scripts/validate.sh filled (its matched scenes, Mitsuba exports and venv);
# LFGEN: binaries to time side by side (default: target/release/lfgen), e.g. an old and a new
# build; ROUNDS (2) repeats the whole set, since a shared machine's timings wander.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=$(realpath "${OUT:-target/validation}")
SPP=${SPP:-1024}
ROUNDS=${ROUNDS:-2}
BINS=("$@")
[ ${#BINS[@]} -gt 0 ] || BINS=("$(realpath target/release/lfgen)")
PY="${VENV:-$OUT/venv}/bin/python"
VAL="$(pwd)/scripts/validate.py"
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
    for f in /usr/lib/x86_64-linux-gnu/libLLVM-19.so /usr/lib/llvm-19/lib/libLLVM.so; do
        if [ -e "$f" ]; then export DRJIT_LIBLLVM_PATH=$f; break; fi
    done
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
timed() {
    local label=$1
    shift
    /usr/bin/time -f "%e %U %S" -o "$tmp/t" "$@" >/dev/null 2>"$tmp/err" || {
        cat "$tmp/err"
        exit 1
    }
    awk -v l="$label" '{printf "| %s | %.1f s | %.1f s |\n", l, $1, $2 + $3}' "$tmp/t"
}
echo "| render ($SPP spp) | wall | CPU |"
echo "|---|---|---|"
for round in $(seq "$ROUNDS"); do
    for case in diffuse glossy; do
        dir="$OUT/colour/$case"
        for bin in "${BINS[@]}"; do
            rm -rf "$tmp/lfgen"
            (cd "$OUT" && timed "$round, $case, lfgen $bin" "$bin" render "$dir/matched/scene.json" \
                --out "$tmp/lfgen" --set render.spp="$SPP" --set render.max_depth=5 \
                --set render.rr_depth=6 --set 'render.shading="independent"' \
                --set render.adaptive_spp=0 --quiet)
        done
        xml="$dir/mitsuba/scene.xml" variants="scalar_rgb llvm_ad_rgb"
        # The glossy case is lfgen's own BSDF in Mitsuba (validate.sh writes scene_lfgen.xml).
        [ "$case" = glossy ] && xml="$dir/mitsuba/scene_lfgen.xml" variants="llvm_ad_rgb"
        for v in $variants; do
            timed "$round, $case, Mitsuba 3 $v" "$PY" "$VAL" mitsuba-render "$xml" "$tmp/m.npy" \
                --variant "$v" --spp "$SPP"
        done
    done
done

#!/usr/bin/env bash
# Time to equal quality, lfgen against Blender Cycles, on one exported scene's 81 views
# (docs/validation.md, "Time to the same PSNR"). One built-in scene at RES (128²), 9×9 views,
# every material made Lambert and opaque (validate.py match --diffuse), so both renderers
# converge to one image; the reference is Mitsuba 3 at REF_SPP on the centre view, a third
# renderer. lfgen renders the 81 views at its default settings (shared shading, 16 spp, centre
# GT) and at LF_SPPS with independent shading; Cycles renders the centre view at CYCLES_SPPS.
# PSNR is linear, scaled by the reference's automatic exposure, peak 1 (validate.py psnr).
# Cycles' time for 81 views is its start-up (a 1-spp render) plus 81 times the rest, as if one
# process rendered them all.
#
#   scripts/race.sh    # OUT=target/race RES=128,128 REF_SPP=4096 LF_SPPS="16 64" VENV=…
#                      # CYCLES_SPPS="16 64 256 1024"
#
# Needs what scripts/validate.sh needs (python3 with mitsuba, numpy, OpenEXR; blender).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=$(realpath -m "${OUT:-target/race}")
RES=${RES:-128,128}
REF_SPP=${REF_SPP:-4096}
LF_SPPS=${LF_SPPS:-16 64}
CYCLES_SPPS=${CYCLES_SPPS:-16 64 256 1024}
# shellcheck source=scripts/tools.sh
. scripts/tools.sh
command -v blender >/dev/null || { echo "blender not found (Debian: apt-get install blender)"; exit 1; }

rm -rf "$OUT/ds" "$OUT/matched" "$OUT/mitsuba" "$OUT/blender"* "$OUT/lfgen"* "$OUT/cycles"
lf --scenes 1 --out "$OUT/ds" --set "camera.resolution=[$RES]" --set dataset.date=2026-01-01 \
    --quiet
SCENE="$OUT/ds/train/scene_0000"
lf export --to blender "$SCENE" --out "$OUT/blender_source" --views center
mkdir -p "$OUT/matched"
$PY "$VAL" match "$SCENE/scene.json" "$OUT/blender_source/blender_scene.json" "$OUT/matched/scene.json" \
    --dielectric-only --diffuse --keep-grid
lf export --to mitsuba "$OUT/matched" --out "$OUT/mitsuba" --views center
lf export --to blender "$OUT/matched" --out "$OUT/blender" --views center
CENTRE=$($PY -c "import json; print(json.load(open('$OUT/blender/blender_scene.json'))['cameras'][0]['view'])")
$PY "$VAL" mitsuba-render "$OUT/mitsuba/scene.xml" "$OUT/reference.npy" --spp "$REF_SPP"

echo "| renderer | shading | spp | PSNR linear (dB) | wall clock, 81 views (s) |"
echo "|---|---|---|---|---|"
row() {  # renderer shading spp image seconds
    local p
    p=$($PY "$VAL" psnr "$OUT/reference.npy" "$4" | cut -d' ' -f1)
    echo "| $1 | $2 | $3 | $p | $5 |"
}
lf_run() {  # name, then --set arguments
    local name=$1
    shift
    $PY "$VAL" timed "$OUT/$name.seconds" "$LF" render "$OUT/matched/scene.json" \
        --out "$OUT/$name" --set render.write_exr=true --quiet "$@" >/dev/null
    printf %.1f "$(cut -d' ' -f1 "$OUT/$name.seconds")"
}
t=$(lf_run lfgen_default)
row lfgen "shared (default)" 16 "$OUT/lfgen_default/input_Cam$(printf %03d "$CENTRE").exr" "$t"
for spp in $LF_SPPS; do
    t=$(lf_run "lfgen_$spp" --set render.spp="$spp" --set render.shading=independent)
    row lfgen independent "$spp" "$OUT/lfgen_$spp/input_Cam$(printf %03d "$CENTRE").exr" "$t"
done
mkdir -p "$OUT/cycles"
cycles() {  # spp → seconds of one centre-view render
    local t0 t1
    t0=$(date +%s.%N)
    blender -b --factory-startup -P "$OUT/blender/scene.py" -- --view "$CENTRE" \
        --out "$OUT/cycles/spp$1.exr" --spp "$1" >/dev/null 2>&1
    t1=$(date +%s.%N)
    echo "$t1 - $t0" | bc
}
start=$(cycles 1)
for spp in $CYCLES_SPPS; do
    t=$(cycles "$spp")
    total=$(echo "$start + 81 * ($t - $start)" | bc)
    row Cycles "Diffuse BSDF" "$spp" "$OUT/cycles/spp$spp.exr" "$(printf %.1f "$total")"
done

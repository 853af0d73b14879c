#!/usr/bin/env bash
# lfgen against Mitsuba 3 and Blender Cycles (README, "Validation"): depth of the centre and
# corner views, colour and wall-clock time of a colour-matched scene. POV-Ray's depth check is
# a cargo test (tests/povray.rs).
#
#   scripts/validate.sh            # OUT=target/validation RES=160,120 SPP=256
#
# Needs python3 (a venv with mitsuba, numpy, OpenEXR is made under $OUT) and, for Cycles,
# Blender on the PATH (Debian: apt-get install blender); without it Cycles is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-target/validation}
RES=${RES:-160,120}
SPP=${SPP:-256}
LF=target/release/lfgen
cargo build --release --quiet
mkdir -p "$OUT"
if [ ! -x "$OUT/venv/bin/python" ]; then
    python3 -m venv "$OUT/venv"
    "$OUT/venv/bin/pip" install --quiet mitsuba numpy OpenEXR
fi
PY="$OUT/venv/bin/python"
HAVE_BLENDER=1
command -v blender >/dev/null || { HAVE_BLENDER=0; echo "blender not found: Cycles skipped"; }
bl() { if [ "$HAVE_BLENDER" = 1 ]; then echo "--blender $1"; fi; }

# The depth scene has no glass, semi-transparent or cut-out materials by chance (furniture may
# still bring cut-outs, evaluated exactly for Mitsuba): glass counts in the HCI depth only at
# grazing angles and coincident back-to-back cut-out quads are ties, both handled (and counted)
# by tests/povray.rs on the default scene.
echo "== depth: generated scene, 3x3 views at ${RES/,/x}, centre and corner views"
rm -rf "$OUT/depth"
$LF --scenes 1 --out "$OUT/depth/ds" --set "camera.resolution=[$RES]" --set camera.grid=[3,3] \
    --set render.spp=1 --set render.gt_views=all --set dataset.date=2026-01-01 --quiet \
    --set scene.glass=0 --set scene.semi_transparent=0 --set scene.cutout=0
SCENE="$OUT/depth/ds/train/scene_0000"
$LF export --to mitsuba "$SCENE" --out "$OUT/depth/mitsuba" --views 4,0,2,6,8
$LF export --to blender "$SCENE" --out "$OUT/depth/blender" --views 4,0,2,6,8
$PY scripts/validate.py depth "$SCENE" "$OUT/depth/mitsuba" $(bl "$OUT/depth/blender") --work "$OUT/depth"

echo "== colour and speed: the same scene with uniform materials, centre view, $SPP spp"
rm -rf "$OUT/colour"
mkdir -p "$OUT/colour/matched"
$PY scripts/validate.py match "$SCENE/scene.json" "$OUT/depth/blender/blender_scene.json" \
    "$OUT/colour/matched/scene.json" --dielectric-only
start=$(date +%s.%N)
$LF render "$OUT/colour/matched/scene.json" --out "$OUT/colour/lfgen" --set render.spp="$SPP" \
    --set render.write_exr=true --quiet
$PY -c "print($(date +%s.%N) - $start)" > "$OUT/colour/lfgen_seconds"
$LF export --to mitsuba "$OUT/colour/matched" --out "$OUT/colour/mitsuba"
$LF export --to blender "$OUT/colour/matched" --out "$OUT/colour/blender"
$PY scripts/validate.py colour "$OUT/colour/lfgen/input_Cam000.exr" "$OUT/colour/lfgen_seconds" \
    "$OUT/colour/mitsuba" $(bl "$OUT/colour/blender") --spp "$SPP" --work "$OUT/colour"

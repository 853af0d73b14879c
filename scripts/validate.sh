#!/usr/bin/env bash
# lfgen against Mitsuba 3, Blender Cycles and POV-Ray (README, "Validation"): depth of the centre
# and corner views; colour under matched settings (Lambert everywhere; lfgen's own Standard BSDF
# in Mitsuba for glossy and metallic surfaces; direct light only); wall clock at equal spp.
# POV-Ray's depth check is a cargo test (tests/povray.rs).
#
#   scripts/validate.sh            # OUT=target/validation RES=160,120 SPP=1024 VARIANTS=1
#
# SPP: samples per pixel of every colour render (all renderers the same); METAL_SPP: the same for
# the near-mirror metal room (roughness 0.2, metallic 1), whose noise at SPP alone exceeds 1 %;
# VARIANTS=0 skips the four roughness/metallic variants of the glossy scene. LF=path/to/lfgen uses that binary
# instead of building one. lfgen runs inside $OUT, so it uses the built-in defaults (= the
# shipped generator.toml) whatever ./generator.toml holds.
#
# Needs python3 (a venv with mitsuba, numpy, OpenEXR is made under $OUT), Debian's libllvm19 for
# Mitsuba's llvm_ad_rgb variant (apt-get install libllvm19), povray, and, for Cycles, Blender on
# the PATH (Debian: apt-get install blender); without Blender, Cycles is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=$(realpath -m "${OUT:-target/validation}")
RES=${RES:-160,120}
SPP=${SPP:-1024}
METAL_SPP=${METAL_SPP:-8192}
VARIANTS=${VARIANTS:-1}
# shellcheck source=scripts/tools.sh
. scripts/tools.sh
# Dr.Jit's LLVM backend (Mitsuba's llvm_ad_rgb) looks for libLLVM.so; Debian names it by version.
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
    for f in /usr/lib/x86_64-linux-gnu/libLLVM-19.so /usr/lib/llvm-19/lib/libLLVM.so; do
        if [ -e "$f" ]; then export DRJIT_LIBLLVM_PATH=$f; break; fi
    done
fi
HAVE_BLENDER=1
command -v blender >/dev/null || { HAVE_BLENDER=0; echo "blender not found: Cycles skipped"; }
bl() { if [ "$HAVE_BLENDER" = 1 ]; then echo "--blender $1"; fi; }

# The depth scene has no glass, semi-transparent or cut-out materials by chance (furniture may
# still bring cut-outs, evaluated exactly for Mitsuba): glass counts in the HCI depth only at
# grazing angles and coincident back-to-back cut-out quads are ties, both handled (and counted)
# by tests/povray.rs on the default scene.
echo "== depth: generated scene, 3x3 views at ${RES/,/x}, centre and corner views"
rm -rf "$OUT/depth"
lf --scenes 1 --out "$OUT/depth/ds" --set "camera.resolution=[$RES]" --set camera.grid=[3,3] \
    --set render.spp=1 --set render.gt_views=all --set dataset.date=2026-01-01 --quiet \
    --set scene.glass=0 --set scene.semi_transparent=0 --set scene.cutout=0
SCENE="$OUT/depth/ds/train/scene_0000"
lf export --to mitsuba "$SCENE" --out "$OUT/depth/mitsuba" --views 4,0,2,6,8
lf export --to blender "$SCENE" --out "$OUT/depth/blender" --views 4,0,2,6,8
$PY "$VAL" depth "$SCENE" "$OUT/depth/mitsuba" $(bl "$OUT/depth/blender") --work "$OUT/depth"

# One colour case: the depth scene with uniform materials (validate.py match MATCH_ARGS),
# rendered by lfgen at render.max_depth=DEPTH and exported to the references with the same
# limit (Mitsuba max_depth DEPTH+1, Cycles DEPTH-1 bounces); centre view, SPP (default $SPP)
# spp everywhere. Russian roulette is off (rr_depth past the last vertex) in lfgen and Mitsuba:
# it trades noise for speed, and the table measures differences that noise blurs.
#   colour NAME DEPTH "MATCH_ARGS" "COLOUR_ARGS" TITLE [SPP]
colour() {
    local name=$1 depth=$2 match=$3 args=$4 title=$5 spp=${6:-$SPP} dir="$OUT/colour/$1"
    local limits=(--set render.max_depth="$depth" --set render.rr_depth=$((depth + 1)))
    rm -rf "$dir"
    mkdir -p "$dir/matched"
    # shellcheck disable=SC2086
    $PY "$VAL" match "$SCENE/scene.json" "$OUT/depth/blender/blender_scene.json" \
        "$dir/matched/scene.json" $match
    (cd "$OUT" && $PY "$VAL" timed "$dir/lfgen_seconds" "$LF" render "$dir/matched/scene.json" \
        --out "$dir/lfgen" --set render.spp="$spp" "${limits[@]}" \
        --set render.write_exr=true --quiet)
    lf export --to mitsuba "$dir/matched" --out "$dir/mitsuba" "${limits[@]}"
    lf export --to blender "$dir/matched" --out "$dir/blender" "${limits[@]}"
    lf export --to pov "$dir/matched" --out "$dir/pov" "${limits[@]}"
    $PY "$VAL" povdirect "$dir/pov" "$dir/blender"
    # shellcheck disable=SC2086
    $PY "$VAL" colour "$dir/lfgen/input_Cam000.exr" "$dir/lfgen_seconds" --mitsuba "$dir/mitsuba" \
        --spp "$spp" --work "$dir" --title "$title" $args
}

echo "== colour and speed: the depth scene with uniform opaque materials, centre view, $SPP spp"
colour diffuse 5 "--dielectric-only --diffuse" \
    "--variants scalar_rgb,llvm_ad_rgb --lfgen-bsdf-name Diffuse $(bl "$OUT/colour/diffuse/blender")" \
    "Lambert everywhere (lfgen Diffuse = Standard with specular 0), max_depth 5"
colour glossy 5 "--dielectric-only" \
    "--variants llvm_ad_rgb --lfgen-bsdf" \
    "lfgen Standard (scene roughness, metallic 0) vs lfgen_standard in Mitsuba, max_depth 5"
colour principled 5 "--dielectric-only" \
    "--variants scalar_rgb $(bl "$OUT/colour/principled/blender")" \
    "the same scene vs the references' own principled BSDFs (Disney diffuse, not lfgen's model)"
if [ "$VARIANTS" = 1 ]; then
    for rm in "0.2 0 $SPP" "0.8 0 $SPP" "0.2 1 $METAL_SPP" "0.8 1 $SPP"; do
        set -- $rm
        colour "r$1_m$2" 5 "--dielectric-only --roughness $1 --metallic $2" \
            "--variants llvm_ad_rgb --lfgen-bsdf" \
            "every Standard material roughness $1, metallic $2, vs lfgen_standard in Mitsuba" "$3"
    done
fi

echo "== direct light only (render.max_depth = 1): Lambert, area lights, vs POV-Ray"
colour direct 1 "--dielectric-only --diffuse" \
    "--variants llvm_ad_rgb --lfgen-bsdf-name Diffuse --pov $OUT/colour/direct/pov --pov-supersample 4 $(bl "$OUT/colour/direct/blender")" \
    "direct light only: lfgen max_depth 1 = Mitsuba max_depth 2 = Cycles 0 bounces = POV-Ray without radiosity"

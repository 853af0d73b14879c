#!/bin/sh
# Embree's tutorials against `lfgen bench speed` on the same scene (docs/design/performance.md,
# "BVH traversal"): built-in scene 0 at 192², exported through the Mitsuba writer and merged
# into one OBJ, traced by Embree's path tracer (paths of up to 5 vertices, 1 spp) and its
# viewer's primary rays (eyelight), from the scene's first camera, on the same threads.
#
# Usage: scripts/embree_compare.sh [THREADS]   (default 2)
# Needs Debian's embree-tools (pathtracer, viewer) and lfgen on PATH
# (export PATH="$PWD/target/release:$PATH").
set -eu
threads=${1:-2}
for tool in pathtracer viewer lfgen python3; do
    command -v "$tool" >/dev/null || { echo "$tool is missing (embree-tools: apt-get install embree-tools)" >&2; exit 2; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
lfgen --no-config --quiet --scenes 1 --set camera.resolution=[192,192] --set camera.grid=[3,3] \
    --set render.spp=1 --set render.adaptive_spp=0 --out "$work/ds"
lfgen export --no-config --to mitsuba --out "$work/mi" "$work/ds/train/scene_0000" >/dev/null
# One OBJ of every mesh, and the first sensor's look-at and field of view as Embree options.
camera=$(python3 - "$work" <<'PY'
import glob, re, sys
work = sys.argv[1]
offset, faces = 0, 0
with open(f"{work}/all.obj", "w") as out:
    for name in sorted(glob.glob(f"{work}/mi/meshes/*.obj")):
        lines = open(name).read().splitlines()
        verts = [l for l in lines if l.startswith("v ")]
        out.writelines(v + "\n" for v in verts)
        for l in lines:
            if l.startswith("f "):
                idx = [int(t.split("/")[0]) + offset for t in l.split()[1:]]
                out.write("f " + " ".join(map(str, idx)) + "\n")
                faces += 1
        offset += len(verts)
xml = open(f"{work}/mi/scene.xml").read()
fov = re.search(r'name="fov" value="([^"]+)"', xml).group(1)
look = re.search(r'origin="([^"]+)" target="([^"]+)" up="([^"]+)"', xml)
vec = lambda s: " ".join(v.strip() for v in s.split(","))
print(f"--vp {vec(look.group(1))} --vi {vec(look.group(2))} --vu {vec(look.group(3))} --fov {fov}")
print(f"{faces} triangles", file=sys.stderr)
PY
)
# shellcheck disable=SC2086 # the camera options are separate words
pt=$(pathtracer -i "$work/all.obj" $camera --size 192 192 --spp 1 --max-path-length 5 \
    --threads "$threads" --benchmark 4 16 2>&1 | awk '/MRAYPS_AVG /{print $2}')
# shellcheck disable=SC2086
eye=$(viewer -i "$work/all.obj" $camera --size 192 192 --shader eyelight --threads "$threads" \
    --benchmark 4 16 2>&1 | awk '/MRAYPS_AVG /{print $2}')
echo "Embree path tracer (5 vertices, 1 spp): $pt Mrays/s"
echo "Embree viewer, primary rays (eyelight): $eye Mrays/s"
lfgen bench speed --no-config --threads "$threads" --results "$work/bench.jsonl" | grep -i "kernel\|mrays"

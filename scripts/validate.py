"""lfgen against Mitsuba 3, Blender Cycles and POV-Ray (README, "Validation"); driven by
validate.sh.

Subcommands:
  depth     SCENE_DIR MITSUBA_DIR [--blender BLENDER_DIR]  planar depth vs gt_depth_lowres_CamNNN.pfm
  match     SCENE_JSON BLENDER_JSON OUT_JSON [--diffuse] [--roughness R] [--metallic M] ...
                                                           the colour-matched scene (see below)
  colour    LFGEN_EXR LFGEN_SECONDS [--mitsuba DIR [--variants V,..] [--lfgen-bsdf]]
            [--blender DIR] [--pov DIR]                    colour vs lfgen's linear EXR, timings
  povdirect POV_DIR BLENDER_DIR                            direct.pov: lfgen's direct light in POV-Ray
  timed     OUT COMMAND...                                 "wall cpu" seconds of a command
  mitsuba-render XML OUT.npy [--variant V] [--spp N]      one Mitsuba render (lfgen_standard registered)

Depth: Mitsuba renders the `position` AOV with one non-jittered stratified sample (the pixel
centre) and planar depth is (p - o)·forward; Blender's Z pass at 1 spp is planar depth of the
pixel-centre sample. Only surfaces lfgen's HCI depth counts are present (the exporters mark
them). Pixels next to a depth discontinuity in lfgen's map (silhouettes) are reported apart.

Colour: renderers differ in textures, so `match` rewrites scene.json with every base colour and
opacity replaced by the uniform means the exporters give other renderers (`--diffuse`: every
material lfgen's Lambert-only `diffuse` model, which Mitsuba and Cycles have exactly); lfgen
re-renders that scene and the references render the same export at the same spp and bounce
limit. With `--lfgen-bsdf` Mitsuba renders lfgen's own Standard BSDF (scripts/lfgen_bsdf.py)
instead of `principled`. Metric: per 8×8 block the mean over pixels and channels, relative to
lfgen; mean, 90th percentile, and the ratio of the totals.
"""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np


def read_pfm(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"Pf":
            sys.exit(f"{path}: not a greyscale PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4").reshape(h, w)
    return data[::-1].astype(np.float64)  # rows are stored bottom-up


def read_exr(path):
    """Every channel of an EXR file as float64 arrays, by full channel name."""
    import OpenEXR

    out = {}
    with OpenEXR.File(path, separate_channels=True) as f:
        for part in f.parts:
            for name, ch in part.channels.items():
                out[name] = np.asarray(ch.pixels, dtype=np.float64)
    return out


def rgb(channels):
    pick = lambda c: next(v for k, v in channels.items() if k.split(".")[-1] == c)
    return np.stack([pick("R"), pick("G"), pick("B")], axis=-1)


def silhouettes(z, jump=0.01):
    """Pixels whose 3×3 neighbourhood holds a relative depth jump above `jump`."""
    zz = np.nan_to_num(z, nan=1e9)
    edge = np.zeros(z.shape, bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            shifted = np.roll(np.roll(zz, dy, 0), dx, 1)
            edge |= np.abs(shifted - zz) > jump * zz
    edge[0, :] = edge[-1, :] = edge[:, 0] = edge[:, -1] = True
    return edge


def depth_table_row(name, view, want, got, exclude):
    valid = np.isfinite(want) & ~exclude
    rel = np.abs(got - want) / want
    inner = valid & ~silhouettes(want)
    ok_all = np.mean(rel[valid] <= 1e-4)
    ok_inner = np.mean(rel[inner] <= 1e-4)
    print(f"| {name} | Cam{view:03} | {inner.sum()} | {100 * ok_inner:.3f} % | {100 * ok_all:.2f} % "
          f"| {np.nanmedian(rel[inner]):.1e} |")
    bad = np.argwhere(inner & ~(rel <= 1e-4))
    for y, x in bad[:5]:
        print(f"    {name} view {view} pixel ({x}, {y}): lfgen {want[y, x]:.6f} {name} {got[y, x]:.6f}")
    return ok_inner


def opacity(op, uv):
    """lfgen's opacity patterns (scene.json `opacity`) at texture coordinate uv (metres)."""
    kind = op["type"]
    if kind == "constant":
        return op["value"]
    if kind == "grid":
        f = np.asarray(uv) / op["period"] % 1.0
        return op["value"] if f[0] < op["bar"] or f[1] < op["bar"] else 0.0
    if kind == "leaves":
        f = np.asarray(uv) / np.asarray(op["period"]) % 1.0
        half = 0.42 * np.sin(np.pi * f[1]) ** 0.8
        return 1.0 if abs(f[0] - 0.5) < half else 0.0
    return 1.0  # image alpha is not exported


def mitsuba_depths(mi_dir, desc):
    """Planar depth of the pixel-centre ray of every exported sensor: the first surface of
    depth.xml whose opacity at the hit is at least 0.5 (lfgen's HCI rule; depth.xml already
    holds only surfaces that can count). Also returns where a cut-out surface was crossed."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    scene = mi.load_file(os.path.join(mi_dir, "depth.xml"), optimize=False)
    mats = [desc["materials"][o["material"]] for o in desc["objects"]]
    for sensor in scene.sensors():
        view = int(sensor.id()[3:])
        w, h = sensor.film().size()
        m = np.array(mi.Transform4f(sensor.world_transform()).matrix, dtype=np.float64)
        origin, forward = m[:3, 3], m[:3, 2]
        z = np.full((h, w), np.nan)
        cutout = np.zeros((h, w), bool)
        # Depths of the see-through cut-out hits passed on the way (ties, see cmd_depth).
        passed = np.full((h, w, 8), np.nan)
        for y in range(h):
            for x in range(w):
                ray, _ = sensor.sample_ray(0.0, 0.5, [(x + 0.5) / w, (y + 0.5) / h], [0.5, 0.5])
                for k in range(64):
                    si = scene.ray_intersect(ray)
                    if not si.is_valid():
                        break
                    op = mats[int(si.shape.id()[1:].split("_")[0])]["opacity"]
                    cutout[y, x] |= op["type"] != "constant"
                    if opacity(op, si.uv) >= 0.5:
                        z[y, x] = (np.array(si.p) - origin) @ forward
                        break
                    passed[y, x, k % 8] = (np.array(si.p) - origin) @ forward
                    ray = si.spawn_ray(ray.d)
        yield view, z, cutout, passed


def blender_depth(bl_dir, view, out_dir):
    out = os.path.join(out_dir, f"blender_depth_{view}.exr")
    run_blender(bl_dir, ["--view", str(view), "--out", out, "--depth"])
    ch = read_exr(out)
    z = next(v for k, v in ch.items() if k.endswith("Depth.Z") or k == "Z")
    return np.where(z > 1e9, np.nan, z)


def run_blender(bl_dir, args):
    cmd = ["blender", "-b", "--factory-startup", "-P", os.path.join(bl_dir, "scene.py"), "--"] + args
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0 or "Error" in r.stderr:
        sys.exit(f"blender failed: {' '.join(cmd)}\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")


def cmd_depth(a):
    print("| renderer | view | pixels (no silhouette) | within 1e-4 | within 1e-4, all pixels | median rel. diff |")
    print("|---|---|---|---|---|---|")
    worst = 1.0
    desc = json.load(open(os.path.join(a.scene, "scene.json")))
    for view, z, cutout, passed in mitsuba_depths(a.mitsuba, desc):
        want = read_pfm(os.path.join(a.scene, f"gt_depth_lowres_Cam{view:03}.pfm"))
        # A tie: lfgen's surface lies at the depth of a see-through cut-out hit (coincident
        # back-to-back quads); which one a renderer meets first is arbitrary, and after the
        # see-through one Mitsuba's offset ray skips the other.
        tie = np.any(np.abs(passed - want[..., None]) <= 1e-4 * want[..., None], axis=2)
        worst = min(worst, depth_table_row("Mitsuba 3", view, want, z, tie))
        print(f"    (Mitsuba 3: {tie.sum()} tie pixels left out)")
        if a.blender:
            # Blender gets no cut-out patterns: pixels whose ray met one are left out.
            got = blender_depth(a.blender, view, a.work)
            worst = min(worst, depth_table_row("Cycles", view, want, got, cutout))
            print(f"    (Cycles: {cutout.sum()} pixels crossing cut-out surfaces left out)")
    print(f"lowest agreement away from silhouettes: {100 * worst:.3f} %")


def cmd_match(a):
    desc = json.load(open(a.scene_json))
    exported = json.load(open(a.blender_json))["materials"]
    for m, e in zip(desc["materials"], exported):
        m["base_color"] = {"type": "constant", "color": e["color"]}
        m["opacity"] = {"type": "constant", "value": e["opacity"] if a.keep_opacity else 1.0}
        # Emission maps (skies, facades behind windows) become their mean, as exported.
        m.pop("emission_map", None)
        m["emission"] = e["emission"]
        if a.dielectric_only:
            # Diffuse + glossy only: no metals, no glass (the matched setting).
            m["metallic"] = 0.0
            m["model"] = {"type": "standard"}
        if a.diffuse:
            # Pure Lambert everywhere (lfgen's Standard model without its glossy layer), which
            # every renderer has exactly: Mitsuba `diffuse`, Cycles Diffuse BSDF at roughness 0.
            m["model"] = {"type": "diffuse"}
            m["metallic"] = 0.0
        if a.roughness is not None and m["model"]["type"] == "standard" and not any(m["emission"]):
            m["roughness"] = a.roughness
        if a.metallic is not None and m["model"]["type"] == "standard" and not any(m["emission"]):
            m["metallic"] = a.metallic
    # One view (the centre camera): timings compare one image with one image.
    if not a.keep_grid:
        desc["camera"]["grid"] = [1, 1]
    json.dump(desc, open(a.out_json, "w"))


def block_stats(ref, img, n=8):
    h, w = (ref.shape[0] // n) * n, (ref.shape[1] // n) * n
    block = lambda x: x[:h, :w].mean(axis=2).reshape(h // n, n, w // n, n).mean(axis=(1, 3))
    a, b = block(ref), block(img)
    rel = np.abs(b - a) / np.maximum(a, 1e-6)
    return rel.mean(), np.percentile(rel, 90), b.sum() / a.sum() - 1


def cmd_colour(a):
    """One table: lfgen's linear EXR against each reference renderer at the same spp."""
    ref = rgb(read_exr(a.lfgen_exr))
    h, w = ref.shape[:2]
    # "wall [cpu]" seconds (validate.py timed); CPU time = user + system of the process tree,
    # which other jobs sharing the cores inflate much less than the wall clock.
    lf_wall, lf_cpu = (open(a.lfgen_time).read().split() + [None])[:2]
    lf_time, lf_cpu = float(lf_wall), float(lf_cpu) if lf_cpu else float("nan")
    if a.title:
        print(f"\n{a.title}\n")
    print("| renderer | BSDF | spp | mean rel. diff (8×8 blocks) | p90 | total energy diff "
          "| wall clock | lfgen / renderer | CPU time | lfgen / renderer (CPU) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    print(f"| lfgen | {a.lfgen_bsdf_name} | {a.spp} | – | – | – | {lf_time:.1f} s | 1 "
          f"| {lf_cpu:.1f} s | 1 |")

    refs = {}

    def row(name, bsdf, img, t, cpu):
        refs[name] = img
        mean, p90, energy = block_stats(ref, img)
        print(f"| {name} | {bsdf} | {a.spp} | {100 * mean:.2f} % | {100 * p90:.2f} % | "
              f"{100 * energy:+.2f} % | {t:.1f} s | {lf_time / t:.2f} | {cpu:.1f} s "
              f"| {lf_cpu / cpu:.2f} |", flush=True)

    for variant in a.variants.split(",") if a.mitsuba else []:
        xml = os.path.join(a.mitsuba, "scene.xml")
        bsdf = "principled / diffuse"
        if a.lfgen_bsdf:
            # lfgen's own Standard model (scripts/lfgen_bsdf.py) in place of `principled`.
            text = open(xml).read().replace('type="principled"', 'type="lfgen_standard"')
            xml = os.path.join(a.mitsuba, "scene_lfgen.xml")
            open(xml, "w").write(text)
            bsdf = "lfgen_standard / diffuse"
        out = os.path.join(a.work, f"mitsuba_{variant}.npy")
        t0, c0 = time.time(), children_cpu()
        # A process per render: one Mitsuba variant per process, and the wall clock includes
        # start-up (and the JIT compilation of llvm variants) as lfgen's and Blender's do.
        cmd = [sys.executable, os.path.abspath(__file__), "mitsuba-render", xml, out,
               "--variant", variant, "--spp", str(a.spp)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"mitsuba failed: {' '.join(cmd)}\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")
        row(f"Mitsuba 3 `{variant}`", bsdf, np.load(out), time.time() - t0, children_cpu() - c0)
    if a.blender:
        out = os.path.join(a.work, "blender_colour.exr")
        t0, c0 = time.time(), children_cpu()
        run_blender(a.blender, ["--view", "0", "--out", os.path.abspath(out), "--spp", str(a.spp)])
        row("Cycles", "Principled / Diffuse", rgb(read_exr(out)), time.time() - t0,
            children_cpu() - c0)
    if a.pov:
        out = os.path.join(a.work, "pov_direct.exr")
        t0, c0 = time.time(), children_cpu()
        img = render_pov_direct(a.pov, 0, w, h, a.pov_supersample, out)
        row(f"POV-Ray 3.7 ({a.pov_supersample}² rays/px)", "Lambert, point-light grid", img,
            time.time() - t0, children_cpu() - c0)
    # The references against each other (the first one as the reference).
    names = list(refs)
    for other in names[1:]:
        mean, p90, energy = block_stats(refs[names[0]], refs[other])
        print(f"\n{other} against {names[0]}: mean {100 * mean:.2f} %, p90 {100 * p90:.2f} %, "
              f"energy {100 * energy:+.2f} %")


def children_cpu():
    """User + system seconds of all waited-for child processes so far."""
    import resource

    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def cmd_timed(a):
    """Runs a command and writes "wall cpu" seconds to a file (cpu: user + system)."""
    t0, c0 = time.time(), children_cpu()
    r = subprocess.run(a.command)
    if r.returncode != 0:
        sys.exit(r.returncode)
    with open(a.out, "w") as f:
        f.write(f"{time.time() - t0} {children_cpu() - c0}\n")


def psnr(ref, img):
    """PSNR of linear `img` against `ref`, both scaled by the reference's automatic exposure
    (key 0.18 on the log-average luminance, as lfgen's `auto_exposure`), peak 1: the figure
    `lfgen bench quality` calls linear PSNR."""
    lum = ref @ np.array([0.2126, 0.7152, 0.0722])
    k = 0.18 / np.exp(np.mean(np.log(lum + 1e-4)))
    return -10 * np.log10(np.mean(((img - ref) * k) ** 2))


def load_image(path):
    return np.load(path) if path.endswith(".npy") else rgb(read_exr(path))


def cmd_psnr(a):
    """Prints the PSNR of every image against the reference, one per line."""
    ref = load_image(a.reference)
    for path in a.images:
        print(f"{psnr(ref, load_image(path)):.2f} {path}")


def cmd_mitsuba_render(a):
    import mitsuba as mi

    mi.set_variant(a.variant)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import lfgen_bsdf

    lfgen_bsdf.register()
    scene = mi.load_file(a.xml, spp=a.spp)
    img = np.array(mi.render(scene, sensor=0, seed=a.seed), dtype=np.float64)[..., :3]
    np.save(a.out, img)


def read_obj_triangles(path):
    """World-space triangles (n, 3, 3) of an exported OBJ (every face a triangle)."""
    v, faces = [], []
    for line in open(path):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            faces.append([int(c.split("/")[0]) - 1 for c in line.split()[1:4]])
    return np.asarray(v, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]


def sub_lights(tri, target_area):
    """Centroids, area and unit normal of the n² equal sub-triangles of `tri` (n chosen so
    each is at most `target_area`): the midpoint rule for the emitter's area integral."""
    p0, p1, p2 = tri
    cross = np.cross(p1 - p0, p2 - p0)
    area = 0.5 * np.linalg.norm(cross)
    n = max(1, int(np.ceil(np.sqrt(area / target_area))))
    a, b = (p1 - p0) / n, (p2 - p0) / n
    cents = []
    for i in range(n):
        for j in range(n - i):
            cents.append(p0 + (i + 1 / 3) * a + (j + 1 / 3) * b)  # upward (i,j),(i+1,j),(i,j+1)
            if i + j < n - 1:
                cents.append(p0 + (i + 2 / 3) * a + (j + 2 / 3) * b)  # downward
    return np.asarray(cents), area / (n * n), cross / (2.0 * area)


# POV-Ray attenuates a light by 2 / (1 + (d/FADE)²) with fade_power 2: 2·FADE²/d² for a tiny
# FADE, so colours are scaled by 1/(2·FADE²) to give the inverse-square law exactly.
POV_FADE = 1e-3


def cmd_povdirect(a):
    """direct.pov: lfgen's direct light (camera hit + one light bounce, Lambert) in POV-Ray.

    Every emitter triangle becomes n² point lights at the centroids of its equal sub-triangles,
    each a spotlight with `radius 90 falloff 90 tightness 1` (attenuation exactly cos θ about
    the emitter normal; checked against cos θ by rendering a plane) of intensity L·A_sub along
    the normal: a Lambertian emitter of radiance L, integrated by the midpoint rule (error
    O((size/distance)²), ~0.1 % for `--light-area` 0.01 m² at 1 m). Surfaces: pigment = the
    exported mean colour, `diffuse 1/π` (POV-Ray's diffuse term is k·colour·I·cos θ, so the
    radiance is albedo/π · E as lfgen's), `ambient 0`, no specular, no radiosity; emitters
    show their emission and cast no shadow (lfgen's shadow rays stop short of the light).
    Punctual lights are not written (the built-in scenes have none).
    """
    data = json.load(open(os.path.join(a.blender, "blender_scene.json")))
    mats = data["materials"]
    out = ['#version 3.7;', 'global_settings { assumed_gamma 1.0 max_trace_level 5 }',
           '#include "cameras.inc"', '#include "geometry.inc"',
           "background {{ rgb <{}, {}, {}> }}".format(*data["environment"])]
    num = lambda x: repr(float(x))
    to_pov = lambda p: f"<{num(p[0])}, {num(p[1])}, {num(-p[2])}>"  # POV-Ray mirrors z
    n_lights = 0
    for o in data["objects"]:
        m = mats[o["material"]]
        c, e = m["color"], m["emission"]
        if max(e) > 0:
            out.append(f"object {{ {o['id']} texture {{ pigment {{ rgb 1 }} finish {{ ambient 0 "
                       f"diffuse 0 emission <{e[0]}, {e[1]}, {e[2]}> }} }} no_shadow }}")
            for tri in read_obj_triangles(os.path.join(a.blender, o["mesh"])):
                cents, sub_area, normal = sub_lights(tri, a.light_area)
                col = np.asarray(e) * sub_area / (2.0 * POV_FADE ** 2)
                for p in cents:
                    out.append(
                        f"light_source {{ {to_pov(p)} rgb <{num(col[0])}, {num(col[1])}, {num(col[2])}> "
                        f"spotlight point_at {to_pov(p + normal)} radius 90 falloff 90 tightness 1 "
                        f"fade_distance {POV_FADE} fade_power 2 }}")
                    n_lights += 1
        else:
            out.append(f"object {{ {o['id']} texture {{ pigment {{ rgb <{c[0]}, {c[1]}, {c[2]}> }} "
                       f"finish {{ ambient 0 diffuse {1 / np.pi!r} specular 0 phong 0 }} }} }}")
    with open(os.path.join(a.pov, "direct.pov"), "w") as f:
        f.write("\n".join(out) + "\n")
    print(f"direct.pov: {n_lights} point lights")


def render_pov_direct(pov_dir, view, w, h, supersample, out_exr):
    """Renders direct.pov at `supersample`× the resolution (no anti-aliasing: one ray per
    sub-pixel centre) and box-filters it down: lfgen's box-filtered pixel."""
    cmd = ["povray", "+Idirect.pov", f"+O{os.path.abspath(out_exr)}", "+FE", f"+W{w * supersample}",
           f"+H{h * supersample}", "-A", "-D", "File_Gamma=1.0", f"Declare=View={view}", "+WT2"]
    r = subprocess.run(cmd, cwd=pov_dir, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"povray failed: {' '.join(cmd)}\n{r.stderr[-2000:]}")
    img = rgb(read_exr(out_exr))
    return img.reshape(h, supersample, w, supersample, 3).mean(axis=(1, 3))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("depth")
    d.add_argument("scene")
    d.add_argument("mitsuba")
    d.add_argument("--blender")
    d.add_argument("--work", default=".")
    m = sub.add_parser("match")
    m.add_argument("scene_json")
    m.add_argument("blender_json")
    m.add_argument("out_json")
    m.add_argument("--keep-opacity", action="store_true", help="keep mean opacities (else opaque)")
    m.add_argument("--dielectric-only", action="store_true", help="metallic 0, glass made standard")
    m.add_argument("--diffuse", action="store_true", help="every material pure Lambert")
    m.add_argument("--keep-grid", action="store_true", help="keep every view (else the centre one)")
    m.add_argument("--roughness", type=float, help="one roughness for every Standard material")
    m.add_argument("--metallic", type=float, help="one metallic for every Standard material")
    c = sub.add_parser("colour")
    c.add_argument("lfgen_exr")
    c.add_argument("lfgen_time")
    c.add_argument("--mitsuba", help="Mitsuba export folder")
    c.add_argument("--variants", default="scalar_rgb", help="Mitsuba variants, comma-separated")
    c.add_argument("--lfgen-bsdf", action="store_true", help="Mitsuba renders lfgen's Standard model")
    c.add_argument("--lfgen-bsdf-name", default="Standard", help="lfgen's model, for the table")
    c.add_argument("--blender", help="Blender export folder")
    c.add_argument("--pov", help="POV-Ray export folder with direct.pov (see povdirect)")
    c.add_argument("--pov-supersample", type=int, default=2)
    c.add_argument("--spp", type=int, default=256)
    c.add_argument("--title")
    c.add_argument("--work", default=".")
    t = sub.add_parser("timed")
    t.add_argument("out")
    t.add_argument("command", nargs=argparse.REMAINDER)
    r = sub.add_parser("mitsuba-render")
    r.add_argument("xml")
    r.add_argument("out")
    r.add_argument("--variant", default="scalar_rgb")
    r.add_argument("--spp", type=int, default=256)
    r.add_argument("--seed", type=int, default=0)
    s = sub.add_parser("psnr")
    s.add_argument("reference", help="linear EXR or .npy")
    s.add_argument("images", nargs="+")
    v = sub.add_parser("povdirect")
    v.add_argument("pov", help="POV-Ray export folder (cameras.inc, geometry.inc)")
    v.add_argument("blender", help="Blender export folder of the same scene (materials, meshes)")
    v.add_argument("--light-area", type=float, default=0.01, help="largest point-light patch, m²")
    a = p.parse_args()
    {"depth": cmd_depth, "match": cmd_match, "colour": cmd_colour,
     "mitsuba-render": cmd_mitsuba_render, "povdirect": cmd_povdirect, "timed": cmd_timed,
     "psnr": cmd_psnr}[a.cmd](a)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Packs what issue 15's GPU check needs into one folder small enough for a device machine's
64 MiB transfer, and unpacks it there.

pack:   gpu_carry.py pack DATASET OUT --train N [--val SCENE ...] [--bin target/release/lftrain]
unpack: gpu_carry.py unpack OUT          (on the GPU machine: writes OUT/lftrain, PNG views)

A scene keeps only what `lftrain train`/`predict` read: parameters.cfg, gt_disp_lowres.pfm,
modes.exr and the 33 star views. The views travel as lossless WebP (about 30 % smaller than
lfgen's PNGs, pixel-identical after unpacking) and the stripped binary as xz (the wgpu build is
~100 MB stripped, ~17 MB packed). A 256² scene then takes ~4.5 MB. No manifest travels, so
lfformat does not check the pruned scenes against the dataset's checksums. Needs Python 3 and
Pillow (WebP support) on both machines.
"""
import argparse
import lzma
import shutil
import subprocess
import sys
from multiprocessing import Pool
from pathlib import Path

from PIL import Image

TRUTH = ("parameters.cfg", "gt_disp_lowres.pfm", "modes.exr")


def star(n):
    """View indices of the star (row, column and both diagonals) of an n×n grid: the views
    lftrain reads, as lfformat's `ViewSet::Star` defines them."""
    c = n // 2
    return [v * n + u for v in range(n) for u in range(n)
            if u == c or v == c or abs(u - c) == abs(v - c)]


def grid_side(scene):
    for line in (scene / "parameters.cfg").read_text().splitlines():
        if line.strip().startswith("num_cams_x"):
            return int(line.split("=")[1])
    sys.exit(f"{scene}/parameters.cfg: no num_cams_x")


def to_webp(pair):
    src, dst = pair
    Image.open(src).save(dst, "WEBP", lossless=True, quality=100, method=4)


def to_png(path):
    Image.open(path).save(path.with_suffix(".png"), "PNG", compress_level=1)
    path.unlink()


def pack(args):
    out = Path(args.out)
    if out.exists():
        sys.exit(f"{out}: already exists")
    jobs = []
    # Hidden folders are lfgen's unfinished scenes (written under a temporary name).
    train = Path(args.dataset) / "train"
    scenes = sorted(p for p in train.iterdir() if p.is_dir() and not p.name.startswith("."))
    chosen = [("train", s) for s in scenes[: args.train]]
    chosen += [("val", Path(args.dataset) / "val" / v) for v in args.val]
    for split, scene in chosen:
        dst = out / "data" / split / scene.name
        dst.mkdir(parents=True)
        for name in TRUTH:
            shutil.copy(scene / name, dst / name)
        for i in star(grid_side(scene)):
            jobs.append((scene / f"input_Cam{i:03d}.png", dst / f"input_Cam{i:03d}.webp"))
    with Pool() as pool:
        pool.map(to_webp, jobs, chunksize=8)
    stripped = out / "lftrain"
    subprocess.run(["strip", "-o", stripped, args.bin], check=True)
    with open(stripped, "rb") as f, lzma.open(out / "lftrain.xz", "wb", preset=9) as g:
        shutil.copyfileobj(f, g)
    stripped.unlink()
    size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
    print(f"{out}: {len(chosen)} scenes, {size / 2**20:.1f} MiB")


def unpack(args):
    out = Path(args.out)
    binary = out / "lftrain"
    with lzma.open(out / "lftrain.xz") as f, open(binary, "wb") as g:
        shutil.copyfileobj(f, g)
    binary.chmod(0o755)
    views = list((out / "data").rglob("input_Cam*.webp"))
    with Pool() as pool:
        pool.map(to_png, views, chunksize=8)
    print(f"{out}: lftrain and {len(views)} views unpacked")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("pack")
    p.add_argument("dataset")
    p.add_argument("out")
    p.add_argument("--train", type=int, required=True, help="first N training scenes")
    p.add_argument("--val", nargs="*", default=[], help="validation scene folder names")
    p.add_argument("--bin", default="target/release/lftrain")
    p.set_defaults(run=pack)
    u = sub.add_parser("unpack")
    u.add_argument("out")
    u.set_defaults(run=unpack)
    args = parser.parse_args()
    args.run(args)


if __name__ == "__main__":
    main()

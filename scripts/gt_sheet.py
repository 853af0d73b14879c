#!/usr/bin/env python3
"""One scene's ground truth on one sheet: the centre view, HCI disparity, normals, object,
material and class IDs, valid mask and the five HCI evaluation masks.

    python3 -m pip install numpy pillow OpenEXR
    python3 scripts/gt_sheet.py DATASET/train/scene_0000 docs/ground-truth-sheet.png

The sheet in docs/ was made from `lfgen generate --no-config --preset quick
--set camera.grid=[3,3] --set camera.resolution=[256,256] --scenes 1 --out SHEET`.
"""
import json
import sys
from pathlib import Path

import numpy as np
import OpenEXR
from PIL import Image, ImageDraw

from pfm import read_pfm

MASKS = ["discontinuities", "planes", "smooth_surfaces", "fine", "fine_surrounding"]


def read_normals(path):
    """gt_normals_lowres.exr: camera-space unit normals in R, G, B."""
    with OpenEXR.File(str(path)) as f:
        channels = f.channels()
        if "RGB" in channels:
            return np.asarray(channels["RGB"].pixels, dtype=np.float32)
        return np.stack([channels[c].pixels for c in "RGB"], axis=-1).astype(np.float32)


def id_colours(ids):
    """A fixed pseudo-random colour per ID, black for 0 (no surface)."""
    rng = np.random.default_rng(7)
    table = rng.integers(40, 256, size=(int(ids.max()) + 1, 3), dtype=np.uint8)
    table[0] = 0
    return table[ids]


def disparity_colours(d):
    lo, hi = np.nanpercentile(d, [1, 99])
    t = np.clip((d - lo) / max(hi - lo, 1e-6), 0, 1)
    # A blue → yellow ramp: near is bright.
    return (np.stack([t, 0.3 + 0.6 * t, 1 - t], axis=-1) * 255).astype(np.uint8)


def panels(scene):
    centre = sorted(scene.glob("input_Cam*.png"))
    centre = np.asarray(Image.open(centre[len(centre) // 2]).convert("RGB"))
    normals = read_normals(scene / "gt_normals_lowres.exr")
    out = [
        ("centre view", centre),
        ("HCI disparity", disparity_colours(read_pfm(scene / "gt_disp_lowres.pfm"))),
        ("normals (camera)", ((normals * 0.5 + 0.5).clip(0, 1) * 255).astype(np.uint8)),
    ]
    for name in ["objectids", "materialids", "classids"]:
        ids = np.asarray(Image.open(scene / f"{name}_lowres.png")).astype(np.int64)
        out.append((name.replace("ids", " IDs"), id_colours(ids)))
    valid = np.asarray(Image.open(scene / "valid_mask.png").convert("RGB"))
    out.append(("valid_mask", valid))
    for m in MASKS:
        mask = np.asarray(Image.open(scene / f"mask_{m}_lowres.png").convert("L")) > 0
        out.append((f"mask_{m}", np.where(mask[..., None], centre, centre // 5)))
    return out


def main():
    scene, target = Path(sys.argv[1]), Path(sys.argv[2])
    tiles = panels(scene)
    h, w = tiles[0][1].shape[:2]
    cols, label = 4, 16
    rows = -(-len(tiles) // cols)
    sheet = Image.new("RGB", (cols * w, rows * (h + label)), "white")
    draw = ImageDraw.Draw(sheet)
    for i, (name, img) in enumerate(tiles):
        x, y = (i % cols) * w, (i // cols) * (h + label)
        sheet.paste(Image.fromarray(img), (x, y + label))
        draw.text((x + 3, y + 2), name, fill="black")
    classes = json.loads((scene / "ids.json").read_text()).get("classes")
    sheet.save(target, optimize=True)
    print(f"{target}: {len(tiles)} panels; classes {classes}")


if __name__ == "__main__":
    main()

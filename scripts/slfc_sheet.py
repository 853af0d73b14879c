#!/usr/bin/env python3
"""Thesis Figure 5.6 as a sheet: per held-out scene, the centre view's crop, the front-most
ground-truth disparity, and the point estimates of each method given (SLFC's and DPP's
most probable bin, ...) on one colour scale, with each method's BadPix(0.07)
over the crop under its map.

    python3 -m pip install numpy pillow
    python3 scripts/slfc_sheet.py DATASET/val --crop 0.5 --out docs/slfc-sheet.png \
        slfc=PRED/slfc dpp=PRED/dpp

A method's maps may cover the whole image or only the crop (as `lfeval slfc --crop` writes);
the ground truth is cropped to the same centred square as `lfeval --crop` scores.
"""
import argparse
import math
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from pfm import read_pfm

CELL = 192  # pixels per map on the sheet
LABEL = 18  # height of a caption line


def centre_crop(shape, fraction):
    """Rows and columns of the centred crop, rounded as lfdata's Region::centre."""
    h, w = shape
    # Rust's f64::round rounds halves away from zero, Python's round to even.
    ch = min(max(math.floor(h * fraction + 0.5), 1), h)
    cw = min(max(math.floor(w * fraction + 0.5), 1), w)
    y0, x0 = (h - ch) // 2, (w - cw) // 2
    return slice(y0, y0 + ch), slice(x0, x0 + cw)


def colour(disparity, lo, hi):
    """Disparity on a blue (far) to yellow (near) ramp; not-a-number is black."""
    t = np.clip((disparity - lo) / max(hi - lo, 1e-6), 0.0, 1.0)
    ramp = np.stack([t, 0.25 + 0.6 * t * (1 - t) * 2, 1.0 - t], axis=-1)
    rgb = (255 * np.clip(ramp, 0, 1)).astype(np.uint8)
    rgb[~np.isfinite(disparity)] = 0
    return rgb


def tile(rgb):
    return Image.fromarray(rgb).resize((CELL, CELL), Image.NEAREST)


def front_truth(scene):
    """The HCI layer (gt_disp_lowres.pfm): the front-most mode Table 5.2 scores wherever the
    front surface covers the pixel centre, so the BadPix here is close to, not equal to, lfeval's."""
    return read_pfm(scene / "gt_disp_lowres.pfm")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("split", type=Path, help="folder of scene folders (e.g. DATASET/val)")
    ap.add_argument("methods", nargs="+", help="NAME=PREDICTION_FOLDER")
    ap.add_argument("--crop", type=float, default=0.5)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    methods = [m.split("=", 1) for m in a.methods]
    scenes = sorted(p for p in a.split.iterdir() if (p / "gt_disp_lowres.pfm").exists())
    columns = ["view", "ground truth"] + [name for name, _ in methods]
    sheet = Image.new("RGB", (CELL * len(columns), (CELL + 2 * LABEL) * len(scenes)), "white")
    draw = ImageDraw.Draw(sheet)
    for row, scene in enumerate(scenes):
        gt = front_truth(scene)
        rows, cols = centre_crop(gt.shape, a.crop)
        gt = gt[rows, cols]
        lo, hi = np.nanpercentile(gt, 1), np.nanpercentile(gt, 99)
        n = int(np.sqrt(len(list(scene.glob("input_Cam*.png")))))
        view = np.asarray(Image.open(scene / f"input_Cam{(n * n) // 2:03d}.png").convert("RGB"))
        cells = [
            (tile(view[rows, cols]), scene.name),
            (tile(colour(gt, lo, hi)), f"{lo:.2f} to {hi:.2f} px"),
        ]
        for name, folder in methods:
            pred = read_pfm(Path(folder) / "disp_maps" / f"{scene.name}.pfm")
            if pred.shape != gt.shape:
                pred = pred[rows, cols]
            bad = np.abs(pred - gt) > 0.07
            known = np.isfinite(gt)
            share = 100.0 * np.count_nonzero(bad & known) / np.count_nonzero(known)
            cells.append((tile(colour(pred, lo, hi)), f"BadPix {share:.1f} %"))
        y = row * (CELL + 2 * LABEL)
        for col, (image, caption) in enumerate(cells):
            sheet.paste(image, (col * CELL, y + LABEL))
            draw.text((col * CELL + 4, y + LABEL + CELL + 2), caption, fill="black")
            draw.text((col * CELL + 4, y + 2), columns[col], fill="black")
    a.out.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(a.out)


if __name__ == "__main__":
    main()

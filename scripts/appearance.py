#!/usr/bin/env python3
"""Appearance figures of light-field centre views, as lfgen's stats.json computes them
(src/appearance.rs), for any folder of HCI-style scenes: lfgen datasets of any version, the
HCI benchmark, other light fields. On 8-bit luminance L = 0.2126 R + 0.7152 G + 0.0722 B:
local contrast = median |L - mean3x3(L)|, flat share = share of 16x16 residual blocks with a
standard deviation below 1.5 levels, mean luminance, and Immerkaer's noise estimate.

usage: scripts/appearance.py FOLDER [FOLDER ...]   (every */input_CamNNN.png centre view
found below each folder; prints per-folder quantiles [min, q25, median, q75, max] as JSON)
"""
import glob, json, math, os, sys

import numpy as np
from PIL import Image


def figures(path):
    rgb = np.asarray(Image.open(path).convert("RGB")).astype(np.float64)
    lum = 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]
    h, w = lum.shape
    win = sum(lum[dy:h - 2 + dy, dx:w - 2 + dx] for dy in range(3) for dx in range(3))
    centre = lum[1:-1, 1:-1]
    residual = centre - win / 9.0
    mask = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], dtype=np.float64)
    conv = sum(mask[dy, dx] * lum[dy:h - 2 + dy, dx:w - 2 + dx] for dy in range(3) for dx in range(3))
    rh, rw = residual.shape
    by, bx = rh // 16, rw // 16
    blocks = residual[:by * 16, :bx * 16].reshape(by, 16, bx, 16).std(axis=(1, 3))
    return {
        "local_contrast": float(np.median(np.abs(residual))),
        "flat_share": float((blocks < 1.5).mean()) if blocks.size else 0.0,
        "mean_luminance": float(lum.mean()),
        "noise": math.sqrt(math.pi / 2) * float(np.abs(conv).sum()) / (6.0 * rh * rw),
    }


def centre_view(scene):
    cfg = os.path.join(scene, "parameters.cfg")
    if os.path.exists(cfg):
        pairs = (l.split("=", 1) for l in open(cfg).read().splitlines() if "=" in l)
        keys = {k.strip(): v.strip() for k, v in pairs}
        nx, ny = int(keys.get("num_cams_x", "9")), int(keys.get("num_cams_y", "9"))
        return os.path.join(scene, "input_Cam%03d.png" % ((ny // 2) * nx + nx // 2))
    views = sorted(glob.glob(os.path.join(scene, "input_Cam*.png")))
    return views[len(views) // 2]


def main():
    out = {}
    for folder in sys.argv[1:]:
        scenes = sorted({os.path.dirname(p) for p in glob.glob(os.path.join(folder, "**", "input_Cam000.png"), recursive=True)})
        per = [figures(centre_view(s)) for s in scenes]
        q = lambda k: [float(np.quantile([p[k] for p in per], t)) for t in (0, 0.25, 0.5, 0.75, 1)]
        out[folder] = {"scenes": len(per), **{k: q(k) for k in per[0]}} if per else {"scenes": 0}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()

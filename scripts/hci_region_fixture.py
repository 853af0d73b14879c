#!/usr/bin/env python3
"""Builds the region-metric fixture and scores it with the HCI evaluation toolkit itself.

lfeval's region metrics (Discontinuities, Bumpiness, MAE, Fine Fattening / Thinning) must
equal the HCI 4D Light Field Benchmark toolkit's. This script writes a small synthetic scene
in the HCI folder layout (a 64 x 64 ground truth of two slanted planes, a smooth bump and a
thin bar, its high-resolution version at 5x, the five region masks at both resolutions) plus
a noisy "algorithm" result, then runs the toolkit's own `compute_scores` on it and stores
the scores next to the data. lfeval's test `region_metrics` compares with those numbers.

Re-run (needs numpy, scipy, scikit-image, matplotlib, pillow; the toolkit is
https://github.com/lightfield-analysis/evaluation-toolkit, its `source` folder):

    python3 scripts/hci_region_fixture.py /path/to/evaluation-toolkit/source \
        crates/lfeval/tests/fixtures/hci_region

The toolkit is Python 2 code; the shims below only adapt its file reading to Python 3
(ConfigParser's module name, bytes header lines of PFM files, the removed scipy.misc.imread).
None of its arithmetic is touched.
"""

import configparser
import io
import json
import os
import sys

import numpy as np
from PIL import Image
from scipy import ndimage

LOW = 64  # low-resolution side, pixels
FILE_SCALE = 5  # the stored high-res files; the toolkit zooms them to its 10x
SCENE = "regions"
CAMERA = dict(focal_length_mm=100.0, sensor_size_mm=35.0, baseline_mm=6.0, focus_distance_m=1.5)


def labels_and_disparity(n, scale):
    """Region labels (0 background, 1 box, 2 bump, 3 bar) and disparity at pixel centres."""
    c = (np.arange(n) + 0.5) / scale
    x, y = np.meshgrid(c, c)
    disp = -0.5 + 0.01 * x + 0.005 * y
    labels = np.zeros((n, n), dtype=np.uint8)
    box = (x >= 10) & (x < 30) & (y >= 12) & (y < 40)
    disp[box] = (1.0 + 0.02 * x - 0.01 * y)[box]
    labels[box] = 1
    r2 = ((x - 45.0) ** 2 + (y - 42.0) ** 2) / 12.0 ** 2
    bump = r2 < 1.0
    disp[bump] += (0.8 * (1.0 - r2) ** 2)[bump]
    labels[bump] = 2
    bar = (x >= 36.0) & (x < 37.5) & (y >= 6) & (y < 30)
    disp[bar] = 1.5
    labels[bar] = 3
    return labels, disp.astype(np.float32)


def masks(labels, scale):
    """The five region masks, widths in low-res pixels times `scale`."""
    w = max(1, int(round(2 * scale)))
    edge = np.zeros(labels.shape, dtype=bool)
    edge[:, 1:] |= labels[:, 1:] != labels[:, :-1]
    edge[1:, :] |= labels[1:, :] != labels[:-1, :]
    near_edge = ndimage.binary_dilation(edge, iterations=w)
    bar = labels == 3
    return {
        "mask_discontinuities": near_edge & (labels != 3),
        "mask_planes": (labels <= 1) & ~near_edge,
        "mask_smooth_surfaces": (labels == 2) & ~near_edge,
        "mask_fine": bar,
        "mask_fine_surrounding": ndimage.binary_dilation(bar, iterations=2 * w) & ~bar,
    }


def algorithm_result(gt):
    """The ground truth, blurred, noisy, fattened around the bar, with a few NaN pixels."""
    rng = np.random.RandomState(7)
    out = ndimage.gaussian_filter(gt.astype(np.float64), 0.7)
    out += rng.normal(0.0, 0.02, gt.shape)
    out[6:30, 35:39] = np.maximum(out[6:30, 35:39], 1.4)  # fattening: bar too wide
    out[20:30, 36] = 0.0  # thinning: bar's lower part lost
    out[rng.randint(0, LOW, 12), rng.randint(0, LOW, 12)] = np.nan
    return out.astype(np.float32)


def write_pfm(path, data):
    with open(path, "wb") as f:
        f.write(b"Pf\n%d %d\n-1\n" % (data.shape[1], data.shape[0]))
        f.write(np.flipud(data).astype("<f4").tobytes())


def write_mask(path, mask):
    Image.fromarray(mask.astype(np.uint8) * 255, mode="L").save(path)


def write_fixture(out):
    scene_dir = os.path.join(out, SCENE)
    os.makedirs(scene_dir, exist_ok=True)
    os.makedirs(os.path.join(out, "disp_maps"), exist_ok=True)
    for suffix, scale in (("lowres", 1), ("highres", FILE_SCALE)):
        labels, disp = labels_and_disparity(LOW * scale, scale)
        write_pfm(os.path.join(scene_dir, "gt_disp_%s.pfm" % suffix), disp)
        for name, mask in masks(labels, scale).items():
            write_mask(os.path.join(scene_dir, "%s_%s.png" % (name, suffix)), mask)
        if scale == 1:
            write_pfm(os.path.join(out, "disp_maps", SCENE + ".pfm"), algorithm_result(disp))
    cfg = (
        "[intrinsics]\nfocal_length_mm = {focal_length_mm}\nimage_resolution_x_px = {n}\n"
        "image_resolution_y_px = {n}\nsensor_size_mm = {sensor_size_mm}\nfstop = 100.0\n\n"
        "[extrinsics]\nnum_cams_x = 9\nnum_cams_y = 9\nbaseline_mm = {baseline_mm}\n"
        "focus_distance_m = {focus_distance_m}\ncenter_cam_x_m = 0.0\ncenter_cam_y_m = 0.0\n"
        "center_cam_z_m = 0.0\ncenter_cam_rx_rad = 0.0\ncenter_cam_ry_rad = 0.0\n"
        "center_cam_rz_rad = 0.0\n\n"
        "[meta]\nscene = {scene}\ncategory = training\ndate = 2026-01-01\nversion = v1\n"
        "cycles_seed = 0\ndisp_min = -1.0\ndisp_max = 2.0\nfrustum_disp_min = -1.0\n"
        "frustum_disp_max = 2.0\ndepth_map_scale = {s}.0\n"
    ).format(n=LOW, s=FILE_SCALE, scene=SCENE, **CAMERA)
    with open(os.path.join(scene_dir, "parameters.cfg"), "w") as f:
        f.write(cfg)


def load_toolkit(source):
    """Imports the toolkit with Python 3 shims for its file reading only."""
    sys.modules["ConfigParser"] = configparser
    if not hasattr(configparser.ConfigParser, "readfp"):
        configparser.ConfigParser.readfp = configparser.ConfigParser.read_file
    sys.path.insert(0, source)
    from toolkit.utils import file_io

    def next_line(f):
        line = f.readline().rstrip().decode("ascii")
        while line.startswith("#"):
            line = f.readline().rstrip().decode("ascii")
        return line

    file_io._get_next_line = next_line
    file_io.read_img = lambda path: np.asarray(Image.open(path))
    from toolkit.evaluations import submission_evaluation
    from toolkit.scenes import PhotorealisticScene
    from toolkit.utils import misc

    return submission_evaluation, PhotorealisticScene, misc


def main():
    source, out = sys.argv[1], sys.argv[2]
    write_fixture(out)
    evaluation, Scene, misc = load_toolkit(source)
    scene = Scene(name=SCENE, category="", data_path=out)
    metrics = misc.get_general_metrics() + misc.get_region_metrics()
    scores = evaluation.compute_scores(scene, metrics, out, None, visualize=False)
    values = {k: v["value"] for k, v in sorted(scores.items())}
    with open(os.path.join(out, "toolkit_scores.json"), "w") as f:
        json.dump(values, f, indent=2, sort_keys=True)
        f.write("\n")
    print(json.dumps(values, indent=2, sort_keys=True))


if __name__ == "__main__":
    main()

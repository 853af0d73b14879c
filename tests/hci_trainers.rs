//! An lfgen scene folder read the way the public HCI trainers' loaders read it (OACC-Net,
//! DistgDisp, LFattNet; docs/guide/training.md): their file names, image formats, the PFM's
//! row order, and the disparity-range conditions of their augmentations and cost volumes.

mod bin;

use bin::ok;
use lfformat::modes::read_modes_exr;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A 9×9-view scene (the loaders read exactly 81 views), small and fast otherwise.
fn scene(dir: &Path, extra: &[&str]) -> PathBuf {
    fs::create_dir_all(dir).unwrap();
    let out = dir.join("ds");
    let mut args = vec!["--scenes", "1", "--out", out.to_str().unwrap(), "--quiet"];
    for set in [
        "camera.resolution=[40,32]",
        "camera.grid=[9,9]",
        "render.spp=2",
        "render.adaptive_spp=0",
        "scene.objects=6",
        "dataset.date=2026-01-01",
    ] {
        args.extend(["--set", set]);
    }
    args.extend_from_slice(extra);
    // Run from `dir`, away from the repository's generator.toml: the built-in defaults.
    let run = Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(&args)
        .current_dir(dir)
        .output()
        .expect("lfgen runs");
    ok(run);
    out.join("train/scene_0000")
}

/// `gt_disp_lowres.pfm` as their `read_pfm` reads it: header lines `Pf`, `W H`, a negative
/// scale (little-endian), then float32 rows that `np.flipud` turns top-down.
fn read_pfm_like_the_loaders(path: &Path) -> (usize, usize, Vec<f32>) {
    let bytes = fs::read(path).unwrap();
    let mut lines = bytes.splitn(4, |&b| b == b'\n');
    let mut line = || {
        std::str::from_utf8(lines.next().unwrap())
            .unwrap()
            .to_owned()
    };
    assert_eq!(line(), "Pf", "{}: a greyscale PFM", path.display());
    let dims: Vec<usize> = line()
        .split(' ')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    let scale: f32 = line().trim().parse().unwrap();
    assert!(scale < 0.0, "little-endian data has a negative scale");
    let (w, h) = (dims[0], dims[1]);
    let data = lines.next().unwrap();
    assert_eq!(
        data.len(),
        w * h * 4,
        "{}: {w}x{h} float32 values",
        path.display()
    );
    let stored: Vec<f32> = data
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()) * scale.abs())
        .collect();
    let top_down = stored.chunks_exact(w).rev().flatten().copied().collect();
    (w, h, top_down)
}

#[test]
fn views_and_disparity_read_as_the_hci_trainers_read_them() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = scene(tmp.path(), &[]);
    for i in 0..81 {
        // Python's '%.2d' after "Cam0": Cam000 … Cam080.
        let name = format!("input_Cam0{i:02}.png");
        let img = image::open(dir.join(&name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(img.color(), image::ColorType::Rgb8, "{name}: 8-bit RGB");
        assert_eq!((img.width(), img.height()), (40, 32), "{name}");
    }
    // valid_mask.png: RGB, so that `mask_rgb[:, :, 1] > 0` indexes a green channel.
    let mask = image::open(dir.join("valid_mask.png")).unwrap();
    assert_eq!(
        mask.color(),
        image::ColorType::Rgb8,
        "valid_mask.png: 8-bit RGB"
    );
    let valid = mask.to_rgb8().pixels().filter(|p| p[1] > 0).count();
    assert!(valid > 0, "some pixels are valid");
    let (w, h, disp) = read_pfm_like_the_loaders(&dir.join("gt_disp_lowres.pfm"));
    assert_eq!((w, h), (40, 32));
    // Row order: the flipped rows match the front mode of modes.exr (an EXR is stored
    // top-down) wherever a pixel has one opaque surface — to 0.05 px, as the mode averages
    // the pixel's samples and the PFM holds its centre ray; the scene is not symmetric upside
    // down, so the other order does not match.
    let modes = read_modes_exr(&dir.join("modes.exr")).unwrap();
    let (mut same, mut flipped_same, mut single) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let [mode] = modes.pixel(x, y) else { continue };
            if mode.eta < 0.999 {
                continue;
            }
            single += 1;
            same += usize::from((disp[y * w + x] - mode.disparity).abs() < 0.05);
            let mirrored = disp[(h - 1 - y) * w + x];
            flipped_same += usize::from((mirrored - mode.disparity).abs() < 0.05);
        }
    }
    assert!(single > w * h / 2, "most pixels see one opaque surface");
    assert!(
        same * 10 >= single * 9,
        "flipud(PFM) is top-down: {same} of {single}"
    );
    assert!(
        flipped_same < single / 2,
        "the check tells the two row orders apart"
    );
}

/// The conditions of their training code on a scene's disparity: finite everywhere (their
/// refocus augmentation takes `int(np.min(gt))`), a truncated span `int(max) − int(min)` of at
/// most 6 (else its `randint(6 − span + 1)` raises), and within their cost volumes' [−4, 4].
fn meets_their_conditions(disp: &[f32]) -> bool {
    let finite = disp.iter().all(|d| d.is_finite());
    let (min, max) = disp
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &d| {
            (lo.min(d), hi.max(d))
        });
    let span = max as i64 - min as i64;
    finite && span <= 6 && (-4.0..=4.0).contains(&min) && (-4.0..=4.0).contains(&max)
}

#[test]
fn the_default_range_meets_their_augmentations_and_preset_wide_breaks_them() {
    let tmp = tempfile::tempdir().unwrap();
    let default = scene(&tmp.path().join("default"), &[]);
    let (_, _, disp) = read_pfm_like_the_loaders(&default.join("gt_disp_lowres.pfm"));
    assert!(meets_their_conditions(&disp), "default range");
    let wide = scene(&tmp.path().join("wide"), &["--preset", "wide"]);
    let (_, _, disp) = read_pfm_like_the_loaders(&wide.join("gt_disp_lowres.pfm"));
    assert!(!meets_their_conditions(&disp), "--preset wide");
}

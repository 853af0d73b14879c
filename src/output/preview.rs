//! `preview.png` at the dataset root: one row per scene — centre view, HCI disparity, number of
//! modes with η > 0.3, and η of the front-most mode — read back from the written files, so the
//! sheet shows what users will load.

use crate::stats::MULTIMODAL_ETA;
use anyhow::{Context, Result};
use image::{Rgb, RgbImage};
use lfformat::modes::read_modes_exr;
use lfformat::pfm::read_pfm;
use std::path::Path;

/// Most scenes shown in the sheet.
const MAX_ROWS: usize = 8;
/// Gap between panels, in pixels.
const GAP: u32 = 4;

/// Writes `out/preview.png` from the first scenes of `scene_dirs` (relative to `out`).
pub fn write_preview(out: &Path, scene_dirs: &[String]) -> Result<()> {
    let rows: Vec<[RgbImage; 4]> = scene_dirs
        .iter()
        .take(MAX_ROWS)
        .map(|d| scene_panels(&out.join(d)))
        .collect::<Result<_>>()?;
    let Some(first) = rows.first() else {
        return Ok(());
    };
    let (w, h) = first[0].dimensions();
    let mut sheet = RgbImage::from_pixel(
        4 * w + 3 * GAP,
        rows.len() as u32 * (h + GAP) - GAP,
        Rgb([255; 3]),
    );
    for (r, panels) in rows.iter().enumerate() {
        for (c, p) in panels.iter().enumerate() {
            image::imageops::replace(
                &mut sheet,
                p,
                (c as u32 * (w + GAP)) as i64,
                (r as u32 * (h + GAP)) as i64,
            );
        }
    }
    let path = out.join("preview.png");
    sheet
        .save(&path)
        .with_context(|| format!("cannot write {}", path.display()))
}

fn scene_panels(dir: &Path) -> Result<[RgbImage; 4]> {
    let params = lfformat::HciParameters::read(&dir.join("parameters.cfg"))?;
    let center = (params.num_cams_y / 2) * params.num_cams_x + params.num_cams_x / 2;
    let view_path = dir.join(format!("input_Cam{center:03}.png"));
    let view = image::open(&view_path)
        .with_context(|| format!("cannot read {}", view_path.display()))?
        .to_rgb8();
    let disp = read_pfm(&dir.join("gt_disp_lowres.pfm"))?;
    let modes = read_modes_exr(&dir.join("modes.exr"))?;
    let (w, h) = view.dimensions();
    let (lo, hi) = (params.disp_min as f32, params.disp_max as f32);
    let disparity = RgbImage::from_fn(w, h, |x, y| {
        colormap((disp.get(x as usize, y as usize) - lo) / (hi - lo))
    });
    let count = RgbImage::from_fn(w, h, |x, y| {
        let n = modes
            .pixel(x as usize, y as usize)
            .iter()
            .filter(|m| m.eta > MULTIMODAL_ETA)
            .count();
        colormap(n as f32 / 3.0)
    });
    let front = RgbImage::from_fn(w, h, |x, y| {
        colormap(
            modes
                .pixel(x as usize, y as usize)
                .first()
                .map_or(0.0, |m| m.eta),
        )
    });
    Ok([view, disparity, count, front])
}

/// A perceptually ordered dark-blue → green → yellow ramp (viridis-like) for t in [0, 1].
fn colormap(t: f32) -> Rgb<u8> {
    const STOPS: [[f32; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0) * 4.0
    } else {
        0.0
    };
    let (i, f) = ((t.floor() as usize).min(3), t - t.floor().min(3.0));
    Rgb(std::array::from_fn(|c| {
        (STOPS[i][c] + (STOPS[i + 1][c] - STOPS[i][c]) * f).round() as u8
    }))
}

//! `preview.png` at the dataset root: one row per scene — centre view, HCI disparity, number of
//! modes with η > 0.3, η of the front-most mode, the normals, and the object ids (darkened
//! where `valid_mask.png` is off) — read back from the written files, so the sheet shows what
//! users will load.
//!
//! `lfgen preview DATASET` adds a contact sheet per scene (`previews/<scene>.png`: centre view,
//! GT disparity, mode count, η of the second mode, a horizontal and a vertical epipolar-plane
//! image) and an overview page (`previews/index.html`) with each scene's statistics.

use super::images::save_png;
use crate::stats::MULTIMODAL_ETA;
use anyhow::{Context, Result};
use image::{Rgb, RgbImage};
use lfformat::gt_maps::{read_id_png, read_normals_exr, read_valid_mask};
use lfformat::modes::read_modes_exr;
use lfformat::pfm::read_pfm;
use std::path::Path;

/// Most scenes shown in the sheet.
const MAX_ROWS: usize = 8;
/// Gap between panels, in pixels.
const GAP: u32 = 4;
/// Panels per scene.
const PANELS: usize = 6;

/// Writes `out/preview.png` from the first scenes of `scene_dirs` (relative to `out`).
pub fn write_preview(out: &Path, scene_dirs: &[String]) -> Result<()> {
    let rows: Vec<[RgbImage; PANELS]> = scene_dirs
        .iter()
        .take(MAX_ROWS)
        .map(|d| scene_panels(&out.join(d)))
        .collect::<Result<_>>()?;
    let Some(first) = rows.first() else {
        return Ok(());
    };
    let (w, h) = first[0].dimensions();
    let mut sheet = RgbImage::from_pixel(
        PANELS as u32 * (w + GAP) - GAP,
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
    save_png(&sheet, &out.join("preview.png"))
}

/// Reads view `index` (`input_CamNNN.png`) of a scene folder.
fn read_view(dir: &Path, index: u32) -> Result<RgbImage> {
    let path = dir.join(format!("input_Cam{index:03}.png"));
    Ok(image::open(&path)
        .with_context(|| format!("cannot read {}", path.display()))?
        .to_rgb8())
}

fn scene_panels(dir: &Path) -> Result<[RgbImage; PANELS]> {
    let params = lfformat::HciParameters::read(&dir.join("parameters.cfg"))?;
    let center = (params.num_cams_y / 2) * params.num_cams_x + params.num_cams_x / 2;
    let view = read_view(dir, center)?;
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
    let [normals, objects] = surface_panels(dir, w, h)?;
    Ok([view, disparity, count, front, normals, objects])
}

/// The normals as `(n + 1) / 2` in RGB, and the object ids in hashed colours, half as bright
/// where the pixel is not valid (black: no surface).
fn surface_panels(dir: &Path, w: u32, h: u32) -> Result<[RgbImage; 2]> {
    let (nw, _, n) = read_normals_exr(&dir.join("gt_normals_lowres.exr"))?;
    let (_, _, ids) = read_id_png(&dir.join("objectids_lowres.png"))?;
    let (_, _, valid) = read_valid_mask(&dir.join("valid_mask.png"))?;
    let at = |x: u32, y: u32| y as usize * nw + x as usize;
    let unit = |v: f32| ((v + 1.0) * 127.5).clamp(0.0, 255.0) as u8;
    let normals = RgbImage::from_fn(w, h, |x, y| Rgb(n[at(x, y)].map(unit)));
    let objects = RgbImage::from_fn(w, h, |x, y| {
        let (id, valid) = (ids[at(x, y)] as u32, valid[at(x, y)]);
        let hash = id.wrapping_mul(0x9E37_79B9).to_le_bytes();
        let c = [hash[1], hash[2], hash[3]].map(|v| (v / 2 + 64) >> u8::from(!valid));
        Rgb(if id == 0 { [0; 3] } else { c })
    });
    Ok([normals, objects])
}

/// Rows of an epipolar-plane image are this many pixels tall per view.
const EPI_ROW: u32 = 4;

/// Writes `previews/<scene>.png` for every scene of the dataset's manifest and
/// `previews/index.html`; returns the number of sheets.
pub fn write_contact_sheets(dataset: &Path) -> Result<usize> {
    let manifest = lfformat::manifest::Manifest::read(&dataset.join("manifest.json"))?;
    let out = dataset.join("previews");
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut rows = String::new();
    for e in &manifest.scenes {
        lfformat::manifest::verify_scene_entry(dataset, e)?;
        let dir = dataset.join(&e.dir);
        let sheet = contact_sheet(&dir).with_context(|| format!("{}", dir.display()))?;
        let name = format!("{}.png", e.dir.replace('/', "_"));
        save_png(&sheet, &out.join(&name))?;
        rows.push_str(&overview_row(&dir, &e.dir, &name)?);
    }
    let html = format!(
        "<!doctype html><meta charset=\"utf-8\"><title>lfgen preview</title>\n\
         <style>body{{font-family:sans-serif}}td{{padding:4px;vertical-align:top}}</style>\n\
         <h1>{}</h1><p>Per scene: centre view, GT disparity, number of modes, η of the second \
         mode; below, horizontal and vertical epipolar-plane images.</p>\n<table>{rows}</table>\n",
        dataset.display()
    );
    let index = out.join("index.html");
    lfformat::files::write_file(&index, html.as_bytes())?;
    Ok(manifest.scenes.len())
}

/// One table row of the overview: the scene's statistics next to its sheet.
fn overview_row(dir: &Path, scene: &str, sheet: &str) -> Result<String> {
    let path = dir.join("stats.json");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let s: crate::stats::SceneStats = serde_json::from_str(&text)
        .with_context(|| format!("{}: not valid scene statistics", path.display()))?;
    let placed = s.placement.map_or(String::new(), |p| {
        format!("<br>objects placed {} / rejected {}", p.placed, p.rejected)
    });
    Ok(format!(
        "<tr><td><b>{scene}</b><br>multimodal (≥2 modes η>0.3) {:.1} %<br>≥2 modes {:.1} %\
         <br>disparity {:.2} … {:.2} px<br>exposure {:.2}{placed}</td>\
         <td><img src=\"{sheet}\"></td></tr>\n",
        100.0 * s.multimodal_fraction,
        100.0 * s.two_mode_fraction,
        s.disparity_range[0],
        s.disparity_range[1],
        s.exposure
    ))
}

/// The sheet of one scene folder: four panels on top, the two EPIs below.
fn contact_sheet(dir: &Path) -> Result<RgbImage> {
    let params = lfformat::HciParameters::read(&dir.join("parameters.cfg"))?;
    let [view, disparity, ..] = scene_panels(dir)?;
    let modes = read_modes_exr(&dir.join("modes.exr"))?;
    let (w, h) = view.dimensions();
    let count = RgbImage::from_fn(w, h, |x, y| {
        colormap(modes.pixel(x as usize, y as usize).len() as f32 / 4.0)
    });
    let second = RgbImage::from_fn(w, h, |x, y| {
        colormap(
            modes
                .pixel(x as usize, y as usize)
                .get(1)
                .map_or(0.0, |m| m.eta),
        )
    });
    let (nx, ny) = (params.num_cams_x, params.num_cams_y);
    let horizontal = epi(dir, (0..nx).map(|i| (ny / 2) * nx + i), true)?;
    let vertical = epi(dir, (0..ny).map(|j| j * nx + nx / 2), false)?;
    let (ew, eh) = vertical.dimensions();
    let sheet_h = h + GAP + horizontal.height().max(eh);
    let mut sheet = RgbImage::from_pixel(4 * w + 3 * GAP, sheet_h, Rgb([255; 3]));
    for (c, p) in [view, disparity, count, second].iter().enumerate() {
        image::imageops::replace(&mut sheet, p, (c as u32 * (w + GAP)) as i64, 0);
    }
    image::imageops::replace(&mut sheet, &horizontal, 0, (h + GAP) as i64);
    image::imageops::replace(&mut sheet, &vertical, (w + GAP) as i64, (h + GAP) as i64);
    debug_assert!(ew <= w);
    Ok(sheet)
}

/// An epipolar-plane image through the image centre from `views` (in order): for a row of
/// cameras the centre row of each view stacked downwards, for a column of cameras the centre
/// column of each view side by side. Each view takes [`EPI_ROW`] pixels.
fn epi(dir: &Path, views: impl Iterator<Item = u32>, horizontal: bool) -> Result<RgbImage> {
    let images: Vec<RgbImage> = views.map(|v| read_view(dir, v)).collect::<Result<_>>()?;
    let (w, h) = images[0].dimensions();
    let n = images.len() as u32 * EPI_ROW;
    Ok(match horizontal {
        true => RgbImage::from_fn(w, n, |x, y| {
            *images[(y / EPI_ROW) as usize].get_pixel(x, h / 2)
        }),
        false => RgbImage::from_fn(n, h, |x, y| {
            *images[(x / EPI_ROW) as usize].get_pixel(w / 2, y)
        }),
    })
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

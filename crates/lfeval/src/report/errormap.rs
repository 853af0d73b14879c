//! Per-scene BadPix maps in the style of the HCI benchmark figures: green where the
//! prediction is within the threshold, red where it is not, over the scene's centre view.

use std::path::Path;

use anyhow::{Context, Result};
use image::{Rgb, RgbImage};
use lfdata::metrics::Frame;

const GOOD: [f32; 3] = [40.0, 200.0, 60.0];
const BAD: [f32; 3] = [230.0, 40.0, 30.0];

/// The map of `|pred - gt| > t` inside `frame`: green = good, red = bad, black = no valid
/// comparison (NaN/∞ on either side); the border shows the view in grey. Colours are shaded
/// by `luminance` (the centre view, `[0, 1]`) when given, so the scene stays recognisable.
pub fn badpix_map(
    pred: &[f32],
    gt: &[f32],
    frame: &Frame,
    t: f64,
    luminance: Option<&[f32]>,
) -> RgbImage {
    let (w, h) = (frame.width, frame.height);
    RgbImage::from_fn(w as u32, h as u32, |x, y| {
        let i = y as usize * w + x as usize;
        let lum = luminance.map_or(1.0, |l| l[i]);
        let shade = |c: [f32; 3]| Rgb(c.map(|v| (v * (0.35 + 0.65 * lum)).round() as u8));
        if !frame.contains(i) {
            return Rgb([(lum * 160.0) as u8; 3]);
        }
        let e = f64::from(pred[i]) - f64::from(gt[i]);
        if !e.is_finite() {
            Rgb([0, 0, 0])
        } else if lfdata::metrics::hci::is_bad(pred[i], gt[i], t) {
            shade(BAD)
        } else {
            shade(GOOD)
        }
    })
}

/// Writes `img` as PNG, creating the folder.
pub fn write(path: &Path, img: &RgbImage) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create", dir.display()))?;
    }
    Ok(lfformat::png::write_png(path, img)?)
}

/// Rec. 601 luma of interleaved RGB in `[0, 1]` (EPINET's grey conversion).
pub fn luminance(rgb: &[f32]) -> Vec<f32> {
    rgb.chunks_exact(3)
        .map(|c| 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_follow_the_error_and_the_frame() {
        let frame = Frame::new(4, 3, 1);
        let gt = vec![1.0f32; 12];
        let mut pred = vec![1.0f32; 12];
        pred[6] = 1.5; // inside: bad
        pred[0] = 9.0; // border: not judged
        let img = badpix_map(&pred, &gt, &frame, 0.07, None);
        assert_eq!(img.get_pixel(1, 1).0, [40, 200, 60]);
        assert_eq!(img.get_pixel(2, 1).0, [230, 40, 30]);
        assert_eq!(img.get_pixel(0, 0).0, [160, 160, 160]);
        pred[5] = f32::NAN;
        let img = badpix_map(&pred, &gt, &frame, 0.07, Some(&[0.0; 12]));
        assert_eq!(img.get_pixel(1, 1).0, [0, 0, 0]);
        assert!(img.get_pixel(2, 1).0[0] < 100, "shaded by a black view");
        let l = luminance(&[1.0, 1.0, 1.0, 0.0, 1.0, 0.0]);
        assert!((l[0] - 1.0).abs() < 1e-6 && (l[1] - 0.587).abs() < 1e-6);
    }
}

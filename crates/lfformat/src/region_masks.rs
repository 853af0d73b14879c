//! The HCI benchmark's evaluation masks: `mask_discontinuities`, `mask_planes`,
//! `mask_smooth_surfaces`, `mask_fine` and `mask_fine_surrounding`, each as
//! `{stem}_lowres.png` and `{stem}_highres.png`, 8-bit grey, 255 in the region and 0 outside
//! (the evaluation toolkit reads any non-zero value as "in").

use std::io::Cursor;
use std::path::Path;

use image::GrayImage;

use crate::error::{Error, Result};

/// The mask stems, in the order lfgen writes and lfeval reports them.
pub const MASK_STEMS: [&str; 5] = [
    "mask_discontinuities",
    "mask_planes",
    "mask_smooth_surfaces",
    "mask_fine",
    "mask_fine_surrounding",
];

/// The file name of mask `stem` at the low (`high = false`) or high resolution.
pub fn mask_file(stem: &str, high: bool) -> String {
    let res = if high { "highres" } else { "lowres" };
    format!("{stem}_{res}.png")
}

/// Writes a mask as 8-bit grey PNG, 255 where `mask` holds.
pub fn write_mask_png(path: &Path, width: usize, height: usize, mask: &[bool]) -> Result<()> {
    assert_eq!(mask.len(), width * height, "one flag per pixel");
    let data = mask.iter().map(|&m| u8::from(m) * 255).collect();
    let img = GrayImage::from_raw(width as u32, height as u32, data).expect("buffer size matches");
    let mut bytes = Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|e| Error::format(path, format!("cannot encode PNG: {e}")))?;
    crate::files::write_file(path, bytes.get_ref())
}

/// Reads a mask PNG of any colour type: (width, height, in-region flags), a pixel being in
/// the region where any colour channel is non-zero.
pub fn read_mask_png(path: &Path) -> Result<(usize, usize, Vec<bool>)> {
    let bytes = crate::read::bytes(path)?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| Error::format(path, format!("cannot decode PNG: {e}")))?
        .to_rgb16();
    let (w, h) = (img.width() as usize, img.height() as usize);
    Ok((
        w,
        h,
        img.pixels().map(|p| p.0.iter().any(|&c| c > 0)).collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_round_trip_and_any_non_zero_colour_is_in() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(mask_file(MASK_STEMS[1], false));
        assert!(path.ends_with("mask_planes_lowres.png"));
        let mask = [true, false, false, true, true, false];
        write_mask_png(&path, 3, 2, &mask).unwrap();
        assert_eq!(read_mask_png(&path).unwrap(), (3, 2, mask.to_vec()));
        let rgb = image::RgbImage::from_fn(2, 1, |x, _| image::Rgb([0, x as u8, 0]));
        let path = dir.path().join(mask_file(MASK_STEMS[0], true));
        rgb.save(&path).unwrap();
        assert_eq!(read_mask_png(&path).unwrap(), (2, 1, vec![false, true]));
    }

    #[test]
    fn an_unreadable_mask_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("mask_fine_lowres.png");
        std::fs::write(&path, b"not a png").unwrap();
        let e = read_mask_png(&path).unwrap_err().to_string();
        assert!(
            e.contains("mask_fine_lowres.png") && e.contains("PNG"),
            "{e}"
        );
    }
}

//! Writing PNG images — report charts, error maps, training curves — the way dataset files are
//! written: encoded in memory, then [`crate::files::write_atomic`], so a full disk is an error
//! naming the file and never leaves an empty or truncated image behind a successful run.

use std::io::Cursor;
use std::path::Path;

use image::RgbImage;

use crate::error::{Error, Result};

/// Writes `img` to `path` as PNG, atomically and checked.
pub fn write_png(path: &Path, img: &RgbImage) -> Result<()> {
    let mut bytes = Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|e| Error::format(path, format!("cannot encode PNG: {e}")))?;
    crate::files::write_atomic(path, bytes.get_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_is_written_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let img = RgbImage::from_pixel(3, 2, image::Rgb([1, 2, 3]));
        write_png(&path, &img).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgb8(), img);
        let missing = dir.path().join("missing/b.png");
        let e = write_png(&missing, &img).unwrap_err().to_string();
        assert!(e.contains("missing/b.png"), "{e}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}

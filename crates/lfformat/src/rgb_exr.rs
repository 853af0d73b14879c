//! Float RGB EXR files (the views' linear radiance, the normal maps), written byte for byte the
//! same on every run.

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};

use crate::error::{Error, Result};

/// Writes a `width × height` float32 RGB EXR whose pixel `i` (row-major) is `pixel(i)`.
///
/// One compression thread: the default encoding leaves the line order unspecified, and the exr
/// crate's parallel compressor then stores the chunks in the order they finish, which gives
/// other bytes on every run. RLE on one thread costs little beside rendering the image.
pub fn write_rgb_exr(
    path: &Path,
    width: usize,
    height: usize,
    pixel: impl Fn(usize) -> [f32; 3] + Sync,
) -> Result<()> {
    let channels = SpecificChannels::rgb(|Vec2(x, y)| {
        let [r, g, b] = pixel(y * width + x);
        (r, g, b)
    });
    let mut bytes = Cursor::new(Vec::new());
    Image::from_channels((width, height), channels)
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .map_err(|e| Error::format(path, e.to_string()))?;
    crate::files::write_file(path, bytes.get_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Many chunks of unequal cost: with parallel compression their order on disk varied from
    /// run to run; every write must give the same bytes.
    #[test]
    fn the_same_image_gives_the_same_bytes_every_time() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (97, 300);
        let pixel = |i: usize| {
            let v = if (i / w).is_multiple_of(3) {
                0.5
            } else {
                (i as f32 * 0.618).fract()
            };
            [v, v * 0.5, 1.0 - v]
        };
        let first = dir.path().join("a.exr");
        write_rgb_exr(&first, w, h, pixel).unwrap();
        let want = std::fs::read(&first).unwrap();
        for k in 0..20 {
            let path = dir.path().join(format!("{k}.exr"));
            write_rgb_exr(&path, w, h, pixel).unwrap();
            assert!(std::fs::read(&path).unwrap() == want, "write {k} differs");
        }
    }
}

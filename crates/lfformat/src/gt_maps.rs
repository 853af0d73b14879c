//! Per-pixel ground-truth images of the HCI single-valued layer, in formats any image tool
//! opens: surface normals as float EXR (`gt_normals_*.exr`), object, material and class ids as
//! 16-bit grey PNG (`objectids_*.png`, as the HCI Blender add-on names its object-id maps), and
//! `valid_mask.png`, 8-bit RGB with green > 0 where the disparity is trustworthy (the
//! convention of the OACC-Net and DistgDisp loaders). Row 0 is the top row in memory and on
//! disk.

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{ReadChannels, ReadLayers};
use image::{ImageBuffer, Luma, RgbImage};

use crate::error::{Error, Result};

/// The HCI single-valued layer of an image, row-major from the top-left: per pixel, the first
/// surface with coverage ≥ 0.5 on the pixel-centre ray.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HciLayer {
    pub width: usize,
    pub height: usize,
    /// Planar depth (NaN: no surface).
    pub depth: Vec<f32>,
    /// Unit geometric normal in the camera frame of
    /// [`ModeSurface::normal`](crate::ModeSurface::normal) (NaN: none).
    pub normal: Vec<[f32; 3]>,
    /// Object, material and class ids as in [`ModeSurface`](crate::ModeSurface) (0: none).
    pub object: Vec<u32>,
    pub material: Vec<u32>,
    pub class: Vec<u32>,
}

impl HciLayer {
    /// Appends a pixel (row-major).
    pub fn push(&mut self, depth: f32, s: crate::ModeSurface) {
        self.depth.push(depth);
        self.normal.push(s.normal);
        self.object.push(s.object);
        self.material.push(s.material);
        self.class.push(s.class);
    }

    /// Puts the rows of `other` below these.
    pub fn append(&mut self, other: HciLayer) {
        self.depth.extend(other.depth);
        self.normal.extend(other.normal);
        self.object.extend(other.object);
        self.material.extend(other.material);
        self.class.extend(other.class);
        self.height += other.height;
    }
}

/// Writes unit normals (x, y, z per pixel; NaN where there is no surface) as a float32 EXR
/// whose R, G, B channels hold x, y, z, so viewers show the usual normal colours.
pub fn write_normals_exr(path: &Path, width: usize, height: usize, n: &[[f32; 3]]) -> Result<()> {
    assert_eq!(n.len(), width * height, "one normal per pixel");
    crate::rgb_exr::write_rgb_exr(path, width, height, |i| n[i])
}

/// Reads a normals EXR written by [`write_normals_exr`]: (width, height, normals).
pub fn read_normals_exr(path: &Path) -> Result<(usize, usize, Vec<[f32; 3]>)> {
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| (size.width(), vec![[0.0f32; 3]; size.area()]),
            |(w, px), p, (r, g, b): (f32, f32, f32)| px[p.y() * *w + p.x()] = [r, g, b],
        )
        .first_valid_layer()
        .all_attributes()
        .from_unbuffered(crate::read::open(path)?)
        .map_err(|e| Error::format(path, e.to_string()))?;
    let size = image.layer_data.size;
    let (_, normals) = image.layer_data.channel_data.pixels;
    Ok((size.width(), size.height(), normals))
}

/// Writes ids as a 16-bit grey PNG; an id above 65535 is refused, naming the file.
pub fn write_id_png(path: &Path, width: usize, height: usize, ids: &[u32]) -> Result<()> {
    assert_eq!(ids.len(), width * height, "one id per pixel");
    if let Some(big) = ids.iter().find(|&&id| id > u32::from(u16::MAX)) {
        let m = format!("id {big} does not fit a 16-bit PNG (at most 65535)");
        return Err(Error::format(path, m));
    }
    let data: Vec<u16> = ids.iter().map(|&id| id as u16).collect();
    let img = ImageBuffer::<Luma<u16>, _>::from_raw(width as u32, height as u32, data)
        .expect("buffer size matches");
    let mut bytes = Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|e| Error::format(path, format!("cannot encode PNG: {e}")))?;
    crate::files::write_file(path, bytes.get_ref())
}

/// Reads a 16-bit grey id PNG: (width, height, ids).
pub fn read_id_png(path: &Path) -> Result<(usize, usize, Vec<u16>)> {
    let img = read_png(path)?;
    let grey = match img {
        image::DynamicImage::ImageLuma16(g) => g,
        other => {
            let m = format!("expected a 16-bit grey PNG, found {:?}", other.color());
            return Err(Error::format(path, m));
        }
    };
    let (w, h) = (grey.width() as usize, grey.height() as usize);
    Ok((w, h, grey.into_raw()))
}

/// Writes a validity mask as 8-bit RGB: white where valid, black elsewhere.
pub fn write_valid_mask(path: &Path, width: usize, height: usize, valid: &[bool]) -> Result<()> {
    assert_eq!(valid.len(), width * height, "one flag per pixel");
    let img = RgbImage::from_fn(width as u32, height as u32, |x, y| {
        image::Rgb([u8::from(valid[y as usize * width + x as usize]) * 255; 3])
    });
    crate::png::write_png(path, &img)
}

/// Reads a validity mask the way the HCI-based trainers do: valid where green > 0.
pub fn read_valid_mask(path: &Path) -> Result<(usize, usize, Vec<bool>)> {
    let rgb = read_png(path)?.to_rgb8();
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    Ok((w, h, rgb.pixels().map(|p| p[1] > 0).collect()))
}

fn read_png(path: &Path) -> Result<image::DynamicImage> {
    let bytes = crate::read::bytes(path)?;
    image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| Error::format(path, format!("cannot decode PNG: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_ids_and_masks_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (3, 2);
        let normals: Vec<[f32; 3]> = (0..6).map(|i| [i as f32, -0.5, 0.25]).collect();
        let mut with_nan = normals.clone();
        with_nan[4] = [f32::NAN; 3];
        let path = dir.path().join("n.exr");
        write_normals_exr(&path, w, h, &with_nan).unwrap();
        let (rw, rh, back) = read_normals_exr(&path).unwrap();
        assert_eq!((rw, rh), (w, h));
        for (i, (a, b)) in with_nan.iter().zip(&back).enumerate() {
            match i {
                4 => assert!(b.iter().all(|v| v.is_nan())),
                _ => assert_eq!(a, b),
            }
        }
        let ids = [0, 1, 2, 300, 65535, 7];
        let path = dir.path().join("ids.png");
        write_id_png(&path, w, h, &ids).unwrap();
        let back = read_id_png(&path).unwrap();
        assert_eq!(back, (w, h, ids.iter().map(|&i| i as u16).collect()));
        let valid = [true, false, true, true, false, false];
        let path = dir.path().join("valid_mask.png");
        write_valid_mask(&path, w, h, &valid).unwrap();
        assert_eq!(read_valid_mask(&path).unwrap(), (w, h, valid.to_vec()));
    }

    #[test]
    fn an_id_too_large_for_16_bits_is_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("objectids_lowres.png");
        let e = write_id_png(&path, 1, 1, &[70_000])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("objectids_lowres.png") && e.contains("70000"),
            "{e}"
        );
        assert!(!path.exists());
    }
}

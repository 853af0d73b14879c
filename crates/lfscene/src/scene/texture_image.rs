//! Image textures: how a material refers to an image ([`ImageMap`]: which image, wrap modes,
//! filter, UV transform) and the decoded image itself ([`TextureImage`]: 8-bit RGBA texels,
//! sampled with the glTF conventions).
//!
//! Texels stay 8-bit (4 bytes each, a quarter of linear floats) and are linearised through a
//! lookup table when sampled; bilinear filtering then happens on linear values, as it must.

use super::assets::MAX_IMAGE_BYTES;
use super::memory::{self, Budget};
use anyhow::{Context, Result, bail, ensure};
use glam::{Vec2, Vec3, Vec4};
use image::ImageDecoder;
use serde::{Deserialize, Serialize};
use std::sync::LazyLock;

/// Largest accepted image side, in texels.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Where a material's texture comes from and how it is sampled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageMap {
    /// Index into [`crate::scene::SceneDesc::sources`].
    pub source: u32,
    /// Image index within that source file.
    pub image: u32,
    /// Wrap mode along U and V.
    pub wrap: [Wrap; 2],
    pub filter: Filter,
    /// `KHR_texture_transform`, applied to the UV before the lookup.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<UvTransform>,
}

/// Texture coordinate wrapping outside [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Wrap {
    Repeat,
    Clamp,
    Mirror,
}

/// Magnification filter (there is no mip-mapping: pixels are supersampled instead).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    Nearest,
    Linear,
}

/// `uv' = T(offset) · R(rotation) · S(scale) · uv`, as `KHR_texture_transform` defines it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct UvTransform {
    pub offset: [f32; 2],
    pub rotation: f32,
    pub scale: [f32; 2],
}

impl UvTransform {
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let s = uv * Vec2::from(self.scale);
        let (sin, cos) = self.rotation.sin_cos();
        // Rows [cos sin; -sin cos]: what the extension's example ("offset [0, 1], rotation
        // 90°, scale 0.5 selects the lower-left quadrant") and its sample model require.
        Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y) + Vec2::from(self.offset)
    }
}

/// What decoded images may take: texel bytes of their own, and memory with the rest of the
/// scene.
#[derive(Clone, Debug)]
pub struct DecodeBudgets {
    pub textures: Budget,
    pub memory: Budget,
}

impl DecodeBudgets {
    /// Budgets for the images of one scene with nothing else charged: [`MAX_IMAGE_BYTES`] of
    /// texels within this process's [`memory::limit`].
    pub fn for_images_alone() -> Result<Self> {
        Ok(Self {
            textures: Budget::textures(MAX_IMAGE_BYTES),
            memory: Budget::of_this_process()?,
        })
    }

    /// Counts a decoded image's texels against both budgets.
    pub fn charge(&mut self, what: &str, image: &TextureImage) -> Result<()> {
        self.textures.charge(what, image.texel_bytes())?;
        self.memory.charge(what, image.texel_bytes())
    }
}

/// A decoded image: RGBA8 texels, row 0 at the top (glTF's UV origin is the top-left corner).
#[derive(Clone)]
pub struct TextureImage {
    width: u32,
    height: u32,
    texels: Vec<[u8; 4]>,
    /// Every alpha is 255 (lets opacity take its constant fast path).
    opaque: bool,
}

/// sRGB-encoded 8-bit value → linear, for all 256 codes.
static SRGB_TO_LINEAR: LazyLock<[f32; 256]> =
    LazyLock::new(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)));

pub use lfformat::srgb::to_linear as srgb_to_linear;
/// Size only: materials that hold an image are printed without millions of texels.
impl std::fmt::Debug for TextureImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "TextureImage({}x{}, opaque: {})",
            self.width, self.height, self.opaque
        )
    }
}

impl TextureImage {
    /// Decodes PNG or JPEG bytes (the formats of core glTF), refusing from the image header —
    /// before anything is allocated — an image whose texels or decoding peak do not fit what
    /// is left of `budgets`; [`DecodeBudgets::charge`] then counts the texels. `what` names
    /// the image in errors.
    pub fn decode(bytes: &[u8], what: &str, budgets: &DecodeBudgets) -> Result<Self> {
        let DecodeBudgets { textures, memory } = budgets;
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .with_context(|| format!("{what}: cannot read"))?;
        match reader.format() {
            Some(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
            other => bail!("{what}: only PNG and JPEG images are read (found {other:?})"),
        }
        reader.limits(decode_limits(memory.left()));
        let mut decoder = reader
            .into_decoder()
            .with_context(|| format!("{what}: cannot decode"))?;
        let (width, height) = decoder.dimensions();
        ensure!(
            width.max(height) <= MAX_IMAGE_SIDE,
            "{what}: {width}×{height} texels, more than {MAX_IMAGE_SIDE} a side"
        );
        let sized = format!("{what} ({width}×{height} texels)");
        let pixel = decoder.color_type().bytes_per_pixel() as u64;
        textures.fits(&sized, width as u64 * height as u64 * 4)?;
        let peak = memory::texture_decode_bytes(width, height, pixel);
        memory.fits(&format!("decoding {sized}"), peak)?;
        decoder
            .set_limits(decode_limits(peak))
            .with_context(|| format!("{what}: cannot decode"))?;
        let rgba = image::DynamicImage::from_decoder(decoder)
            .with_context(|| format!("{what}: cannot decode"))?
            .into_rgba8();
        let (width, height) = rgba.dimensions();
        let texels: Vec<[u8; 4]> = rgba.pixels().map(|p| p.0).collect();
        Ok(Self::from_texels(width, height, texels))
    }

    /// An image from RGBA8 texels, row-major from the top-left.
    pub fn from_texels(width: u32, height: u32, texels: Vec<[u8; 4]>) -> Self {
        assert_eq!(
            texels.len(),
            width as usize * height as usize,
            "texel count"
        );
        assert!(width > 0 && height > 0, "empty image");
        let opaque = texels.iter().all(|t| t[3] == 255);
        Self {
            width,
            height,
            texels,
            opaque,
        }
    }

    /// Bytes the texels take.
    pub fn texel_bytes(&self) -> u64 {
        self.texels.len() as u64 * 4
    }

    pub fn is_opaque(&self) -> bool {
        self.opaque
    }

    /// The image with each texel's red level (a grey image's value) as its alpha: scalar
    /// opacity maps (OBJ's `map_d`) carry coverage in their colour.
    pub fn grey_as_alpha(mut self) -> Self {
        for t in &mut self.texels {
            t[3] = t[0];
        }
        self.opaque = self.texels.iter().all(|t| t[3] == 255);
        self
    }

    /// Linear RGB (decoded from sRGB) and linear alpha of texel `(x, y)`.
    #[inline]
    fn texel(&self, x: u32, y: u32) -> Vec4 {
        let t = self.texels[(y * self.width + x) as usize];
        let lut = &*SRGB_TO_LINEAR;
        Vec4::new(
            lut[t[0] as usize],
            lut[t[1] as usize],
            lut[t[2] as usize],
            t[3] as f32 / 255.0,
        )
    }

    /// The colour (linear RGB) and alpha at `uv` as `map` samples it.
    pub fn sample(&self, map: &ImageMap, uv: Vec2) -> Vec4 {
        let uv = map.transform.map_or(uv, |t| t.apply(uv));
        let size = Vec2::new(self.width as f32, self.height as f32);
        let [wu, wv] = map.wrap;
        match map.filter {
            Filter::Nearest => {
                let p = (uv * size).floor();
                self.texel(wrap(p.x, self.width, wu), wrap(p.y, self.height, wv))
            }
            Filter::Linear => {
                // Texel centres sit at half-integers.
                let p = uv * size - Vec2::splat(0.5);
                let base = p.floor();
                let f = p - base;
                let (x0, x1) = (
                    wrap(base.x, self.width, wu),
                    wrap(base.x + 1.0, self.width, wu),
                );
                let (y0, y1) = (
                    wrap(base.y, self.height, wv),
                    wrap(base.y + 1.0, self.height, wv),
                );
                let top = self.texel(x0, y0).lerp(self.texel(x1, y0), f.x);
                let bottom = self.texel(x0, y1).lerp(self.texel(x1, y1), f.x);
                top.lerp(bottom, f.y)
            }
        }
    }

    /// Mean linear RGB over all texels (an emissive texture becomes a constant emission).
    pub fn mean_linear_rgb(&self) -> Vec3 {
        let lut = &*SRGB_TO_LINEAR;
        let sum = self.texels.iter().fold(glam::DVec3::ZERO, |acc, t| {
            acc + glam::DVec3::new(
                lut[t[0] as usize] as f64,
                lut[t[1] as usize] as f64,
                lut[t[2] as usize] as f64,
            )
        });
        (sum / self.texels.len() as f64).as_vec3()
    }
}

/// What the `image` crate may allocate: at most `max_alloc` bytes, sides of at most
/// [`MAX_IMAGE_SIDE`].
fn decode_limits(max_alloc: u64) -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    limits.max_alloc = Some(max_alloc);
    limits
}

/// Integer texel coordinate `i` (any float, also non-finite) wrapped into `0..n`.
#[inline]
fn wrap(i: f32, n: u32, mode: Wrap) -> u32 {
    // `as` saturates (NaN → 0), so a wild UV cannot overflow.
    let (i, n) = (i as i64, n as i64);
    let w = match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m < n { m } else { 2 * n - 1 - m }
        }
    };
    w as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(wrap: Wrap, filter: Filter) -> ImageMap {
        ImageMap {
            source: 0,
            image: 0,
            wrap: [wrap; 2],
            filter,
            transform: None,
        }
    }

    /// 2×1: a black opaque texel left, a white half-transparent one right.
    fn two_texels() -> TextureImage {
        TextureImage::from_texels(2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 51]])
    }

    #[test]
    fn wrap_modes() {
        let r: Vec<u32> = (-3..5).map(|i| wrap(i as f32, 3, Wrap::Repeat)).collect();
        assert_eq!(r, [0, 1, 2, 0, 1, 2, 0, 1]);
        let c: Vec<u32> = (-3..5).map(|i| wrap(i as f32, 3, Wrap::Clamp)).collect();
        assert_eq!(c, [0, 0, 0, 0, 1, 2, 2, 2]);
        let m: Vec<u32> = (-3..7).map(|i| wrap(i as f32, 3, Wrap::Mirror)).collect();
        assert_eq!(m, [2, 1, 0, 0, 1, 2, 2, 1, 0, 0]);
        assert_eq!(wrap(f32::NAN, 3, Wrap::Repeat), 0);
        assert_eq!(wrap(f32::INFINITY, 3, Wrap::Clamp), 2);
    }

    #[test]
    fn nearest_and_bilinear_sampling_on_linear_values() {
        let img = two_texels();
        let near = map(Wrap::Clamp, Filter::Nearest);
        assert_eq!(
            img.sample(&near, Vec2::new(0.2, 0.5)),
            Vec4::new(0.0, 0.0, 0.0, 1.0)
        );
        assert_eq!(
            img.sample(&near, Vec2::new(0.7, 0.5)),
            Vec4::new(1.0, 1.0, 1.0, 0.2)
        );
        // Halfway between the texel centres (u = 0.5): the mean of the linear values.
        let lin = img.sample(&map(Wrap::Clamp, Filter::Linear), Vec2::new(0.5, 0.5));
        assert!((lin - Vec4::new(0.5, 0.5, 0.5, 0.6)).abs().max_element() < 1e-6);
        // Repeat wraps the left neighbour of texel 0 to texel 1.
        let rep = img.sample(&map(Wrap::Repeat, Filter::Linear), Vec2::new(0.0, 0.5));
        assert!((rep.w - 0.6).abs() < 1e-6);
        assert!(!img.is_opaque());
    }

    #[test]
    fn srgb_decoding_matches_the_standard() {
        let lut = &*SRGB_TO_LINEAR;
        assert_eq!(lut[0], 0.0);
        assert_eq!(lut[255], 1.0);
        // sRGB 188 ≈ linear 0.5 (0.50289).
        assert!((lut[188] - 0.50289).abs() < 1e-4);
        let img = TextureImage::from_texels(1, 2, vec![[188, 0, 255, 255], [188, 0, 0, 255]]);
        let m = img.mean_linear_rgb();
        assert!((m - Vec3::new(lut[188], 0.0, 0.5)).abs().max_element() < 1e-6);
    }

    #[test]
    fn texture_transform_follows_the_extension() {
        // Scale 2, then rotate by 90°, then offset: (0.25, 0) → (0.5, 0) → (0, -0.5) → (1, 0).
        let t = UvTransform {
            offset: [1.0, 0.5],
            rotation: std::f32::consts::FRAC_PI_2,
            scale: [2.0, 2.0],
        };
        let uv = t.apply(Vec2::new(0.25, 0.0));
        assert!((uv - Vec2::new(1.0, 0.0)).length() < 1e-6, "{uv}");
    }

    fn budgets() -> DecodeBudgets {
        DecodeBudgets::for_images_alone().unwrap()
    }

    #[test]
    fn decode_rejects_other_formats_and_reads_png() {
        let err = TextureImage::decode(b"GIF89a....", "image 0", &budgets()).unwrap_err();
        assert!(format!("{err:#}").contains("image 0"), "{err:#}");
        let mut png = Vec::new();
        image::RgbaImage::from_raw(2, 1, vec![0, 0, 0, 255, 255, 255, 255, 51])
            .unwrap()
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let img = TextureImage::decode(&png, "image 0", &budgets()).unwrap();
        assert_eq!((img.width, img.height), (2, 1));
        assert_eq!(img.texels, two_texels().texels);
        // JPEG (lossy, opaque): a flat grey survives within a code or two.
        let mut jpeg = Vec::new();
        image::RgbImage::from_pixel(8, 8, image::Rgb([128, 128, 128]))
            .write_to(
                &mut std::io::Cursor::new(&mut jpeg),
                image::ImageFormat::Jpeg,
            )
            .unwrap();
        let img = TextureImage::decode(&jpeg, "image 1", &budgets()).unwrap();
        assert!(img.is_opaque() && img.texels.iter().all(|t| t[0].abs_diff(128) <= 2));
        assert_eq!(format!("{img:?}"), "TextureImage(8x8, opaque: true)");
    }
}

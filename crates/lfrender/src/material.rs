//! Materials as the renderer uses them: the scene's description with image textures bound to
//! their decoded pixels, plus precomputed fast paths.

use super::bsdf::{SurfaceKind, SurfaceParams};
use crate::scene::assets::Assets;
use crate::scene::texture_image::{ImageMap, TextureImage};
use crate::scene::{Material, Opacity, SurfaceModel, Texture};
use crate::textures::TEXTURE_PX;
use crate::textures::generators::TextureSpec;
use anyhow::{Context, Result};
use glam::{Vec2, Vec3, Vec4};
use std::sync::Arc;

// `LibraryTile::sample_level` wraps texel indices with a mask.
const _: () = assert!(TEXTURE_PX.is_power_of_two());

/// A material resolved for rendering.
#[derive(Clone, Debug)]
pub struct RenderMaterial {
    pub base_color: ColorMap,
    pub opacity: OpacityMap,
    /// `Some(a)` when opacity is the same everywhere (skips the UV lookup).
    pub uniform_opacity: Option<f32>,
    pub glass_ior: Option<f32>,
    /// Dielectric specular level of the Standard model (0 for [`SurfaceModel::Diffuse`]).
    pub specular: f32,
    pub roughness: f32,
    pub metallic: f32,
    /// Mean emitted radiance over the surface: what light selection weighs a triangle by and
    /// what tells an emitter apart.
    pub emission: Vec3,
    /// Emitted radiance per point: `emission_scale × map(uv)`; None when uniform
    /// (`emission` then).
    emission_map: Option<(Vec3, ColorMap)>,
}

/// An image with the way a material samples it.
#[derive(Clone, Debug)]
pub struct BoundImage {
    pub pixels: Arc<TextureImage>,
    pub map: ImageMap,
}

impl BoundImage {
    fn bind(map: &ImageMap, assets: &Assets) -> Result<Self> {
        Ok(Self {
            pixels: assets.image(map)?,
            map: map.clone(),
        })
    }

    #[inline]
    fn sample(&self, uv: Vec2) -> Vec4 {
        self.pixels.sample(&self.map, uv)
    }
}

/// Base colour: a scene texture evaluated as it is, an image times a factor, or a library
/// texture drawn once into a tile.
#[derive(Clone, Debug)]
pub enum ColorMap {
    Texture(Texture),
    Image { image: BoundImage, factor: Vec3 },
    Tile(Arc<LibraryTile>),
}

/// A procedural library texture rendered to `TEXTURE_PX`² linear texels (with the tint), so
/// a hit costs a bilinear lookup instead of the generator's noise octaves, plus its mip
/// pyramid (each level the 2×2 box average of the one below, down to one texel) for lookups
/// filtered over a footprint.
#[derive(Debug)]
pub struct LibraryTile {
    /// Level 0 is `px`² texels, level k is `(px >> k)`².
    levels: Vec<Vec<Vec3>>,
    px: usize,
    tile_size_m: f32,
}

impl LibraryTile {
    fn new(seed: u64, index: u32, tint: [f32; 3]) -> Self {
        let spec = TextureSpec::from_index(seed, index);
        let tint = Vec3::from(tint);
        let texels: Vec<Vec3> = crate::textures::render(&spec, TEXTURE_PX)
            .into_iter()
            .map(|c| c * tint)
            .collect();
        let px = TEXTURE_PX as usize;
        let mut levels = vec![texels];
        while levels.last().is_some_and(|l| l.len() > 1) {
            levels.push(downsample(levels.last().expect("non-empty")));
        }
        Self {
            levels,
            px,
            tile_size_m: spec.tile_size_m,
        }
    }

    /// Bilinear lookup with wrap-around (the tile is seamless), UVs in metres.
    #[inline]
    fn sample(&self, uv: Vec2) -> Vec3 {
        self.sample_level(0, uv)
    }

    /// The texture averaged over a footprint `width` metres wide: trilinear between the mip
    /// levels whose texels bracket it. A footprint below one texel is the plain lookup.
    #[inline]
    fn sample_filtered(&self, uv: Vec2, width: f32) -> Vec3 {
        let lod = (width * self.px as f32 / self.tile_size_m).log2();
        if lod.is_nan() || lod <= 0.0 {
            return self.sample(uv);
        }
        let top = (self.levels.len() - 1) as f32;
        let lod = lod.min(top);
        let l = lod.floor();
        let fine = self.sample_level(l as usize, uv);
        let coarse = self.sample_level((l as usize + 1).min(top as usize), uv);
        fine.lerp(coarse, lod - l)
    }

    fn sample_level(&self, level: usize, uv: Vec2) -> Vec3 {
        let n = (self.px >> level).max(1);
        let texels = &self.levels[level];
        let t = (uv / self.tile_size_m).fract_gl() * n as f32 - Vec2::splat(0.5);
        let (x0, y0) = (t.x.floor(), t.y.floor());
        let (fx, fy) = (t.x - x0, t.y - y0);
        // Levels are powers of two (`TEXTURE_PX` is, asserted at compile time), so wrapping is
        // a mask: `rem_euclid` divides, four times per level, and texture lookups are ~8 % of a
        // render's time.
        let ix = |x: f32| (x as i64 & (n as i64 - 1)) as usize;
        let (xa, xb, ya, yb) = (ix(x0), ix(x0 + 1.0), ix(y0), ix(y0 + 1.0));
        let at = |x: usize, y: usize| texels[y * n + x];
        let top = at(xa, ya).lerp(at(xb, ya), fx);
        let bottom = at(xa, yb).lerp(at(xb, yb), fx);
        top.lerp(bottom, fy)
    }
}

/// The next mip level of a square, power-of-two level: 2×2 box averages.
fn downsample(level: &[Vec3]) -> Vec<Vec3> {
    let n = level.len().isqrt();
    let m = (n / 2).max(1);
    (0..m * m)
        .map(|i| {
            let (x, y) = (2 * (i % m), 2 * (i / m));
            let at = |dx: usize, dy: usize| level[((y + dy) % n) * n + (x + dx) % n];
            (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) * 0.25
        })
        .collect()
}

impl ColorMap {
    fn bind(t: &Texture, assets: &Assets) -> Result<Self> {
        Ok(match t {
            Texture::Image { image, factor } => ColorMap::Image {
                image: BoundImage::bind(image, assets)?,
                factor: Vec3::from(*factor),
            },
            &Texture::Library { seed, index, tint } => {
                ColorMap::Tile(Arc::new(LibraryTile::new(seed, index, tint)))
            }
            other => ColorMap::Texture(other.clone()),
        })
    }

    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match self {
            ColorMap::Texture(t) => t.eval(uv),
            ColorMap::Image { image, factor } => image.sample(uv).truncate() * *factor,
            ColorMap::Tile(tile) => tile.sample(uv),
        }
    }

    /// Mean over the unit UV square (a procedural texture's metre, an image once): a light's
    /// weight in light selection, where an approximate mean costs variance, never bias.
    fn mean(&self) -> Vec3 {
        const N: u32 = 32;
        let at = |k: u32| (k as f32 + 0.5) / N as f32;
        let sum: Vec3 = (0..N * N)
            .map(|k| self.eval(Vec2::new(at(k % N), at(k / N))))
            .sum();
        sum / (N * N) as f32
    }

    /// [`Self::eval`] averaged over a footprint `width` metres wide where the map can
    /// (library tiles, through their mip pyramid); other maps are looked up as they are.
    #[inline]
    pub fn eval_filtered(&self, uv: Vec2, width: f32) -> Vec3 {
        match self {
            ColorMap::Tile(tile) => tile.sample_filtered(uv, width),
            other => other.eval(uv),
        }
    }
}

/// Opacity: a scene opacity evaluated as it is, or an image's alpha.
#[derive(Clone, Debug)]
pub enum OpacityMap {
    Opacity(Opacity),
    Image {
        image: BoundImage,
        factor: f32,
        cutoff: Option<f32>,
    },
}

impl OpacityMap {
    fn bind(o: &Opacity, assets: &Assets) -> Result<Self> {
        Ok(match o {
            Opacity::Image {
                image,
                factor,
                cutoff,
            } => OpacityMap::Image {
                image: BoundImage::bind(image, assets)?,
                factor: *factor,
                cutoff: *cutoff,
            },
            other => OpacityMap::Opacity(other.clone()),
        })
    }

    /// `Some(a)` when the opacity does not depend on the surface position: also for an
    /// image without transparent texels.
    fn uniform(&self) -> Option<f32> {
        match self {
            OpacityMap::Opacity(o) => o.uniform(),
            OpacityMap::Image {
                image,
                factor,
                cutoff,
            } => image
                .pixels
                .is_opaque()
                .then(|| Opacity::from_alpha(1.0, *factor, *cutoff)),
        }
    }

    #[inline]
    pub fn eval(&self, uv: Vec2) -> f32 {
        match self {
            OpacityMap::Opacity(o) => o.eval(uv),
            OpacityMap::Image {
                image,
                factor,
                cutoff,
            } => Opacity::from_alpha(image.sample(uv).w, *factor, *cutoff),
        }
    }
}

impl RenderMaterial {
    /// Resolves `m`, binding its image textures to their pixels in `assets`.
    pub fn new(m: &Material, assets: &Assets) -> Result<Self> {
        let bind = || -> Result<(ColorMap, OpacityMap)> {
            Ok((
                ColorMap::bind(&m.base_color, assets)?,
                OpacityMap::bind(&m.opacity, assets)?,
            ))
        };
        let (base_color, opacity) = bind().with_context(|| format!("material {:?}", m.name))?;
        let scale = Vec3::from(m.emission);
        let emission_map = match &m.emission_map {
            Some(t) => Some((scale, ColorMap::bind(t, assets)?)),
            None => None,
        };
        Ok(Self {
            uniform_opacity: opacity.uniform(),
            base_color,
            opacity,
            glass_ior: match m.model {
                SurfaceModel::Glass { ior } => Some(ior),
                SurfaceModel::Standard | SurfaceModel::Diffuse => None,
            },
            specular: match m.model {
                SurfaceModel::Diffuse => 0.0,
                SurfaceModel::Standard | SurfaceModel::Glass { .. } => 0.5,
            },
            roughness: m.roughness,
            metallic: match m.model {
                SurfaceModel::Diffuse => 0.0,
                SurfaceModel::Standard | SurfaceModel::Glass { .. } => m.metallic,
            },
            emission: emission_map
                .as_ref()
                .map_or(scale, |(scale, map)| *scale * map.mean()),
            emission_map,
        })
    }

    /// Radiance emitted at texture coordinate `uv`.
    #[inline]
    pub fn emitted(&self, uv: Vec2) -> Vec3 {
        match &self.emission_map {
            Some((scale, map)) => *scale * map.eval(uv),
            None => self.emission,
        }
    }

    /// The BSDF at a surface point.
    #[inline]
    pub fn surface(&self, uv: Vec2) -> SurfaceParams {
        self.surface_filtered(uv, 0.0)
    }

    /// The BSDF at a surface point, its base colour averaged over a footprint `width` metres
    /// wide (0: the plain lookup).
    #[inline]
    pub fn surface_filtered(&self, uv: Vec2, width: f32) -> SurfaceParams {
        SurfaceParams {
            base_color: self.base_color.eval_filtered(uv, width),
            roughness: self.roughness,
            metallic: self.metallic,
            specular: self.specular,
            kind: match self.glass_ior {
                Some(ior) => SurfaceKind::Glass { ior },
                None => SurfaceKind::Standard,
            },
        }
    }

    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile() -> LibraryTile {
        LibraryTile::new(3, 5, [1.0, 0.9, 0.8])
    }

    fn mean(v: &[Vec3]) -> Vec3 {
        v.iter().copied().sum::<Vec3>() / v.len() as f32
    }

    #[test]
    fn mip_levels_halve_down_to_one_texel_and_keep_the_mean() {
        let t = tile();
        assert_eq!(t.levels.len(), TEXTURE_PX.ilog2() as usize + 1);
        for (k, level) in t.levels.iter().enumerate() {
            assert_eq!(level.len(), (t.px >> k).pow(2));
            let d = (mean(level) - mean(&t.levels[0])).abs().max_element();
            assert!(d < 1e-4, "level {k}: mean off by {d}");
        }
    }

    #[test]
    fn a_lookup_hits_texel_centres_and_wraps_around_the_tile_both_ways() {
        let t = tile();
        let (n, size) = (t.px, t.tile_size_m);
        let centre =
            |x: usize, y: usize| Vec2::new(x as f32 + 0.5, y as f32 + 0.5) * size / n as f32;
        for (x, y) in [(0, 0), (n - 1, 3), (17, n - 1)] {
            let texel = t.levels[0][y * n + x];
            assert!((t.sample(centre(x, y)) - texel).abs().max_element() < 1e-5);
        }
        // Between the last and the first column: the bilinear mix of the two.
        let edge = Vec2::new(0.0, centre(0, 9).y);
        let mix = (t.levels[0][9 * n + n - 1] + t.levels[0][9 * n]) * 0.5;
        assert!((t.sample(edge) - mix).abs().max_element() < 1e-5);
        for uv in [Vec2::new(0.013, 0.2), Vec2::new(0.31, 0.77)] {
            for k in [Vec2::new(3.0, -2.0), Vec2::new(-1.0, -5.0)] {
                let d = (t.sample(uv + k * size) - t.sample(uv)).abs().max_element();
                assert!(d < 1e-3, "{uv} + {k} tiles: {d}");
            }
        }
    }

    #[test]
    fn a_filtered_lookup_is_exact_below_a_texel_and_the_mean_over_the_tile() {
        let t = tile();
        let texel = t.tile_size_m / t.px as f32;
        for uv in [Vec2::new(0.013, 0.2), Vec2::new(1.7, -0.4)] {
            assert_eq!(t.sample_filtered(uv, 0.0), t.sample(uv));
            assert_eq!(t.sample_filtered(uv, 0.5 * texel), t.sample(uv));
            let whole = t.sample_filtered(uv, 10.0 * t.tile_size_m);
            assert!((whole - mean(&t.levels[0])).abs().max_element() < 1e-4);
            // Two texels wide: exactly level 1.
            assert!((t.sample_filtered(uv, 2.0 * texel) - t.sample_level(1, uv)).length() < 1e-5);
        }
    }
}

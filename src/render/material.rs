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
    pub emission: Vec3,
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
/// a hit costs a bilinear lookup instead of the generator's noise octaves.
#[derive(Debug)]
pub struct LibraryTile {
    texels: Vec<Vec3>,
    px: usize,
    tile_size_m: f32,
}

impl LibraryTile {
    fn new(seed: u64, index: u32, tint: [f32; 3]) -> Self {
        let spec = TextureSpec::from_index(seed, index);
        let tint = Vec3::from(tint);
        let texels = crate::textures::render(&spec, TEXTURE_PX)
            .into_iter()
            .map(|c| c * tint)
            .collect();
        Self {
            texels,
            px: TEXTURE_PX as usize,
            tile_size_m: spec.tile_size_m,
        }
    }

    /// Bilinear lookup with wrap-around (the tile is seamless), UVs in metres.
    #[inline]
    fn sample(&self, uv: Vec2) -> Vec3 {
        let n = self.px;
        let t = (uv / self.tile_size_m).fract_gl() * n as f32 - Vec2::splat(0.5);
        let (x0, y0) = (t.x.floor(), t.y.floor());
        let (fx, fy) = (t.x - x0, t.y - y0);
        let ix = |x: f32| (x as i64).rem_euclid(n as i64) as usize;
        let (xa, xb, ya, yb) = (ix(x0), ix(x0 + 1.0), ix(y0), ix(y0 + 1.0));
        let at = |x: usize, y: usize| self.texels[y * n + x];
        let top = at(xa, ya).lerp(at(xb, ya), fx);
        let bottom = at(xa, yb).lerp(at(xb, yb), fx);
        top.lerp(bottom, fy)
    }
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
            emission: Vec3::from(m.emission),
        })
    }

    /// The BSDF at a surface point.
    #[inline]
    pub fn surface(&self, uv: Vec2) -> SurfaceParams {
        SurfaceParams {
            base_color: self.base_color.eval(uv),
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

//! Materials as the renderer uses them: the scene's description plus precomputed fast paths.

use super::bsdf::{SurfaceKind, SurfaceParams};
use crate::scene::{Material, Opacity, SurfaceModel, Texture};
use glam::{Vec2, Vec3};

/// A material resolved for rendering.
#[derive(Clone, Debug)]
pub struct RenderMaterial {
    pub base_color: Texture,
    pub opacity: Opacity,
    /// `Some(a)` when opacity is the same everywhere (skips the UV lookup).
    pub uniform_opacity: Option<f32>,
    pub glass_ior: Option<f32>,
    pub roughness: f32,
    pub metallic: f32,
    pub emission: Vec3,
}

impl RenderMaterial {
    pub fn new(m: &Material) -> Self {
        Self {
            base_color: m.base_color.clone(),
            opacity: m.opacity.clone(),
            uniform_opacity: m.opacity.uniform(),
            glass_ior: match m.model {
                SurfaceModel::Glass { ior } => Some(ior),
                SurfaceModel::Standard => None,
            },
            roughness: m.roughness,
            metallic: m.metallic,
            emission: Vec3::from(m.emission),
        }
    }

    /// The BSDF at a surface point.
    #[inline]
    pub fn surface(&self, uv: Vec2) -> SurfaceParams {
        SurfaceParams {
            base_color: self.base_color.eval(uv),
            roughness: self.roughness,
            metallic: self.metallic,
            specular: 0.5,
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

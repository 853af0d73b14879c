//! Materials and the procedural textures they read (evaluated on UVs measured in metres, so a
//! texture tiles at its real size whatever the object), or image textures of imported scenes
//! (evaluated on the mesh's own texture coordinates).

use super::texture_image::ImageMap;
use crate::util::hash::{mix64, unit_float};
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// A surface: scattering model, base colour, opacity (cut-outs, semi-transparency), emission.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub name: String,
    pub model: SurfaceModel,
    pub base_color: Texture,
    pub roughness: f32,
    pub metallic: f32,
    /// Surface coverage in [0, 1]: the α of the slices and the stochastic-transparency weight.
    pub opacity: Opacity,
    /// Emitted radiance (linear RGB); non-zero makes the surface an area light.
    pub emission: [f32; 3],
    /// Where the emission varies over the surface (a cloudy sky, a lit facade): the radiance
    /// at a point is `emission × emission_map(uv)`. None: uniform.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission_map: Option<Texture>,
}

/// The scattering model of a material.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SurfaceModel {
    /// Lambert diffuse under a GGX glossy layer.
    Standard,
    /// Lambert diffuse alone: the Standard model with its glossy layer switched off
    /// (`specular = 0`; `roughness` and `metallic` are ignored), for comparisons with other
    /// renderers' plain diffuse BSDFs.
    Diffuse,
    /// Smooth dielectric.
    Glass { ior: f32 },
}

/// Base-colour textures (linear RGB).
///
/// [`Texture::Image`] only names its image; the renderer binds the decoded pixels
/// (`render::material`), and [`Texture::eval`] on its own returns the factor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Texture {
    Constant {
        color: [f32; 3],
    },
    /// Squares of side `size` metres.
    Checker {
        a: [f32; 3],
        b: [f32; 3],
        size: f32,
    },
    /// Stripes along U of width `width` metres.
    Stripes {
        a: [f32; 3],
        b: [f32; 3],
        width: f32,
    },
    /// Smooth value noise blending `a` and `b`, feature size `scale` metres.
    Noise {
        a: [f32; 3],
        b: [f32; 3],
        scale: f32,
        seed: u32,
    },
    /// Texture `index` of the procedural library with master `seed`
    /// ([`crate::textures::generators::TextureSpec::from_index`]), tiling at its real size
    /// (`tile_size_m` of the spec), times a linear `tint`. The renderer draws it into an image
    /// once per scene instead of evaluating the generator per hit; `scene.json` stays small.
    Library {
        seed: u64,
        index: u32,
        tint: [f32; 3],
    },
    /// An image (sRGB-encoded, decoded to linear) times a linear `factor` (glTF
    /// `baseColorTexture` × `baseColorFactor`).
    Image {
        image: ImageMap,
        factor: [f32; 3],
    },
}

/// Opacity: a constant, or an alpha pattern (a grid of bars, a woven mesh), or an image's alpha.
///
/// As with [`Texture::Image`], [`Opacity::Image`] is bound to its pixels by the renderer;
/// [`Opacity::eval`] on its own treats the image's alpha as 1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Opacity {
    Constant {
        value: f32,
    },
    /// Bars of width `bar·period` every `period` metres in U and V, opacity `value` on the
    /// bars and 0 in the holes.
    Grid {
        value: f32,
        period: f32,
        bar: f32,
    },
    /// Leaf silhouettes: one pointed leaf (a lens between two circular arcs, along V) per
    /// `period` metres in U and V, opaque inside and absent outside. A quad of one period is
    /// one leaf; a larger one a spray of leaves.
    Leaves {
        period: [f32; 2],
    },
    /// The image's alpha times `factor` (glTF `BLEND`); with a `cutoff` (glTF `MASK`) the
    /// surface is opaque where that product is at least the cutoff and absent elsewhere.
    Image {
        image: ImageMap,
        factor: f32,
        cutoff: Option<f32>,
    },
}

impl Material {
    pub fn is_emissive(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }
}

impl Texture {
    pub fn constant(c: [f32; 3]) -> Self {
        Texture::Constant { color: c }
    }

    /// Whether colours are finite and non-negative and feature sizes positive (a loaded or
    /// hand-edited scene; [`Texture::eval`] divides by the sizes).
    pub fn is_valid(&self) -> bool {
        let rgb = |c: &[f32; 3]| c.iter().all(|v| v.is_finite() && *v >= 0.0);
        let size = |s: f32| s.is_finite() && s > 0.0;
        match self {
            Texture::Constant { color } => rgb(color),
            Texture::Checker { a, b, size: s } => rgb(a) && rgb(b) && size(*s),
            Texture::Stripes { a, b, width } => rgb(a) && rgb(b) && size(*width),
            Texture::Noise { a, b, scale, .. } => rgb(a) && rgb(b) && size(*scale),
            Texture::Library { tint, .. } => rgb(tint),
            Texture::Image { factor, .. } => rgb(factor),
        }
    }

    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match *self {
            Texture::Constant { color } => color.into(),
            Texture::Checker { a, b, size } => {
                let cell = (uv / size).floor();
                pick(a, b, (cell.x + cell.y).rem_euclid(2.0))
            }
            Texture::Stripes { a, b, width } => pick(a, b, (uv.x / width).floor().rem_euclid(2.0)),
            Texture::Noise { a, b, scale, seed } => pick(a, b, value_noise(uv / scale, seed)),
            Texture::Library { seed, index, tint } => {
                let spec = crate::textures::generators::TextureSpec::from_index(seed, index);
                let t = (uv / spec.tile_size_m).fract_gl();
                spec.eval(t.x, t.y) * Vec3::from(tint)
            }
            Texture::Image { factor, .. } => factor.into(),
        }
    }
}

impl Opacity {
    pub fn constant(value: f32) -> Self {
        Opacity::Constant { value }
    }

    /// `Some(a)` when the opacity does not depend on the surface position (the fast path).
    pub fn uniform(&self) -> Option<f32> {
        match *self {
            Opacity::Constant { value } => Some(value),
            Opacity::Grid { .. } | Opacity::Leaves { .. } | Opacity::Image { .. } => None,
        }
    }

    /// Opacity from an image's `alpha` (the alpha test of glTF `MASK` when there is a cutoff).
    #[inline]
    pub fn from_alpha(alpha: f32, factor: f32, cutoff: Option<f32>) -> f32 {
        let a = alpha * factor;
        match cutoff {
            Some(c) if a >= c => 1.0,
            Some(_) => 0.0,
            None => a,
        }
    }

    pub fn eval(&self, uv: Vec2) -> f32 {
        match *self {
            Opacity::Constant { value } => value,
            Opacity::Grid { value, period, bar } => {
                let f = (uv / period).fract_gl();
                if f.x < bar || f.y < bar { value } else { 0.0 }
            }
            Opacity::Leaves { period } => {
                let f = (uv / Vec2::from(period)).fract_gl();
                // Half-width of the leaf at height v: widest in the middle, pointed at both ends.
                let half = 0.42 * (std::f32::consts::PI * f.y).sin().powf(0.8);
                if (f.x - 0.5).abs() < half { 1.0 } else { 0.0 }
            }
            Opacity::Image { factor, cutoff, .. } => Self::from_alpha(1.0, factor, cutoff),
        }
    }
}

fn pick(a: [f32; 3], b: [f32; 3], t: f32) -> Vec3 {
    Vec3::from(a).lerp(Vec3::from(b), t)
}

/// Smoothly interpolated lattice noise in [0, 1].
fn value_noise(p: Vec2, seed: u32) -> f32 {
    crate::textures::noise::interpolate(p.x, p.y, |i, j| lattice(i as i32, j as i32, seed))
}

fn lattice(i: i32, j: i32, seed: u32) -> f32 {
    let key = ((i as u32 as u64) << 32 | j as u32 as u64) ^ ((seed as u64) << 17);
    unit_float(mix64(key))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_and_grid_patterns() {
        let t = Texture::Checker {
            a: [0.0; 3],
            b: [1.0; 3],
            size: 0.5,
        };
        assert_eq!(t.eval(Vec2::new(0.1, 0.1)).x, 0.0);
        assert_eq!(t.eval(Vec2::new(0.6, 0.1)).x, 1.0);
        assert_eq!(t.eval(Vec2::new(-0.1, 0.1)).x, 1.0);
        let g = Opacity::Grid {
            value: 0.9,
            period: 0.1,
            bar: 0.2,
        };
        assert_eq!(g.eval(Vec2::new(0.01, 0.05)), 0.9);
        assert_eq!(g.eval(Vec2::new(0.05, 0.05)), 0.0);
        assert_eq!(g.uniform(), None);
    }

    #[test]
    fn leaves_are_opaque_in_the_middle_and_open_at_the_tips_and_sides() {
        let l = Opacity::Leaves { period: [0.1, 0.2] };
        assert_eq!(l.eval(Vec2::new(0.05, 0.1)), 1.0);
        assert_eq!(l.eval(Vec2::new(0.03, 0.001)), 0.0);
        assert_eq!(l.eval(Vec2::new(0.001, 0.1)), 0.0);
        assert_eq!(l.eval(Vec2::new(0.15, 0.3)), 1.0, "repeats");
    }

    #[test]
    fn surface_models_serialise_by_type_tag() {
        // Existing scene.json files keep their bytes: Standard stays `{"type":"standard"}`.
        let json = |m: SurfaceModel| serde_json::to_string(&m).unwrap();
        assert_eq!(json(SurfaceModel::Standard), r#"{"type":"standard"}"#);
        assert_eq!(json(SurfaceModel::Diffuse), r#"{"type":"diffuse"}"#);
        let back: SurfaceModel = serde_json::from_str(r#"{"type":"diffuse"}"#).unwrap();
        assert_eq!(back, SurfaceModel::Diffuse);
    }

    #[test]
    fn noise_is_continuous_and_bounded() {
        let t = Texture::Noise {
            a: [0.0; 3],
            b: [1.0; 3],
            scale: 1.0,
            seed: 7,
        };
        let mut prev = t.eval(Vec2::new(0.0, 0.3)).x;
        for k in 1..2000 {
            let v = t.eval(Vec2::new(k as f32 * 1e-3, 0.3)).x;
            assert!((0.0..=1.0).contains(&v));
            assert!((v - prev).abs() < 0.01, "jump at {k}");
            prev = v;
        }
    }
}

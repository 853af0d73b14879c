//! Punctual lights (`KHR_lights_punctual`): point, spot and directional lights, which have no
//! surface and are reached only by next-event estimation.
//!
//! # Units
//!
//! The renderer's linear RGB values are one consistent photometric scale: an emissive surface's
//! emission is a luminance (cd/m², "nits"), a point or spot light's `intensity` a luminous
//! intensity (cd = lm/sr) and a directional light's `irradiance` an illuminance (lux = lm/m²),
//! each times its linear RGB colour. glTF uses exactly these units, so its numbers are taken
//! as they are: a point light of `I` cd lights a surface at distance `d` facing it with
//! `I / d²` lux, and a white Lambertian surface under `E` lux has luminance `E / π`. (Radiometric
//! watts would only rescale everything by 683 lm/W, which the automatic exposure removes.)

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A light without area, in world space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Light {
    /// Luminous intensity `intensity` (cd, linear RGB) in every direction from `position`.
    Point {
        position: Vec3,
        intensity: [f32; 3],
        /// Distance beyond which the light has no effect (glTF `range`; none = infinite).
        range: Option<f32>,
    },
    /// A point light restricted to a cone around `direction`: full intensity within
    /// `inner_cone` (radians from the axis), fading smoothly to zero at `outer_cone`.
    Spot {
        position: Vec3,
        /// Unit direction the light shines towards.
        direction: Vec3,
        intensity: [f32; 3],
        inner_cone: f32,
        outer_cone: f32,
        range: Option<f32>,
    },
    /// Parallel light travelling along the unit `direction`, with illuminance `irradiance`
    /// (lux, linear RGB) on a surface facing it.
    Directional {
        direction: Vec3,
        irradiance: [f32; 3],
    },
}

impl Light {
    /// Whether every number is finite, colours are non-negative and directions have unit
    /// length: what a loaded or hand-edited light must satisfy before it is rendered.
    pub fn is_valid(&self) -> bool {
        let rgb = |c: &[f32; 3]| c.iter().all(|v| v.is_finite() && *v >= 0.0);
        let unit = |d: &Vec3| d.is_finite() && (d.length() - 1.0).abs() < 1e-3;
        let range = |r: &Option<f32>| r.is_none_or(|r| r.is_finite() && r > 0.0);
        match self {
            Light::Point {
                position,
                intensity,
                range: r,
            } => position.is_finite() && rgb(intensity) && range(r),
            Light::Spot {
                position,
                direction,
                intensity,
                inner_cone,
                outer_cone,
                range: r,
            } => {
                position.is_finite()
                    && unit(direction)
                    && rgb(intensity)
                    && inner_cone.is_finite()
                    && outer_cone.is_finite()
                    && range(r)
            }
            Light::Directional {
                direction,
                irradiance,
            } => unit(direction) && rgb(irradiance),
        }
    }
}

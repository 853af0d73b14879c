//! Colour helpers shared by the renderer, the procedural textures and the writers.

use glam::Vec3;

/// Luminance of linear Rec. 709 RGB.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

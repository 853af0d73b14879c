//! The two tests a walk repeats — a ray against eight child boxes, and against a packet of four
//! triangles — as one scalar reference and its SIMD translations (`x86`).
//!
//! Every kernel evaluates the reference's expressions lane by lane, in the same order, with no
//! fused multiply-add, and `min`/`max` with the SSE rule (`max(a, b) = a > b ? a : b`): the
//! results are bitwise equal, so which kernel runs never changes an image.

use super::traverse::WideRay;
use super::{Node, Packet};

#[cfg(target_arch = "x86_64")]
mod x86;
#[cfg(target_arch = "x86_64")]
pub(super) use x86::{Avx2, Sse};

/// Relative growth of a box's exit distance that makes the slab test conservative under
/// `f32` rounding (Ize 2013, as pbrt-v4: `1 + 2γ₃`, `γₙ = nε / (1 − nε)`, `ε = 2⁻²⁴`): a ray
/// that meets a box in exact arithmetic is never culled by a rounded distance.
pub(super) const ROBUST: f32 = 1.0 + 2.0 * GAMMA3;
const GAMMA3: f32 = 3.0 * EPS / (1.0 - 3.0 * EPS);
const EPS: f32 = f32::EPSILON * 0.5;

/// A determinant below this (in magnitude) is a ray parallel to the triangle: no hit.
pub(super) const MIN_DET: f32 = 1e-12;

/// A node and triangle test. Implementations may need CPU features.
pub(super) trait Lanes {
    /// The children whose boxes the ray meets within `[ray.tmin, tmax]` as a bit mask, and
    /// each child's entry distance in `near` (clamped below at `ray.tmin`).
    ///
    /// # Safety
    /// The CPU supports the kernel's instructions.
    unsafe fn node(node: &Node, ray: &WideRay, tmax: f32, near: &mut [f32; 8]) -> u32;

    /// The lanes whose triangle the ray hits at `t` in `(ray.tmin, tmax]` as a bit mask, and
    /// `t`, `u`, `v` per lane in `tuv` (Möller–Trumbore, two-sided).
    ///
    /// # Safety
    /// As for [`Lanes::node`].
    unsafe fn packet(p: &Packet, ray: &WideRay, tmax: f32, tuv: &mut [[f32; 4]; 3]) -> u32;
}

/// The reference: one lane at a time.
pub(super) struct Scalar;

#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

impl Lanes for Scalar {
    #[inline(always)]
    unsafe fn node(node: &Node, ray: &WideRay, tmax: f32, near: &mut [f32; 8]) -> u32 {
        let mut mask = 0;
        for (i, near) in near.iter_mut().enumerate() {
            let slab = |axis: usize, row: usize| {
                (node.planes[row][i] - ray.origin[axis]) * ray.inv_dir[axis]
            };
            let [n, f] = [ray.near, ray.far].map(|rows| [0, 1, 2].map(|a| slab(a, rows[a])));
            let t0 = max(max(max(n[0], n[1]), n[2]), ray.tmin);
            let t1 = min(min(min(f[0], f[1]), f[2]) * ROBUST, tmax);
            *near = t0;
            mask |= ((t0 <= t1) as u32) << i;
        }
        mask
    }

    #[inline(always)]
    unsafe fn packet(p: &Packet, ray: &WideRay, tmax: f32, tuv: &mut [[f32; 4]; 3]) -> u32 {
        let [ox, oy, oz] = ray.origin;
        let [dx, dy, dz] = ray.dir;
        let mut mask = 0;
        for lane in 0..4 {
            let [v0x, v0y, v0z, e1x, e1y, e1z, e2x, e2y, e2z] = p.coords.map(|c| c[lane]);
            let (px, py, pz) = (
                dy * e2z - dz * e2y,
                dz * e2x - dx * e2z,
                dx * e2y - dy * e2x,
            );
            let det = (e1x * px + e1y * py) + e1z * pz;
            let inv = 1.0 / det;
            let (sx, sy, sz) = (ox - v0x, oy - v0y, oz - v0z);
            let u = ((sx * px + sy * py) + sz * pz) * inv;
            let (qx, qy, qz) = (
                sy * e1z - sz * e1y,
                sz * e1x - sx * e1z,
                sx * e1y - sy * e1x,
            );
            let v = ((dx * qx + dy * qy) + dz * qz) * inv;
            let t = ((e2x * qx + e2y * qy) + e2z * qz) * inv;
            let miss = det.abs() < MIN_DET
                || u < 0.0
                || v < 0.0
                || u + v > 1.0
                || !(t > ray.tmin && t <= tmax);
            [tuv[0][lane], tuv[1][lane], tuv[2][lane]] = [t, u, v];
            mask |= (!miss as u32) << lane;
        }
        mask
    }
}

//! Periodic noise: value noise whose lattice wraps with the tile, so everything built from it
//! tiles seamlessly by construction.

use crate::util::hash::{mix64, unit_float};

/// Lattice value in [0, 1) at integer point (i, j) of a `period`-wrapped lattice.
fn lattice(i: i64, j: i64, period: i64, seed: u64) -> f32 {
    let (i, j) = (i.rem_euclid(period) as u64, j.rem_euclid(period) as u64);
    unit_float(mix64(seed ^ mix64(i << 32 | j)))
}

/// Smooth value noise in [0, 1) at (u, v) ∈ [0, 1)², with `cells` lattice cells per tile side;
/// periodic in u and v with period 1.
pub fn value(u: f32, v: f32, cells: u32, seed: u64) -> f32 {
    let p = cells as i64;
    interpolate(u * cells as f32, v * cells as f32, |i, j| {
        lattice(i, j, p, seed)
    })
}

/// Value noise at (x, y) from the lattice values `lattice(i, j)` at integer points:
/// smoothstep-weighted bilinear interpolation of the four around (x, y). Every value noise of
/// lfgen (the periodic tiles here, the scene description's `Texture::Noise`) is this with its
/// own lattice hash.
pub fn interpolate(x: f32, y: f32, lattice: impl Fn(i64, i64) -> f32) -> f32 {
    let (i, j) = (x.floor(), y.floor());
    let (fx, fy) = (smooth(x - i), smooth(y - j));
    let (i, j) = (i as i64, j as i64);
    let l = |di, dj| lattice(i + di, j + dj);
    let top = l(0, 0) + (l(1, 0) - l(0, 0)) * fx;
    let bottom = l(0, 1) + (l(1, 1) - l(0, 1)) * fx;
    top + (bottom - top) * fy
}

fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

/// Fractal sum of `octaves` octaves (lacunarity 2, gain ½), normalised to [0, 1).
pub fn fbm(u: f32, v: f32, cells: u32, octaves: u32, seed: u64) -> f32 {
    let (mut sum, mut amp, mut norm) = (0.0, 1.0, 0.0);
    for o in 0..octaves {
        sum += amp * value(u, v, cells << o, seed.wrapping_add(o as u64 * 0x9E37));
        norm += amp;
        amp *= 0.5;
    }
    sum / norm
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_wraps_exactly_at_the_tile_edge() {
        for k in 0..50 {
            let v = k as f32 / 50.0;
            assert!((fbm(0.0, v, 4, 4, 9) - fbm(1.0, v, 4, 4, 9)).abs() < 1e-6);
            assert!((fbm(v, 0.0, 4, 4, 9) - fbm(v, 1.0, 4, 4, 9)).abs() < 1e-6);
        }
    }
}

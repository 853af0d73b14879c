//! Procedural, seamlessly tileable material textures: paint, plaster, wallpaper, tiles, bricks,
//! planks, parquet, wood, marble, granite, concrete, carpet and woven fabric, and the
//! low-contrast [`SUBTLE`] families (paint wash, paper, smooth plaster, smooth concrete) whose
//! luminance stays within [`SUBTLE_AMPLITUDE`] of their base colour's: the texture-poor walls
//! of real rooms, where a depth method has little to match.
//!
//! Every pattern is a function of (u, v) ∈ [0, 1)² that is periodic with period 1: integer
//! repeat counts for the regular structures, and [`noise`](super::noise) whose lattice wraps
//! with the tile for the irregular ones. Seamlessness is therefore exact, not blended.

use super::noise::{fbm, value};
use crate::util::hash::{mix64, unit_float};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The texture families.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    Paint,
    Plaster,
    Stripes,
    Motif,
    Tiles,
    Bricks,
    Planks,
    Parquet,
    Wood,
    Marble,
    Granite,
    Concrete,
    Carpet,
    Weave,
    Wash,
    Paper,
    SmoothPlaster,
    SmoothConcrete,
}

pub const FAMILIES: [Family; 14] = [
    Family::Paint,
    Family::Plaster,
    Family::Stripes,
    Family::Motif,
    Family::Tiles,
    Family::Bricks,
    Family::Planks,
    Family::Parquet,
    Family::Wood,
    Family::Marble,
    Family::Granite,
    Family::Concrete,
    Family::Carpet,
    Family::Weave,
];

/// The low-contrast families, at library indices from [`SUBTLE_BASE`] on (index
/// `SUBTLE_BASE + k` is family `SUBTLE[k % 4]`), so that the indices below it keep the
/// textures they always had.
pub const SUBTLE: [Family; 4] = [
    Family::Wash,
    Family::Paper,
    Family::SmoothPlaster,
    Family::SmoothConcrete,
];

/// First library index of the [`SUBTLE`] families (far above any library size).
pub const SUBTLE_BASE: u32 = 1 << 24;

/// Largest relative deviation of a [`SUBTLE`] texture's luminance from its base colour's.
pub const SUBTLE_AMPLITUDE: f32 = 0.04;

/// Everything that determines one texture; derived from its index alone.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureSpec {
    pub family: Family,
    pub seed: u64,
    /// Main and secondary colour (linear RGB).
    pub a: [f32; 3],
    pub b: [f32; 3],
    /// Repeat count of the family's structure (tiles, bricks, stripes, threads …) per tile.
    pub repeats: u32,
    /// Real-world size of one tile in metres (square).
    pub tile_size_m: f32,
}

/// A small random stream for deriving parameters.
struct Draw(u64);

impl Draw {
    fn unit(&mut self) -> f32 {
        self.0 = mix64(self.0);
        unit_float(self.0)
    }

    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.unit()
    }

    fn int(&mut self, a: u32, b: u32) -> u32 {
        a + (self.unit() * (b - a + 1) as f32) as u32 % (b - a + 1)
    }

    /// A colour around a family's typical hue range.
    fn color(&mut self, hue: (f32, f32), sat: (f32, f32), val: (f32, f32)) -> [f32; 3] {
        hsv(
            self.range(hue.0, hue.1),
            self.range(sat.0, sat.1),
            self.range(val.0, val.1),
        )
    }
}

/// Linear RGB of an HSV colour (h in turns).
fn hsv(h: f32, s: f32, v: f32) -> [f32; 3] {
    let k = |n: f32| {
        let k = (n + h.rem_euclid(1.0) * 6.0) % 6.0;
        v - v * s * k.min(4.0 - k).clamp(0.0, 1.0)
    };
    [k(5.0), k(3.0), k(1.0)].map(|c| c.powf(2.2))
}

impl TextureSpec {
    /// The spec of texture `index` of the library with master `seed`.
    pub fn from_index(seed: u64, index: u32) -> Self {
        let family = match index.checked_sub(SUBTLE_BASE) {
            Some(k) => SUBTLE[k as usize % SUBTLE.len()],
            None => FAMILIES[index as usize % FAMILIES.len()],
        };
        let seed = mix64(seed ^ mix64(index as u64 + 1));
        let mut d = Draw(seed);
        type Range = (f32, f32);
        let (hue, sat, val, repeats, size): (Range, Range, Range, (u32, u32), Range) = match family
        {
            Family::Paint => ((0.0, 1.0), (0.05, 0.35), (0.55, 0.9), (1, 1), (1.0, 2.0)),
            Family::Plaster => ((0.05, 0.15), (0.05, 0.25), (0.6, 0.9), (1, 1), (1.0, 2.0)),
            Family::Stripes => ((0.0, 1.0), (0.1, 0.5), (0.4, 0.9), (4, 16), (0.5, 1.0)),
            Family::Motif => ((0.0, 1.0), (0.1, 0.6), (0.4, 0.9), (3, 8), (0.4, 0.8)),
            Family::Tiles => ((0.0, 1.0), (0.0, 0.5), (0.3, 0.95), (2, 8), (0.4, 1.2)),
            Family::Bricks => ((0.0, 0.08), (0.3, 0.7), (0.3, 0.7), (4, 8), (0.5, 1.0)),
            Family::Planks => ((0.05, 0.11), (0.3, 0.7), (0.25, 0.75), (3, 8), (1.0, 2.0)),
            Family::Parquet => ((0.05, 0.11), (0.3, 0.7), (0.3, 0.75), (2, 6), (0.4, 0.9)),
            Family::Wood => ((0.05, 0.11), (0.35, 0.75), (0.3, 0.8), (3, 12), (0.3, 0.8)),
            Family::Marble => ((0.0, 1.0), (0.0, 0.15), (0.75, 0.95), (1, 4), (0.6, 1.2)),
            Family::Granite => ((0.0, 1.0), (0.0, 0.2), (0.2, 0.7), (1, 1), (0.3, 0.6)),
            Family::Concrete => ((0.0, 0.15), (0.0, 0.08), (0.45, 0.75), (1, 1), (1.0, 2.0)),
            Family::Carpet => ((0.0, 1.0), (0.2, 0.7), (0.2, 0.7), (1, 1), (0.4, 0.8)),
            Family::Weave => ((0.0, 1.0), (0.1, 0.6), (0.3, 0.85), (16, 48), (0.1, 0.3)),
            Family::Wash => ((0.0, 1.0), (0.0, 0.25), (0.5, 0.9), (1, 1), (1.0, 2.0)),
            Family::Paper => ((0.08, 0.15), (0.02, 0.15), (0.75, 0.95), (1, 1), (0.3, 0.6)),
            Family::SmoothPlaster => ((0.05, 0.15), (0.03, 0.2), (0.6, 0.9), (1, 1), (1.0, 2.0)),
            Family::SmoothConcrete => ((0.0, 0.15), (0.0, 0.06), (0.4, 0.7), (1, 1), (1.0, 2.0)),
        };
        let a = d.color(hue, sat, val);
        let b = d.color(hue, sat, (val.0 * 0.6, val.1 * 0.8));
        Self {
            family,
            seed,
            a,
            b,
            repeats: d.int(repeats.0, repeats.1),
            tile_size_m: d.range(size.0, size.1),
        }
    }

    /// Linear RGB at (u, v) ∈ [0, 1)².
    pub fn eval(&self, u: f32, v: f32) -> Vec3 {
        let (a, b) = (Vec3::from(self.a), Vec3::from(self.b));
        let n = self.repeats;
        let s = self.seed;
        match self.family {
            Family::Paint => a * (0.93 + 0.07 * fbm(u, v, 8, 5, s)),
            Family::Plaster => {
                a * (0.8 + 0.2 * fbm(u, v, 4, 6, s)) * (0.97 + 0.03 * value(u, v, 128, s + 1))
            }
            Family::Stripes => stripes(u, v, n, a, b, s),
            Family::Motif => motif(u, v, n, a, b, s),
            Family::Tiles => tiles(u, v, n, n, 0.0, a, b, s),
            Family::Bricks => tiles(u, v, n, 2 * n, 0.5, b, a, s),
            Family::Planks => planks(u, v, n, a, b, s),
            Family::Parquet => parquet(u, v, n, a, b, s),
            Family::Wood => grain(u, v, n, a, b, s),
            Family::Marble => marble(u, v, n, a, b, s),
            Family::Granite => granite(u, v, a, b, s),
            Family::Concrete => concrete(u, v, a, s),
            Family::Carpet => {
                a.lerp(b, fbm(u, v, 64, 2, s)) * (0.85 + 0.15 * value(u, v, 256, s + 3))
            }
            Family::Weave => weave(u, v, n, a, b, s),
            Family::Wash | Family::Paper | Family::SmoothPlaster | Family::SmoothConcrete => {
                a * (1.0 + SUBTLE_AMPLITUDE * subtle(self.family, u, v, s))
            }
        }
    }
}

/// A low-contrast family's relative deviation from its base colour, in [−1, 1]: broad
/// undulation plus fine grain, weighted per family (the weights of each sum to at most 1).
fn subtle(family: Family, u: f32, v: f32, s: u64) -> f32 {
    let signed = |x: f32| 2.0 * x - 1.0;
    match family {
        // Roller paint: soft blotches, a faint stipple.
        Family::Wash => 0.7 * signed(fbm(u, v, 6, 4, s)) + 0.3 * signed(value(u, v, 256, s + 1)),
        // Paper: fibres along u over a fine grain.
        Family::Paper => {
            0.5 * signed(fbm(u, v, 32, 3, s)) + 0.5 * signed(value(u, 4.0 * v % 1.0, 192, s + 1))
        }
        // Trowelled plaster: broad, slow strokes.
        Family::SmoothPlaster => {
            0.85 * signed(fbm(u, v, 3, 5, s)) + 0.15 * signed(value(u, v, 128, s + 1))
        }
        // Cast concrete: cloudy, with sparse small pores a little darker.
        _ => {
            let pores = (value(u, v, 160, s + 5) > 0.9) as u32 as f32;
            0.7 * signed(fbm(u, v, 8, 5, s)) - 0.3 * pores
        }
    }
}

fn stripes(u: f32, _v: f32, n: u32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let x = u * n as f32;
    let c = if (x.floor() as u32).is_multiple_of(2) {
        a
    } else {
        b
    };
    let line = (x.fract() < 0.04) as u32 as f32;
    c * (1.0 - 0.3 * line) * (0.96 + 0.04 * fbm(u, 0.0, 8, 3, s))
}

fn motif(u: f32, v: f32, n: u32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let (fu, fv) = ((u * n as f32).fract() - 0.5, (v * n as f32).fract() - 0.5);
    let diamond = fu.abs() + fv.abs() < 0.3;
    let c = if diamond { b } else { a };
    c * (0.95 + 0.05 * fbm(u, v, 8, 3, s))
}

/// A running-bond grid of `cols × rows` cells with grout; every other row offset by `offset`.
#[allow(clippy::too_many_arguments)]
fn tiles(
    u: f32,
    v: f32,
    cols: u32,
    rows: u32,
    offset: f32,
    cell: Vec3,
    grout: Vec3,
    s: u64,
) -> Vec3 {
    let y = v * rows as f32;
    let row = y.floor() as u32;
    let x = u * cols as f32 + if row % 2 == 1 { offset } else { 0.0 };
    let col = (x.floor() as u32) % cols;
    let (fx, fy) = (x.fract(), y.fract());
    let g = 0.05;
    if fx < g || fy < g * cols as f32 / rows as f32 {
        return grout * (0.9 + 0.1 * value(u, v, 64, s));
    }
    let tint = unit_float(mix64(s ^ (row as u64) << 20 ^ col as u64));
    cell * (0.85 + 0.2 * tint) * (0.92 + 0.08 * fbm(u, v, 16, 3, s + 1))
}

/// Wood grain: noise-distorted lines along u, periodic because `n` is an integer.
fn grain(u: f32, v: f32, n: u32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let warp = 2.0 * fbm(u, v, 4, 4, s);
    let t = 0.5 + 0.5 * (std::f32::consts::TAU * (n as f32 * v + warp)).sin();
    a.lerp(b, t * t) * (0.9 + 0.1 * value(u, v, 128, s + 2))
}

fn planks(u: f32, v: f32, n: u32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let y = v * n as f32;
    let row = y.floor() as u32;
    let shift = unit_float(mix64(s ^ row as u64));
    let x = (u + shift).fract();
    if y.fract() < 0.03 || x < 0.006 {
        return b * 0.5;
    }
    let tint = 0.85 + 0.3 * shift;
    grain(x, v, 4 * n, a, b, s ^ row as u64) * tint
}

/// Basket-weave parquet: `n × n` blocks alternating between horizontal and vertical strips.
fn parquet(u: f32, v: f32, n: u32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let (x, y) = (u * n as f32, v * n as f32);
    let (i, j) = (x.floor() as u32, y.floor() as u32);
    let (fx, fy) = (x.fract(), y.fract());
    let horizontal = (i + j).is_multiple_of(2);
    let across = if horizontal { fy } else { fx };
    if (across * 3.0).fract() < 0.04 || fx < 0.02 || fy < 0.02 {
        return b * 0.5;
    }
    let strip = (across * 3.0).floor() as u64;
    let seed = s ^ mix64((i as u64) << 24 ^ (j as u64) << 8 ^ strip);
    let (gu, gv) = if horizontal { (u, v) } else { (v, u) };
    grain(gu, gv, 6 * n, a, b, seed)
}

fn marble(u: f32, v: f32, n: u32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let turb = 3.0 * fbm(u, v, 4, 6, s);
    let vein = (std::f32::consts::TAU * (n as f32 * (u + v) + turb))
        .sin()
        .abs();
    a.lerp(b, (1.0 - vein).powi(6))
}

fn granite(u: f32, v: f32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let speck = value(u, v, 192, s);
    let base = a.lerp(b, fbm(u, v, 16, 3, s + 1));
    if speck > 0.8 {
        base * 1.4
    } else if speck < 0.15 {
        base * 0.4
    } else {
        base
    }
}

fn concrete(u: f32, v: f32, a: Vec3, s: u64) -> Vec3 {
    let pores = (value(u, v, 160, s + 5) > 0.88) as u32 as f32;
    a * (0.8 + 0.25 * fbm(u, v, 6, 6, s)) * (1.0 - 0.35 * pores)
}

/// Plain weave: warp and weft threads alternating over and under.
fn weave(u: f32, v: f32, n: u32, a: Vec3, b: Vec3, s: u64) -> Vec3 {
    let (x, y) = (u * n as f32, v * n as f32);
    let over = (x.floor() as u32 + y.floor() as u32).is_multiple_of(2);
    let (c, across) = if over { (a, y.fract()) } else { (b, x.fract()) };
    let shade = 0.75 + 0.25 * (std::f32::consts::PI * across).sin();
    c * shade * (0.95 + 0.05 * value(u, v, 4 * n, s))
}

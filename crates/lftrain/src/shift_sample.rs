//! EPI-Shift training samples (thesis §4.2.2, §4.2.5): a random crop, rotated and
//! colour-augmented as for the other models, as horizontal and vertical stacks at every integer
//! shift the crop's `S` shifts and their neighbours need, the centre view, the target and where
//! the shifts clipped.
//!
//! The shifts are integer, `L^s(x, y, u) = L^0(x − u s, y, u)`: every sample is a whole pixel,
//! no interpolation. Where a shifted view would read outside the scene, the nearest edge pixel
//! is repeated ("clipping") and the pixel gets no loss at that shift.

use lfdata::lightfield::{crop_plane, rotate_plane};
use lfdata::stacks::{Direction, Region, extract};

use crate::sample::{Draw, loss_region, target_planes};
use crate::scene::Scene;

/// One EPI-Shift sample of a `patch²` crop with `S` shifts `base + k`, `k = −K ..= K`.
#[derive(Clone, Debug, PartialEq)]
pub struct ShiftSample {
    /// `S + 2` horizontal stacks (shifts `base − K − 1 ..= base + K + 1`), each `n · 3` planes.
    pub horizontal: Vec<f32>,
    /// The same for the vertical stack.
    pub vertical: Vec<f32>,
    /// The centre view, 3 planes.
    pub centre: Vec<f32>,
    /// Target disparity minus `base` (one plane; 0 where there is none).
    pub disparity: Vec<f32>,
    /// 1 inside the loss region where the pixel has a target, else 0 (one plane).
    pub weight: Vec<f32>,
    /// Per shift `k`, 1 where no view of the shifts `k − 1, k, k + 1` clipped (`S` planes).
    pub clip: Vec<f32>,
    /// Pixels with a non-zero weight (the loss' `N`).
    pub loss_pixels: usize,
}

/// The sample of `scene` for `draw` with `offsets` (`−K ..= K`) around the integer base shift
/// `round(draw.shift)`.
pub fn make_shift_sample(
    scene: &Scene,
    draw: &Draw,
    patch: usize,
    border: usize,
    offsets: &[i32],
) -> ShiftSample {
    let base = draw.shift.round() as i32;
    let half = offsets.iter().map(|k| k.abs()).max().unwrap_or(0);
    let (c, _) = scene.lf.centre();
    let reach = c * (base.unsigned_abs() as usize + half as usize + 1);
    let margin = reach + 1;
    let (x0, y0) = (draw.origin.0 as isize, draw.origin.1 as isize);
    let (m, k) = (margin as isize, draw.scale.max(1));
    let side = patch + 2 * margin;
    let corner = (x0 - m * k as isize, y0 - m * k as isize);
    let mut lf = scene.lf.crop(corner, (side, side), k).rotate(draw.turns);
    // Before the colours here, which apply to the extracted stacks.
    let lens = draw.lens((scene.lf.width, scene.lf.height), corner, side);
    draw.degrade.apply_all(&mut lf.views, side, lens);
    let inside = inside_scene(scene, corner, side, k, draw.turns);
    let region = Region {
        x0: margin,
        y0: margin,
        width: patch,
        height: patch,
    };
    let plane = patch * patch;
    let centre_rgb = crop_plane(lf.view(c, c), side, side, 3, (m, m), (patch, patch), 1);
    let pivot = draw.photometric.pivot(&centre_rgb);
    let stack = |dir| {
        let shifts = base - half - 1..=base + half + 1;
        let mut s: Vec<f32> = shifts
            .flat_map(|t| extract(&lf, dir, region, t as f32))
            .collect();
        draw.photometric.apply(&mut s, plane, pivot);
        s
    };
    let horizontal = stack(Direction::Horizontal);
    let vertical = stack(Direction::Vertical);
    let mut centre = planes_of(&centre_rgb, plane);
    draw.photometric.apply(&mut centre, plane, pivot);
    let based = Draw {
        shift: base as f32,
        ..*draw
    };
    let (disparity, eta) = target_planes(&scene.targets, (x0, y0), patch, &based);
    let region_mask = loss_region(scene, (x0, y0), patch, draw, border);
    let weight: Vec<f32> = eta.iter().zip(&region_mask).map(|(e, r)| e * r).collect();
    let clip = offsets
        .iter()
        .flat_map(|&o| {
            let r = c * ((base + o).unsigned_abs() as usize + 1);
            unclipped(&inside, side, margin, patch, r)
        })
        .collect();
    ShiftSample {
        horizontal,
        vertical,
        centre,
        disparity,
        loss_pixels: weight.iter().filter(|&&w| w > 0.0).count(),
        weight,
        clip,
    }
}

/// RGB interleaved → three planes.
fn planes_of(rgb: &[f32], plane: usize) -> Vec<f32> {
    (0..3)
        .flat_map(|ch| (0..plane).map(move |i| rgb[i * 3 + ch]))
        .collect()
}

/// 1 where a pixel of the `side²` crop at `corner` (every `step`-th scene pixel, then turned
/// `turns` times) lies inside the scene, 0 where the crop repeated an edge pixel.
fn inside_scene(
    scene: &Scene,
    corner: (isize, isize),
    side: usize,
    step: usize,
    turns: usize,
) -> Vec<f32> {
    let (w, h) = (scene.lf.width as isize, scene.lf.height as isize);
    let within = |v: isize, n: isize| (0..n).contains(&v);
    let mut inside: Vec<f32> = (0..side * side)
        .map(|i| {
            let x = corner.0 + (i % side * step) as isize;
            let y = corner.1 + (i / side * step) as isize;
            if within(x, w) && within(y, h) {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    for _ in 0..turns % 4 {
        inside = rotate_plane(&inside, side, side, 1);
    }
    inside
}

/// Per pixel of the `patch²` region at `(margin, margin)`: 1 where the pixels `reach` to the
/// left, right, top and bottom are all inside the scene. The outer views of a shift `t` read
/// `x ∓ c·t` (horizontal stack) and `y ∓ c·t` (vertical); the inside is a rectangle, so its
/// four extremes decide.
fn unclipped(inside: &[f32], side: usize, margin: usize, patch: usize, reach: usize) -> Vec<f32> {
    let at = |x: usize, y: usize| inside[y * side + x] > 0.0;
    (0..patch * patch)
        .map(|i| {
            let (x, y) = (margin + i % patch, margin + i / patch);
            let ok = at(x - reach, y) && at(x + reach, y) && at(x, y - reach) && at(x, y + reach);
            if ok { 1.0 } else { 0.0 }
        })
        .collect()
}

/// A batch of shift samples in the network's layout (crop after crop; see
/// [`crate::epishift::ShiftInput`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ShiftBatch {
    /// Crops.
    pub size: usize,
    /// Crop side.
    pub patch: usize,
    /// Channels per stack.
    pub stack_channels: usize,
    /// Shifts `S` per crop.
    pub shifts: usize,
    /// `[B, S+2, n·3, P, P]`.
    pub horizontal: Vec<f32>,
    /// `[B, S+2, n·3, P, P]`.
    pub vertical: Vec<f32>,
    /// `[B, 3, P, P]`.
    pub centre: Vec<f32>,
    /// `[B, 1, P, P]`, relative to each crop's base shift.
    pub disparity: Vec<f32>,
    /// `[B, 1, P, P]`.
    pub weight: Vec<f32>,
    /// `[B, S, P, P]`.
    pub clip: Vec<f32>,
    /// Pixels with a target inside the loss region, over all crops.
    pub loss_pixels: usize,
}

impl ShiftBatch {
    /// Concatenates `samples` (all of the same shape) of `shifts` shifts each.
    pub fn from_samples(samples: Vec<ShiftSample>, patch: usize, shifts: usize) -> Self {
        let plane = patch * patch;
        let stack_channels = samples[0].horizontal.len() / ((shifts + 2) * plane);
        let mut b = Self {
            size: samples.len(),
            patch,
            stack_channels,
            shifts,
            horizontal: Vec::new(),
            vertical: Vec::new(),
            centre: Vec::new(),
            disparity: Vec::new(),
            weight: Vec::new(),
            clip: Vec::new(),
            loss_pixels: samples.iter().map(|s| s.loss_pixels).sum(),
        };
        for s in samples {
            b.horizontal.extend(s.horizontal);
            b.vertical.extend(s.vertical);
            b.centre.extend(s.centre);
            b.disparity.extend(s.disparity);
            b.weight.extend(s.weight);
            b.clip.extend(s.clip);
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::augment::{Degrade, Photometric};
    use crate::config::TrainConfig;
    use crate::synthetic::TwoPlanes;

    fn scene(size: usize) -> Scene {
        let dir = tempfile::tempdir().unwrap();
        TwoPlanes::new(5, size).write(dir.path(), false).unwrap();
        let uni = crate::scene::Unimodal::of(&TrainConfig::default());
        Scene::load(dir.path(), "s", 1, uni).unwrap()
    }

    fn draw(origin: (usize, usize), shift: f32) -> Draw {
        Draw {
            origin,
            scale: 1,
            turns: 0,
            shift,
            photometric: Photometric::IDENTITY,
            degrade: Degrade::NONE,
        }
    }

    #[test]
    fn integer_stacks_and_the_clipping_mask_at_the_scene_corner() {
        let s = scene(20);
        let (patch, offsets) = (8, [-1, 0, 1]);
        // Base shift 1 (0.6 rounds to 1): shifts 0, 1, 2 with neighbours -1 ..= 3.
        let sample = make_shift_sample(&s, &draw((0, 0), 0.6), patch, 0, &offsets);
        let plane = patch * patch;
        let region = Region {
            x0: 0,
            y0: 0,
            width: patch,
            height: patch,
        };
        let stack = 15 * plane;
        for (j, t) in (-1..=3).enumerate() {
            let whole = extract(&s.lf, Direction::Vertical, region, t as f32);
            let got = &sample.vertical[j * stack..(j + 1) * stack];
            // The identity photometric draw still rounds ((v − pivot) + pivot).
            let diff = got
                .iter()
                .zip(&whole)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f32::max);
            assert!(diff < 1e-6, "shift {t}: differs by {diff}");
        }
        // The outer views (c = 2) of shifts t - 1 ..= t + 1 read 2·(|t| + 1) px to each side;
        // at the corner (0, 0) only pixels at least that far from the top and left count.
        for (j, t) in [0usize, 1, 2].iter().enumerate() {
            let reach = 2 * (t + 1);
            for i in 0..plane {
                let (x, y) = (i % patch, i / patch);
                let want = if x >= reach && y >= reach { 1.0 } else { 0.0 };
                assert_eq!(sample.clip[j * plane + i], want, "shift {t}, ({x}, {y})");
            }
        }
        // Targets are relative to the base shift; the centre view is the view (2, 2).
        let d0 = s.targets.pairs[0];
        assert!((sample.disparity[0] - (d0 - 1.0)).abs() < 1e-6);
        let (centre, red) = (
            &sample.centre[..plane],
            &sample.horizontal[6 * plane..7 * plane],
        );
        assert!(centre.iter().zip(red).all(|(a, b)| (a - b).abs() < 1e-6));
        assert_eq!(sample.loss_pixels, plane);
    }
}

//! EPI-Shift inference (thesis §4.2, §4.2.6): the network at every integer shift that covers
//! the scene's disparity range, `D = s* + R^{s*}` with `s* = argmax_s C^s`, and the refinement
//! of eq. 4.11 where no classification is confident; optionally coarse to fine
//! (`epishift.coarse_max`), which the thesis does not do.

use std::collections::VecDeque;

use burn::prelude::*;
use lfdata::lightfield::LightField;
use lfdata::stacks::{Direction, Region, extract};

use crate::config::{EpiShiftConfig, MAX_SHIFTS};
use crate::epishift::EpiShiftNet;
use crate::tensors::{tensor4, values};

/// The range assumed for a light field without `parameters.cfg` (built in memory): the
/// thesis' training range.
pub const FALLBACK_RANGE: [f32; 2] = [-3.5, 3.5];

/// The disparity range inference covers for `lf`: `cfg.range` if set, else the scene's
/// `parameters.cfg` range.
fn scene_range(cfg: &EpiShiftConfig, lf: &LightField) -> [f32; 2] {
    cfg.range.or(lf.disparity_range).unwrap_or(FALLBACK_RANGE)
}

/// The inference shifts for `lf`: every integer shift of its range (`scene_range`).
pub fn scene_shifts(cfg: &EpiShiftConfig, lf: &LightField) -> Vec<i32> {
    let [lo, hi] = scene_range(cfg, lf);
    let mut shifts = EpiShiftConfig::shifts_for(lo, hi);
    shifts.truncate(MAX_SHIFTS);
    shifts
}

/// The estimate of `net` for `lf`: one pass over the shifts covering its range or, where
/// `cfg.coarse_max` asks for it, first a pass on the views down-scaled by
/// [`EpiShiftConfig::coarse_scale`] whose estimate, scaled back up, limits each pixel's
/// choice at full size to the shifts within `cfg.coarse_radius` of it.
pub fn estimate(
    net: &EpiShiftNet,
    lf: &LightField,
    cfg: &EpiShiftConfig,
    device: &Device,
) -> ShiftEstimate {
    let range = scene_range(cfg, lf);
    let k = cfg.coarse_scale(range);
    let mut shifts = scene_shifts(cfg, lf);
    let prior = (k > 1).then(|| {
        let small = lf.downscale(k);
        let kf = k as f32;
        let coarse = EpiShiftConfig {
            coarse_max: 0.0,
            range: Some([range[0] / kf, range[1] / kf]),
            ..cfg.clone()
        };
        let est = estimate(net, &small, &coarse, device);
        upsample(
            &est.disparity,
            (small.width, small.height),
            k,
            (lf.width, lf.height),
        )
    });
    if let Some(p) = &prior {
        // Only the shifts some pixel may still choose.
        let (lo, hi) = p
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &d| {
                (a.min(d), b.max(d))
            });
        shifts
            .retain(|&s| s as f32 >= lo - cfg.coarse_radius && s as f32 <= hi + cfg.coarse_radius);
    }
    let maps = run_shifts(net, lf, &shifts, cfg.unet_depth, device);
    decide(&maps, cfg, prior.as_deref())
}

/// A `w × h` disparity map scaled up by `k` to `out` (nearest neighbour, the values × `k`;
/// pixels beyond the last whole block take the edge block's value).
fn upsample(d: &[f32], (w, h): (usize, usize), k: usize, (ow, oh): (usize, usize)) -> Vec<f32> {
    (0..oh)
        .flat_map(|y| (0..ow).map(move |x| (x, y)))
        .map(|(x, y)| d[(y / k).min(h - 1) * w + (x / k).min(w - 1)] * k as f32)
        .collect()
}

/// `C^s` and `R^s` of every shift, planes of `width × height`.
#[derive(Clone, Debug, PartialEq)]
pub struct ShiftMaps {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// The shifts, increasing by one.
    pub shifts: Vec<i32>,
    /// `C^s` per shift.
    pub class: Vec<Vec<f32>>,
    /// `R^s` per shift.
    pub reg: Vec<Vec<f32>>,
}

/// Runs `net` (validation mode, no autodiff) on `lf` at `shifts` (consecutive integers).
///
/// The stacks are read over the image rounded up to a multiple of `2^depth` (the U-Net's
/// input sizes; edge pixels repeated) and the outputs cut back. Each shift's features are
/// computed once and kept while the neighbouring shifts need them.
pub fn run_shifts(
    net: &EpiShiftNet,
    lf: &LightField,
    shifts: &[i32],
    depth: usize,
    device: &Device,
) -> ShiftMaps {
    let unit = 1 << depth;
    let (pw, ph) = (
        lf.width.div_ceil(unit) * unit,
        lf.height.div_ceil(unit) * unit,
    );
    let region = Region {
        x0: 0,
        y0: 0,
        width: pw,
        height: ph,
    };
    let shape = [1, lf.nx * 3, ph, pw];
    let stacks = |t: i32, dir| tensor4(extract(lf, dir, region, t as f32), shape, device);
    let features = |t: i32| {
        [
            net.features(stacks(t, Direction::Horizontal), false),
            net.features(stacks(t, Direction::Vertical), true),
        ]
    };
    let (c, _) = lf.centre();
    let centre = stacks(0, Direction::Horizontal).narrow(1, 3 * c, 3);
    let mut window: VecDeque<[Tensor<4>; 2]> = VecDeque::new();
    let mut maps = ShiftMaps {
        width: lf.width,
        height: lf.height,
        shifts: shifts.to_vec(),
        class: Vec::with_capacity(shifts.len()),
        reg: Vec::with_capacity(shifts.len()),
    };
    for &s in shifts {
        while window.len() < 3 {
            let t = s - 1 + window.len() as i32;
            window.push_back(features(t));
        }
        let h = std::array::from_fn(|i| window[i][0].clone());
        let v = std::array::from_fn(|i| window[i][1].clone());
        let out = values(net.head(h, v, centre.clone()));
        let (class, reg) = out.split_at(pw * ph);
        maps.class.push(cut(class, pw, lf.width, lf.height));
        maps.reg.push(cut(reg, pw, lf.width, lf.height));
        window.pop_front();
    }
    maps
}

/// The top-left `w × h` of a plane `stride` wide.
fn cut(plane: &[f32], stride: usize, w: usize, h: usize) -> Vec<f32> {
    (0..h)
        .flat_map(|y| plane[y * stride..y * stride + w].iter().copied())
        .collect()
}

/// The result of one scene: the disparity and the confidence `max_s C^s` per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct ShiftEstimate {
    /// `D`, row-major.
    pub disparity: Vec<f32>,
    /// `max_s C^s` (before refinement), row-major.
    pub confidence: Vec<f32>,
    /// Pixels the refinement (eq. 4.11) re-decided.
    pub refined: usize,
}

/// `D = s* + R^{s*}`; where `max_s C^s < cfg.refine_threshold` (eq. 4.11), `s*` is taken on
/// the median-filtered `C^s` (a `median_window²` window, clipped to the image) instead.
/// With a `prior` (a disparity per pixel), pixel `i` chooses only among the shifts within
/// `cfg.coarse_radius` of `prior[i]` clamped to the shifts' range, so at least one remains.
pub fn decide(maps: &ShiftMaps, cfg: &EpiShiftConfig, prior: Option<&[f32]>) -> ShiftEstimate {
    let (w, h) = (maps.width, maps.height);
    let mut est = ShiftEstimate {
        disparity: Vec::with_capacity(w * h),
        confidence: Vec::with_capacity(w * h),
        refined: 0,
    };
    let (first, last) = (
        maps.shifts[0] as f32,
        maps.shifts[maps.shifts.len() - 1] as f32,
    );
    for i in 0..w * h {
        let allowed = |k: usize| {
            prior.is_none_or(|p| {
                (maps.shifts[k] as f32 - p[i].clamp(first, last)).abs() <= cfg.coarse_radius
            })
        };
        let masked = |k: usize, v: f32| if allowed(k) { v } else { f32::NEG_INFINITY };
        let (mut best, conf) = argmax(maps.class.iter().enumerate().map(|(k, c)| masked(k, c[i])));
        est.confidence.push(conf);
        if conf < cfg.refine_threshold {
            let r = cfg.median_window / 2;
            // The median (a sort) only at the shifts this pixel may choose.
            let filtered = maps.class.iter().enumerate().map(|(k, c)| {
                if allowed(k) {
                    median(c, w, h, i, r)
                } else {
                    f32::NEG_INFINITY
                }
            });
            best = argmax(filtered).0;
            est.refined += 1;
        }
        est.disparity
            .push(maps.shifts[best] as f32 + maps.reg[best][i]);
    }
    est
}

/// Index and value of the largest value (the first on ties; NaN never wins).
fn argmax(values: impl Iterator<Item = f32>) -> (usize, f32) {
    values
        .enumerate()
        .fold((0, f32::NEG_INFINITY), |(bi, bv), (i, v)| {
            if v > bv { (i, v) } else { (bi, bv) }
        })
}

/// Median of `plane` over the `(2r+1)²` window around pixel `i`, clipped to the image (the
/// lower median for an even count).
fn median(plane: &[f32], w: usize, h: usize, i: usize, r: usize) -> f32 {
    let (x, y) = (i % w, i / w);
    let mut v: Vec<f32> = (y.saturating_sub(r)..(y + r + 1).min(h))
        .flat_map(|yy| (x.saturating_sub(r)..(x + r + 1).min(w)).map(move |xx| yy * w + xx))
        .map(|j| plane[j])
        .collect();
    v.sort_by(f32::total_cmp);
    v[(v.len() - 1) / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn maps(class: Vec<Vec<f32>>, reg: Vec<Vec<f32>>, w: usize, h: usize) -> ShiftMaps {
        ShiftMaps {
            width: w,
            height: h,
            shifts: (0..class.len() as i32).map(|k| k - 1).collect(),
            class,
            reg,
        }
    }

    #[test]
    fn argmax_shift_plus_its_offset() {
        // Shifts -1, 0, 1; pixel 0 peaks at 1 (offset 0.3), pixel 1 at -1 (offset -0.2).
        let m = maps(
            vec![vec![0.1, 0.9], vec![0.2, 0.1], vec![0.8, 0.0]],
            vec![vec![9.0, -0.2], vec![9.0, 9.0], vec![0.3, 9.0]],
            2,
            1,
        );
        let e = decide(&m, &EpiShiftConfig::default(), None);
        let want = [1.3, -1.2];
        assert!(
            e.disparity
                .iter()
                .zip(want)
                .all(|(a, b)| (a - b).abs() < 1e-6),
            "{:?}",
            e.disparity
        );
        assert_eq!(e.confidence, vec![0.8, 0.9]);
        assert_eq!(e.refined, 0);
    }

    #[test]
    fn unconfident_pixels_take_the_median_filtered_classification() {
        // 3×3 image, shifts -1 and 0. Everywhere shift 0 wins with 0.9, except the centre,
        // where both are below 0.01 and shift -1 is marginally larger: the median over the
        // 3×3 window picks shift 0 (0.9 against the centre's neighbours' 0.0).
        let mut c0 = vec![0.9; 9];
        let mut c1 = vec![0.0; 9];
        (c0[4], c1[4]) = (0.001, 0.005);
        let m = maps(vec![c1, c0], vec![vec![0.1; 9], vec![0.25; 9]], 3, 3);
        let cfg = EpiShiftConfig {
            median_window: 3,
            ..EpiShiftConfig::default()
        };
        let e = decide(&m, &cfg, None);
        assert_eq!(e.refined, 1);
        assert_eq!(e.disparity[4], 0.25);
        let off = EpiShiftConfig {
            refine_threshold: 0.0,
            ..cfg
        };
        assert_eq!(decide(&m, &off, None).disparity[4], -0.9);
    }

    #[test]
    fn a_prior_limits_the_choice_to_nearby_shifts() {
        // Shifts -1..=3 at one pixel; shift 3 has the largest C, but the prior 0.4 with
        // radius 1.5 allows only -1, 0 and 1, of which 1 is the largest (offset 0.2).
        let m = maps(
            vec![vec![0.1], vec![0.2], vec![0.5], vec![0.0], vec![0.9]],
            vec![vec![0.0], vec![0.0], vec![0.2], vec![0.0], vec![-0.1]],
            1,
            1,
        );
        let cfg = EpiShiftConfig {
            coarse_radius: 1.5,
            ..EpiShiftConfig::default()
        };
        assert_eq!(decide(&m, &cfg, None).disparity, vec![2.9]);
        let e = decide(&m, &cfg, Some(&[0.4]));
        assert_eq!((e.disparity[0], e.confidence[0]), (1.2, 0.5));
        // A prior beyond the shifts is clamped to the last one: 3 (and 2) stay allowed.
        assert_eq!(decide(&m, &cfg, Some(&[40.0])).disparity, vec![2.9]);
    }

    #[test]
    fn coarse_scale_brings_the_range_within_coarse_max() {
        let mut cfg = EpiShiftConfig::default();
        assert_eq!(cfg.coarse_scale([-40.0, 40.0]), 1, "off by default");
        cfg.coarse_max = 12.0;
        assert_eq!(cfg.coarse_scale([-3.5, 3.5]), 1);
        assert_eq!(cfg.coarse_scale([-12.0, 5.0]), 1);
        assert_eq!(cfg.coarse_scale([-39.7, 33.8]), 4);
        assert_eq!(cfg.coarse_scale([0.0, 24.5]), 4);
        assert_eq!(cfg.coarse_scale([0.0, 24.0]), 2);
    }

    #[test]
    fn upsampling_repeats_blocks_and_scales_values() {
        // 2 × 1 → 5 × 2 at k = 2: the fifth column takes the last block.
        let up = upsample(&[1.0, -0.5], (2, 1), 2, (5, 2));
        assert_eq!(up, [2.0, 2.0, -1.0, -1.0, -1.0].repeat(2));
    }

    #[test]
    fn shifts_cover_a_range_with_half_a_pixel_each() {
        assert_eq!(EpiShiftConfig::shifts_for(-2.2, 1.4), vec![-2, -1, 0, 1]);
        assert_eq!(EpiShiftConfig::shifts_for(-40.1, 40.1).len(), 81);
        assert_eq!(EpiShiftConfig::shifts_for(0.6, 0.6), vec![1]);
    }
}

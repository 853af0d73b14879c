//! The plane-sweep photo-consistency cost (thesis §2.4.2) built with the EPI shift (chapter 4,
//! eq. 4.2 / 5.11): for a disparity hypothesis `d`, view `(u, v)` is sampled at
//! `(x - (u-uc)·d, y - (v-vc)·d)`, so a surface at disparity `d` lines up in every view and
//! the views agree in colour there. The cost is their colour variance, in two forms: the
//! classical baseline's volume over a set of views and the whole image ([`cost_volume`]), and
//! one stack's planes over a region, the network input with `net.input = "cost"`
//! ([`cost_stack`]).

use rayon::prelude::*;

use crate::bins::Bins;
use crate::lightfield::LightField;
use crate::stacks::{Direction, Region, shift_view};

/// The default variance floor before the logarithm of [`cost_stack`]: about the variance of
/// 8-bit quantisation noise summed over RGB, so that exact matches on flat colour do not
/// dominate the input's range.
pub const VARIANCE_FLOOR: f32 = 1e-5;

/// One cost slice per bin centre over every loaded view of `lf`, each `width × height`
/// row-major: `[k][y * width + x]`.
pub fn cost_volume(lf: &LightField, bins: &Bins) -> Vec<Vec<f32>> {
    bins.centres()
        .into_par_iter()
        .map(|d| cost_slice(lf, d as f32))
        .collect()
}

/// Mean over channels of the variance over the loaded views of the colour, after shifting
/// every view by disparity `d`. Samples outside a view are clamped to its border
/// (nearest-neighbour padding, as in the thesis' EPI shift).
pub fn cost_slice(lf: &LightField, d: f32) -> Vec<f32> {
    let positions: Vec<(usize, usize)> = lf.loaded().map(|(at, _)| at).collect();
    let plane = lf.width * lf.height;
    let (mut scratch, mut out) = (vec![0.0; 9 * plane], vec![0.0; plane]);
    variance(lf, &positions, Region::whole(lf), d, &mut scratch, &mut out);
    out.iter_mut().for_each(|v| *v = (*v / 3.0).max(0.0));
    out
}

/// The cost planes of stack `dir` over `region`, one per hypothesis (`hypotheses.len()`
/// planes of `region.width × region.height`), for the light field EPI-shifted by `shift`.
///
/// Each plane is `ln(var + floor)` of the views' colours at that hypothesis (RGB variances
/// summed; `floor` the cost of a perfect match, e.g. [`VARIANCE_FLOOR`]), centred per pixel
/// over the hypotheses: the logarithm makes a contrast change an offset, and the centring
/// removes it, so the network sees where along the hypotheses the views agree, not how
/// textured the pixel is in absolute terms.
pub fn cost_stack(
    lf: &LightField,
    dir: Direction,
    region: Region,
    shift: f32,
    hypotheses: &[f32],
    floor: f32,
) -> Vec<f32> {
    let plane = region.width * region.height;
    let positions = dir.positions(lf.nx);
    let mut scratch = vec![0.0; 9 * plane];
    let mut out = vec![0.0; hypotheses.len() * plane];
    for (&h, slice) in hypotheses.iter().zip(out.chunks_exact_mut(plane)) {
        variance(lf, &positions, region, shift + h, &mut scratch, slice);
        slice
            .iter_mut()
            .for_each(|v| *v = (v.max(0.0) + floor).ln());
    }
    centre_per_pixel(&mut out, plane);
    out
}

/// Per pixel of `region`, the colour variance over the views at `positions` of `lf`
/// EPI-shifted by `shift`, the RGB channels' population variances summed, into `out`.
/// `scratch` holds nine planes: one shifted view and the per-channel sums and sums of squares,
/// which take the views one after another (contiguous, so the loops vectorise), each pixel's
/// terms in view order.
fn variance(
    lf: &LightField,
    positions: &[(usize, usize)],
    region: Region,
    shift: f32,
    scratch: &mut [f32],
    out: &mut [f32],
) {
    let plane = out.len();
    let (view, sums) = scratch.split_at_mut(3 * plane);
    let (sum, sq) = sums.split_at_mut(3 * plane);
    sum.fill(0.0);
    sq.fill(0.0);
    for &at in positions {
        shift_view(lf, at, region, shift, view);
        for ((s, q), &x) in sum.iter_mut().zip(sq.iter_mut()).zip(view.iter()) {
            *s += x;
            *q += x * x;
        }
    }
    let n = positions.len() as f32;
    out.fill(0.0);
    for (s, q) in sum.chunks_exact(plane).zip(sq.chunks_exact(plane)) {
        for ((v, &s), &q) in out.iter_mut().zip(s).zip(q) {
            let mean = s / n;
            *v += q / n - mean * mean;
        }
    }
}

/// Subtracts from every pixel the mean of its values over the planes of `volume`, plane by
/// plane (contiguous reads; the loader runs this for every crop and direction).
fn centre_per_pixel(volume: &mut [f32], plane: usize) {
    let k = (volume.len() / plane) as f32;
    let mut mean = vec![0.0f32; plane];
    for slice in volume.chunks_exact(plane) {
        mean.iter_mut().zip(slice).for_each(|(m, v)| *m += v);
    }
    mean.iter_mut().for_each(|m| *m /= k);
    for slice in volume.chunks_exact_mut(plane) {
        slice.iter_mut().zip(&mean).for_each(|(v, m)| *v -= m);
    }
}

/// Mean over the `(2r+1)²` window around each pixel (the part inside the image), by
/// separable running sums so the cost does not grow with `r`.
pub fn box_filter(values: &[f32], width: usize, height: usize, r: usize) -> Vec<f32> {
    if r == 0 {
        return values.to_vec();
    }
    let rows: Vec<f32> = values
        .chunks_exact(width)
        .flat_map(|row| window_means(row.iter().copied(), width, r))
        .collect();
    let mut out = vec![0.0; values.len()];
    for x in 0..width {
        let column = (0..height).map(|y| rows[y * width + x]);
        for (y, m) in window_means(column, height, r).into_iter().enumerate() {
            out[y * width + x] = m;
        }
    }
    out
}

/// Means of `values` (length `len`) over windows `[i-r, i+r]` clipped to the sequence.
fn window_means(values: impl Iterator<Item = f32>, len: usize, r: usize) -> Vec<f32> {
    let mut prefix = Vec::with_capacity(len + 1);
    prefix.push(0.0f64);
    for v in values {
        prefix.push(prefix[prefix.len() - 1] + f64::from(v));
    }
    (0..len)
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(r), (i + r + 1).min(len));
            ((prefix[hi] - prefix[lo]) / (hi - lo) as f64) as f32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_is_zero_at_the_true_disparity_and_positive_elsewhere() {
        // Three views of a 1-D texture at d = 1 px per view step: a point at x in the
        // centre is at x - du in view du, so view du shows texture(x + du) (offset by 2).
        let texture = [0.0f32, 1.0, 0.0, 0.5, 1.0, 0.2, 0.9, 0.1, 0.4, 0.7];
        let width = 6;
        let views = [-1.0f32, 0.0, 1.0]
            .iter()
            .map(|&du| {
                let rgb = (0..width).flat_map(|x| [texture[(x as f32 + 2.0 + du) as usize]; 3]);
                Some(rgb.collect())
            })
            .collect();
        let lf = LightField {
            nx: 3,
            ny: 1,
            width,
            height: 1,
            views,
            disparity_range: None,
        };
        let at_truth = cost_slice(&lf, 1.0);
        // Pixels 1..=4 see no clamping: exact agreement.
        assert!(
            at_truth[1..5].iter().all(|&c| c.abs() < 1e-6),
            "{at_truth:?}"
        );
        let wrong = cost_slice(&lf, 0.0);
        assert!(wrong[1..5].iter().all(|&c| c > 1e-3), "{wrong:?}");
    }

    /// Two views of two pixels, hand-computed: pixel 0 has (0.2, 0.4, 0.6) and
    /// (0.4, 0.4, 0.2), variances 0.01 + 0 + 0.04; pixel 1 the same colour twice. The
    /// baseline's slice is their mean over channels.
    #[test]
    fn the_variance_sums_the_channels_population_variances() {
        let colours = [[[0.2, 0.4, 0.6], [0.5; 3]], [[0.4, 0.4, 0.2], [0.5; 3]]];
        let views: Vec<Option<Vec<f32>>> = colours.iter().map(|v| Some(v.concat())).collect();
        let lf = LightField {
            nx: 1,
            ny: 3,
            width: 2,
            height: 1,
            views: [vec![None], views].concat(),
            disparity_range: None,
        };
        let (mut scratch, mut out) = ([0.0; 18], [0.0; 2]);
        variance(
            &lf,
            &[(0, 1), (0, 2)],
            Region::whole(&lf),
            0.0,
            &mut scratch,
            &mut out,
        );
        assert!((out[0] - 0.05).abs() < 1e-6, "{out:?}");
        assert!(out[1].abs() < 1e-7, "{out:?}");
        let slice = cost_slice(&lf, 0.0);
        assert!((slice[0] - 0.05 / 3.0).abs() < 1e-6, "{slice:?}");
    }

    /// A 9×9 light field of a random texture at constant disparity `d`: view `(u, v)` at
    /// pixel `x` shows the texture at `x + (u - c) d` (the convention of [`extract`]).
    fn plane_at(d: f32, size: usize) -> LightField {
        let texture = |x: f32, y: f32| {
            let s = (x * 0.9).sin() * (y * 1.3).cos() + (x * 0.37 + y * 0.21).sin();
            [0.5 + 0.2 * s, 0.5 - 0.1 * s, 0.4 + 0.15 * (x * 0.5).cos()]
        };
        LightField::from_fn(9, size, size, |u, v, x, y| {
            let (du, dv) = (u as f32 - 4.0, v as f32 - 4.0);
            texture(x as f32 + du * d, y as f32 + dv * d)
        })
    }

    #[test]
    fn a_shift_moves_the_hypotheses_and_contrast_does_not_matter() {
        let lf = plane_at(-0.5, 40);
        let region = Region {
            x0: 12,
            y0: 12,
            width: 16,
            height: 16,
        };
        let dir = Direction::Diagonal45;
        let hyps = [-1.0, -0.5, 0.0, 0.5];
        let base = cost_stack(&lf, dir, region, 0.5, &hyps, VARIANCE_FLOOR);
        let moved: Vec<f32> = hyps.iter().map(|h| h + 0.5).collect();
        assert_eq!(
            cost_stack(&lf, dir, region, 0.0, &moved, VARIANCE_FLOOR),
            base
        );
        // Doubling the contrast about 0.5 quadruples every variance: after the logarithm
        // and the centring only the floor's share changes, which matters only where the
        // views agree to within the floor. The best hypothesis of every pixel stays.
        let mut contrast = lf.clone();
        for view in contrast.views.iter_mut().flatten() {
            view.iter_mut().for_each(|x| *x = 0.5 + 2.0 * (*x - 0.5));
        }
        let doubled = cost_stack(&contrast, dir, region, 0.5, &hyps, VARIANCE_FLOOR);
        let plane = 16 * 16;
        let best = |c: &[f32], i: usize| {
            (0..hyps.len())
                .min_by(|&a, &b| c[a * plane + i].total_cmp(&c[b * plane + i]))
                .unwrap()
        };
        assert!((0..plane).all(|i| best(&base, i) == best(&doubled, i)));
        let mean_gap = base
            .iter()
            .zip(&doubled)
            .map(|(a, b)| (a - b).abs())
            .sum::<f32>()
            / base.len() as f32;
        // Measured 0.066, against values that spread over ±2.5.
        assert!(mean_gap < 0.15, "{mean_gap}");
        let spread = base.iter().copied().fold(0.0, f32::max);
        assert!(spread > 1.0, "{spread}");
    }

    #[test]
    fn the_cost_is_lowest_at_the_true_disparity_in_every_direction() {
        let (size, d) = (48, 1.0);
        let lf = plane_at(d, size);
        let hyps: Vec<f32> = (-6..=6).map(|k| k as f32 * 0.5).collect();
        let region = Region {
            x0: 16,
            y0: 16,
            width: 16,
            height: 16,
        };
        for dir in Direction::ALL {
            let cost = cost_stack(&lf, dir, region, 0.0, &hyps, VARIANCE_FLOOR);
            let plane = 16 * 16;
            for i in [0, 37, 255] {
                let best = (0..hyps.len())
                    .min_by(|&a, &b| cost[a * plane + i].total_cmp(&cost[b * plane + i]))
                    .unwrap();
                assert_eq!(hyps[best], d, "{dir:?} pixel {i}");
                // Centred: the values of a pixel sum to zero over the hypotheses.
                let sum: f32 = (0..hyps.len()).map(|k| cost[k * plane + i]).sum();
                assert!(sum.abs() < 1e-3, "{sum}");
            }
            // At the true disparity the views agree to interpolation error only.
            let k = hyps.iter().position(|&h| h == d).unwrap();
            let raw = cost_stack(&lf, dir, region, 0.0, &[d], VARIANCE_FLOOR);
            assert_eq!(raw.iter().copied().fold(0.0, f32::max), 0.0);
            let _ = k;
        }
    }

    /// Sensor noise of σ = 2/255 lifts the cost of a perfect match from 8-bit quantisation to
    /// about `3σ²`: with the default floor the input's dips change by logs, with a floor at
    /// a camera's noise variance they hardly move, and the best hypothesis stays.
    #[test]
    fn a_floor_at_the_noise_variance_hides_the_noise() {
        let lf = plane_at(1.0, 40);
        let mut noisy = lf.clone();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let sigma = 2.0 / 255.0;
        for v in noisy
            .views
            .iter_mut()
            .flatten()
            .flat_map(|view| view.iter_mut())
        {
            // Uniform on ±σ√3 (variance σ²) from a xorshift stream.
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 11) as f32 / (1u64 << 53) as f32;
            *v += sigma * 3f32.sqrt() * (2.0 * u - 1.0);
        }
        let region = Region {
            x0: 12,
            y0: 12,
            width: 16,
            height: 16,
        };
        let hyps: Vec<f32> = (-4..=4).map(|k| k as f32 * 0.5).collect();
        let gap = |floor: f32| {
            let (dir, plane) = (Direction::Horizontal, 16 * 16);
            let clean = cost_stack(&lf, dir, region, 0.0, &hyps, floor);
            let rough = cost_stack(&noisy, dir, region, 0.0, &hyps, floor);
            let best = |c: &[f32], i: usize| {
                (0..hyps.len())
                    .min_by(|&a, &b| c[a * plane + i].total_cmp(&c[b * plane + i]))
                    .unwrap()
            };
            assert!((0..plane).all(|i| best(&clean, i) == best(&rough, i)));
            let sum: f32 = clean.iter().zip(&rough).map(|(a, b)| (a - b).abs()).sum();
            sum / clean.len() as f32
        };
        let (default, camera) = (gap(VARIANCE_FLOOR), gap(3.0 * (3.0f32 / 255.0).powi(2)));
        assert!(camera < default / 3.0, "{camera} vs {default}");
    }

    #[test]
    fn box_filter_averages_the_clipped_window() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let out = box_filter(&v, 3, 2, 1);
        // Every window covers both rows; columns clip at the sides.
        assert_eq!(out, vec![3.0, 3.5, 4.0, 3.0, 3.5, 4.0]);
        assert_eq!(box_filter(&v, 3, 2, 0), v.to_vec());
    }
}

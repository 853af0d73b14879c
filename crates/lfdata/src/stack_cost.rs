//! The plane-sweep cost volume of one stack, the network's input with `net.input = "cost"`
//! (`lftrain`'s `NetInput::Cost`): for each disparity hypothesis `h`, the stack's views
//! EPI-shifted by `h` line up wherever the scene has disparity `h`, and their colour variance
//! is small there (thesis §2.4.2; lfeval's baseline builds the same cost over the cross views
//! and picks its minimum, the network learns what to make of it).

use crate::lightfield::LightField;
use crate::stacks::{Direction, Region, extract_into};

/// Variance floor before the logarithm: about the variance of 8-bit quantisation noise
/// summed over RGB, so that exact matches on flat colour do not dominate the input's range.
const VARIANCE_FLOOR: f32 = 1e-5;

/// The cost planes of stack `dir` over `region`, one per hypothesis (`hypotheses.len()`
/// planes of `region.width × region.height`), for the light field EPI-shifted by `shift`.
///
/// Each plane is `ln(var + floor)` of the views' colours at that hypothesis (RGB variances
/// summed), centred per pixel over the hypotheses: the logarithm makes a contrast change an
/// offset, and the centring removes it, so the network sees where along the hypotheses the
/// views agree, not how textured the pixel is in absolute terms.
pub fn cost_stack(
    lf: &LightField,
    dir: Direction,
    region: Region,
    shift: f32,
    hypotheses: &[f32],
) -> Vec<f32> {
    let plane = region.width * region.height;
    let mut stack = vec![0.0; lf.n * 3 * plane];
    let mut sums = vec![0.0; 2 * plane];
    let mut out = vec![0.0; hypotheses.len() * plane];
    for (&h, slice) in hypotheses.iter().zip(out.chunks_exact_mut(plane)) {
        extract_into(lf, dir, region, shift + h, &mut stack);
        variance(&stack, lf.n, &mut sums, slice);
        slice
            .iter_mut()
            .for_each(|v| *v = (v.max(0.0) + VARIANCE_FLOOR).ln());
    }
    centre_per_pixel(&mut out, plane);
    out
}

/// Per pixel, the colour variance over the `n` views of `stack` (`n * 3` planes), RGB summed;
/// `sums` is scratch for two planes. The views are summed plane after plane (contiguous, so
/// the loops vectorise), each pixel's terms in view order.
fn variance(stack: &[f32], n: usize, sums: &mut [f32], out: &mut [f32]) {
    let plane = out.len();
    let (sum, sq) = sums.split_at_mut(plane);
    out.fill(0.0);
    for ch in 0..3 {
        sum.fill(0.0);
        sq.fill(0.0);
        for k in 0..n {
            let view = &stack[(k * 3 + ch) * plane..(k * 3 + ch + 1) * plane];
            for ((s, q), &x) in sum.iter_mut().zip(sq.iter_mut()).zip(view) {
                *s += x;
                *q += x * x;
            }
        }
        for ((v, &s), &q) in out.iter_mut().zip(sum.iter()).zip(sq.iter()) {
            let mean = s / n as f32;
            *v += q / n as f32 - mean * mean;
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

#[cfg(test)]
mod tests {
    use super::*;

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

    /// Two views of two pixels, hand-computed: pixel 0 has (0.2, 0.4, 0.6) and
    /// (0.4, 0.4, 0.2), variances 0.01 + 0 + 0.04; pixel 1 the same colour twice.
    #[test]
    fn the_variance_sums_the_channels_population_variances() {
        // Planes [view][R, G, B][pixel].
        let stack = [0.2, 0.5, 0.4, 0.5, 0.6, 0.5, 0.4, 0.5, 0.4, 0.5, 0.2, 0.5];
        let (mut sums, mut out) = ([0.0; 4], [0.0; 2]);
        variance(&stack, 2, &mut sums, &mut out);
        assert!((out[0] - 0.05).abs() < 1e-6, "{out:?}");
        assert!(out[1].abs() < 1e-7, "{out:?}");
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
        let base = cost_stack(&lf, dir, region, 0.5, &hyps);
        let moved: Vec<f32> = hyps.iter().map(|h| h + 0.5).collect();
        assert_eq!(cost_stack(&lf, dir, region, 0.0, &moved), base);
        // Doubling the contrast about 0.5 quadruples every variance: after the logarithm
        // and the centring only the floor's share changes, which matters only where the
        // views agree to within the floor. The best hypothesis of every pixel stays.
        let mut contrast = lf.clone();
        for view in contrast.views.iter_mut().flatten() {
            view.iter_mut().for_each(|x| *x = 0.5 + 2.0 * (*x - 0.5));
        }
        let doubled = cost_stack(&contrast, dir, region, 0.5, &hyps);
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
            let cost = cost_stack(&lf, dir, region, 0.0, &hyps);
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
            let raw = cost_stack(&lf, dir, region, 0.0, &[d]);
            assert_eq!(raw.iter().copied().fold(0.0, f32::max), 0.0);
            let _ = k;
        }
    }
}

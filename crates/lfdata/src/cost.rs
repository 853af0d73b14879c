//! The plane-sweep photo-consistency cost volume (thesis §2.4.2) built with the EPI shift
//! (chapter 4, eq. 4.2 / 5.11): for a disparity `d`, view `(u, v)` is sampled at
//! `(x - (u-uc)·d, y - (v-vc)·d)`, so a surface at disparity `d` lines up in every view and
//! the views agree in colour there. The cost is their colour variance.

use rayon::prelude::*;

use crate::bins::Bins;
use lfformat::views::LightField;

/// One cost slice per bin centre, each `width × height` row-major: `[k][y * width + x]`.
pub fn cost_volume(lf: &LightField, bins: &Bins) -> Vec<Vec<f32>> {
    bins.centres()
        .into_par_iter()
        .map(|d| cost_slice(lf, d as f32))
        .collect()
}

/// Mean over channels of the variance over views of the colour, after shifting every view
/// by disparity `d`. Samples outside a view are clamped to its border (nearest-neighbour
/// padding, as in the thesis' EPI shift).
pub fn cost_slice(lf: &LightField, d: f32) -> Vec<f32> {
    let n = lf.width * lf.height;
    let mut sum = vec![0.0f32; 3 * n];
    let mut sum_sq = vec![0.0f32; 3 * n];
    let mut shifted = vec![0.0f32; 3 * n];
    for view in &lf.views {
        shift(
            &view.rgb,
            lf.width,
            lf.height,
            -view.du * d,
            -view.dv * d,
            &mut shifted,
        );
        for ((s, q), &c) in sum.iter_mut().zip(&mut sum_sq).zip(&shifted) {
            *s += c;
            *q += c * c;
        }
    }
    let count = lf.views.len() as f32;
    sum.chunks_exact(3)
        .zip(sum_sq.chunks_exact(3))
        .map(|(s, q)| {
            let var: f32 = s
                .iter()
                .zip(q)
                .map(|(s, q)| q / count - (s / count).powi(2))
                .sum();
            (var / 3.0).max(0.0)
        })
        .collect()
}

/// `out(x, y) = rgb(x + ox, y + oy)`, bilinear, coordinates clamped to the image.
pub fn shift(rgb: &[f32], width: usize, height: usize, ox: f32, oy: f32, out: &mut [f32]) {
    let taps = |offset: f32, len: usize| -> Vec<(usize, usize, f32)> {
        let (whole, frac) = (offset.floor(), offset - offset.floor());
        let clamp = |i: isize| i.clamp(0, len as isize - 1) as usize;
        (0..len as isize)
            .map(|i| {
                let a = i + whole as isize;
                (clamp(a), clamp(a + 1), frac)
            })
            .collect()
    };
    let (xs, ys) = (taps(ox, width), taps(oy, height));
    for (y, &(y0, y1, fy)) in ys.iter().enumerate() {
        let (row0, row1) = (&rgb[y0 * width * 3..], &rgb[y1 * width * 3..]);
        for (x, &(x0, x1, fx)) in xs.iter().enumerate() {
            for c in 0..3 {
                let top = row0[x0 * 3 + c] * (1.0 - fx) + row0[x1 * 3 + c] * fx;
                let bottom = row1[x0 * 3 + c] * (1.0 - fx) + row1[x1 * 3 + c] * fx;
                out[(y * width + x) * 3 + c] = top * (1.0 - fy) + bottom * fy;
            }
        }
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
    use lfformat::views::View;

    #[test]
    fn shift_moves_by_whole_and_fractional_pixels_with_clamping() {
        // 4×1 grey ramp 0, 1, 2, 3 in all channels.
        let rgb: Vec<f32> = (0..4).flat_map(|v| [v as f32; 3]).collect();
        let mut out = vec![0.0; 12];
        shift(&rgb, 4, 1, 1.0, 0.0, &mut out);
        let red: Vec<f32> = out.chunks(3).map(|c| c[0]).collect();
        assert_eq!(red, vec![1.0, 2.0, 3.0, 3.0]);
        shift(&rgb, 4, 1, -0.25, 0.0, &mut out);
        let red: Vec<f32> = out.chunks(3).map(|c| c[0]).collect();
        assert_eq!(red, vec![0.0, 0.75, 1.75, 2.75]);
    }

    #[test]
    fn cost_is_zero_at_the_true_disparity_and_positive_elsewhere() {
        // Three views of a 1-D texture at d = 1 px per view step: a point at x in the
        // centre is at x - du in view du, so view du shows texture(x + du) (offset by 2).
        let texture = [0.0f32, 1.0, 0.0, 0.5, 1.0, 0.2, 0.9, 0.1, 0.4, 0.7];
        let width = 6;
        let views = [-1.0f32, 0.0, 1.0]
            .iter()
            .map(|&du| View {
                du,
                dv: 0.0,
                rgb: (0..width)
                    .flat_map(|x| [texture[(x as f32 + 2.0 + du) as usize]; 3])
                    .collect(),
            })
            .collect();
        let lf = LightField {
            width,
            height: 1,
            views,
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

    #[test]
    fn box_filter_averages_the_clipped_window() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let out = box_filter(&v, 3, 2, 1);
        // Every window covers both rows; columns clip at the sides.
        assert_eq!(out, vec![3.0, 3.5, 4.0, 3.0, 3.5, 4.0]);
        assert_eq!(box_filter(&v, 3, 2, 0), v.to_vec());
    }
}

//! Where the loss applies (thesis author's recipe, `mmlf`): not within the receptive radius of
//! the crop edge, where zero padding reaches into what the network sees, and not where the
//! centre view is flat, where no view holds a disparity cue.

/// Per pixel of a `width × height` RGB image (row-major, `[0, 1]`): 1 where the mean over the
/// `window × window` neighbourhood (clipped to the image) of |neighbour − centre|, averaged over
/// R, G and B, is at least `threshold`; 0 where the image is flat. `threshold = 0` keeps every
/// pixel.
///
/// Computed once per scene (`O(pixels · window²)`): no crate offers this statistic, and it is
/// not separable, so it is a direct loop.
pub fn texture_mask(
    rgb: &[f32],
    width: usize,
    height: usize,
    window: usize,
    threshold: f32,
) -> Vec<f32> {
    assert_eq!(rgb.len(), width * height * 3, "texture_mask: RGB size");
    if threshold <= 0.0 {
        return vec![1.0; width * height];
    }
    let r = window / 2;
    let mut mask = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let c = &rgb[(y * width + x) * 3..][..3];
            let (mut sum, mut n) = (0.0f32, 0usize);
            for qy in y.saturating_sub(r)..(y + r + 1).min(height) {
                for qx in x.saturating_sub(r)..(x + r + 1).min(width) {
                    let q = &rgb[(qy * width + qx) * 3..][..3];
                    sum += (q[0] - c[0]).abs() + (q[1] - c[1]).abs() + (q[2] - c[2]).abs();
                    n += 1;
                }
            }
            mask.push(if sum / (3 * n) as f32 >= threshold {
                1.0
            } else {
                0.0
            });
        }
    }
    mask
}

/// Whether pixel `(x, y)` of a `patch²` crop is at least `border` pixels from every edge.
#[inline]
pub fn inside_border(x: usize, y: usize, patch: usize, border: usize) -> bool {
    x >= border && y >= border && x + border < patch && y + border < patch
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Grey image from a function of the pixel.
    fn grey(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> Vec<f32> {
        (0..w * h).flat_map(|i| [f(i % w, i / w); 3]).collect()
    }

    #[test]
    fn a_single_step_edge_by_hand() {
        // Columns 0–2 black, 3–5 white; window 3. At (2, 1), interior row: the 3×3 window holds
        // columns 1–3, one of three columns differs by 1: mean 3/9. At (0, 1): columns 0–1,
        // all black: 0. At (2, 0), top row: 2 rows × 3 columns, one column white: 2/6.
        let img = grey(6, 3, |x, _| if x >= 3 { 1.0 } else { 0.0 });
        let m = texture_mask(&img, 6, 3, 3, 0.3);
        assert_eq!(m[6 + 2], 1.0); // 0.333 ≥ 0.3
        assert_eq!(m[6], 0.0);
        assert_eq!(m[2], 1.0); // 0.333
        let strict = texture_mask(&img, 6, 3, 3, 0.34);
        assert_eq!(strict[6 + 2], 0.0);
        // A flat image is masked everywhere; threshold 0 keeps everything.
        let flat = grey(5, 4, |_, _| 0.4);
        assert!(
            texture_mask(&flat, 5, 4, 23, 0.02)
                .iter()
                .all(|&v| v == 0.0)
        );
        assert!(texture_mask(&flat, 5, 4, 23, 0.0).iter().all(|&v| v == 1.0));
    }

    #[test]
    fn colour_differences_are_the_rgb_mean() {
        // A red pixel among black ones: its own window (3×3 inside the image) sees 8 pixels
        // differing by (1, 0, 0): mean over 9 pixels and 3 channels = 8 / 27.
        let mut img = vec![0.0; 3 * 3 * 3];
        img[(3 + 1) * 3] = 1.0;
        let m = texture_mask(&img, 3, 3, 3, 8.0 / 27.0 - 1e-6);
        assert_eq!(m[4], 1.0);
        let m = texture_mask(&img, 3, 3, 3, 8.0 / 27.0 + 1e-6);
        assert_eq!(m[4], 0.0);
    }

    #[test]
    fn the_border_leaves_the_inner_square() {
        let inner: Vec<(usize, usize)> = (0..8)
            .flat_map(|y| (0..8).map(move |x| (x, y)))
            .filter(|&(x, y)| inside_border(x, y, 8, 3))
            .collect();
        assert_eq!(inner, vec![(3, 3), (4, 3), (3, 4), (4, 4)]);
        assert!((0..8).all(|x| inside_border(x, 5, 8, 0)));
    }
}

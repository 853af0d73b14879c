//! Test-time denoising of a light field through its own redundancy.
//!
//! Sensor noise differs from view to view; the scene does not. Given a disparity map (a first
//! prediction), each pixel of a view is averaged with what its angular neighbours see of the
//! same surface point, each neighbour weighted by how far its colour is from the pixel's in
//! units of the noise (a cross-view bilateral filter). Agreement within the noise is averaged
//! away; disagreement (an occlusion, a wrong disparity, a specular highlight) keeps the pixel
//! its own colour. The filter's width follows the noise measured in the views themselves, so
//! views without noise between them pass through unchanged.
//!
//! Why not a spatial filter: a blur removes the texture that depth comes from along with the
//! noise; averaging across views at the right disparity removes only the noise.

use rayon::prelude::*;

use lfformat::views::ViewSet;

use crate::lightfield::LightField;

/// Angular radius of the neighbourhood: the 3 × 3 views around each view. The disparity of a
/// neighbour's pixel is read at the same pixel of the centre view's map, an approximation
/// that grows with the distance between views (a 5 × 5 neighbourhood measured worse).
const RADIUS: isize = 1;

/// Per-channel standard deviation of the noise that differs between the views of `lf`: the
/// robust spread (median absolute value / 0.6745) of the difference between each view of the
/// centre row and its right neighbour warped onto it by `disparity` (the centre view's map,
/// `width × height`), over the image less a border of an eighth of its side (where the warp
/// clamps), divided by √2 for the two views' noises in each difference. Zero for views that
/// agree exactly.
pub fn view_noise(lf: &LightField, disparity: &[f32]) -> f32 {
    let (w, h) = (lf.width, lf.height);
    let (bx, by) = (w / 8, h / 8);
    let cv = lf.centre().1;
    let mut diffs = Vec::new();
    for u in 0..lf.nx.saturating_sub(1) {
        let (Some(a), Some(b)) = (view_at(lf, u, cv), view_at(lf, u + 1, cv)) else {
            continue;
        };
        for y in by..h - by {
            for x in bx..w - bx {
                let d = disparity[y * w + x];
                if !d.is_finite() {
                    continue;
                }
                let s = bilinear(b, w, h, x as f32 - d, y as f32);
                let own = &a[3 * (y * w + x)..][..3];
                diffs.extend((0..3).map(|c| (own[c] - s[c]).abs()));
            }
        }
    }
    if diffs.is_empty() {
        return 0.0;
    }
    let mid = diffs.len() / 2;
    let median = *diffs.select_nth_unstable_by(mid, f32::total_cmp).1;
    median / 0.6745 / std::f32::consts::SQRT_2
}

/// The views of `set` that `lf` holds, each replaced by its cross-view bilateral mean over the
/// loaded views within [`RADIUS`] (see the module documentation); the other views are left
/// out, so a predictor that reads the star holds 33 views of 9 × 9, not 81, twice. `disparity`
/// is the centre view's map (`width × height`); a neighbour's colour weighs `exp(−|Δ|² / 2h²)`
/// against the pixel's own weight of 1, `|Δ|²` summed over RGB and
/// `h = strength × view_noise`. A `strength` of 0, or views without measurable noise, keep
/// the views as they are.
pub fn denoise(lf: &LightField, disparity: &[f32], strength: f32, set: ViewSet) -> LightField {
    let h = strength * view_noise(lf, disparity);
    let inv_two_h2 = 1.0 / (2.0 * h * h);
    let mut views = vec![None; lf.views.len()];
    let wanted: Vec<(usize, usize)> = (set.positions(lf.nx, lf.ny).into_iter())
        .filter(|&(u, v)| view_at(lf, u, v).is_some())
        .collect();
    let filtered: Vec<Vec<f32>> = (wanted.par_iter())
        .map(|&at| match h > 0.0 {
            true => filter_view(lf, at, disparity, inv_two_h2),
            false => lf.view(at.0, at.1).to_vec(),
        })
        .collect();
    for ((u, v), view) in wanted.into_iter().zip(filtered) {
        views[v * lf.nx + u] = Some(view);
    }
    LightField {
        views,
        disparity_range: lf.disparity_range,
        ..*lf
    }
}

/// View `(u, v)` of `lf` filtered over its loaded neighbours (see [`denoise`]).
fn filter_view(
    lf: &LightField,
    (u, v): (usize, usize),
    disparity: &[f32],
    inv_two_h2: f32,
) -> Vec<f32> {
    let (w, h) = (lf.width, lf.height);
    let own = lf.view(u, v);
    let neighbours: Vec<(f32, f32, &[f32])> = (-RADIUS..=RADIUS)
        .flat_map(|dv| (-RADIUS..=RADIUS).map(move |du| (du, dv)))
        .filter(|&d| d != (0, 0))
        .filter_map(|(du, dv)| {
            let at = (u.checked_add_signed(du)?, v.checked_add_signed(dv)?);
            Some((du as f32, dv as f32, view_at(lf, at.0, at.1)?))
        })
        .collect();
    let mut out = Vec::with_capacity(own.len());
    for y in 0..h {
        for x in 0..w {
            let d = disparity[y * w + x];
            let centre = &own[3 * (y * w + x)..][..3];
            if !d.is_finite() {
                // No estimate to align the neighbours by: the pixel keeps its colour.
                out.extend_from_slice(centre);
                continue;
            }
            let (mut sum, mut weight) = ([centre[0], centre[1], centre[2]], 1.0);
            for &(du, dv, view) in &neighbours {
                let s = bilinear(view, w, h, x as f32 - du * d, y as f32 - dv * d);
                let dist2: f32 = (0..3).map(|c| (s[c] - centre[c]).powi(2)).sum();
                let wt = (-dist2 * inv_two_h2).exp();
                (0..3).for_each(|c| sum[c] += wt * s[c]);
                weight += wt;
            }
            out.extend(sum.map(|s| s / weight));
        }
    }
    out
}

/// View `(u, v)` if it lies on the grid and was loaded.
fn view_at(lf: &LightField, u: usize, v: usize) -> Option<&[f32]> {
    (u < lf.nx && v < lf.ny)
        .then(|| lf.views[v * lf.nx + u].as_deref())
        .flatten()
}

/// The RGB image `rgb` (`w × h`) at `(x, y)`, bilinear, clamped to the image.
fn bilinear(rgb: &[f32], w: usize, h: usize, x: f32, y: f32) -> [f32; 3] {
    let x = x.clamp(0.0, (w - 1) as f32);
    let y = y.clamp(0.0, (h - 1) as f32);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (ax, ay) = (x - x0 as f32, y - y0 as f32);
    let px = |xx: usize, yy: usize, c: usize| rgb[3 * (yy * w + xx) + c];
    std::array::from_fn(|c| {
        let top = px(x0, y0, c) * (1.0 - ax) + px(x1, y0, c) * ax;
        let bottom = px(x0, y1, c) * (1.0 - ax) + px(x1, y1, c) * ax;
        top * (1.0 - ay) + bottom * ay
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    const N: usize = 5;
    const SIDE: usize = 48;

    /// A textured fronto-parallel plane at integer disparity `d` seen by an `N × N` grid, every
    /// view loaded, with Gaussian noise of standard deviation `sigma` added per view and
    /// channel; returns the noisy light field and the noise-free one.
    fn plane(d: f32, sigma: f32) -> (LightField, LightField) {
        let texture = |x: f32, y: f32, c: usize| {
            let k = c as f32 + 1.0;
            0.5 + 0.2 * (0.7 * k * x).sin() * (0.45 * y + k).cos()
                + 0.1 * (0.23 * (x + 2.0 * y)).sin()
        };
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut clean = Vec::new();
        let mut noisy = Vec::new();
        let c = (N / 2) as f32;
        for v in 0..N {
            for u in 0..N {
                let view: Vec<f32> = (0..SIDE * SIDE * 3)
                    .map(|i| {
                        let (x, y) = ((i / 3 % SIDE) as f32, (i / 3 / SIDE) as f32);
                        texture(x + (u as f32 - c) * d, y + (v as f32 - c) * d, i % 3)
                    })
                    .collect();
                let mut z = || {
                    let n: f32 = StandardNormal.sample(&mut rng);
                    sigma * n
                };
                noisy.push(Some(view.iter().map(|&p| p + z()).collect()));
                clean.push(Some(view));
            }
        }
        let field = |views| LightField {
            nx: N,
            ny: N,
            width: SIDE,
            height: SIDE,
            views,
            disparity_range: None,
        };
        (field(noisy), field(clean))
    }

    /// The test light field follows the library's EPI-shift convention (the one the cost
    /// volume, checked against rendered scenes, uses): its views agree at disparity 1, all but
    /// the columns and rows the shift clamps at the image's border.
    #[test]
    fn the_test_plane_lines_up_at_its_disparity() {
        let (_, clean) = plane(1.0, 0.0);
        let mean = |d| {
            let cost = crate::cost::cost_slice(&clean, d);
            cost.iter().sum::<f32>() / cost.len() as f32
        };
        assert!(
            mean(1.0) < 0.05 * mean(-1.0),
            "{} vs {}",
            mean(1.0),
            mean(-1.0)
        );
    }

    fn rms_error(a: &[f32], b: &[f32]) -> f32 {
        let sum: f32 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
        (sum / a.len() as f32).sqrt()
    }

    /// The estimate recovers the noise added to the views, not the texture (which the warp
    /// aligns), and is zero on views that agree exactly.
    #[test]
    fn the_noise_estimate_is_the_noise_between_views() {
        let truth = vec![1.0; SIDE * SIDE];
        for sigma in [0.005, 0.02] {
            let est = view_noise(&plane(1.0, sigma).0, &truth);
            assert!(
                (est / sigma - 1.0).abs() < 0.1,
                "σ {sigma}: estimated {est}"
            );
        }
        assert_eq!(view_noise(&plane(1.0, 0.0).0, &truth), 0.0);
    }

    /// At the true disparity the filter takes most of the noise out of every view with all
    /// eight neighbours (nine views at most divide it by 3), the star's views alone come out
    /// the same when asked for; without noise it changes nothing.
    #[test]
    fn the_true_disparity_takes_the_noise_out() {
        let truth = vec![1.0; SIDE * SIDE];
        let (noisy, clean) = plane(1.0, 0.02);
        let out = denoise(&noisy, &truth, 2.0, ViewSet::Full);
        for (at, view) in clean.loaded() {
            let inner = (1..N - 1).contains(&at.0) && (1..N - 1).contains(&at.1);
            let before = rms_error(noisy.view(at.0, at.1), view);
            let after = rms_error(out.view(at.0, at.1), view);
            let bound = if inner { 0.55 } else { 0.8 };
            assert!(after < bound * before, "view {at:?}: {before} → {after}");
        }
        let star = denoise(&noisy, &truth, 2.0, ViewSet::Star);
        for (i, view) in star.views.iter().enumerate() {
            let on_star = ViewSet::Star.positions(N, N).contains(&(i % N, i / N));
            assert_eq!(view.is_some(), on_star, "view {i}");
            assert!(view.is_none() || view == &out.views[i], "view {i}");
        }
        let (still, _) = plane(1.0, 0.0);
        assert_eq!(denoise(&still, &truth, 2.0, ViewSet::Full), still);
        assert_eq!(denoise(&noisy, &truth, 0.0, ViewSet::Full), noisy);
    }

    /// A pixel without a first estimate (NaN) keeps its colour, and the estimate of the noise
    /// ignores it.
    #[test]
    fn pixels_without_an_estimate_keep_their_colour() {
        let (noisy, _) = plane(1.0, 0.02);
        let mut map = vec![1.0; SIDE * SIDE];
        map[20 * SIDE + 21] = f32::NAN;
        let out = denoise(&noisy, &map, 2.0, ViewSet::Full);
        let c = N / 2;
        let pixel = |lf: &LightField| lf.view(c, c)[3 * (20 * SIDE + 21)..][..3].to_vec();
        assert_eq!(pixel(&out), pixel(&noisy));
        assert!(out.loaded().all(|(_, v)| v.iter().all(|p| p.is_finite())));
        let with = view_noise(&noisy, &map);
        let without = view_noise(&noisy, &[1.0; SIDE * SIDE]);
        assert!(
            with.is_finite() && (with / without - 1.0).abs() < 0.01,
            "{with} {without}"
        );
    }

    /// Where the disparity is wrong (a patch of the map) the neighbours disagree with the pixel
    /// by more than the noise, and the pixel keeps its own colour: far less change than a plain
    /// mean of the misaligned neighbours makes.
    #[test]
    fn a_wrong_disparity_leaves_the_texture_alone() {
        let (noisy, clean) = plane(1.0, 0.005);
        let patch = |i: usize| (16..32).contains(&(i % SIDE)) && (16..32).contains(&(i / SIDE));
        let map: Vec<f32> = (0..SIDE * SIDE)
            .map(|i| if patch(i) { -1.0 } else { 1.0 })
            .collect();
        let in_patch = |view: &[f32]| -> Vec<f32> {
            (view.chunks_exact(3).enumerate())
                .filter(|(i, _)| patch(*i))
                .flat_map(|(_, p)| p.to_vec())
                .collect()
        };
        let c = N / 2;
        let error =
            |lf: &LightField| rms_error(&in_patch(lf.view(c, c)), &in_patch(clean.view(c, c)));
        let before = error(&noisy);
        let after = error(&denoise(&noisy, &map, 2.0, ViewSet::Full));
        let plain = error(&denoise(&noisy, &map, 1e6, ViewSet::Full));
        assert!(after < 2.0 * before, "{before} → {after}");
        assert!(after < 0.3 * plain, "bilateral {after}, plain mean {plain}");
    }
}

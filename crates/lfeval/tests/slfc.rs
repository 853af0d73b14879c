//! SLFC against analytic light fields whose disparities are known exactly: one textured plane,
//! and a semi-transparent textured layer over a textured wall.

use indicatif::ProgressBar;
use lfdata::lightfield::LightField;
use lfdata::posterior::PosteriorForm;
use lfeval::slfc::{SlfcConfig, estimate};

/// A broadband grey-ish texture (several incommensurate waves, so no single frequency makes
/// the disparity ambiguous), `layer` picking one of two unrelated patterns.
fn texture(a: f32, b: f32, layer: usize) -> [f32; 3] {
    let o = layer as f32 * 2.3;
    let v = 0.5
        + 0.1 * (0.9 * a + 0.3 * b + o).sin()
        + 0.1 * (1.7 * a - 0.8 * b + 1.0 + o).sin()
        + 0.1 * (0.45 * a + 1.3 * b + 2.0 - o).sin()
        + 0.1 * (2.3 * a + 0.5 * b + 0.4 + 2.0 * o).sin();
    [v, 0.9 * v, 1.1 * v - 0.05]
}

/// The star views of an `n × n` grid of a `size²` scene where the view at grid offset
/// `(du, dv)` sees, at pixel `(x, y)`, the layer of disparity `d` at `(x + du·d, y + dv·d)`.
/// Layers are `(disparity, opacity)` front to back, composited over each other.
fn layered(n: usize, size: usize, layers: &[(f32, f32)]) -> LightField {
    let c = (n / 2) as f32;
    LightField::from_fn(n, size, size, |u, v, x, y| {
        let (du, dv) = (u as f32 - c, v as f32 - c);
        let mut colour = [0.0f32; 3];
        let mut left = 1.0;
        for (l, &(d, alpha)) in layers.iter().enumerate() {
            let t = texture(x as f32 + du * d, y as f32 + dv * d, l);
            for (c, t) in colour.iter_mut().zip(t) {
                *c += left * alpha * t;
            }
            left *= 1.0 - alpha;
        }
        colour
    })
}

/// The posterior's probabilities, pixel after pixel.
fn probabilities(lf: &LightField, cfg: &SlfcConfig) -> (Vec<f32>, usize) {
    let out = estimate(lf, cfg, &ProgressBar::hidden()).expect("estimate");
    assert_eq!(out.unconverged, 0);
    let posterior = out.prediction.posterior.expect("a posterior");
    let PosteriorForm::Discrete { probs, bins } = posterior.form else {
        panic!("SLFC writes a discrete posterior");
    };
    assert_eq!(bins, cfg.bins);
    (probs, posterior.width * posterior.height)
}

/// The bin indices of the local maxima of `p`, largest first.
fn peaks(p: &[f32]) -> Vec<usize> {
    let mut found: Vec<usize> = (0..p.len())
        .filter(|&k| {
            let left = k == 0 || p[k - 1] < p[k];
            let right = k + 1 == p.len() || p[k + 1] <= p[k];
            left && right && p[k] > 0.0
        })
        .collect();
    found.sort_by(|&a, &b| p[b].total_cmp(&p[a]));
    found
}

/// The posterior averaged over the pixels.
fn mean(probs: &[f32], bins: usize) -> Vec<f32> {
    let pixels = (probs.len() / bins) as f32;
    let mut mean = vec![0.0f32; bins];
    for pixel in probs.chunks_exact(bins) {
        for (m, p) in mean.iter_mut().zip(pixel) {
            *m += p / pixels;
        }
    }
    mean
}

/// 8×8 pixels in the middle of a 32² image: every EPI window lies inside the views.
fn config() -> SlfcConfig {
    SlfcConfig {
        crop: 0.25,
        ..SlfcConfig::default()
    }
}

/// The largest bin of `p`.
fn strongest(p: &[f32]) -> usize {
    (0..p.len())
        .max_by(|&a, &b| p[a].total_cmp(&p[b]))
        .expect("bins")
}

/// On a textured plane, every pixel's strongest bin (SLFC's point estimate) and the mean
/// posterior's are the plane's, ±1 of 108 over [-3.5, 3.5], at disparities from −3.1 to 3.1.
#[test]
fn strongest_disparity_of_a_textured_plane_is_its_disparity() {
    let cfg = config();
    let bins = cfg.bins;
    for k in [5, 20, 40, 61, 80, 95, 102] {
        let d = bins.centre(k) as f32;
        let (probs, pixels) = probabilities(&layered(9, 32, &[(d, 1.0)]), &cfg);
        assert_eq!(pixels, 64);
        let best = strongest(&mean(&probs, bins.count));
        assert!(
            best.abs_diff(k) <= 1,
            "d = {d}: strongest bin {best}, truth {k}"
        );
        for pixel in probs.chunks_exact(bins.count) {
            let best = strongest(pixel);
            assert!(
                best.abs_diff(k) <= 1,
                "d = {d}: a pixel's strongest bin {best}, truth {k}"
            );
        }
    }
}

/// A half-transparent layer over a wall: the mean posterior's two largest peaks are at the
/// two disparities (±1 bin).
#[test]
fn a_transparent_layer_over_a_wall_gives_two_peaks_at_their_disparities() {
    let cfg = config();
    let bins = cfg.bins;
    let (front, back) = (80, 30);
    let layers = [
        (bins.centre(front) as f32, 0.5),
        (bins.centre(back) as f32, 1.0),
    ];
    let (probs, _) = probabilities(&layered(9, 32, &layers), &cfg);
    let mut top: Vec<usize> = peaks(&mean(&probs, bins.count))
        .into_iter()
        .take(2)
        .collect();
    top.sort();
    assert!(
        top.len() == 2 && top[0].abs_diff(back) <= 1 && top[1].abs_diff(front) <= 1,
        "peaks at {top:?}"
    );
}

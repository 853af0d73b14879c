//! The HCI benchmark's region metrics (Honauer et al., ACCV 2016), computed as its evaluation
//! toolkit computes them, so a score compares with a published one.
//!
//! Each metric is evaluated on one of the scene's region masks, intersected with the
//! [`Frame`] (15 px at the low resolution, `15 · scale` px at the high one):
//! - Discontinuities: BadPix(0.07) on `mask_discontinuities`.
//! - Bumpiness Planes / Contin. Surfaces: `100 ·` the mean over `mask_planes` /
//!   `mask_smooth_surfaces` of `min(‖H(pred − gt)‖_F, 0.05)`, the Frobenius norm of the
//!   Hessian of the error by two passes of the Scharr filter (weights `[3, 10, 3] / 16`).
//! - MAE Planes / Contin. Surfaces: the median angle, in degrees, between the normals of the
//!   predicted and the true depth, both from [`depth_normals`].
//! - Fine Fattening: % of `mask_fine_surrounding` with `gt − pred < −0.15`; Fine Thinning:
//!   % of `mask_fine` with `gt − pred > 0.15`.
//!
//! The toolkit scores Discontinuities, Fattening and Thinning on the high-resolution ground
//! truth and masks, against the prediction enlarged by [`zoom_nearest`]; the others at the
//! low resolution. Comparisons and the disparity-to-depth step run in float32 as numpy runs
//! them on the float32 PFM data, the filters and angles in float64.
//!
//! Two of the toolkit's border conventions are not reproduced because the frame hides them:
//! scikit-image 0.11 zeroes the outer pixel of each Scharr pass and the normals wrap around the
//! image; both reach at most 2 px inside, far outside any evaluated pixel.

use std::borrow::Cow;

use serde::Serialize;

use super::Frame;
use super::hci::is_bad;

/// BadPix threshold of the Discontinuities score, pixels.
pub const DISCONTINUITY_THRESHOLD: f64 = 0.07;
/// `gt − pred` below this is fattening, pixels.
pub const FATTENING_THRESHOLD: f32 = -0.15;
/// `gt − pred` above this is thinning, pixels.
pub const THINNING_THRESHOLD: f32 = 0.15;
/// Upper clip of the per-pixel bumpiness.
pub const BUMPINESS_CLIP: f64 = 0.05;
/// Factor of the bumpiness score.
pub const BUMPINESS_FACTOR: f64 = 100.0;

/// The camera numbers of `parameters.cfg` that turn disparity into depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthCamera {
    /// `focal_length_mm`.
    pub focal_length_mm: f64,
    /// `sensor_size_mm`.
    pub sensor_size_mm: f64,
    /// `baseline_mm`.
    pub baseline_mm: f64,
    /// `focus_distance_m`.
    pub focus_distance_m: f64,
    /// `max(image_resolution_x_px, image_resolution_y_px)` of the low-resolution views.
    pub max_side_px: usize,
}

impl DepthCamera {
    /// Depth in metres of disparity `d`, in float32 exactly as the toolkit's
    /// `1 / ((1000 · sensor) · d / q + 1 / focus)` with `q = baseline · focal · max_side`.
    pub fn depth(&self, d: f32) -> f32 {
        let q = self.baseline_mm * self.focal_length_mm * self.max_side_px as f64;
        let scale = (1000.0 * self.sensor_size_mm) as f32;
        1.0 / (scale * d / q as f32 + (1.0 / self.focus_distance_m) as f32)
    }
}

/// One image's region masks (row-major, `true` = in the region); `None` where the scene has
/// no such mask file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RegionMasks {
    /// `mask_discontinuities`.
    pub discontinuities: Option<Vec<bool>>,
    /// `mask_planes`.
    pub planes: Option<Vec<bool>>,
    /// `mask_smooth_surfaces`.
    pub smooth_surfaces: Option<Vec<bool>>,
    /// `mask_fine`.
    pub fine: Option<Vec<bool>>,
    /// `mask_fine_surrounding`.
    pub fine_surrounding: Option<Vec<bool>>,
}

impl RegionMasks {
    /// Whether no mask is present.
    pub fn is_empty(&self) -> bool {
        [
            &self.discontinuities,
            &self.planes,
            &self.smooth_surfaces,
            &self.fine,
            &self.fine_surrounding,
        ]
        .iter()
        .all(|m| m.is_none())
    }
}

/// The toolkit scores its high-resolution metrics at this factor over the low resolution
/// (`set_high_gt_scale`), whatever the scale of the scene's high-resolution files.
pub const HIGHRES_EVAL_SCALE: usize = 10;

/// The high-resolution ground truth as stored: disparity and masks at `width × height`.
#[derive(Clone, Debug, PartialEq)]
pub struct HighRes {
    /// Columns of the stored maps.
    pub width: usize,
    /// Rows of the stored maps.
    pub height: usize,
    /// `gt_disp_highres.pfm`, row-major.
    pub gt: Vec<f32>,
    /// The `*_highres.png` masks.
    pub masks: RegionMasks,
}

/// Everything about a scene the region metrics need besides the prediction.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionTruth {
    /// Camera numbers for the normals.
    pub camera: DepthCamera,
    /// The `*_lowres.png` masks.
    pub masks: RegionMasks,
    /// High-resolution ground truth, when the scene has it.
    pub high: Option<HighRes>,
}

/// Resolution a group of region scores was computed at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Resolution {
    /// The views' resolution.
    Low,
    /// The high-resolution ground truth's.
    High,
}

/// The seven region scores; `None` where the scene lacks the mask or the mask holds no
/// evaluated pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RegionScores {
    /// BadPix(0.07) % on `mask_discontinuities`.
    pub discontinuities: Option<f64>,
    /// Bumpiness × 100 on `mask_planes`.
    pub bumpiness_planes: Option<f64>,
    /// Bumpiness × 100 on `mask_smooth_surfaces`.
    pub bumpiness_surfaces: Option<f64>,
    /// Median normal angle (degrees) on `mask_planes`.
    pub mae_planes: Option<f64>,
    /// Median normal angle (degrees) on `mask_smooth_surfaces`.
    pub mae_surfaces: Option<f64>,
    /// % of `mask_fine_surrounding` with `gt − pred < −0.15`.
    pub fine_fattening: Option<f64>,
    /// % of `mask_fine` with `gt − pred > 0.15`.
    pub fine_thinning: Option<f64>,
    /// Resolution of Discontinuities, Fattening and Thinning: high where the scene has the
    /// high-resolution ground truth and masks (as the toolkit requires), else low.
    pub fine_resolution: Option<Resolution>,
}

/// Column titles of [`RegionScores::to_array`].
pub const REGION_SCORE_NAMES: [&str; 7] = [
    "Discont. %",
    "Bump. Planes",
    "Bump. Surf.",
    "MAE Planes °",
    "MAE Surf. °",
    "Fine Fat. %",
    "Fine Thin. %",
];

impl RegionScores {
    /// Every region score of `pred` (row-major, `frame.width × frame.height`) against `gt`.
    pub fn compute(pred: &[f32], gt: &[f32], frame: &Frame, truth: &RegionTruth) -> Self {
        let (w, h) = (frame.width, frame.height);
        let m = &truth.masks;
        let smooth_regions = m.planes.is_some() || m.smooth_surfaces.is_some();
        let bump = smooth_regions.then(|| bumpiness(pred, gt, w, h));
        let angles = smooth_regions.then(|| angular_error(pred, gt, w, h, &truth.camera));
        let bump_on = |mask: &Option<Vec<bool>>| {
            let (mask, bump) = mask.as_deref().zip(bump.as_deref())?;
            bumpiness_score(bump, mask, frame)
        };
        let mae_on = |mask: &Option<Vec<bool>>| {
            let (mask, angles) = mask.as_deref().zip(angles.as_deref())?;
            mae_score(angles, pred, mask, frame)
        };
        let fine = FineInputs::new(pred, gt, frame, truth);
        let percent = |mask: &Option<Vec<bool>>, bad: fn(f32, f32) -> bool| {
            let mask = mask.as_deref()?;
            masked_percent(&fine.pred, &fine.gt, mask, &fine.frame, bad)
        };
        let discontinuities = percent(&fine.masks.discontinuities, |p, g| {
            is_bad(p, g, DISCONTINUITY_THRESHOLD)
        });
        let fine_fattening = percent(&fine.masks.fine_surrounding, |p, g| {
            g - p < FATTENING_THRESHOLD
        });
        let fine_thinning = percent(&fine.masks.fine, |p, g| g - p > THINNING_THRESHOLD);
        let any_fine = [discontinuities, fine_fattening, fine_thinning]
            .iter()
            .any(Option::is_some);
        Self {
            discontinuities,
            bumpiness_planes: bump_on(&m.planes),
            bumpiness_surfaces: bump_on(&m.smooth_surfaces),
            mae_planes: mae_on(&m.planes),
            mae_surfaces: mae_on(&m.smooth_surfaces),
            fine_fattening,
            fine_thinning,
            fine_resolution: any_fine.then_some(fine.resolution),
        }
    }

    /// Score-wise mean over `scenes`, each score over the scenes that have it; the
    /// resolution is kept where every scene with fine scores used the same one.
    pub fn mean(scenes: &[RegionScores]) -> Self {
        let arrays: Vec<_> = scenes.iter().map(|s| s.to_array()).collect();
        let [a, b, c, d, e, f, g] =
            std::array::from_fn(|k| super::mean(arrays.iter().map(|v| v[k])));
        let mut resolutions = scenes.iter().filter_map(|s| s.fine_resolution);
        let first = resolutions.next();
        Self {
            discontinuities: a,
            bumpiness_planes: b,
            bumpiness_surfaces: c,
            mae_planes: d,
            mae_surfaces: e,
            fine_fattening: f,
            fine_thinning: g,
            fine_resolution: first.filter(|r| resolutions.all(|o| o == *r)),
        }
    }

    /// The scores in [`REGION_SCORE_NAMES`] order.
    pub fn to_array(self) -> [Option<f64>; 7] {
        [
            self.discontinuities,
            self.bumpiness_planes,
            self.bumpiness_surfaces,
            self.mae_planes,
            self.mae_surfaces,
            self.fine_fattening,
            self.fine_thinning,
        ]
    }
}

/// The data Discontinuities, Fattening and Thinning are scored on. With high-resolution
/// masks, as the toolkit does: everything at [`HIGHRES_EVAL_SCALE`] times the low
/// resolution, the prediction and any stored map of another size enlarged by
/// [`zoom_nearest`], the frame scaled alike. Without them, the low-resolution data.
struct FineInputs<'a> {
    pred: Cow<'a, [f32]>,
    gt: Cow<'a, [f32]>,
    masks: Cow<'a, RegionMasks>,
    frame: Frame,
    resolution: Resolution,
}

impl<'a> FineInputs<'a> {
    fn new(pred: &'a [f32], gt: &'a [f32], frame: &Frame, truth: &'a RegionTruth) -> Self {
        let Some(hr) = truth.high.as_ref().filter(|hr| !hr.masks.is_empty()) else {
            return Self {
                pred: Cow::Borrowed(pred),
                gt: Cow::Borrowed(gt),
                masks: Cow::Borrowed(&truth.masks),
                frame: *frame,
                resolution: Resolution::Low,
            };
        };
        let (w, h) = (frame.width, frame.height);
        let (big_w, big_h) = (w * HIGHRES_EVAL_SCALE, h * HIGHRES_EVAL_SCALE);
        let stored = (hr.width, hr.height);
        let (gt, masks) = if stored == (big_w, big_h) {
            (Cow::Borrowed(hr.gt.as_slice()), Cow::Borrowed(&hr.masks))
        } else {
            let zoom = |m: &Option<Vec<bool>>| {
                m.as_deref()
                    .map(|m| zoom_nearest(m, hr.width, hr.height, big_w, big_h))
            };
            let masks = RegionMasks {
                discontinuities: zoom(&hr.masks.discontinuities),
                planes: zoom(&hr.masks.planes),
                smooth_surfaces: zoom(&hr.masks.smooth_surfaces),
                fine: zoom(&hr.masks.fine),
                fine_surrounding: zoom(&hr.masks.fine_surrounding),
            };
            let gt = zoom_nearest(&hr.gt, hr.width, hr.height, big_w, big_h);
            (Cow::Owned(gt), Cow::Owned(masks))
        };
        Self {
            pred: Cow::Owned(zoom_nearest(pred, w, h, big_w, big_h)),
            gt,
            masks,
            frame: frame.scaled(HIGHRES_EVAL_SCALE),
            resolution: Resolution::High,
        }
    }
}

/// `100 · #(mask ∧ frame ∧ bad) / #(mask ∧ frame)`: the toolkit's BadPix-style percentage,
/// where a NaN comparison is not bad but its pixel still counts.
fn masked_percent(
    pred: &[f32],
    gt: &[f32],
    mask: &[bool],
    frame: &Frame,
    bad: fn(f32, f32) -> bool,
) -> Option<f64> {
    let (n, n_bad) = frame
        .indices()
        .filter(|&i| mask[i])
        .fold((0usize, 0usize), |(n, b), i| {
            (n + 1, b + usize::from(bad(pred[i], gt[i])))
        });
    (n > 0).then(|| 100.0 * n_bad as f64 / n as f64)
}

/// `100 · Σ b / n` over the pixels of `mask ∧ frame` whose bumpiness `b` is finite.
fn bumpiness_score(bump: &[f64], mask: &[bool], frame: &Frame) -> Option<f64> {
    let (sum, n) = frame
        .indices()
        .filter(|&i| mask[i] && bump[i].is_finite())
        .fold((0.0, 0usize), |(s, n), i| (s + bump[i], n + 1));
    (n > 0).then(|| BUMPINESS_FACTOR * sum / n as f64)
}

/// The median angle over `mask ∧ frame` where the prediction and the angle are finite
/// (numpy's median: the mean of the two middle values for an even count).
fn mae_score(angles: &[f64], pred: &[f32], mask: &[bool], frame: &Frame) -> Option<f64> {
    let mut values: Vec<f64> = frame
        .indices()
        .filter(|&i| mask[i] && pred[i].is_finite() && angles[i].is_finite())
        .map(|i| angles[i])
        .collect();
    median(&mut values)
}

/// Median of `values` (reordered), `None` when empty.
fn median(values: &mut [f64]) -> Option<f64> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    let (lower, &mut upper, _) = values.select_nth_unstable_by(n / 2, f64::total_cmp);
    if n % 2 == 1 {
        return Some(upper);
    }
    let below = lower.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some((below + upper) / 2.0)
}

/// Per-pixel bumpiness `min(‖H‖_F, 0.05)` of `pred − gt` (the difference rounded to float32
/// first, as numpy subtracts the float32 maps), NaN where the error or a neighbour's is.
pub fn bumpiness(pred: &[f32], gt: &[f32], w: usize, h: usize) -> Vec<f64> {
    let diff: Vec<f64> = pred.iter().zip(gt).map(|(p, g)| f64::from(p - g)).collect();
    let dx = scharr(&diff, w, h, Axis::Columns);
    let dy = scharr(&diff, w, h, Axis::Rows);
    let dxx = scharr(&dx, w, h, Axis::Columns);
    let dxy = scharr(&dx, w, h, Axis::Rows);
    let dyy = scharr(&dy, w, h, Axis::Rows);
    let dyx = scharr(&dy, w, h, Axis::Columns);
    (0..w * h)
        .map(|i| {
            let sq = dxx[i] * dxx[i] + dxy[i] * dxy[i] + dyy[i] * dyy[i] + dyx[i] * dyx[i];
            sq.sqrt().clamp(0.0, BUMPINESS_CLIP)
        })
        .collect()
}

/// Direction a 3×3 derivative filter differentiates along.
#[derive(Clone, Copy)]
enum Axis {
    /// Along a column (down the rows): the toolkit's `scharr_h`.
    Rows,
    /// Along a row (across the columns): `scharr_v`.
    Columns,
}

/// Scharr derivative `([3, 10, 3] / 16)` smoothing × central difference, mirrored at the
/// border (scipy's `reflect`).
fn scharr(f: &[f64], w: usize, h: usize, axis: Axis) -> Vec<f64> {
    let clamp = |v: isize, n: usize| v.clamp(0, n as isize - 1) as usize;
    let at = |x: isize, y: isize| f[clamp(y, h) * w + clamp(x, w)];
    derivative(w, h, axis, 16.0, &at)
}

/// `Σ [3, 10, 3] · (f(+1) − f(−1)) / norm` at every pixel, the difference taken along `axis`
/// and the weights across it; `at` reads a pixel with the caller's border rule.
fn derivative(
    w: usize,
    h: usize,
    axis: Axis,
    norm: f64,
    at: &dyn Fn(isize, isize) -> f64,
) -> Vec<f64> {
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h as isize {
        for x in 0..w as isize {
            let mut sum = 0.0;
            for (k, weight) in [(-1, 3.0), (0, 10.0), (1, 3.0)] {
                let (fwd, back) = match axis {
                    Axis::Rows => (at(x + k, y + 1), at(x + k, y - 1)),
                    Axis::Columns => (at(x + 1, y + k), at(x - 1, y + k)),
                };
                sum += weight * (fwd - back);
            }
            out.push(sum / norm);
        }
    }
    out
}

/// Unit normals of the depth map of disparity `disp` as the toolkit's `get_depth_normals`
/// computes them: points `(c, r) / (N − 1) · 0.5 · sensor · z / f` (N = the larger side),
/// derivatives by the Scharr kernel `/ 64` with the image wrapped around, normal = the
/// cross product of the two tangents. NaN where the tangents are parallel or not finite.
pub fn depth_normals(disp: &[f32], w: usize, h: usize, cam: &DepthCamera) -> Vec<[f64; 3]> {
    let z: Vec<f64> = disp.iter().map(|&d| f64::from(cam.depth(d))).collect();
    let span = (w.max(h) - 1) as f64;
    let lateral = |p: usize, i: usize| {
        (p as f64 / span * 0.5) * cam.sensor_size_mm * z[i] / cam.focal_length_mm
    };
    let xx: Vec<f64> = (0..w * h).map(|i| lateral(i % w, i)).collect();
    let yy: Vec<f64> = (0..w * h).map(|i| lateral(i / w, i)).collect();
    let grad = |f: &[f64], axis| {
        let wrapped = |x: isize, y: isize| {
            f[y.rem_euclid(h as isize) as usize * w + x.rem_euclid(w as isize) as usize]
        };
        derivative(w, h, axis, 64.0, &wrapped)
    };
    let (dzdx, dzdy) = (grad(&z, Axis::Rows), grad(&z, Axis::Columns));
    let (dxdx, dxdy) = (grad(&xx, Axis::Rows), grad(&xx, Axis::Columns));
    let (dydx, dydy) = (grad(&yy, Axis::Rows), grad(&yy, Axis::Columns));
    (0..w * h)
        .map(|i| {
            let n = [
                dzdx[i] * dxdy[i] - dxdx[i] * dzdy[i],
                -(dydx[i] * dzdy[i] - dzdx[i] * dydy[i]),
                -(dxdx[i] * dydy[i] - dydx[i] * dxdy[i]),
            ];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            n.map(|c| c / len)
        })
        .collect()
}

/// Angle in degrees between the normals of `pred` and of `gt` at every pixel.
pub fn angular_error(pred: &[f32], gt: &[f32], w: usize, h: usize, cam: &DepthCamera) -> Vec<f64> {
    let a = depth_normals(pred, w, h, cam);
    let b = depth_normals(gt, w, h, cam);
    a.iter()
        .zip(&b)
        .map(|(a, b)| {
            let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            dot.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .collect()
}

/// scipy's `zoom(src, order=0)` to `out_w × out_h`: output pixel `o` takes input
/// `⌊o · (n − 1) / (N − 1) + 0.5⌋` on each axis (corners aligned, not pixel replication).
pub fn zoom_nearest<T: Copy>(src: &[T], w: usize, h: usize, out_w: usize, out_h: usize) -> Vec<T> {
    let map = |n: usize, big: usize| -> Vec<usize> {
        let step = if big > 1 {
            (n as f64 - 1.0) / (big as f64 - 1.0)
        } else {
            0.0
        };
        (0..big)
            .map(|o| ((o as f64 * step + 0.5).floor() as usize).min(n - 1))
            .collect()
    };
    let (xs, ys) = (map(w, out_w), map(h, out_h));
    ys.iter()
        .flat_map(|&y| xs.iter().map(move |&x| src[y * w + x]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoom_aligns_the_corners_as_scipy_does() {
        // (n − 1) / (N − 1) = 1/4: outputs 0…4 read 0, 0.25, 0.5, 0.75, 1 → rounded half up.
        assert_eq!(zoom_nearest(&[1, 2], 2, 1, 5, 1), vec![1, 1, 2, 2, 2]);
        let src: Vec<u32> = (0..4).collect();
        assert_eq!(
            zoom_nearest(&src, 2, 2, 2, 2),
            src,
            "same size is the identity"
        );
    }

    #[test]
    fn the_median_is_numpys() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&mut []), None);
    }

    #[test]
    fn an_affine_error_is_not_bumpy_and_a_curved_one_is() {
        let (w, h) = (9, 9);
        let gt = vec![0.0f32; w * h];
        let tilted: Vec<f32> = (0..w * h).map(|i| 0.01 * (i % w) as f32).collect();
        let bump = bumpiness(&tilted, &gt, w, h);
        assert!(bump[4 * w + 4].abs() < 1e-12, "a plane's Hessian is zero");
        let curved: Vec<f32> = (0..w * h)
            .map(|i| 0.001 * ((i % w) as f32).powi(2))
            .collect();
        // f'' = 0.002; each Scharr pass is an undivided central difference (twice the
        // derivative), so the toolkit's Hessian is 4 f'' = 0.008.
        assert!((bumpiness(&curved, &gt, w, h)[4 * w + 4] - 0.008).abs() < 1e-6);
    }

    #[test]
    fn each_score_needs_its_mask_and_fine_ones_fall_back_to_low_resolution() {
        let (w, h) = (8, 8);
        let frame = Frame::new(w, h, 1);
        let gt = vec![1.0f32; w * h];
        let mut pred = gt.clone();
        pred[2 * w + 2] = 1.5;
        let truth = RegionTruth {
            camera: DepthCamera {
                focal_length_mm: 100.0,
                sensor_size_mm: 35.0,
                baseline_mm: 10.0,
                focus_distance_m: 2.0,
                max_side_px: w,
            },
            masks: RegionMasks {
                fine: Some(vec![true; w * h]),
                ..RegionMasks::default()
            },
            high: None,
        };
        let s = RegionScores::compute(&pred, &gt, &frame, &truth);
        // Thinning is gt − pred > 0.15; the one wrong pixel is fattening (gt − pred = −0.5).
        assert_eq!(s.fine_thinning, Some(0.0));
        assert_eq!(s.fine_fattening, None);
        assert_eq!(
            (s.bumpiness_planes, s.mae_planes, s.discontinuities),
            (None, None, None)
        );
        assert_eq!(s.fine_resolution, Some(Resolution::Low));
    }
}

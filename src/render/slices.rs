//! Single-pass multimodal ground truth: per-sample hits → 128 depth slices → over-compositing
//! → modes (SPEC §3, thesis eq. 5.17–5.19).
//!
//! Per sample, the hits of one slice composite front to back with the over operator, giving
//! that slice's coverage α and α-weighted depth; per pixel these are averaged over samples (box
//! filter), and the slices are then composited front to back: `η_j = α_j Π_{k<j} (1 − α_k)`.
//! `η_exact` sums `T·a` per hit (T the transmittance in front of it, per sample): the exact
//! visible fraction that the over operator approximates when coverages are correlated.

use crate::scene::SliceRange;
use glam::Vec3;
use lfformat::Mode;

/// One surface along a sample ray: planar depth and coverage in [0, 1].
#[derive(Clone, Copy, Debug)]
pub struct SliceHit {
    pub z: f32,
    pub coverage: f32,
    /// Radiance leaving the surface towards the camera, when every hit is shaded
    /// (`render.write_slices`); `None` otherwise.
    pub radiance: Option<Vec3>,
}

/// Per-pixel slice accumulators, reused across pixels (no allocation per sample).
pub struct SliceAccumulator {
    alpha: Vec<f32>,
    alpha_z: Vec<f64>,
    exact: Vec<f32>,
    color: Vec<Vec3>,
    color_weight: Vec<f32>,
    touched: Vec<u32>,
    marked: Vec<bool>,
    samples: u32,
}

/// Per-pixel ground truth: modes front to back and their colours.
pub struct PixelModes<'a> {
    pub modes: &'a [Mode],
    pub colors: &'a [[f32; 3]],
}

impl SliceAccumulator {
    pub fn new(slices: usize) -> Self {
        Self {
            alpha: vec![0.0; slices],
            alpha_z: vec![0.0; slices],
            exact: vec![0.0; slices],
            color: vec![Vec3::ZERO; slices],
            color_weight: vec![0.0; slices],
            touched: Vec::with_capacity(slices),
            marked: vec![false; slices],
            samples: 0,
        }
    }

    fn touch(&mut self, k: usize) {
        if !self.marked[k] {
            self.marked[k] = true;
            self.touched.push(k as u32);
        }
    }

    /// Adds one sample ray's hits (sorted front to back).
    pub fn add_sample(&mut self, range: &SliceRange, hits: &[SliceHit]) {
        self.samples += 1;
        let mut transmittance = 1.0f32;
        let mut i = 0;
        while i < hits.len() {
            let k = range.index(hits[i].z);
            self.touch(k);
            let mut slice_t = 1.0f32;
            while i < hits.len() && range.index(hits[i].z) == k {
                let a = hits[i].coverage;
                self.alpha_z[k] += (slice_t * a) as f64 * hits[i].z as f64;
                if let Some(radiance) = hits[i].radiance {
                    self.color[k] += radiance * (slice_t * a);
                    self.color_weight[k] += slice_t * a;
                }
                self.exact[k] += transmittance * a;
                slice_t *= 1.0 - a;
                transmittance *= 1.0 - a;
                i += 1;
            }
            self.alpha[k] += 1.0 - slice_t;
        }
    }

    /// Attributes a sample's radiance to the slice of the surface it saw (slice colours at no
    /// extra shading cost; `weight` is 1 for the visible hit, or the hit's in-slice over weight
    /// when every hit is shaded).
    pub fn add_color(&mut self, range: &SliceRange, z: f32, radiance: Vec3, weight: f32) {
        let k = range.index(z);
        self.touch(k);
        self.color[k] += radiance * weight;
        self.color_weight[k] += weight;
    }

    /// Composites the pixel's slices and appends its modes (η or η_exact above `epsilon`) and
    /// their colours; resets the accumulators for the next pixel.
    pub fn finish_pixel(
        &mut self,
        disparity: impl Fn(f64) -> f64,
        epsilon: f32,
        modes: &mut Vec<Mode>,
        colors: &mut Vec<[f32; 3]>,
    ) {
        self.touched.sort_unstable();
        let n = self.samples.max(1) as f32;
        let mut transmittance = 1.0f32;
        for &k in &self.touched {
            let k = k as usize;
            let alpha = self.alpha[k] / n;
            let eta = alpha * transmittance;
            let eta_exact = self.exact[k] / n;
            transmittance *= 1.0 - alpha;
            if (eta > epsilon || eta_exact > epsilon) && self.alpha[k] > 0.0 {
                let z = self.alpha_z[k] / self.alpha[k] as f64;
                let d = disparity(z) as f32;
                modes.push(Mode { disparity: d, depth: z as f32, eta, eta_exact });
                let c = if self.color_weight[k] > 0.0 { self.color[k] / self.color_weight[k] } else { Vec3::ZERO };
                colors.push(c.to_array());
            }
            self.alpha[k] = 0.0;
            self.alpha_z[k] = 0.0;
            self.exact[k] = 0.0;
            self.color[k] = Vec3::ZERO;
            self.color_weight[k] = 0.0;
            self.marked[k] = false;
        }
        self.touched.clear();
        self.samples = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SliceSpacing;

    fn range() -> SliceRange {
        SliceRange { z_near: 1.0, z_far: 9.0, count: 8, spacing: SliceSpacing::Depth }
    }

    fn hit(z: f32, coverage: f32) -> SliceHit {
        SliceHit { z, coverage, radiance: None }
    }

    #[test]
    fn shaded_hits_give_over_weighted_slice_colours() {
        let mut acc = SliceAccumulator::new(8);
        let red = SliceHit { z: 2.2, coverage: 0.5, radiance: Some(Vec3::X) };
        let blue = SliceHit { z: 2.8, coverage: 1.0, radiance: Some(Vec3::Z) };
        acc.add_sample(&range(), &[red, blue]);
        let (mut m, mut c) = (Vec::new(), Vec::new());
        acc.finish_pixel(|z| 1.0 / z, 1e-4, &mut m, &mut c);
        // Weights 0.5 (red) and 0.5 (blue behind it): the straight colour is their mean.
        assert_eq!(c, vec![[0.5, 0.0, 0.5]]);
    }

    fn finish(acc: &mut SliceAccumulator) -> Vec<Mode> {
        let (mut m, mut c) = (Vec::new(), Vec::new());
        acc.finish_pixel(|z| 1.0 / z, 1e-4, &mut m, &mut c);
        m
    }

    #[test]
    fn pane_over_wall_gives_two_modes_by_hand() {
        let mut acc = SliceAccumulator::new(8);
        let hits = [hit(2.5, 0.4), hit(7.5, 1.0)];
        acc.add_sample(&range(), &hits);
        let m = finish(&mut acc);
        assert_eq!(m.len(), 2);
        assert!((m[0].eta - 0.4).abs() < 1e-6 && (m[1].eta - 0.6).abs() < 1e-6);
        assert!((m[0].eta_exact - 0.4).abs() < 1e-6 && (m[1].eta_exact - 0.6).abs() < 1e-6);
        assert!((m[0].depth - 2.5).abs() < 1e-6 && (m[1].depth - 7.5).abs() < 1e-6);
        assert!((m[0].disparity - 0.4).abs() < 1e-6);
    }

    #[test]
    fn hits_in_one_slice_composite_over_each_other() {
        let mut acc = SliceAccumulator::new(8);
        let hits = [hit(2.2, 0.5), hit(2.8, 0.5)];
        acc.add_sample(&range(), &hits);
        let m = finish(&mut acc);
        // α = 1 - 0.5·0.5 = 0.75; depth = (0.5·2.2 + 0.25·2.8) / 0.75.
        assert_eq!(m.len(), 1);
        assert!((m[0].eta - 0.75).abs() < 1e-6);
        assert!((m[0].depth - (0.5 * 2.2 + 0.25 * 2.8) / 0.75).abs() < 1e-5);
    }

    #[test]
    fn over_operator_differs_from_exact_for_correlated_coverage() {
        // Two samples: one sees only the front slice, the other only the middle slice; both
        // see the wall. Over: α = ½, ½ → η = ½, ¼, ¼. Exact: ½, ½, 0.
        let mut acc = SliceAccumulator::new(8);
        let wall = hit(8.5, 1.0);
        acc.add_sample(&range(), &[hit(1.5, 1.0), wall]);
        acc.add_sample(&range(), &[hit(4.5, 1.0), wall]);
        let m = finish(&mut acc);
        let eta: Vec<f32> = m.iter().map(|m| m.eta).collect();
        let exact: Vec<f32> = m.iter().map(|m| m.eta_exact).collect();
        assert_eq!(eta, [0.5, 0.25, 0.25]);
        assert_eq!(exact, [0.5, 0.5, 0.0]);
    }

    #[test]
    fn occluded_slices_are_dropped_and_state_resets() {
        let mut acc = SliceAccumulator::new(8);
        let hits = [hit(1.5, 1.0), hit(8.5, 1.0)];
        acc.add_sample(&range(), &hits);
        assert_eq!(finish(&mut acc).len(), 1);
        acc.add_sample(&range(), &[hit(5.5, 1.0)]);
        let m = finish(&mut acc);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].depth, 5.5);
    }
}

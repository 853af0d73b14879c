//! Single-pass multimodal ground truth: per-sample hits → 128 depth slices → over-compositing
//! → modes (docs/reference/format.md, Slices and modes; thesis eq. 5.17–5.19).
//!
//! Per sample, the hits of one slice composite front to back with the over operator, giving
//! that slice's coverage α and α-weighted depth; per pixel these are averaged over samples (box
//! filter), and the slices are then composited front to back: `η_j = α_j Π_{k<j} (1 − α_k)`.
//! `η_exact` sums `T·a` per hit (T the transmittance in front of it, per sample): the exact
//! visible fraction that the over operator approximates when coverages are correlated.
//!
//! The same hits give each mode its surface: the over-weighted mean of the hits' normals, and
//! the ids of the object with the largest over weight in the slice.

use glam::Vec3;
use lfformat::{Mode, ModeSurface};
use serde::{Deserialize, Serialize};

/// Which depth decides a hit's slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SliceAssignment {
    /// The depth of the hit's surface (its triangle's plane) at the pixel centre: a continuous
    /// surface is never cut by a slice boundary inside a pixel.
    Surface,
    /// The sample's own hit depth: literal camera-side clipping, as in the thesis.
    Sample,
}

/// One surface along a sample ray: its slice, planar depth and coverage in [0, 1].
#[derive(Clone, Copy, Debug)]
pub struct SliceHit {
    pub slice: u32,
    pub z: f32,
    pub coverage: f32,
    /// Radiance leaving the surface towards the camera, when every hit is shaded
    /// (`render.write_slices`); `None` otherwise.
    pub radiance: Option<Vec3>,
    /// Unit geometric normal in the camera frame, facing the camera.
    pub normal: Vec3,
    pub ids: SurfaceIds,
    /// Glass, or a coverage strictly between 0 and 1: what lies behind it is seen through it.
    pub translucent: bool,
}

/// The ids of a hit's surface (see [`ModeSurface`]; 0: none).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SurfaceIds {
    pub object: u32,
    pub material: u32,
    pub class: u32,
}

/// How many distinct objects a slice of one pixel tallies; a further one is not counted (five
/// objects in one slice of one pixel are rare, and the largest is almost always among the
/// first four met).
const VOTES: usize = 4;

/// An object's summed over weight in a slice.
#[derive(Clone, Copy, Default)]
struct Vote {
    ids: SurfaceIds,
    weight: f32,
}

/// Per-pixel slice accumulators, reused across pixels (no allocation per sample).
pub struct SliceAccumulator {
    alpha: Vec<f32>,
    alpha_z: Vec<f64>,
    exact: Vec<f32>,
    color: Vec<Vec3>,
    color_weight: Vec<f32>,
    /// Over-weighted sum of the hits' normals, and the objects' weights, per slice.
    normal: Vec<Vec3>,
    votes: Vec<[Vote; VOTES]>,
    /// Nearest depth of a translucent hit some sample saw (infinity: none).
    translucent_z: f32,
    touched: Vec<u32>,
    marked: Vec<bool>,
    /// In-slice transmittance of the current sample, and the slices it touched.
    sample_t: Vec<f32>,
    sample_touched: Vec<u32>,
    /// The pixel's modes before sorting by depth.
    pixel_modes: Vec<(Mode, [f32; 3], ModeSurface)>,
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
            normal: vec![Vec3::ZERO; slices],
            votes: vec![[Vote::default(); VOTES]; slices],
            translucent_z: f32::INFINITY,
            touched: Vec::with_capacity(slices),
            marked: vec![false; slices],
            sample_t: vec![1.0; slices],
            sample_touched: Vec::with_capacity(slices),
            pixel_modes: Vec::new(),
            samples: 0,
        }
    }

    fn touch(&mut self, k: usize) {
        if !self.marked[k] {
            self.marked[k] = true;
            self.touched.push(k as u32);
        }
    }

    /// Adds one sample ray's hits (sorted front to back). Within a slice, hits composite over
    /// each other in ray order; slices need not be monotone along the ray.
    pub fn add_sample(&mut self, hits: &[SliceHit]) {
        self.samples += 1;
        let mut transmittance = 1.0f32;
        for h in hits {
            let k = h.slice as usize;
            self.touch(k);
            if !self.sample_touched.contains(&h.slice) {
                self.sample_touched.push(h.slice);
            }
            let w = self.sample_t[k] * h.coverage;
            self.alpha_z[k] += w as f64 * h.z as f64;
            self.normal[k] += h.normal * w;
            vote(&mut self.votes[k], h.ids, w);
            if h.translucent && transmittance > 0.0 {
                self.translucent_z = self.translucent_z.min(h.z);
            }
            if let Some(radiance) = h.radiance {
                self.color[k] += radiance * w;
                self.color_weight[k] += w;
            }
            self.exact[k] += transmittance * h.coverage;
            self.sample_t[k] *= 1.0 - h.coverage;
            transmittance *= 1.0 - h.coverage;
        }
        for &k in &self.sample_touched {
            self.alpha[k as usize] += 1.0 - self.sample_t[k as usize];
            self.sample_t[k as usize] = 1.0;
        }
        self.sample_touched.clear();
    }

    /// Attributes a sample's radiance to the slice of the surface it saw (slice colours at no
    /// extra shading cost; `weight` is 1 for the visible hit, or the hit's in-slice over weight
    /// when every hit is shaded).
    pub fn add_color(&mut self, slice: u32, radiance: Vec3, weight: f32) {
        let k = slice as usize;
        self.touch(k);
        self.color[k] += radiance * weight;
        self.color_weight[k] += weight;
    }

    /// Composites the pixel's slices front to back and appends its modes (η or η_exact above
    /// `epsilon`), their colours and surfaces, sorted by depth; resets the accumulators for
    /// the next pixel and returns the nearest depth of a translucent hit a sample saw
    /// (infinity: none). (Slice order and depth order differ only where two surfaces of
    /// neighbouring slices interleave inside one pixel, at creases.)
    pub fn finish_pixel(
        &mut self,
        disparity: impl Fn(f64) -> f64,
        epsilon: f32,
        modes: &mut Vec<Mode>,
        colors: &mut Vec<[f32; 3]>,
        surfaces: &mut Vec<ModeSurface>,
    ) -> f32 {
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
                let c = if self.color_weight[k] > 0.0 {
                    self.color[k] / self.color_weight[k]
                } else {
                    Vec3::ZERO
                };
                let mode = Mode {
                    disparity: d,
                    depth: z as f32,
                    eta,
                    eta_exact,
                };
                let surface = self.surface(k);
                self.pixel_modes.push((mode, c.to_array(), surface));
            }
            self.alpha[k] = 0.0;
            self.alpha_z[k] = 0.0;
            self.exact[k] = 0.0;
            self.color[k] = Vec3::ZERO;
            self.color_weight[k] = 0.0;
            self.normal[k] = Vec3::ZERO;
            self.votes[k] = [Vote::default(); VOTES];
            self.marked[k] = false;
        }
        self.pixel_modes
            .sort_by(|a, b| a.0.depth.total_cmp(&b.0.depth));
        modes.extend(self.pixel_modes.iter().map(|m| m.0));
        colors.extend(self.pixel_modes.iter().map(|m| m.1));
        surfaces.extend(self.pixel_modes.iter().map(|m| m.2));
        self.pixel_modes.clear();
        self.touched.clear();
        self.samples = 0;
        std::mem::replace(&mut self.translucent_z, f32::INFINITY)
    }

    /// Slice `k`'s surface: the normalised mean normal and the ids of its heaviest object.
    fn surface(&self, k: usize) -> ModeSurface {
        let normal = self.normal[k].try_normalize().unwrap_or(Vec3::NAN);
        let top = (self.votes[k].iter()).fold(Vote::default(), |a, &b| match b.weight > a.weight {
            true => b,
            false => a,
        });
        ModeSurface {
            normal: normal.to_array(),
            object: top.ids.object,
            material: top.ids.material,
            class: top.ids.class,
        }
    }
}

/// Adds `weight` to the vote of `ids` in a slice's tally (a new object takes a free place).
fn vote(votes: &mut [Vote; VOTES], ids: SurfaceIds, weight: f32) {
    if weight <= 0.0 {
        return;
    }
    let place = votes.iter().position(|v| v.ids == ids || v.weight == 0.0);
    if let Some(i) = place {
        votes[i].ids = ids;
        votes[i].weight += weight;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SliceRange;
    use crate::scene::SliceSpacing;

    fn range() -> SliceRange {
        SliceRange {
            z_near: 1.0,
            z_far: 9.0,
            count: 8,
            spacing: SliceSpacing::Depth,
        }
    }

    fn hit(z: f32, coverage: f32) -> SliceHit {
        SliceHit {
            slice: range().index(z) as u32,
            z,
            coverage,
            radiance: None,
            normal: Vec3::Z,
            ids: SurfaceIds::default(),
            translucent: false,
        }
    }

    #[test]
    fn shaded_hits_give_over_weighted_slice_colours() {
        let mut acc = SliceAccumulator::new(8);
        let red = SliceHit {
            radiance: Some(Vec3::X),
            ..hit(2.2, 0.5)
        };
        let blue = SliceHit {
            radiance: Some(Vec3::Z),
            ..hit(2.8, 1.0)
        };
        acc.add_sample(&[red, blue]);
        let (mut m, mut c, mut s) = (Vec::new(), Vec::new(), Vec::new());
        acc.finish_pixel(|z| 1.0 / z, 1e-4, &mut m, &mut c, &mut s);
        // Weights 0.5 (red) and 0.5 (blue behind it): the straight colour is their mean.
        assert_eq!(c, vec![[0.5, 0.0, 0.5]]);
    }

    fn finish(acc: &mut SliceAccumulator) -> Vec<Mode> {
        finish_all(acc).0
    }

    fn finish_all(acc: &mut SliceAccumulator) -> (Vec<Mode>, Vec<ModeSurface>, f32) {
        let (mut m, mut c, mut s) = (Vec::new(), Vec::new(), Vec::new());
        let translucent_z = acc.finish_pixel(|z| 1.0 / z, 1e-4, &mut m, &mut c, &mut s);
        (m, s, translucent_z)
    }

    fn ids(object: u32) -> SurfaceIds {
        SurfaceIds {
            object,
            material: 10 + object,
            class: 20 + object,
        }
    }

    /// A crease inside one slice: three samples on face A (normal x), one on face B (normal
    /// y), both of object 1: the mean normal is ∝ 3x + y. Then two objects in one slice:
    /// the heavier one names the mode.
    #[test]
    fn a_modes_surface_is_its_mean_normal_and_heaviest_object() {
        let mut acc = SliceAccumulator::new(8);
        let on = |normal, object| SliceHit {
            normal,
            ids: ids(object),
            ..hit(2.5, 1.0)
        };
        for _ in 0..3 {
            acc.add_sample(&[on(Vec3::X, 1)]);
        }
        acc.add_sample(&[on(Vec3::Y, 1)]);
        let (m, s, translucent_z) = finish_all(&mut acc);
        assert_eq!(m.len(), 1);
        let n = Vec3::from(s[0].normal);
        assert!(
            (n - Vec3::new(3.0, 1.0, 0.0).normalize()).length() < 1e-6,
            "{n}"
        );
        assert_eq!((s[0].object, s[0].material, s[0].class), (1, 11, 21));
        assert_eq!(translucent_z, f32::INFINITY);
        // Object 2 carries 0.6 of the slice, object 1 (behind it) 0.4.
        let front = SliceHit {
            coverage: 0.6,
            ..on(Vec3::Z, 2)
        };
        let back = SliceHit {
            z: 2.6,
            ..on(Vec3::Z, 1)
        };
        acc.add_sample(&[back, front]);
        let (_, s, _) = finish_all(&mut acc);
        assert_eq!(s[0].object, 1, "ray order: object 1 first, weight 1");
        acc.add_sample(&[front, back]);
        let (_, s, _) = finish_all(&mut acc);
        assert_eq!(s[0].object, 2);
    }

    /// A translucent pane is reported where a sample saw it, not where it was hidden.
    #[test]
    fn the_nearest_visible_translucent_hit_is_reported_once() {
        let mut acc = SliceAccumulator::new(8);
        let pane = SliceHit {
            translucent: true,
            ..hit(2.5, 0.3)
        };
        let hidden = SliceHit {
            translucent: true,
            ..hit(8.5, 0.3)
        };
        acc.add_sample(&[hit(1.5, 1.0), hidden]);
        assert_eq!(finish_all(&mut acc).2, f32::INFINITY);
        acc.add_sample(&[hit(1.5, 1.0), hidden]);
        acc.add_sample(&[pane, hit(7.5, 1.0)]);
        assert_eq!(finish_all(&mut acc).2, 2.5);
        assert_eq!(finish_all(&mut acc).2, f32::INFINITY);
    }

    #[test]
    fn pane_over_wall_gives_two_modes_by_hand() {
        let mut acc = SliceAccumulator::new(8);
        let hits = [hit(2.5, 0.4), hit(7.5, 1.0)];
        acc.add_sample(&hits);
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
        acc.add_sample(&hits);
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
        acc.add_sample(&[hit(1.5, 1.0), wall]);
        acc.add_sample(&[hit(4.5, 1.0), wall]);
        let m = finish(&mut acc);
        let eta: Vec<f32> = m.iter().map(|m| m.eta).collect();
        let exact: Vec<f32> = m.iter().map(|m| m.eta_exact).collect();
        assert_eq!(eta, [0.5, 0.25, 0.25]);
        assert_eq!(exact, [0.5, 0.5, 0.0]);
    }

    #[test]
    fn a_slice_revisited_along_the_ray_composites_once() {
        // Slices 1, 5, 1 along the ray (intersecting surfaces): slice 1 gets α = 1 - 0.5·0.5.
        let mut acc = SliceAccumulator::new(8);
        let h = |slice, z| SliceHit {
            slice,
            ..hit(z, 0.5)
        };
        acc.add_sample(&[h(1, 2.0), h(5, 2.1), h(1, 2.2)]);
        let m = finish(&mut acc);
        assert_eq!(m.len(), 2);
        assert!((m[0].eta - 0.75).abs() < 1e-6 && (m[1].eta - 0.5 * 0.25).abs() < 1e-6);
        assert!((m[0].eta_exact - 0.625).abs() < 1e-6 && (m[1].eta_exact - 0.25).abs() < 1e-6);
    }

    #[test]
    fn occluded_slices_are_dropped_and_state_resets() {
        let mut acc = SliceAccumulator::new(8);
        let hits = [hit(1.5, 1.0), hit(8.5, 1.0)];
        acc.add_sample(&hits);
        assert_eq!(finish(&mut acc).len(), 1);
        acc.add_sample(&[hit(5.5, 1.0)]);
        let m = finish(&mut acc);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].depth, 5.5);
    }
}

//! Rendering one view: colour for every view, and the multimodal ground truth in the same pass
//! for the views that need it.

use super::RenderScene;
use super::cache::{CacheGrid, CacheParams, CacheSums, RadianceCache};
use super::geometry::Hit;
use super::integrator::{PathSettings, Shading};
use super::sampler::{RayKey, Sampler};
use super::slices::{SliceAccumulator, SliceAssignment, SliceHit, SurfaceIds};
use super::valid::is_valid;
use crate::camera::{CameraRay, LightFieldCamera, ViewRays};
use crate::scene::SliceRange;
use glam::{Mat3, Vec2, Vec3};
pub use lfformat::gt_maps::HciLayer;
use lfformat::{Mode, ModeMap, ModeSurface};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Everything a view render needs besides the scene and camera.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub path: PathSettings,
    pub spp: u32,
    /// Camera samples per pixel of the ground truth (modes, η, mode colours). Equal to `spp`,
    /// the GT is built from the colour's own rays (one all-hits trace serves both); otherwise
    /// from `gt_spp` rays of its own, so η is not limited by the colour's sample count.
    pub gt_spp: u32,
    pub seed: u64,
    pub scene_index: u64,
    pub mode_epsilon: f32,
    /// Shade every hit of GT rays, so mode colours are true slice colours (else each sample's
    /// colour goes to the slice of the surface it saw).
    pub shade_all_hits: bool,
    pub slice_assignment: SliceAssignment,
    pub adaptive: Adaptive,
}

/// Adaptive sampling: a pixel whose estimate is still noisy after its `spp` samples gets
/// `extra` more, from a stream of their own.
///
/// Why: a view's own noise (what shared shading cannot share: the pixel-area integral over
/// edges and fine texture, glass, mirrors and narrow glossy lobes) sits in few pixels — at
/// 128² the noisiest 5 % hold about 80 % of it (`lfgen bench quality`) — so spending samples
/// there buys more PSNR than raising `spp` everywhere. The test is Cycles' adaptive-sampling
/// error, the standard error of the pixel mean summed over RGB divided by the square root of
/// its summed brightness (a rough perceptual weight), in display units.
///
/// Bias: the test looks at the samples it then averages, so pixels that drew a rare bright path
/// get it diluted while pixels that missed it keep their dark estimate: the result leans dark
/// where light arrives by rare paths, by at most the share `extra / (spp + extra)` of the
/// selected pixels' first-pass excess. It vanishes as the threshold goes to zero (every pixel
/// gets `spp + extra` samples) and is measured against the converged independent render in
/// docs/design/shared-shading.md.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Adaptive {
    /// Extra camera samples of a noisy pixel (0: off).
    pub extra: u32,
    /// Largest accepted error (see above).
    pub threshold: f32,
    /// Radiance × `display_scale` = display units (1: white); the scene's exposure.
    pub display_scale: f32,
}

impl Adaptive {
    /// Whether the pixel whose `n` samples have these moments needs the extra samples.
    fn wants_more(&self, m: &Moments, n: u32) -> bool {
        if self.extra == 0 || n < 2 {
            return false;
        }
        let n_f = n as f32;
        let mean = m.sum / n_f;
        // Unbiased sample variance, then the variance of the mean; in display units.
        let var = ((m.squares / n_f - mean * mean) * (n_f / (n_f - 1.0))).max(Vec3::ZERO);
        let k = self.display_scale;
        let std_error = (var / n_f).map(f32::sqrt) * k;
        let brightness = (mean * k).element_sum().max(0.0);
        std_error.element_sum() / (1e-4 + brightness.sqrt()) > self.threshold
    }
}

/// Sum and sum of squares (per channel) of a pixel's sample radiance.
#[derive(Clone, Copy, Default)]
struct Moments {
    sum: Vec3,
    squares: Vec3,
}

impl Moments {
    fn add(&mut self, radiance: Vec3) {
        self.sum += radiance;
        self.squares += radiance * radiance;
    }
}

impl RenderSettings {
    /// Camera samples per pixel of a view: the colour's, plus the GT's own where it has them.
    pub fn samples_per_pixel(&self, with_gt: bool) -> u32 {
        self.spp
            + if with_gt {
                gt_own_spp(self.spp, self.gt_spp)
            } else {
                0
            }
    }
}

/// The camera samples a GT view traces for its ground truth on top of the colour's: none when
/// `gt_spp == spp` (the colour's own rays carry the GT), else `gt_spp` of their own.
pub fn gt_own_spp(spp: u32, gt_spp: u32) -> u32 {
    if gt_spp == spp { 0 } else { gt_spp }
}

/// Linear radiance, row-major from the top-left.
pub struct ViewImage {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<Vec3>,
    /// Pixels that adaptive sampling gave extra samples ([`Adaptive`]).
    pub refined: usize,
}

/// Ground truth of one view.
pub struct ViewGt {
    pub modes: ModeMap,
    /// Linear colour of each mode, in [`ModeMap`] storage order.
    pub colors: Vec<[f32; 3]>,
    /// Normal and ids of each mode, in [`ModeMap`] storage order.
    pub surfaces: Vec<ModeSurface>,
    /// The single-valued HCI layer.
    pub hci: HciLayer,
    /// Where the HCI disparity is trustworthy ([`is_valid`]).
    pub valid: Vec<bool>,
}

pub struct ViewOutput {
    pub image: ViewImage,
    pub gt: Option<ViewGt>,
}

/// How far (relative depth) a hit's surface plane, at the pixel centre, may lie from the same
/// object's hit on the pixel-centre ray and still be snapped to it: planes of one surface meet
/// there up to the curvature or crease inside one pixel; distinct parts of an object are
/// farther apart.
const SNAP_TOLERANCE: f32 = 0.02;

/// Most semi-transparent layers a composited camera ray passes (light behind more is lost;
/// the built-in scenes stack at most a few).
const MAX_LAYERS: usize = 16;

/// Rows per parallel work item: small enough to balance two to many cores.
const BAND_ROWS: u32 = 2;

/// Per-thread scratch buffers, reused for every pixel of a band.
struct Scratch {
    hits: Vec<Hit>,
    /// Every surface on the pixel-centre ray (HCI depth, and slice snapping).
    centre_hits: Vec<Hit>,
    slice_hits: Vec<SliceHit>,
    /// The layers a composited camera ray met: hit, its radiance, its weight `T·a`.
    layers: Vec<(Hit, Vec3, f32)>,
    acc: SliceAccumulator,
}

/// Output of one band of rows.
#[derive(Default)]
struct Band {
    pixels: Vec<Vec3>,
    modes: Vec<Mode>,
    mode_counts: Vec<u32>,
    colors: Vec<[f32; 3]>,
    surfaces: Vec<ModeSurface>,
    hci: HciLayer,
    valid: Vec<bool>,
    /// Pixels that got adaptive sampling's extra samples.
    refined: usize,
}

/// Salt of the fill pass's sample streams, so they are not the render's own.
const FILL_STREAM: u64 = 0xF111_CACE;

/// One pixel of a fill pass: (view, x, y), the view's grid position, and the pass's stream.
#[derive(Clone, Copy)]
struct FillPixel {
    at: (u32, u32, u32),
    uv: Vec2,
    stream: u64,
}

/// Stream offset of a pixel's path decisions. Pixel positions and stochastic-transparency keys
/// come from the pixel's camera stream alone, so the ground truth (built from those rays) is the
/// same whatever the shading mode draws along the path: an independent render and a shared one
/// write byte-identical `modes.exr`.
const PATH_STREAM: u64 = 0xA7B5_7EA3;

/// Salt of the final gather's camera and path streams (its own samples, not the fill's again).
const GATHER_STREAM: u64 = 0x6A7E_0F11;

/// Salt of the ground truth's own camera and path streams when `gt_spp` differs from `spp`.
const GT_STREAM: u64 = 0x6700_57EA;

/// Salt of the camera and path streams of adaptive sampling's extra samples.
const ADAPTIVE_STREAM: u64 = 0xADA9_7100;

impl RenderScene {
    /// Renders `view` with the independent estimator; `samples_done` counts camera samples
    /// for progress reporting.
    pub fn render_view(
        &self,
        cam: &LightFieldCamera,
        slices: &SliceRange,
        settings: &RenderSettings,
        view: u32,
        with_gt: bool,
        samples_done: &AtomicU64,
    ) -> ViewOutput {
        let shading = Shading::Independent;
        self.render_view_with(cam, slices, settings, view, with_gt, shading, samples_done)
    }

    /// Fills the shared-shading cache from `spp` samples per pixel of every view of `cam`
    /// (views and bands merged in order: the same sums for any thread count), and as many
    /// again gathering from that cache if `params.final_gather`.
    pub fn fill_cache(
        &self,
        cam: &LightFieldCamera,
        settings: &RenderSettings,
        spp: u32,
        params: CacheParams,
        samples_done: &AtomicU64,
    ) -> RadianceCache {
        let grid = CacheGrid::new(cam, params);
        let fill = Shading::Fill(&grid);
        let mut sums = self.fill_pass(cam, settings, spp, fill, FILL_STREAM, samples_done);
        if params.final_gather {
            let prior = sums.finish(grid);
            let (grid, prior, view) = (&grid, &prior, Vec2::ZERO);
            let gather = Shading::Gather { grid, prior, view };
            let gathered = self.fill_pass(cam, settings, spp, gather, GATHER_STREAM, samples_done);
            sums.merge_view(vec![gathered]);
        }
        sums.finish(grid)
    }

    /// The sums of one fill pass: `spp` samples per pixel of every view, shaded as `fill`
    /// says, from the camera and path streams salted by `stream`.
    fn fill_pass(
        &self,
        cam: &LightFieldCamera,
        settings: &RenderSettings,
        spp: u32,
        fill: Shading,
        stream: u64,
        samples_done: &AtomicU64,
    ) -> CacheSums {
        let (w, h) = (cam.width(), cam.height());
        let mut all = CacheSums::default();
        for view in 0..cam.num_views() {
            let rays = cam.view_rays(view);
            let uv = grid_position(cam, view);
            let shading = fill.seen_from(uv);
            let bands: Vec<CacheSums> = (0..h.div_ceil(BAND_ROWS))
                .into_par_iter()
                .map(|b| {
                    let mut sums = CacheSums::default();
                    for y in b * BAND_ROWS..((b + 1) * BAND_ROWS).min(h) {
                        for x in 0..w {
                            let pixel = FillPixel {
                                at: (view, x, y),
                                uv,
                                stream,
                            };
                            self.fill_pixel(&rays, settings, shading, pixel, spp, &mut sums);
                        }
                        samples_done.fetch_add(w as u64 * spp as u64, Ordering::Relaxed);
                    }
                    sums
                })
                .collect();
            all.merge_view(bands);
        }
        all
    }

    /// The fill samples of one pixel.
    fn fill_pixel(
        &self,
        rays: &ViewRays,
        s: &RenderSettings,
        fill: Shading,
        FillPixel { at, uv, stream }: FillPixel,
        spp: u32,
        sums: &mut CacheSums,
    ) {
        let (view, x, y) = at;
        let scene = s.scene_index ^ stream;
        let mut sampler = Sampler::new(s.seed, scene, view, x, y, spp);
        for i in 0..spp {
            let off = sampler.pixel_offset(i);
            let ray = rays.ray(x as f32 + off.x, y as f32 + off.y);
            let key = sampler.next_key();
            let first =
                (self.geometry).closest(&self.materials, ray.origin, ray.dir, f32::INFINITY, key);
            let traced = self.trace(&s.path, ray.origin, ray.dir, first, &mut sampler, fill);
            if let Some((cells, estimate, at)) = traced.fill {
                sums.add(&cells, estimate, uv, at);
            }
            for (cells, irradiance) in traced.later.estimates() {
                sums.add_later(cells, irradiance);
            }
        }
    }

    /// Renders `view`, its first non-delta vertices shaded as `shading` says.
    #[allow(clippy::too_many_arguments)]
    pub fn render_view_with(
        &self,
        cam: &LightFieldCamera,
        slices: &SliceRange,
        settings: &RenderSettings,
        view: u32,
        with_gt: bool,
        shading: Shading,
        samples_done: &AtomicU64,
    ) -> ViewOutput {
        let (w, h) = (cam.width(), cam.height());
        let rays = cam.view_rays(view);
        let shading = shading.seen_from(grid_position(cam, view));
        let to_camera = camera_frame(cam);
        let bands: Vec<Band> = (0..h.div_ceil(BAND_ROWS))
            .into_par_iter()
            .map_init(
                || Scratch {
                    hits: Vec::new(),
                    centre_hits: Vec::new(),
                    slice_hits: Vec::new(),
                    layers: Vec::new(),
                    acc: SliceAccumulator::new(slices.count as usize),
                },
                |scratch, b| {
                    let rows = b * BAND_ROWS..((b + 1) * BAND_ROWS).min(h);
                    let mut band = Band::default();
                    for y in rows {
                        for x in 0..w {
                            let ctx = PixelCtx {
                                scene: self,
                                cam,
                                rays: &rays,
                                slices,
                                settings,
                                view,
                                x,
                                y,
                                centre: rays.ray(x as f32 + 0.5, y as f32 + 0.5),
                                shading,
                                to_camera,
                            };
                            ctx.render(with_gt, scratch, &mut band);
                        }
                        let per_pixel = settings.samples_per_pixel(with_gt);
                        samples_done.fetch_add(w as u64 * per_pixel as u64, Ordering::Relaxed);
                    }
                    band
                },
            )
            .collect();
        assemble(w as usize, h as usize, bands, with_gt)
    }
}

/// The position of `view` in the camera grid, in view steps from the centre view.
fn grid_position(cam: &LightFieldCamera, view: u32) -> Vec2 {
    let (u, v) = cam.view_offset(view);
    Vec2::new(u as f32, v as f32)
}

/// The rotation from world to camera frame: x right, y up, z towards the camera (every view
/// shares the centre camera's orientation).
fn camera_frame(cam: &LightFieldCamera) -> Mat3 {
    let (right, up, back) = (cam.right(), cam.up, -cam.forward);
    Mat3::from_cols(right.as_vec3(), up.as_vec3(), back.as_vec3()).transpose()
}

/// Joins bands (in row order) into the view's image and ground truth.
fn assemble(width: usize, height: usize, bands: Vec<Band>, with_gt: bool) -> ViewOutput {
    let mut pixels = Vec::with_capacity(width * height);
    let mut modes = ModeMap::new(width, height);
    let (mut colors, mut surfaces, mut valid, mut refined) = (vec![], vec![], vec![], 0);
    let mut hci = HciLayer {
        width,
        ..HciLayer::default()
    };
    for band in bands {
        refined += band.refined;
        pixels.extend(band.pixels);
        let mut start = 0;
        for n in band.mode_counts {
            modes.push_pixel(&band.modes[start..start + n as usize]);
            start += n as usize;
        }
        colors.extend(band.colors);
        surfaces.extend(band.surfaces);
        hci.append(band.hci);
        valid.extend(band.valid);
    }
    hci.height = height;
    let gt = with_gt.then_some(ViewGt {
        modes,
        colors,
        surfaces,
        hci,
        valid,
    });
    ViewOutput {
        image: ViewImage {
            width,
            height,
            pixels,
            refined,
        },
        gt,
    }
}

/// One pixel's render inputs.
struct PixelCtx<'a> {
    scene: &'a RenderScene,
    cam: &'a LightFieldCamera,
    rays: &'a ViewRays,
    slices: &'a SliceRange,
    settings: &'a RenderSettings,
    view: u32,
    x: u32,
    y: u32,
    /// The ray through the pixel centre (HCI depth, slice snapping), computed once per pixel.
    centre: CameraRay,
    shading: Shading<'a>,
    /// World to camera frame ([`camera_frame`]), for normals.
    to_camera: Mat3,
}

impl PixelCtx<'_> {
    fn render(&self, with_gt: bool, scratch: &mut Scratch, band: &mut Band) {
        let s = self.settings;
        // The colour's rays carry the GT too, unless the GT has its own sample count.
        let gt_inline = with_gt && gt_own_spp(s.spp, s.gt_spp) == 0;
        if with_gt {
            let (centre, geo) = (self.centre, &self.scene.geometry);
            geo.all_hits(
                centre.origin,
                centre.dir,
                f32::INFINITY,
                &mut scratch.centre_hits,
            );
        }
        // A GT view takes its colour's first hits from the all-hits trace either way, so its
        // image does not depend on `gt_spp` (the closest-hit query can pick the other one of
        // two coincident faces).
        let first = self.samples(s.scene_index, s.spp, with_gt, gt_inline, scratch);
        let (mut sum, mut n) = (first.sum, s.spp);
        if s.adaptive.wants_more(&first, s.spp) {
            band.refined += 1;
            // Colour only: the GT keeps its own fixed count, so η does not depend on noise.
            let extra = s.adaptive.extra;
            let stream = s.scene_index ^ ADAPTIVE_STREAM;
            sum += self.samples(stream, extra, with_gt, false, scratch).sum;
            n += extra;
        }
        if with_gt && !gt_inline {
            self.samples(s.scene_index ^ GT_STREAM, s.gt_spp, true, true, scratch);
        }
        band.pixels.push(sum / n as f32);
        if with_gt {
            self.finish_gt(scratch, band);
        }
    }

    /// The pixel's modes, their surfaces, its HCI layer and validity, from the accumulated
    /// hits and the pixel-centre ray.
    fn finish_gt(&self, scratch: &mut Scratch, band: &mut Band) {
        let before = band.modes.len();
        let cam = self.cam;
        let translucent_z = scratch.acc.finish_pixel(
            |z| cam.disparity(z),
            self.settings.mode_epsilon,
            &mut band.modes,
            &mut band.colors,
            &mut band.surfaces,
        );
        band.mode_counts.push((band.modes.len() - before) as u32);
        let first = self.hci_hit(&scratch.centre_hits, self.centre.dir);
        let depth = first.map_or(f32::NAN, |h| h.t);
        let surface = first.map_or(ModeSurface::NONE, |h| {
            let (normal, ids) = self.surface(&h, self.centre.dir);
            mode_surface(normal, ids)
        });
        band.hci.push(depth, surface);
        let modes = &band.modes[before..];
        band.valid.push(is_valid(modes, translucent_z, depth));
    }

    /// Traces `n` stratified camera samples of the pixel from the streams of `stream`
    /// (camera: pixel positions and transparency keys; path: its own) and returns the sum of
    /// their radiance and of its squares. With `all_hits` each sample ray collects every surface and the path
    /// starts from the first it keeps; with `gt` those hits also go into the slice accumulator.
    fn samples(
        &self,
        stream: u64,
        n: u32,
        all_hits: bool,
        gt: bool,
        scratch: &mut Scratch,
    ) -> Moments {
        let s = self.settings;
        let (view, x, y) = (self.view, self.x, self.y);
        let mut camera = Sampler::new(s.seed, stream, view, x, y, n);
        let mut sampler = Sampler::new(s.seed, stream ^ PATH_STREAM, view, x, y, 1);
        let mut moments = Moments::default();
        for i in 0..n {
            sampler.start_sample(i);
            let off = camera.pixel_offset(i);
            let ray = self.rays.ray(x as f32 + off.x, y as f32 + off.y);
            let key = camera.next_key();
            let radiance = if all_hits {
                self.sample_all_hits(ray.origin, ray.dir, key, &mut sampler, scratch, gt)
            } else if self.composites() {
                let (geo, mats) = (&self.scene.geometry, &self.scene.materials);
                let next = |after: Option<&Hit>| geo.next_layer(mats, ray.origin, ray.dir, after);
                self.composite(ray.origin, ray.dir, &mut sampler, next, &mut scratch.layers)
            } else {
                let first = self.scene.geometry.closest(
                    &self.scene.materials,
                    ray.origin,
                    ray.dir,
                    f32::INFINITY,
                    key,
                );
                let traced = (self.scene).trace(
                    &s.path,
                    ray.origin,
                    ray.dir,
                    first,
                    &mut sampler,
                    self.shading,
                );
                traced.radiance
            };
            moments.add(radiance);
        }
        moments
    }

    /// Traces every hit of a sample ray and returns the radiance of the surface the colour
    /// path continues from (the first kept by stochastic transparency); with `gt` the hits
    /// also go into the slice accumulator.
    fn sample_all_hits(
        &self,
        origin: Vec3,
        dir: Vec3,
        key: RayKey,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
        gt: bool,
    ) -> Vec3 {
        let centre = self.centre;
        let (scene, geo, mats) = (self.scene, &self.scene.geometry, &self.scene.materials);
        let centre_hits = &scratch.centre_hits;
        geo.all_hits(origin, dir, f32::INFINITY, &mut scratch.hits);
        let path = &self.settings.path;
        let (radiance, first) = match self.composites() {
            true => {
                let mut rest = scratch.hits.iter();
                let next = |_: Option<&Hit>| rest.find(|h| geo.hit_opacity(mats, h) > 0.0).copied();
                let layers = &mut scratch.layers;
                (self.composite(origin, dir, sampler, next, layers), None)
            }
            false => {
                let first = scratch.hits.iter().position(|h| geo.accepts(mats, h, key));
                let first_hit = first.map(|i| scratch.hits[i]);
                let traced = scene.trace(path, origin, dir, first_hit, sampler, self.shading);
                (traced.radiance, first)
            }
        };
        if !gt {
            return radiance;
        }
        let layer = |h: &Hit| (scratch.layers.iter()).find(|l| l.0.t == h.t && l.0.tri == h.tri);
        scratch.slice_hits.clear();
        for (i, h) in scratch.hits.iter().enumerate() {
            let shaded = match self.settings.shade_all_hits {
                true if Some(i) == first => Some(radiance),
                // A composited layer was shaded already; hidden surfaces draw from their own
                // stream so the colour image stays the same.
                true => layer(h).map(|l| l.1).or_else(|| {
                    Some(scene.radiance(
                        path,
                        origin,
                        dir,
                        Some(*h),
                        &mut Sampler::from_key(key.stream() ^ i as u64),
                    ))
                }),
                false => None,
            };
            let slice = self.slice_of(h, centre.origin, centre.dir, centre_hits);
            let (normal, ids) = self.surface(h, dir);
            scratch.slice_hits.push(SliceHit {
                slice,
                z: h.t,
                coverage: geo.coverage(mats, h, dir),
                radiance: shaded,
                normal,
                ids,
                translucent: self.translucent(h),
            });
        }
        scratch.acc.add_sample(&scratch.slice_hits);
        if !self.settings.shade_all_hits {
            // The colour goes to the slice of the surface it came from: a composited ray's
            // layers each to their own, weighted by their share of the pixel.
            if let Some(i) = first {
                (scratch.acc).add_color(scratch.slice_hits[i].slice, radiance, 1.0);
            }
            for &(h, light, weight) in &scratch.layers {
                let slice = self.slice_of(&h, centre.origin, centre.dir, centre_hits);
                scratch.acc.add_color(slice, light, weight);
            }
        }
        radiance
    }

    /// Whether camera rays composite semi-transparent surfaces (shared shading) rather than
    /// keep one stochastically (the independent reference estimator).
    fn composites(&self) -> bool {
        matches!(self.shading, Shading::Read { .. })
    }

    /// Radiance along a camera ray with its semi-transparent surfaces composited front to
    /// back by the over operator, `Σ T_k a_k L_k` with `T_k = Π_{j<k} (1 − a_j)`, instead of
    /// one kept per sample with probability `a` (stochastic transparency). Both have the same
    /// expectation; the composite has no variance from the choice. That variance is large
    /// where a bright surface lies behind a faint one (a bulb behind a lampshade: the pixel
    /// takes 50× diffuse white or the shade's own light), and costs little to remove once
    /// shading a layer is a cache lookup. `next(after)` gives the layer behind `after`;
    /// `layers` receives each layer's hit, radiance and weight `T_k a_k`.
    fn composite(
        &self,
        origin: Vec3,
        dir: Vec3,
        sampler: &mut Sampler,
        mut next: impl FnMut(Option<&Hit>) -> Option<Hit>,
        layers: &mut Vec<(Hit, Vec3, f32)>,
    ) -> Vec3 {
        let (scene, path) = (self.scene, &self.settings.path);
        layers.clear();
        let (mut sum, mut transmitted, mut after) = (Vec3::ZERO, 1.0f32, None);
        for _ in 0..MAX_LAYERS {
            let hit = next(after.as_ref());
            let light = (scene.trace(path, origin, dir, hit, sampler, self.shading)).radiance;
            let Some(h) = hit else {
                sum += transmitted * light;
                break;
            };
            let a = scene.geometry.hit_opacity(&scene.materials, &h).min(1.0);
            layers.push((h, light, transmitted * a));
            sum += transmitted * a * light;
            transmitted *= 1.0 - a;
            if transmitted <= 0.0 {
                break;
            }
            after = Some(h);
        }
        sum
    }

    /// Slice of a hit. With surface slicing it is the slice of the hit's *surface* at the pixel
    /// centre: the depth where the pixel-centre ray meets the hit triangle's plane (the hit's
    /// own depth for a plane seen nearly edge-on), snapped to the pixel-centre ray's hit on the
    /// same object when that lies within [`SNAP_TOLERANCE`] of the plane depth or of the hit
    /// depth — so the faces of one object meeting
    /// at a crease inside the pixel, and the facets of a tessellated curve, stay one layer.
    /// Otherwise the hit depth itself decides (literal camera-side clipping).
    fn slice_of(&self, h: &Hit, origin: Vec3, centre_dir: Vec3, centre_hits: &[Hit]) -> u32 {
        if self.settings.slice_assignment == SliceAssignment::Sample {
            return self.slices.index(h.t) as u32;
        }
        let geo = &self.scene.geometry;
        let plane = geo.plane_distance(h.tri, origin, centre_dir);
        let z = plane
            .filter(|z| *z > 0.5 * h.t && *z < 2.0 * h.t)
            .unwrap_or(h.t);
        let object = geo.shading[h.tri as usize].object;
        let snapped = centre_hits
            .iter()
            .filter(|c| geo.shading[c.tri as usize].object == object)
            .map(|c| c.t)
            .map(|c| (c, (c - z).abs().min((c - h.t).abs())))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .filter(|(c, gap)| *gap <= SNAP_TOLERANCE * c)
            .map(|(c, _)| c);
        let z = snapped.unwrap_or(z);
        self.slices.index(z) as u32
    }

    /// HCI semantics: the first surface with coverage ≥ 0.5 on the pixel-centre ray.
    fn hci_hit(&self, centre_hits: &[Hit], dir: Vec3) -> Option<Hit> {
        self.scene.hci_hit(centre_hits, dir)
    }

    /// A hit's geometric normal in the camera frame, turned to face the camera, and its ids.
    fn surface(&self, h: &Hit, dir: Vec3) -> (Vec3, SurfaceIds) {
        self.scene.hit_surface(h, dir, &self.to_camera)
    }

    /// Whether what lies behind the hit shows through it: glass, or a coverage strictly
    /// between 0 and 1.
    fn translucent(&self, h: &Hit) -> bool {
        let (geo, mats) = (&self.scene.geometry, &self.scene.materials);
        let a = geo.hit_opacity(mats, h);
        let material = &mats[geo.shading[h.tri as usize].material as usize];
        material.glass_ior.is_some() || (a > 0.0 && a < 1.0)
    }
}

/// A mode surface of a single hit.
fn mode_surface(normal: Vec3, ids: SurfaceIds) -> ModeSurface {
    ModeSurface {
        normal: normal.to_array(),
        object: ids.object,
        material: ids.material,
        class: ids.class,
    }
}

impl RenderScene {
    /// The HCI layer of `view` on a grid `scale` times finer in each direction, from the
    /// pixel-centre rays of the finer grid: the HCI add-on's high-resolution ground truth
    /// (`depth_map_scale`). Row after row in parallel; the same for any thread count.
    pub fn render_hci_layer(&self, cam: &LightFieldCamera, view: u32, scale: u32) -> HciLayer {
        let rays = cam.view_rays(view);
        let to_camera = camera_frame(cam);
        let (w, h) = (cam.width() * scale, cam.height() * scale);
        let fine = |i: u32| (i as f32 + 0.5) / scale as f32;
        let rows: Vec<HciLayer> = (0..h)
            .into_par_iter()
            .map_init(Vec::new, |hits, y| {
                let mut row = HciLayer::default();
                for x in 0..w {
                    let ray = rays.ray(fine(x), fine(y));
                    self.geometry
                        .all_hits(ray.origin, ray.dir, f32::INFINITY, hits);
                    let first = self.hci_hit(hits, ray.dir);
                    let surface = first.map_or(ModeSurface::NONE, |h| {
                        let (normal, ids) = self.hit_surface(&h, ray.dir, &to_camera);
                        mode_surface(normal, ids)
                    });
                    row.push(first.map_or(f32::NAN, |h| h.t), surface);
                }
                row.height = 1;
                row
            })
            .collect();
        let mut layer = HciLayer {
            width: w as usize,
            ..HciLayer::default()
        };
        rows.into_iter().for_each(|row| layer.append(row));
        layer
    }

    /// HCI semantics: the first of `hits` (sorted front to back, along `dir`) with coverage
    /// ≥ 0.5.
    fn hci_hit(&self, hits: &[Hit], dir: Vec3) -> Option<Hit> {
        let (geo, mats) = (&self.geometry, &self.materials);
        hits.iter()
            .find(|h| geo.coverage(mats, h, dir) >= 0.5)
            .copied()
    }

    /// A hit's geometric normal turned to face the ray's origin, rotated by `to_camera`, and
    /// the ids of its object, material and class.
    fn hit_surface(&self, h: &Hit, dir: Vec3, to_camera: &Mat3) -> (Vec3, SurfaceIds) {
        let n = self.geometry.geometric_normal(h.tri);
        let n = if n.dot(dir) > 0.0 { -n } else { n };
        let s = &self.geometry.shading[h.tri as usize];
        let ids = SurfaceIds {
            object: s.object + 1,
            material: s.material + 1,
            class: self.classes[s.object as usize],
        };
        (*to_camera * n, ids)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn moments(samples: &[f32]) -> Moments {
        let mut m = Moments::default();
        samples.iter().for_each(|&v| m.add(Vec3::splat(v)));
        m
    }

    /// Samples 0, 0, 0, 4 (grey): mean 1, sample variance (1 + 1 + 1 + 9) / 3 = 4, standard
    /// error √(4 / 4) = 1 per channel, 3 over RGB, over √3 of brightness: √3 ≈ 1.732. At a
    /// quarter of the display scale the error and brightness shrink 4×, the ratio 2×.
    #[test]
    fn the_noise_test_matches_hand_computed_values() {
        let m = moments(&[0.0, 0.0, 0.0, 4.0]);
        let at = |threshold, display_scale| Adaptive {
            extra: 8,
            threshold,
            display_scale,
        };
        assert!(at(1.73, 1.0).wants_more(&m, 4));
        assert!(!at(1.74, 1.0).wants_more(&m, 4));
        assert!(at(0.86, 0.25).wants_more(&m, 4));
        assert!(!at(0.87, 0.25).wants_more(&m, 4));
        // Off, a single sample (no variance estimate), or no noise at all: never.
        assert!(
            !Adaptive {
                extra: 0,
                ..at(0.0, 1.0)
            }
            .wants_more(&m, 4)
        );
        assert!(!at(0.0, 1.0).wants_more(&moments(&[4.0]), 1));
        assert!(!at(0.0, 1.0).wants_more(&moments(&[0.5; 4]), 4));
    }
}

//! Unidirectional path tracing with next-event estimation, MIS (power heuristic), Russian
//! roulette and stochastic transparency. Punctual lights are sampled at every vertex, all of
//! them, deterministically (no random numbers, so scenes without them draw the same streams).

use super::RenderScene;
use super::bsdf::{Bsdf, BsdfSample, Frame, Lobes, power_heuristic};
use super::cache::{Anchor, COARSER, CacheGrid, Estimate, MAX_FILL_VERTICES, RadianceCache};
use super::geometry::Hit;
use super::sampler::Sampler;
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// How light that passes through smooth glass reaches the surfaces behind it. Next-event
/// estimation cannot see a light through a refracting surface, so without help that light
/// arrives only by BSDF-sampled paths that happen to refract into a light: refractive
/// caustics, the grain under glass tables and behind glass shelves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GlassLight {
    /// Unbiased: light through glass only by refractive caustic paths (noisy there).
    #[default]
    Caustics,
    /// Shadow rays pass straight through smooth glass, weighted by its tint and `1 − F` at
    /// each interface, and light reached by refraction after a surface vertex is dropped (that
    /// vertex's light sample took it): the "architectural glass" of production renderers. The
    /// bias: refraction's offset and focusing are ignored (exact for a pane with parallel
    /// faces up to its internal reflections, off for curved or thick glass).
    Shadows,
    /// Refractive caustics dropped and glass opaque to shadow rays, as Cycles' "refractive
    /// caustics" switched off: what is lit only through glass goes dark.
    Off,
}

/// Path-tracing limits, and the texture filter of camera paths.
#[derive(Clone, Copy, Debug)]
pub struct PathSettings {
    pub max_depth: u32,
    pub rr_depth: u32,
    /// Width of the texture filter per metre of camera-ray length (0: no filtering). Library
    /// textures seen by camera paths (directly or through smooth glass) are averaged over
    /// this times the path's length — pbrt-v4's choice: a pixel's footprint scaled by
    /// `max(1/8, 1/√spp)`, the width of one sample's stratum, so the sub-pixel samples still
    /// integrate the pixel while the texture detail inside each stratum, which they would
    /// only alias, is averaged instead.
    pub footprint: f32,
    /// Light through smooth glass (see [`GlassLight`]).
    pub glass_light: GlassLight,
    /// With shared shading, trace both the reflection and the refraction of smooth glass a
    /// camera ray meets, each with its Fresnel weight, instead of choosing one with that
    /// probability ([`RenderScene::reflection`]). Unbiased either way.
    pub split_glass: bool,
}

/// Offset for spawning rays off a surface, relative to the scene scale.
const RAY_EPS: f32 = 1e-4;

/// How the path arrived at the current vertex (for MIS on emitters).
#[derive(Clone, Copy)]
struct Arrival {
    pdf: f32,
    is_delta: bool,
    /// The vertex the path left: light selection depends on the shading point.
    from: Vec3,
}

/// Where a traced path starts: a camera path at loop depth 0, or the reflection branch of its
/// glass ([`RenderScene::reflection`]) one vertex later.
#[derive(Clone, Copy)]
struct Start {
    origin: Vec3,
    dir: Vec3,
    /// The first surface, from the caller's traversal (`None`: the ray escaped).
    first: Option<Hit>,
    depth: u32,
    /// Camera-ray length before the start (the texture filter's footprint grows with it).
    camera_length: f32,
    /// Whether smooth glass on the camera ray is split into its two branches.
    split: bool,
}

/// How a camera path treats its first non-delta vertex (see [`super::cache`]).
#[derive(Clone, Copy)]
pub enum Shading<'a> {
    /// Every lobe traced by every path: the reference estimator.
    Independent,
    /// Estimate the coupled irradiance there, or where the lobe is shared the glossy term
    /// (see [`super::cache`]), and end: one sample for the shared cache.
    Fill(&'a CacheGrid),
    /// Diffuse light from the cache; the glossy lobe too where the cache shares it, else
    /// traced by this path. `view`: the view's position in the grid ([`Shading::seen_from`]).
    Read {
        cache: &'a RadianceCache,
        view: Vec2,
    },
    /// A final gather: as `Fill` at the first non-delta vertex, whose estimate then reads
    /// `prior` at the path's next non-delta vertex as `Read` does (the path traces on where
    /// `prior` has no cell). Its light beyond that vertex is the prior's smooth value, not
    /// one more path's noise, so the estimate has about half a fill path's variance; it adds
    /// no later-vertex estimates. `view` as for `Read`.
    Gather {
        grid: &'a CacheGrid,
        prior: &'a RadianceCache,
        view: Vec2,
    },
}

impl<'a> Shading<'a> {
    /// Reading `cache` (the view is set by the view's render).
    pub fn read(cache: &'a RadianceCache) -> Self {
        Self::Read {
            cache,
            view: Vec2::ZERO,
        }
    }

    /// This shading for the view at grid position `view` (view steps from the centre).
    pub fn seen_from(self, view: Vec2) -> Self {
        match self {
            Self::Read { cache, .. } => Self::Read { cache, view },
            Self::Gather { grid, prior, .. } => Self::Gather { grid, prior, view },
            other => other,
        }
    }
}

/// A surface vertex of a path, as the light samples need it.
struct Vertex<'a> {
    p: Vec3,
    hit: &'a Hit,
    frame: &'a Frame,
    wo_l: Vec3,
    bsdf: &'a Bsdf,
    /// Shadow rays pass through smooth glass ([`GlassLight::Shadows`]).
    through_glass: bool,
}

/// What a traced path found.
pub struct Traced {
    pub radiance: Vec3,
    /// With [`Shading::Fill`] or [`Shading::Gather`]: the cells (one per level) of the first
    /// non-delta vertex, the estimate made there and where it lies (none if the path never
    /// reached one).
    pub fill: Option<([u64; COARSER + 1], Estimate, Anchor)>,
    /// With [`Shading::Fill`]: the coupled irradiance estimated at later surface vertices.
    pub later: Later,
}

/// The cells of one later vertex of a fill path, and its coupled irradiance estimate.
#[derive(Clone, Copy, Default)]
struct LaterVertex {
    cells: [u64; COARSER + 1],
    /// The path's throughput since this vertex, for the coupled-irradiance integrand.
    weight: Vec3,
    irradiance: Vec3,
    /// The loop depth whose vertex only adds the light it hits to this estimate.
    last: u32,
}

/// Coupled-irradiance estimates a fill path makes at its later surface vertices
/// ([`super::cache::CacheSums::add_later`]). Each is the path's own estimator with the
/// vertex's BSDF replaced by the coupled-irradiance integrand `(1 − E(μi))`: the same light
/// sample (its MIS weight against the BSDF pdf the path really sampled), and the same
/// continuation, weighted by the integrand over that pdf. So the light the path gathers after
/// a vertex is added to it with its own throughput. Allocation-free: at most
/// [`MAX_FILL_VERTICES`] − 1.
#[derive(Clone, Copy, Default)]
pub struct Later {
    vertices: [LaterVertex; MAX_FILL_VERTICES as usize - 1],
    len: usize,
}

impl Later {
    /// The estimates: cells and coupled irradiance.
    pub fn estimates(&self) -> impl Iterator<Item = (&[u64; COARSER + 1], Vec3)> {
        self.vertices[..self.len]
            .iter()
            .map(|v| (&v.cells, v.irradiance))
    }

    /// Light `l` a vertex at `depth` samples (light samples, with the path's throughput so
    /// far) counts for every estimate it has not ended for, with theirs.
    fn gather(&mut self, l: Vec3, depth: u32) {
        for v in self.vertices[..self.len].iter_mut() {
            if depth < v.last {
                v.irradiance += v.weight * l;
            }
        }
    }

    /// Light `l` the path hits on arriving at `depth` (an emitter, the environment).
    fn arrive(&mut self, l: Vec3, depth: u32) {
        for v in self.vertices[..self.len].iter_mut() {
            if depth <= v.last {
                v.irradiance += v.weight * l;
            }
        }
    }

    /// Whether an estimate still gathers light past the vertex at `depth`.
    fn open_beyond(&self, depth: u32) -> bool {
        self.vertices[..self.len].iter().any(|v| depth < v.last)
    }

    /// The largest throughput of the estimates that gather past `depth`.
    fn weight_beyond(&self, depth: u32) -> f32 {
        (self.vertices[..self.len].iter())
            .filter(|v| depth < v.last)
            .map(|v| v.weight.max_element())
            .fold(0.0, f32::max)
    }

    /// Every open estimate's throughput times `f`, as the path's.
    fn scale(&mut self, f: Vec3) {
        for v in &mut self.vertices[..self.len] {
            v.weight *= f;
        }
    }

    /// A new estimate at a vertex with cells `cells`, its light sample's share `direct` (its
    /// throughput is set once the path has sampled its continuation), gathering up to the
    /// vertex at loop depth `last`.
    fn open(&mut self, cells: [u64; COARSER + 1], direct: Vec3, last: u32) {
        self.vertices[self.len] = LaterVertex {
            cells,
            weight: Vec3::ZERO,
            irradiance: direct,
            last,
        };
        self.len += 1;
    }

    /// The throughput of the estimate opened last, once its vertex sampled its continuation.
    fn weigh_newest(&mut self, weight: Vec3) {
        self.vertices[self.len - 1].weight = weight;
    }
}

/// A later vertex opens an estimate only where the path samples its diffuse lobe at least
/// half the time: the estimate weighs the path's continuation by the integrand over the whole
/// BSDF's pdf, at most `π (1 − E) / (1 − q)` for a glossy share `q`, which a dark diffuse
/// under a bright lobe would blow up into fireflies in the cell.
const LATER_MAX_GLOSSY: f32 = 0.5;

/// What a path's role ([`Shading`]) fixes for all its vertices.
struct Role<'a> {
    /// The grid of a fill path, whose later vertices open estimates of their own (a
    /// gathering path's do not: their light is the prior's).
    fill_grid: Option<&'a CacheGrid>,
    /// The cache a reading (or gathering) path reads, and the view it is seen from.
    read: Option<(&'a RadianceCache, Vec2)>,
    /// The most later-vertex estimates the path opens.
    later_max: usize,
    /// Light reached by refraction after a surface vertex is dropped ([`GlassLight`]).
    drop_caustics: bool,
    /// Shadow rays pass through smooth glass ([`GlassLight::Shadows`]).
    through_glass: bool,
}

impl<'a> Role<'a> {
    fn of(shading: Shading<'a>, settings: &PathSettings) -> Self {
        let (fill_grid, read) = match shading {
            Shading::Independent => (None, None),
            Shading::Fill(grid) => (Some(grid), None),
            Shading::Read { cache, view } => (None, Some((cache, view))),
            Shading::Gather { grid, prior, view } => (Some(grid), Some((prior, view))),
        };
        let later_max = match shading {
            Shading::Fill(grid) => grid.fill_vertices as usize - 1,
            _ => 0,
        };
        Self {
            fill_grid,
            read,
            later_max,
            drop_caustics: settings.glass_light != GlassLight::Caustics,
            through_glass: settings.glass_light == GlassLight::Shadows,
        }
    }
}

/// What a path carries from vertex to vertex.
struct PathState {
    radiance: Vec3,
    /// Throughput.
    beta: Vec3,
    arrival: Arrival,
    /// The shared cache still has its part at the next non-delta vertex ([`RenderScene::first_vertex`]).
    pending: bool,
    /// A fill path's estimate: its cells, whether it is the glossy term, where it lies.
    fill: Option<([u64; COARSER + 1], bool, Anchor)>,
    later: Later,
    /// The loop depth of the fill's first vertex.
    first_depth: u32,
    /// Camera-ray length so far while only delta vertices were passed (texture filter).
    camera_length: Option<f32>,
    /// Whether the path left a surface vertex (one with a light sample) and has refracted
    /// through glass since: light it reaches now is a refractive caustic.
    left_surface: bool,
    refracted: bool,
    /// The coupled-irradiance share of the current vertex's light samples ([`Later`]).
    direct: Vec3,
}

impl PathState {
    fn new(start: &Start, shading: Shading) -> Self {
        Self {
            radiance: Vec3::ZERO,
            beta: Vec3::ONE,
            arrival: Arrival {
                pdf: 0.0,
                is_delta: true,
                from: start.origin,
            },
            pending: !matches!(shading, Shading::Independent),
            fill: None,
            later: Later::default(),
            first_depth: 0,
            camera_length: Some(start.camera_length),
            left_surface: false,
            refracted: false,
            direct: Vec3::ZERO,
        }
    }

    /// Light `l` the path hits on arriving at loop depth `depth` (an emitter, the
    /// environment): its own while it `arrives`, and its open estimates'.
    fn arrive(&mut self, l: Vec3, depth: u32, arrives: bool) {
        if arrives {
            self.radiance += self.beta * l;
        }
        self.later.arrive(l, depth);
    }

    /// A light sample's light `l` and coupled share `coupled` at a vertex at `depth`, one of
    /// the path's `own` or serving only its open estimates.
    fn gather(&mut self, l: Vec3, coupled: Vec3, depth: u32, own: bool) {
        if own {
            self.radiance += self.beta * l;
        }
        self.later.gather(l, depth);
        self.direct += coupled;
    }

    /// Notes the lobe `bs` the path took at a vertex (delta or not) seen from `wo_l`.
    fn passed(&mut self, bs: &BsdfSample, vertex_is_delta: bool, wo_l: Vec3) {
        if !bs.is_delta {
            self.camera_length = None;
        }
        if vertex_is_delta {
            self.refracted |= self.left_surface && bs.wi.z * wo_l.z < 0.0;
        } else {
            (self.left_surface, self.refracted) = (true, false);
        }
    }

    /// Russian roulette after the vertex at `depth`; false ends the path. It keeps the path as
    /// likely as its largest weight asks, the open estimates' included: their weight is not
    /// the path's (it restarts at each).
    fn roulette(&mut self, depth: u32, own: bool, sampler: &mut Sampler) -> bool {
        let own_weight = if own { self.beta.max_element() } else { 0.0 };
        let survive = own_weight.max(self.later.weight_beyond(depth)).min(0.95);
        if sampler.next_f32() >= survive {
            return false;
        }
        self.beta /= survive;
        self.later.scale(Vec3::splat(survive.recip()));
        true
    }

    fn traced(self) -> Traced {
        let radiance = self.radiance;
        let estimate = |glossy| match glossy {
            true => Estimate::Glossy(radiance),
            false => Estimate::Irradiance(radiance),
        };
        Traced {
            radiance,
            fill: (self.fill).map(|(cells, glossy, at)| (cells, estimate(glossy), at)),
            later: self.later,
        }
    }
}

/// A surface vertex as the path met it.
struct Surface {
    p: Vec3,
    material: u32,
    bsdf: Bsdf,
    frame: Frame,
    wo_l: Vec3,
}

/// How a vertex is shaded.
struct Plan {
    /// The lobes its light samples and continuation take.
    lobes: Lobes,
    /// Probability that it continues by BSDF sampling (below 1 only for the glossy lobe of a
    /// cached vertex): the BSDF strategy's pdf for MIS is scaled by it.
    select: f32,
    /// Light samples it averages (more only at a fill path's first vertex).
    light_samples: u32,
    /// It opens a later-vertex estimate of its own ([`Later`]).
    opens: bool,
    /// It is one of the path's own vertices (else it serves only the open estimates).
    own: bool,
}

/// What the shared cache leaves a path to do at its first non-delta vertex.
enum First {
    /// Nothing: the cache holds all its light.
    Done,
    /// Shade it with these lobes, selection probability and light samples ([`Plan`]).
    Shade(Lobes, f32, u32),
}

/// What a path's continuation needs besides the vertex.
struct Scatter<'a> {
    settings: &'a PathSettings,
    /// Smooth glass on the camera ray is split into its two branches ([`Start::split`]).
    split: bool,
    shading: Shading<'a>,
    plan: &'a Plan,
    depth: u32,
}

impl RenderScene {
    /// Radiance arriving along `dir` at `origin`, given the first surface already chosen
    /// (`first`, from the caller's traversal; `None` means the ray escaped).
    pub fn radiance(
        &self,
        settings: &PathSettings,
        origin: Vec3,
        dir: Vec3,
        first: Option<Hit>,
        sampler: &mut Sampler,
    ) -> Vec3 {
        let shading = Shading::Independent;
        (self.trace(settings, origin, dir, first, sampler, shading)).radiance
    }

    /// [`Self::radiance`] with the first non-delta vertex shaded as `shading` says.
    pub fn trace(
        &self,
        settings: &PathSettings,
        origin: Vec3,
        dir: Vec3,
        first: Option<Hit>,
        sampler: &mut Sampler,
        shading: Shading,
    ) -> Traced {
        let start = Start {
            origin,
            dir,
            first,
            depth: 0,
            camera_length: 0.0,
            split: settings.split_glass && matches!(shading, Shading::Read { .. }),
        };
        self.trace_from(settings, start, sampler, shading)
    }

    /// [`Self::trace`] of a path that starts at loop depth `start.depth`: a camera path, or
    /// the reflection branch of a camera path's glass ([`Self::reflection`]). Each pass of the
    /// loop is one vertex: the light the path arrives with ([`PathState::arrive`]), the shared
    /// cache's part at the first non-delta vertex ([`Self::first_vertex`]), next-event
    /// estimation ([`Self::next_event`]) and the continuation ([`Self::scatter`]).
    fn trace_from(
        &self,
        settings: &PathSettings,
        start: Start,
        sampler: &mut Sampler,
        shading: Shading,
    ) -> Traced {
        let role = Role::of(shading, settings);
        let mut path = PathState::new(&start, shading);
        let (mut origin, mut dir, mut hit) = (start.origin, start.dir, start.first);
        // One pass more than `max_depth` vertices: the last vertex's BSDF-sampled ray only
        // picks up the light it hits, the MIS partner of that vertex's light sample (as pbrt
        // and Mitsuba do). A light sample taking all the direct light alone instead would be
        // unbiased too, but fires on glossy surfaces: its pdf knows nothing of the lobe.
        // Past it the path goes on only for the estimates of its later vertices (each as many
        // vertices beyond its own as the fill's first vertex has).
        for depth in start.depth.. {
            sampler.start_vertex(depth);
            // Whether the path's own estimate still takes the light it reaches here.
            let arrives = depth <= settings.max_depth;
            let Some(h) = hit else {
                path.arrive(self.environment, depth, arrives);
                break;
            };
            if !(role.drop_caustics && path.refracted) {
                path.arrive(self.emitted(&h, dir, path.arrival), depth, arrives);
            }
            // Whether this vertex is one of the path's own (else it serves the open estimates).
            let own = depth < settings.max_depth;
            if !own && !path.later.open_beyond(depth) {
                break;
            }
            let surface = self.surface(settings, &h, origin, dir, &mut path.camera_length);
            let (bsdf, wo_l) = (&surface.bsdf, surface.wo_l);
            // A later vertex of a fill path that estimates its coupled irradiance too.
            let opens = own
                && path.fill.is_some()
                && path.later.len < role.later_max
                && !bsdf.is_delta()
                && wo_l.z > 0.0
                && bsdf.specular_probability(wo_l) <= LATER_MAX_GLOSSY;
            let mut plan = Plan {
                lobes: Lobes::All,
                select: 1.0,
                light_samples: 1,
                opens,
                own,
            };
            if path.pending && !bsdf.is_delta() {
                path.pending = false;
                let first = self.first_vertex(&role, &surface, depth, sampler, &mut path);
                match first {
                    First::Done => break,
                    First::Shade(lobes, select, light_samples) => {
                        (plan.lobes, plan.select, plan.light_samples) =
                            (lobes, select, light_samples)
                    }
                }
            }
            let vertex = Vertex {
                p: surface.p,
                hit: &h,
                frame: &surface.frame,
                wo_l,
                bsdf,
                through_glass: role.through_glass,
            };
            self.next_event(&vertex, &plan, depth, sampler, &mut path);
            if let (true, Some(grid)) = (opens, role.fill_grid) {
                let cells = grid.keys(surface.p, surface.frame.n, surface.material);
                let last = depth + settings.max_depth - path.first_depth;
                path.later.open(cells, path.direct, last);
            }
            let continuation = Scatter {
                settings,
                split: start.split,
                shading,
                plan: &plan,
                depth,
            };
            let Some(next) = self.scatter(&continuation, &vertex, sampler, &mut path) else {
                break;
            };
            (origin, dir) = next;
            hit = (self.geometry).closest(
                &self.materials,
                origin,
                dir,
                f32::INFINITY,
                sampler.next_key(),
            );
        }
        path.traced()
    }

    /// The surface a path meets at `h` on its ray from `origin` along `dir`, with its BSDF
    /// filtered over the camera ray's footprint while `camera_length` (the camera ray's length
    /// so far, while only delta vertices were passed) is known; it grows by this segment.
    fn surface(
        &self,
        settings: &PathSettings,
        h: &Hit,
        origin: Vec3,
        dir: Vec3,
        camera_length: &mut Option<f32>,
    ) -> Surface {
        let p = origin + dir * h.t;
        let material = self.geometry.shading[h.tri as usize].material;
        let mat = &self.materials[material as usize];
        let wo = -dir.normalize();
        let width = camera_length.map_or(0.0, |len| {
            let len = len + h.t * dir.length();
            *camera_length = Some(len);
            let cos = wo.dot(self.geometry.geometric_normal(h.tri)).abs();
            len * settings.footprint / cos.max(0.05).sqrt()
        });
        let bsdf = mat.surface_filtered(self.geometry.uv(h), width).bsdf();
        let frame = Frame::from_normal(self.shading_normal(h, wo, mat.glass_ior.is_some()));
        let wo_l = frame.to_local(wo);
        Surface {
            p,
            material,
            bsdf,
            frame,
            wo_l,
        }
    }

    /// The shared cache's part at a path's first non-delta vertex: a fill path opens its
    /// estimate there (and restarts its radiance and throughput: light before the vertex is
    /// not part of it), a reading path reads the cache (and ends where the cache holds all
    /// the vertex's light).
    fn first_vertex(
        &self,
        role: &Role,
        surface: &Surface,
        depth: u32,
        sampler: &mut Sampler,
        path: &mut PathState,
    ) -> First {
        let (p, n, bsdf, wo_l) = (surface.p, surface.frame.n, &surface.bsdf, surface.wo_l);
        let material = surface.material;
        let all = First::Shade(Lobes::All, 1.0, 1);
        // A fill path opens its estimate at its first such vertex; a reading path (a gathering
        // one at its next) reads there.
        match (role.fill_grid.filter(|_| path.fill.is_none()), role.read) {
            (None, None) => all,
            (Some(grid), _) => {
                // From here the path estimates I(p), or the shared glossy term.
                let glossy = self.fills_glossy(grid, p, bsdf, wo_l, sampler);
                let cells = grid.keys(p, n, material);
                path.fill = Some((cells, glossy, Anchor { p, n, material }));
                path.first_depth = depth;
                path.radiance = Vec3::ZERO;
                let lobes = match glossy {
                    true => {
                        let albedo = bsdf.specular_albedo(wo_l);
                        path.beta = albedo.max(Vec3::splat(1e-6)).recip();
                        Lobes::Specular
                    }
                    false => {
                        path.beta = Vec3::ONE;
                        Lobes::CoupledIrradiance
                    }
                };
                First::Shade(lobes, 1.0, grid.fill_light_samples)
            }
            (None, Some((cache, view))) => {
                let Some(c) = cache.lookup(p, n, material) else {
                    return all;
                };
                path.radiance += path.beta * bsdf.diffuse_out(wo_l) * c.irradiance;
                let q = bsdf.specular_probability(wo_l);
                if q <= 0.0 {
                    return First::Done;
                }
                let width = bsdf.glossy_width();
                if let Some(g) = c.glossy.filter(|_| cache.grid.shares_glossy(p, width)) {
                    path.radiance += path.beta * bsdf.specular_albedo(wo_l) * g.at(view);
                    return First::Done;
                }
                // The glossy lobe per view: its light sample always, its continuation as
                // often as the lobe matters.
                First::Shade(Lobes::Specular, q, 1)
            }
        }
    }

    /// Next-event estimation at `v`: the light samples of the emitters and every punctual
    /// light, added to the path's radiance (at its own vertices) and to its open estimates;
    /// where this vertex opens an estimate, the same samples' coupled-irradiance share goes to
    /// `path.direct`.
    fn next_event(
        &self,
        v: &Vertex,
        plan: &Plan,
        depth: u32,
        sampler: &mut Sampler,
        path: &mut PathState,
    ) {
        path.direct = Vec3::ZERO;
        if v.bsdf.is_delta() {
            return;
        }
        if !self.lights.is_empty() {
            let strategy = (plan.lobes, plan.select);
            let (mut l, mut coupled) = self.direct_light(v, strategy, plan.opens, sampler);
            if plan.light_samples > 1 {
                // The others from a side sequence of their own, stratified among themselves.
                // Each is the same MIS-weighted estimator, so their mean keeps the weights'
                // sum with the BSDF sample at one.
                let mut side = sampler.side(depth);
                for k in 1..plan.light_samples {
                    side.start_sample(k);
                    let (a, b) = self.direct_light(v, strategy, plan.opens, &mut side);
                    (l, coupled) = (l + a, coupled + b);
                }
                let n = plan.light_samples as f32;
                (l, coupled) = (l / n, coupled / n);
            }
            path.gather(l, coupled, depth, plan.own);
        }
        if !self.punctual_lights.is_empty() {
            let (l, coupled) = self.punctual_light(v, plan.lobes, plan.opens);
            path.gather(l, coupled, depth, plan.own);
        }
    }

    /// The path's continuation from `v`: the glossy lobe's selection, a BSDF sample (with
    /// split glass's reflection branch traced here), the throughput, the roulette; `None`
    /// where the path ends, else the next ray's origin and direction.
    fn scatter(
        &self,
        s: &Scatter,
        v: &Vertex,
        sampler: &mut Sampler,
        path: &mut PathState,
    ) -> Option<(Vec3, Vec3)> {
        let (plan, depth, bsdf, wo_l) = (s.plan, s.depth, v.bsdf, v.wo_l);
        if plan.select < 1.0 {
            if sampler.next_f32() >= plan.select {
                return None;
            }
            path.beta /= plan.select;
        }
        // Glass on the camera ray is split: the path always refracts, and the reflection is
        // traced as a branch of its own (see [`Self::reflection`]).
        let split = s.split && bsdf.is_delta() && path.camera_length.is_some();
        let u_lobe = sampler.next_f32();
        let u_lobe = if split { 1.0 } else { u_lobe };
        let bs = bsdf.sample_lobes(wo_l, u_lobe, sampler.next2(), plan.lobes)?;
        if bs.pdf <= 0.0 {
            return None;
        }
        let mut f = bs.f * bs.wi.z.abs() / bs.pdf;
        if split && bs.pdf < 1.0 {
            // Refraction was sampled with probability `pdf = 1 − F`; split, both branches
            // carry their throughput `f cos` instead of being chosen with their pdf.
            f *= bs.pdf;
            let length = path.camera_length.unwrap_or(0.0);
            let reflected = self.reflection(s.settings, v, depth, length, sampler, s.shading);
            path.radiance += path.beta * reflected;
        }
        path.beta *= f;
        path.later.scale(f);
        if plan.opens {
            let (coupling, _) = bsdf.eval_lobes(wo_l, bs.wi, Lobes::CoupledIrradiance);
            path.later.weigh_newest(coupling * bs.wi.z.abs() / bs.pdf);
        }
        path.passed(&bs, bsdf.is_delta(), wo_l);
        // A glossy continuation from a cached vertex reads the cache again at its next
        // non-delta vertex, as a camera path through glass does: only the lobe is per view.
        path.pending |= plan.lobes == Lobes::Specular && matches!(s.shading, Shading::Read { .. });
        // A gathering path reads the prior at its next non-delta vertex.
        path.pending |= matches!(s.shading, Shading::Gather { .. }) && depth == path.first_depth;
        path.arrival = Arrival {
            pdf: bs.pdf * plan.select,
            is_delta: bs.is_delta,
            from: v.p,
        };
        if depth + 1 >= s.settings.rr_depth && !path.roulette(depth, plan.own, sampler) {
            return None;
        }
        let dir = v.frame.to_world(bs.wi);
        Some((self.spawn(v.p, v.hit.tri, dir), dir))
    }

    /// Light the mirror reflection at glass `v` (loop depth `depth`, camera ray `length` long
    /// so far) brings back, times its throughput `F`: the branch of a split camera path.
    /// Choosing reflection with probability F, as the path does elsewhere, leaves the pixel
    /// to average how many of its samples took it; under a bright reflection (a window in a
    /// glass table) that count is most of the pixel's noise at 16 spp, and each view counts
    /// its own. Tracing both costs one ray and mostly one cache lookup. The branch continues
    /// at the depth the chosen reflection would have, splits no further, and draws from the
    /// dimensions of its own depths: the pixel's sequence resumes where it was for the path's
    /// own decisions.
    fn reflection(
        &self,
        settings: &PathSettings,
        v: &Vertex,
        depth: u32,
        length: f32,
        sampler: &mut Sampler,
        shading: Shading,
    ) -> Vec3 {
        // The glass BSDF's own reflection: `u_lobe = 0` lies below any F > 0.
        let Some(r) = v.bsdf.sample(v.wo_l, 0.0, Vec2::ZERO) else {
            return Vec3::ZERO;
        };
        let resume = sampler.dimension();
        let dir = v.frame.to_world(r.wi);
        let origin = self.spawn(v.p, v.hit.tri, dir);
        let key = sampler.next_key();
        let first = (self.geometry).closest(&self.materials, origin, dir, f32::INFINITY, key);
        let start = Start {
            origin,
            dir,
            first,
            depth: depth + 1,
            camera_length: length,
            split: false,
        };
        let traced = self.trace_from(settings, start, sampler, shading);
        sampler.resume_at(resume);
        r.f * r.wi.z.abs() * traced.radiance
    }

    /// Whether a fill sample estimates the shared glossy term at its first vertex (else the
    /// coupled irradiance). Only where the lobe is shared; then with the lobe's share of the
    /// reflected light, kept within [1/8, 1/2] so neither estimate starves (each cell averages
    /// the samples that made it, so the choice biases neither).
    fn fills_glossy(
        &self,
        grid: &CacheGrid,
        p: Vec3,
        bsdf: &Bsdf,
        wo_l: Vec3,
        sampler: &mut Sampler,
    ) -> bool {
        let q = bsdf.specular_probability(wo_l);
        if q <= 0.0 || !grid.shares_glossy(p, bsdf.glossy_width()) {
            return false;
        }
        sampler.next_f32() < q.clamp(0.125, 0.5)
    }

    /// Emission picked up at a hit, MIS-weighted against light sampling unless the path
    /// arrived by a delta lobe (or from the camera).
    fn emitted(&self, h: &Hit, dir: Vec3, arrival: Arrival) -> Vec3 {
        let mat = &self.materials[self.geometry.shading[h.tri as usize].material as usize];
        if !mat.is_emissive() {
            return Vec3::ZERO;
        }
        let ng = self.geometry.geometric_normal(h.tri);
        let dist = dir.length() * h.t;
        let cos_light = -dir.normalize().dot(ng);
        if cos_light <= 0.0 {
            return Vec3::ZERO;
        }
        let emission = mat.emitted(self.geometry.uv(h));
        if arrival.is_delta {
            return emission;
        }
        let light_pdf = self
            .lights
            .pdf(&self.geometry, h.tri, arrival.from, dist, cos_light);
        emission * power_heuristic(arrival.pdf, light_pdf)
    }

    /// One light sample with a shadow ray through semi-transparent surfaces, MIS-weighted
    /// against BSDF sampling of `lobes`, which the path takes with probability `select`; and
    /// with `coupled`, the same sample's estimate of the coupled irradiance ([`Later`]).
    fn direct_light(
        &self,
        v: &Vertex,
        (lobes, select): (Lobes, f32),
        coupled: bool,
        sampler: &mut Sampler,
    ) -> (Vec3, Vec3) {
        const NONE: (Vec3, Vec3) = (Vec3::ZERO, Vec3::ZERO);
        let (p, frame, wo_l, bsdf) = (v.p, v.frame, v.wo_l, v.bsdf);
        let ls = self.lights.sample(
            &self.geometry,
            &self.materials,
            p,
            sampler.next_f32(),
            sampler.next2(),
        );
        let to_light = ls.p - p;
        let dist = to_light.length();
        let wi = to_light / dist;
        let cos_light = -wi.dot(ls.n);
        if cos_light <= 0.0 || dist <= 0.0 {
            return NONE;
        }
        let wi_l = frame.to_local(wi);
        let (f, bsdf_pdf) = bsdf.eval_lobes(wo_l, wi_l, lobes);
        let bsdf_pdf = bsdf_pdf * select;
        let f_coupled = match coupled {
            true => bsdf.eval_lobes(wo_l, wi_l, Lobes::CoupledIrradiance).0,
            false => Vec3::ZERO,
        };
        if f == Vec3::ZERO && f_coupled == Vec3::ZERO {
            return NONE;
        }
        // Aim just off the light, on the side facing `p`: a ray that reached the light's
        // surface could count the light itself as the occluder.
        let target = ls.p + ls.n * ray_eps(ls.p);
        let (tr, crossed_glass) = self.visibility(p, v.hit.tri, target, v.through_glass);
        if tr == Vec3::ZERO {
            return NONE;
        }
        let light_pdf = ls.pdf_area * dist * dist / cos_light;
        // Through glass the BSDF partner refracts and is dropped: the light sample is alone.
        let weight = match crossed_glass {
            true => 1.0,
            false => power_heuristic(light_pdf, bsdf_pdf),
        };
        // The path's own product keeps its factor order, so `fill_vertices = 1` renders bit
        // for bit what the first-vertex-only estimator rendered (checked on the golden set).
        let share = tr * wi_l.z.abs() * weight / light_pdf;
        (f * ls.emission * share, f_coupled * ls.emission * share)
    }

    /// Light from every punctual light, each with a shadow ray through semi-transparent
    /// surfaces. A delta light has no MIS partner: no BSDF sample can hit it. With `coupled`,
    /// also the coupled irradiance it gives ([`Later`]).
    fn punctual_light(&self, v: &Vertex, lobes: Lobes, coupled: bool) -> (Vec3, Vec3) {
        let (p, frame, wo_l, bsdf, tri) = (v.p, v.frame, v.wo_l, v.bsdf, v.hit.tri);
        let (mut sum, mut sum_coupled) = (Vec3::ZERO, Vec3::ZERO);
        for light in &self.punctual_lights {
            let Some(inc) = light.incident(p) else {
                continue;
            };
            let wi_l = frame.to_local(inc.wi);
            let (f, _) = bsdf.eval_lobes(wo_l, wi_l, lobes);
            let f_coupled = match coupled {
                true => bsdf.eval_lobes(wo_l, wi_l, Lobes::CoupledIrradiance).0,
                false => Vec3::ZERO,
            };
            if f == Vec3::ZERO && f_coupled == Vec3::ZERO {
                continue;
            }
            let glass = v.through_glass;
            let (tr, _) = match inc.dist.is_finite() {
                true => self.visibility(p, tri, p + inc.wi * inc.dist, glass),
                false => {
                    let origin = self.spawn(p, tri, inc.wi);
                    let geo = &self.geometry;
                    geo.transmittance(&self.materials, origin, inc.wi, f32::INFINITY, glass)
                }
            };
            let share = tr * wi_l.z.abs();
            sum += f * inc.irradiance * share;
            sum_coupled += f_coupled * inc.irradiance * share;
        }
        (sum, sum_coupled)
    }

    /// Shading normal; opaque surfaces are two-sided, so it is turned towards the viewer.
    /// Glass keeps its outward orientation so the BSDF knows inside from outside.
    fn shading_normal(&self, h: &Hit, wo: Vec3, is_glass: bool) -> Vec3 {
        let ng = self.geometry.geometric_normal(h.tri);
        let ns = self.geometry.shading_normal(h);
        if is_glass {
            return if ns.dot(ng) > 0.0 { ns } else { ng };
        }
        let ng = if ng.dot(wo) < 0.0 { -ng } else { ng };
        let ns = if ns.dot(ng) < 0.0 { -ns } else { ns };
        if ns.dot(wo) > 0.0 { ns } else { ng }
    }

    /// Ray origin just off the surface, on the side `dir` leaves to.
    fn spawn(&self, p: Vec3, tri: u32, dir: Vec3) -> Vec3 {
        let ng = self.geometry.geometric_normal(tri);
        p + ng * ray_eps(p).copysign(ng.dot(dir))
    }

    /// Transmittance of the segment from just off the surface at `p` (triangle `tri`) to
    /// `target`. The shadow ray is aimed from the offset origin itself: along the direction
    /// from `p` it would end beside `target`, by as much as the offset over the cosine, which
    /// within ~10³ offsets of a light reaches into the light's own surface. It stops 1e-4
    /// short, so a point light placed on a surface is not hidden by it.
    fn visibility(&self, p: Vec3, tri: u32, target: Vec3, through_glass: bool) -> (Vec3, bool) {
        let origin = self.spawn(p, tri, target - p);
        let to_target = target - origin;
        let dist = to_target.length();
        let tmax = dist * (1.0 - 1e-4);
        let dir = to_target / dist;
        (self.geometry).transmittance(&self.materials, origin, dir, tmax, through_glass)
    }
}

/// Distance of a ray's origin from the surface it leaves, relative to the scene scale.
fn ray_eps(p: Vec3) -> f32 {
    RAY_EPS * p.abs().max_element().max(1.0)
}

//! Surface scattering: the BSDFs the path tracer samples and evaluates at every hit.
//!
//! Everything works in the local shading frame (`z` = shading normal) so the formulas stay
//! the textbook ones; [`Frame`] converts to and from world space. `wo` points from the surface
//! toward the viewer, `wi` toward where the light comes from.
//!
//! # Standard material
//!
//! A GGX microfacet specular layer over a Lambert base:
//!
//! * Specular: `D(h) G2(wo, wi) F(wo·h) / (4 cos_o cos_i)` with the GGX distribution, the
//!   height-correlated Smith term and Schlick's Fresnel `F0 + (F90 - F0)(1 - wo·h)^5`.
//!   `F0 = lerp(0.08·specular, base_color, metallic)`. The dielectric layer uses
//!   `F90 = min(1, 50·F0)` so that `specular = 0` truly switches the layer off (Schlick would
//!   otherwise keep a grazing reflection that no index of refraction produces); metals use 1.
//! * Diffuse: `(1 - metallic) · base_color / π · (1 - E(cos_o)) (1 - E(cos_i)) / (1 - E_avg)`,
//!   where `E(μ)` is the directional albedo of the dielectric specular layer and `E_avg` its
//!   cosine-weighted average (Kelemen & Szirmay-Kalos 2001). The base receives exactly the energy
//!   the specular layer does not reflect, so a white dielectric reflects all light at every angle
//!   and roughness and the model stays reciprocal; an ad-hoc `(1 - F(wo·h))` split instead
//!   exceeds 1 at grazing angles. `E` is tabulated once per process by integrating this very
//!   specular lobe (`AlbedoTable`); as `F` is linear in `(F0, F90)`, two channels cover every
//!   `specular`.
//! * Energy lost by single-scattering GGX on metals (rough metals darken) is not compensated.
//! * Sampling: one lobe is picked with probability proportional to its directional albedo for
//!   `wo`; the specular lobe samples visible normals (Heitz 2018, spherical-cap form of Dupuy &
//!   Benyoub 2023), the diffuse lobe is cosine-weighted. The returned pdf is the one-sample mixture
//!   `p_spec·pdf_spec + p_diff·pdf_diff`, which is also what [`Bsdf::eval`] returns.
//!   Visible-normal samples that reflect below the horizon are rejected (`None`), so the pdf
//!   integrates to the acceptance probability: below 1 for rough specular lobes (a pure GGX lobe
//!   at normal incidence keeps `1/(1+α²)`, only 0.5 at roughness 1).
//!
//! # Glass
//!
//! A smooth dielectric: the exact unpolarised Fresnel reflectance picks reflection or refraction,
//! and total internal reflection always reflects. Roughness is ignored. Transmission is tinted by
//! `base_color` once per interface crossing.
//!
//! **η² convention**: the paths are camera paths carrying radiance, and radiance changes by the
//! squared ratio of indices across an interface. The refraction value therefore includes the
//! factor `1/η²` with `η = n(wi side) / n(wo side)`: `f = base_color (1 - F) / (η² |cos_i|)`.
//! Light tracing (importance transport) would have to drop that factor.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};
use std::sync::OnceLock;

/// Smallest GGX α: below it `D` overflows f32 and sampled directions lose all precision.
const MIN_ALPHA: f32 = 1e-3;

/// Resolved material at a hit point (texture already looked up by the caller).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceParams {
    /// Diffuse albedo (dielectric), F0 (metal) or transmission tint (glass), linear RGB.
    pub base_color: Vec3,
    /// Perceptual roughness in [0, 1]; GGX `α = roughness²`, clamped to at least 1e-3.
    pub roughness: f32,
    /// Blend from dielectric (0) to metal (1).
    pub metallic: f32,
    /// Dielectric specular level: `F0 = 0.08·specular` (0.5 gives the common 0.04).
    pub specular: f32,
    pub kind: SurfaceKind,
}

/// The scattering model of a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SurfaceKind {
    /// Lambert diffuse + GGX glossy layer (metallic blends base colour into F0).
    Standard,
    /// Smooth (delta) dielectric: specular reflection + refraction with Fresnel, `ior`, tinted
    /// by base_color on transmission.
    Glass { ior: f32 },
}

/// A sampled incident direction with the quantities the estimator divides.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Incident direction in the local frame (unit length).
    pub wi: Vec3,
    /// BSDF value, without the cosine.
    pub f: Vec3,
    /// Solid-angle pdf; for delta lobes the discrete probability of the chosen lobe.
    pub pdf: f32,
    /// The direction came from a delta lobe: skip MIS with light sampling.
    pub is_delta: bool,
}

impl SurfaceParams {
    /// The BSDF at this hit, its per-hit constants (GGX α, Fresnel, the albedo-table row)
    /// resolved once, as pbrt's `GetBSDF` does: a path vertex evaluates and samples it several
    /// times (light samples, the continuation, the cache's split).
    pub fn bsdf(&self) -> Bsdf {
        Bsdf(match self.kind {
            SurfaceKind::Standard => Model::Standard(StandardLobes::new(self)),
            SurfaceKind::Glass { ior } => Model::Glass {
                tint: self.base_color,
                ior,
            },
        })
    }
}

/// A hit's BSDF, ready to evaluate and sample ([`SurfaceParams::bsdf`]).
pub struct Bsdf(Model);

enum Model {
    Standard(StandardLobes),
    Glass { tint: Vec3, ior: f32 },
}

impl Bsdf {
    /// f(wo, wi) and the pdf with which `sample` would produce wi (0 for delta materials).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        match &self.0 {
            Model::Standard(lobe) => lobe.eval(wo, wi),
            Model::Glass { .. } => (Vec3::ZERO, 0.0),
        }
    }

    /// Sample wi given two uniform numbers; None when the sample is absorbed/invalid.
    /// `u_lobe` chooses the lobe, `u` the direction.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        match &self.0 {
            Model::Standard(lobe) => lobe.sample(wo, u_lobe, u),
            Model::Glass { tint, ior } => sample_glass(*tint, *ior, wo, u_lobe),
        }
    }

    /// True when the material has no non-delta lobe (NEE is pointless).
    pub fn is_delta(&self) -> bool {
        matches!(self.0, Model::Glass { .. })
    }

    /// The Standard lobes, or `None` for a delta material.
    fn standard(&self) -> Option<&StandardLobes> {
        match &self.0 {
            Model::Standard(lobe) => Some(lobe),
            Model::Glass { .. } => None,
        }
    }

    /// [`Self::eval`] restricted to `lobes` (see [`Lobes`]); delta materials give zero.
    pub fn eval_lobes(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> (Vec3, f32) {
        match (lobes, self.standard()) {
            (Lobes::All, _) => self.eval(wo, wi),
            (_, None) => (Vec3::ZERO, 0.0),
            (Lobes::Specular, Some(lobe)) => lobe.specular_only(wo, wi),
            (Lobes::CoupledIrradiance, Some(lobe)) => lobe.coupling_in(wi),
        }
    }

    /// [`Self::sample`] restricted to `lobes`: the glossy lobe by its visible normals, or the
    /// coupled-irradiance integrand by the cosine.
    pub fn sample_lobes(&self, wo: Vec3, u_lobe: f32, u: Vec2, lobes: Lobes) -> Option<BsdfSample> {
        if lobes == Lobes::All {
            return self.sample(wo, u_lobe, u);
        }
        let lobe = self.standard()?;
        if wo.z <= 0.0 {
            return None;
        }
        let (wi, (f, pdf)) = match lobes {
            Lobes::Specular => {
                let wi = reflect(wo, sample_ggx_vndf(wo, lobe.alpha, u));
                (wi, lobe.specular_only(wo, wi))
            }
            _ => {
                let wi = cosine_sample_hemisphere(u);
                (wi, lobe.coupling_in(wi))
            }
        };
        (pdf > 0.0).then_some(BsdfSample {
            wi,
            f,
            pdf,
            is_delta: false,
        })
    }

    /// The outgoing factor of the diffuse term, `ρ/π' · (1 − E(μo))`: the diffuse light
    /// leaving towards `wo` is this times the coupled irradiance (`render::cache`).
    pub fn diffuse_out(&self, wo: Vec3) -> Vec3 {
        match self.standard() {
            Some(_) if wo.z <= 0.0 => Vec3::ZERO,
            Some(lobe) => lobe.diffuse * (1.0 - lobe.albedo_split(wo.z).dot(lobe.dielectric)),
            None => Vec3::ZERO,
        }
    }

    /// The glossy lobe's directional albedo `A(μo) = F0·P(μo) + F90·Q(μo)`: the light it
    /// reflects towards `wo` is this times the lobe-weighted mean of the incident light
    /// (`render::cache` shares that mean where the lobe is wide); 0 for delta materials.
    pub fn specular_albedo(&self, wo: Vec3) -> Vec3 {
        match self.standard() {
            Some(lobe) if wo.z > 0.0 => {
                let pq = lobe.albedo_split(wo.z);
                lobe.f0 * pq.x + lobe.f90 * pq.y
            }
            _ => Vec3::ZERO,
        }
    }

    /// The glossy lobe's width, `2α` radians (about its full width at half maximum); 0 for
    /// delta materials.
    pub fn glossy_width(&self) -> f32 {
        self.standard().map_or(0.0, |lobe| 2.0 * lobe.alpha)
    }

    /// The share of the glossy lobe in the light leaving towards `wo` (the probability with
    /// which [`Self::sample`] picks it); 0 for delta materials.
    pub fn specular_probability(&self, wo: Vec3) -> f32 {
        match self.standard() {
            Some(_) if wo.z <= 0.0 => 0.0,
            Some(lobe) => lobe.specular_probability(lobe.albedo_split(wo.z)),
            None => 0.0,
        }
    }
}

/// The part of a vertex's BSDF an estimator integrates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobes {
    /// The whole BSDF (the independent estimator).
    All,
    /// The GGX glossy lobe alone: what shared shading keeps per view.
    Specular,
    /// `(1 − E(μi))`, no albedo and no `1/π`: the integrand of the coupled irradiance that
    /// shared shading estimates once for all views, sampled by the cosine.
    CoupledIrradiance,
}

/// Orthonormal, right-handed basis around a unit normal, for world <-> local conversion.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Duff et al. 2017: branchless and continuous except across `n.z = 0`, and exact for
    /// `n = ±z`, where the classic cross-product constructions lose precision.
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Self {
            t: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            b: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// World-space vector to local coordinates (`z` along the normal).
    pub fn to_local(self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    /// Local coordinates back to world space.
    pub fn to_world(self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

/// Cosine-weighted direction on the +z hemisphere (pdf `cos θ / π`).
///
/// Uses the concentric square-to-disk map (Shirley & Chiu 1997) before lifting to the
/// hemisphere, because it keeps strata compact, which stratified samplers rely on.
pub fn cosine_sample_hemisphere(u: Vec2) -> Vec3 {
    let d = 2.0 * u - Vec2::ONE;
    if d == Vec2::ZERO {
        return Vec3::Z;
    }
    let (r, theta) = if d.x.abs() > d.y.abs() {
        (d.x, FRAC_PI_4 * (d.y / d.x))
    } else {
        (d.y, FRAC_PI_2 - FRAC_PI_4 * (d.x / d.y))
    };
    let (s, c) = theta.sin_cos();
    let disk = r * Vec2::new(c, s);
    Vec3::new(
        disk.x,
        disk.y,
        (1.0 - disk.length_squared()).max(0.0).sqrt(),
    )
}

/// Veach's power heuristic (β = 2): the MIS weight of strategy `a` against `b`.
///
/// Written as `1 / (1 + (b/a)²)` rather than `a² / (a² + b²)` so that squaring cannot
/// overflow or underflow, and so that delta strategies work: `a = ∞` gives 1, `b = ∞` gives 0.
/// A zero, negative or NaN `a` gives 0; two infinite pdfs share the weight equally.
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    if pdf_a.is_nan() || pdf_a <= 0.0 {
        return 0.0;
    }
    let ratio = if pdf_a == pdf_b { 1.0 } else { pdf_b / pdf_a };
    // `max` maps a NaN `pdf_b` to 0: a strategy that cannot be evaluated takes no weight.
    let r = ratio.max(0.0);
    1.0 / (1.0 + r * r)
}

/// Mirror `v` about the unit normal `n`.
fn reflect(v: Vec3, n: Vec3) -> Vec3 {
    2.0 * v.dot(n) * n - v
}

/// GGX α from perceptual roughness, shared by the table and the lobes so they always agree.
fn alpha_from_roughness(roughness: f32) -> f32 {
    (roughness * roughness).max(MIN_ALPHA)
}

/// GGX (Trowbridge-Reitz) normal distribution for a unit half vector in the local frame.
fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = h.z * h.z * (a2 - 1.0) + 1.0;
    a2 / (PI * t * t)
}

/// Smith Λ for GGX; `G1 = 1/(1+Λ)`, height-correlated `G2 = 1/(1+Λo+Λi)`.
fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let tan2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// Microfacet normal distributed as the normals visible from `wo` (wo.z > 0).
///
/// Spherical-cap form of Heitz's visible-normal sampling (Dupuy & Benyoub 2023): fewer
/// operations than the original, same distribution `G1(wo) max(0, wo·h) D(h) / wo.z`.
fn sample_ggx_vndf(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let v = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let phi = 2.0 * PI * u.x;
    let z = (1.0 - u.y) * (1.0 + v.z) - v.z;
    let sin_theta = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = phi.sin_cos();
    let h = Vec3::new(sin_theta * c, sin_theta * s, z) + v;
    // A zero vector (measure-zero corner) reflects wo below the horizon and is rejected later.
    Vec3::new(alpha * h.x, alpha * h.y, h.z).normalize_or_zero()
}

/// Schlick's `(1 - cos)^5` weight, the part of Fresnel that F90 scales.
fn schlick_weight(cos: f32) -> f32 {
    (1.0 - cos).clamp(0.0, 1.0).powi(5)
}

/// Mean of the three channels: a lobe weight that is never zero while any channel is not.
fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}

/// Nodes per axis of the specular-albedo table (axes: `sqrt(cos θ)` and perceptual roughness).
const TABLE_N: usize = 32;
/// Stratified visible-normal samples per axis when integrating one table entry.
const TABLE_STRATA: usize = 16;
/// Midpoint steps of the cosine-weighted average of one table row.
const TABLE_AVG_STEPS: usize = 256;

/// Directional albedo of the GGX specular layer, split by the Fresnel terms:
/// `E(μ) = F0·P(μ, r) + F90·Q(μ, r)` with `P = ∫ρ(1 - s⁵)`, `Q = ∫ρ s⁵`, `s = 1 - wo·h`,
/// ρ the Fresnel-free lobe times cos θi. Stored as `Vec2(P, Q)`.
///
/// Built at first use, by integrating the same lobe the renderer evaluates, rather than
/// shipped as literals or fitted: the diffuse coupling conserves energy only as well as `E`
/// matches that lobe. The cos-axis uses `sqrt(μ)` so nodes crowd at grazing angles, where
/// `E` changes fastest.
struct AlbedoTable {
    /// `[roughness node][sqrt(μ) node]`.
    pq: [[Vec2; TABLE_N]; TABLE_N],
    /// Per roughness node, `∫ E 2μ dμ` of the linearly interpolated row, split like `pq`.
    avg: [Vec2; TABLE_N],
}

impl AlbedoTable {
    /// The process-wide table; the first caller pays a few milliseconds to build it.
    fn get() -> &'static Self {
        static TABLE: OnceLock<AlbedoTable> = OnceLock::new();
        TABLE.get_or_init(Self::build)
    }

    fn build() -> Self {
        let pq: [[Vec2; TABLE_N]; TABLE_N] = std::array::from_fn(|j| {
            let alpha = alpha_from_roughness(table_node(j));
            std::array::from_fn(|i| integrate_specular(table_node(i).powi(2), alpha))
        });
        let avg = std::array::from_fn(|j| cosine_average(&pq[j]));
        Self { pq, avg }
    }

    /// Bilinear look-up of `(P, Q)` at `cos θ = mu` on the roughness row `rough`.
    fn lookup(&self, rough: TableCoord, mu: f32) -> Vec2 {
        let lo = lerp_row(&self.pq[rough.index], mu.max(0.0).sqrt());
        let hi = lerp_row(&self.pq[rough.index + 1], mu.max(0.0).sqrt());
        lo.lerp(hi, rough.frac)
    }

    /// Interpolated cosine-weighted average of `(P, Q)`; exact for the bilinear interpolant
    /// because the average is linear in the row.
    fn average(&self, rough: TableCoord) -> Vec2 {
        self.avg[rough.index].lerp(self.avg[rough.index + 1], rough.frac)
    }
}

/// Position of node `i` on a table axis spanning [0, 1].
fn table_node(i: usize) -> f32 {
    i as f32 / (TABLE_N - 1) as f32
}

/// A continuous table coordinate split into the lower node and the blend toward the next.
#[derive(Clone, Copy, Debug)]
struct TableCoord {
    index: usize,
    frac: f32,
}

impl TableCoord {
    fn new(x: f32) -> Self {
        let f = x.clamp(0.0, 1.0) * (TABLE_N - 1) as f32;
        let index = (f as usize).min(TABLE_N - 2);
        Self {
            index,
            frac: f - index as f32,
        }
    }
}

/// Linear interpolation of a table row at axis position `x` in [0, 1].
fn lerp_row(row: &[Vec2; TABLE_N], x: f32) -> Vec2 {
    let c = TableCoord::new(x);
    row[c.index].lerp(row[c.index + 1], c.frac)
}

/// `(P, Q)` for one `(μ, α)` by stratified visible-normal sampling: each sample's weight is
/// `G2/G1(wo)`, so the estimate is smooth even for near-mirror α.
fn integrate_specular(mu: f32, alpha: f32) -> Vec2 {
    // μ = 0 makes Λ(wo) infinite; the limit is reached long before 1e-4.
    let mu = mu.clamp(1e-4, 1.0);
    let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let lambda_o = ggx_lambda(wo, alpha);
    let n = TABLE_STRATA;
    let sum: Vec2 = (0..n * n)
        .map(|k| {
            let u = (Vec2::new((k % n) as f32, (k / n) as f32) + 0.5) / n as f32;
            let h = sample_ggx_vndf(wo, alpha, u);
            let wi = reflect(wo, h);
            if wi.z <= 0.0 {
                return Vec2::ZERO;
            }
            let w = (1.0 + lambda_o) / (1.0 + lambda_o + ggx_lambda(wi, alpha));
            let s5 = schlick_weight(wo.dot(h));
            w * Vec2::new(1.0 - s5, s5)
        })
        .sum();
    sum / (n * n) as f32
}

/// `∫₀¹ row(sqrt μ) 2μ dμ` of the linearly interpolated row (midpoint rule in μ), so the
/// diffuse coupling normalises against the very function it looks up.
fn cosine_average(row: &[Vec2; TABLE_N]) -> Vec2 {
    let n = TABLE_AVG_STEPS as f32;
    let sum: Vec2 = (0..TABLE_AVG_STEPS)
        .map(|k| {
            let mu = (k as f32 + 0.5) / n;
            lerp_row(row, mu.sqrt()) * (2.0 * mu)
        })
        .sum();
    sum / n
}

/// The Standard material with its per-hit constants resolved once for eval and sample.
struct StandardLobes {
    alpha: f32,
    table: &'static AlbedoTable,
    rough: TableCoord,
    /// Specular Fresnel at normal incidence and at grazing.
    f0: Vec3,
    f90: Vec3,
    /// `(F0, F90)` of the dielectric layer; `E(μ) = dot(lookup(μ), this)`.
    dielectric: Vec2,
    /// `(1 - metallic)·base_color / π / (1 - E_avg)`: the μ-independent part of the diffuse.
    diffuse: Vec3,
}

impl StandardLobes {
    fn new(p: &SurfaceParams) -> Self {
        let roughness = p.roughness.clamp(0.0, 1.0);
        let metallic = p.metallic.clamp(0.0, 1.0);
        let f0_dielectric = (0.08 * p.specular).clamp(0.0, 1.0);
        let dielectric = Vec2::new(f0_dielectric, (50.0 * f0_dielectric).min(1.0));
        let table = AlbedoTable::get();
        let rough = TableCoord::new(roughness);
        let e_avg = table.average(rough).dot(dielectric);
        Self {
            alpha: alpha_from_roughness(roughness),
            table,
            rough,
            f0: Vec3::splat(dielectric.x).lerp(p.base_color, metallic),
            f90: Vec3::splat(dielectric.y).lerp(Vec3::ONE, metallic),
            dielectric,
            diffuse: (1.0 - metallic) * p.base_color * FRAC_1_PI / (1.0 - e_avg).max(1e-4),
        }
    }

    /// `(P, Q)` of the specular layer at `cos θ = mu`.
    fn albedo_split(&self, mu: f32) -> Vec2 {
        self.table.lookup(self.rough, mu)
    }

    /// Probability of sampling the specular lobe: its share of the directional albedo.
    fn specular_probability(&self, pq_o: Vec2) -> f32 {
        let spec = mean(self.f0 * pq_o.x + self.f90 * pq_o.y);
        let diffuse = mean(self.diffuse) * PI * (1.0 - pq_o.dot(self.dielectric));
        spec / (spec + diffuse).max(f32::MIN_POSITIVE)
    }

    /// Specular value and its visible-normal pdf for an upper-hemisphere pair.
    fn specular(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let h = (wo + wi).normalize();
        let d = ggx_d(h, self.alpha);
        let lambda_o = ggx_lambda(wo, self.alpha);
        let g2 = 1.0 / (1.0 + lambda_o + ggx_lambda(wi, self.alpha));
        let fresnel = self.f0 + (self.f90 - self.f0) * schlick_weight(wo.dot(h));
        let f = fresnel * (d * g2 / (4.0 * wo.z * wi.z));
        // Visible-normal pdf of h times the reflection Jacobian 1/(4 wo·h); wo·h cancels.
        let pdf = d / ((1.0 + lambda_o) * 4.0 * wo.z);
        (f, pdf)
    }

    /// The glossy lobe alone, with the pdf of sampling it alone.
    fn specular_only(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        self.specular(wo, wi)
    }

    /// The incident factor of the diffuse coupling, `1 − E(μi)`, with the cosine pdf.
    fn coupling_in(&self, wi: Vec3) -> (Vec3, f32) {
        if wi.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let c = 1.0 - self.albedo_split(wi.z).dot(self.dielectric);
        (Vec3::splat(c), wi.z * FRAC_1_PI)
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let pq_o = self.albedo_split(wo.z);
        let pq_i = self.albedo_split(wi.z);
        let coupling = (1.0 - pq_o.dot(self.dielectric)) * (1.0 - pq_i.dot(self.dielectric));
        let (spec_f, spec_pdf) = self.specular(wo, wi);
        let p_spec = self.specular_probability(pq_o);
        let pdf = p_spec * spec_pdf + (1.0 - p_spec) * wi.z * FRAC_1_PI;
        (spec_f + self.diffuse * coupling, pdf)
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let p_spec = self.specular_probability(self.albedo_split(wo.z));
        let wi = if u_lobe < p_spec {
            reflect(wo, sample_ggx_vndf(wo, self.alpha, u))
        } else {
            cosine_sample_hemisphere(u)
        };
        // Evaluating both lobes gives the mixture pdf that eval reports, by construction.
        let (f, pdf) = self.eval(wo, wi);
        (pdf > 0.0).then_some(BsdfSample {
            wi,
            f,
            pdf,
            is_delta: false,
        })
    }
}

/// Exact unpolarised Fresnel reflectance and the transmitted cosine for relative index
/// `eta = n_transmitted / n_incident`; total internal reflection gives `(1, 0)`.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> (f32, f32) {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (0.5 * (r_s * r_s + r_p * r_p), cos_t)
}

/// Smooth dielectric: reflect with probability F, else refract. `wo.z < 0` means the viewer is
/// inside the medium, so the relative index flips.
fn sample_glass(tint: Vec3, ior: f32, wo: Vec3, u_lobe: f32) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let eta = if wo.z > 0.0 { ior } else { 1.0 / ior };
    let cos_o = wo.z.abs();
    let (fresnel, cos_t) = fresnel_dielectric(cos_o, eta);
    // `fresnel >= 1` keeps total internal reflection a reflection even for u_lobe = 1.
    if fresnel >= 1.0 || u_lobe < fresnel {
        return Some(BsdfSample {
            wi: Vec3::new(-wo.x, -wo.y, wo.z),
            f: Vec3::splat(fresnel / cos_o),
            pdf: fresnel,
            is_delta: true,
        });
    }
    let n = Vec3::new(0.0, 0.0, wo.z.signum());
    let transmit = 1.0 - fresnel;
    Some(BsdfSample {
        wi: (-wo / eta + (cos_o / eta - cos_t) * n).normalize(),
        f: tint * (transmit / (eta * eta * cos_t)),
        pdf: transmit,
        is_delta: true,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64: a self-contained, seedable source of uniform numbers for the tests.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f32 {
            let h = crate::util::hash::mix64(self.0);
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            crate::util::hash::unit_float(h)
        }

        fn next2(&mut self) -> Vec2 {
            Vec2::new(self.next(), self.next())
        }

        /// Uniform direction on the sphere.
        fn direction(&mut self) -> Vec3 {
            let z = 2.0 * self.next() - 1.0;
            let phi = 2.0 * PI * self.next();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        }

        /// Uniform direction on the upper hemisphere, away from the horizon.
        fn upper(&mut self) -> Vec3 {
            let d = self.direction();
            Vec3::new(d.x, d.y, d.z.abs().max(0.02)).normalize()
        }
    }

    fn standard(base: Vec3, roughness: f32, metallic: f32) -> SurfaceParams {
        SurfaceParams {
            base_color: base,
            roughness,
            metallic,
            specular: 0.5,
            kind: SurfaceKind::Standard,
        }
    }

    fn glass(ior: f32) -> SurfaceParams {
        SurfaceParams {
            base_color: Vec3::ONE,
            roughness: 0.0,
            metallic: 0.0,
            specular: 0.5,
            kind: SurfaceKind::Glass { ior },
        }
    }

    /// Viewer direction at `cos θ = mu` in the xz-plane.
    fn wo_at(mu: f32) -> Vec3 {
        Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu)
    }

    /// Midpoint quadrature over the upper hemisphere in (θ, φ); fine enough for α ≥ 0.09.
    fn hemisphere_quadrature(mut g: impl FnMut(Vec3) -> Vec3) -> Vec3 {
        const NT: usize = 256;
        const NP: usize = 512;
        let (dt, dp) = (FRAC_PI_2 / NT as f32, 2.0 * PI / NP as f32);
        let mut sum = Vec3::ZERO;
        for i in 0..NT {
            let (st, ct) = ((i as f32 + 0.5) * dt).sin_cos();
            for j in 0..NP {
                let (sp, cp) = ((j as f32 + 0.5) * dp).sin_cos();
                sum += g(Vec3::new(st * cp, st * sp, ct)) * (st * dt * dp);
            }
        }
        sum
    }

    /// Monte-Carlo directional albedo `E[f cos / pdf]`, absorbed samples counting zero.
    fn albedo_mc(p: &SurfaceParams, wo: Vec3, n: usize, rng: &mut Rng) -> Vec3 {
        let sum: Vec3 = (0..n)
            .filter_map(|_| p.bsdf().sample(wo, rng.next(), rng.next2()))
            .map(|s| s.f * s.wi.z.abs() / s.pdf)
            .sum();
        sum / n as f32
    }

    fn assert_close(a: f32, b: f32, rel: f32, what: &str) {
        assert!(
            (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-6),
            "{what}: {a} vs {b}"
        );
    }

    #[test]
    fn white_furnace_standard() {
        let mut rng = Rng(1);
        for roughness in [0.0, 0.1, 0.3, 0.6, 1.0] {
            for metallic in [0.0, 1.0] {
                let p = standard(Vec3::ONE, roughness, metallic);
                for mu in [1.0, 0.7, 0.4, 0.15, 0.05] {
                    let a = albedo_mc(&p, wo_at(mu), 20_000, &mut rng);
                    let what = format!("r={roughness} m={metallic} mu={mu}: {a}");
                    assert!(a.max_element() <= 1.01, "{what}");
                    // The coupled diffuse takes everything the specular layer leaves.
                    if metallic == 0.0 {
                        assert!(a.min_element() >= 0.98, "{what}");
                    }
                    // A near-mirror white metal reflects everything (G ≈ 1, F0 = 1).
                    if metallic == 1.0 && roughness <= 0.1 && mu >= 0.15 {
                        assert!(a.min_element() >= 0.98, "{what}");
                    }
                }
            }
        }
    }

    #[test]
    fn white_furnace_by_quadrature() {
        // Independent of the sampling code: integrate f·cos directly.
        for roughness in [0.3, 0.7, 1.0] {
            for mu in [1.0, 0.5, 0.2] {
                let p = standard(Vec3::ONE, roughness, 0.0);
                let a = hemisphere_quadrature(|wi| p.bsdf().eval(wo_at(mu), wi).0 * wi.z);
                assert_close(a.x, 1.0, 0.01, &format!("r={roughness} mu={mu}"));
            }
        }
    }

    #[test]
    fn sample_agrees_with_eval() {
        let mut rng = Rng(2);
        for _ in 0..20_000 {
            let p = SurfaceParams {
                base_color: Vec3::new(rng.next(), rng.next(), rng.next()),
                roughness: rng.next(),
                metallic: rng.next(),
                specular: rng.next(),
                kind: SurfaceKind::Standard,
            };
            let wo = rng.upper();
            let Some(s) = p.bsdf().sample(wo, rng.next(), rng.next2()) else {
                continue;
            };
            let (f, pdf) = p.bsdf().eval(wo, s.wi);
            assert!(!s.is_delta && s.wi.z > 0.0 && s.pdf > 0.0);
            assert_close(s.wi.length(), 1.0, 1e-4, "unit wi");
            assert_close(pdf, s.pdf, 1e-3, "pdf");
            for c in 0..3 {
                assert_close(f[c], s.f[c], 1e-3, "f");
            }
        }
    }

    #[test]
    fn pdf_integrates_to_acceptance_and_matches_samples() {
        let mut rng = Rng(3);
        let base = Vec3::new(0.8, 0.5, 0.2);
        for (roughness, metallic) in [(0.3, 1.0), (0.6, 0.0), (1.0, 1.0), (0.45, 0.5)] {
            let p = standard(base, roughness, metallic);
            for mu in [1.0, 0.5, 0.15] {
                let wo = wo_at(mu);
                let test_fn = |wi: Vec3| Vec3::new(wi.x, wi.z * wi.z, wi.x * wi.y + wi.z);
                let integral = hemisphere_quadrature(|wi| Vec3::splat(p.bsdf().eval(wo, wi).1)).x;
                let expected = hemisphere_quadrature(|wi| test_fn(wi) * p.bsdf().eval(wo, wi).1);
                let n = 50_000;
                let (mut accepted, mut mean) = (0usize, Vec3::ZERO);
                for s in (0..n).filter_map(|_| p.bsdf().sample(wo, rng.next(), rng.next2())) {
                    accepted += 1;
                    mean += test_fn(s.wi) / n as f32;
                }
                let what = format!("r={roughness} m={metallic} mu={mu}");
                let acceptance = accepted as f32 / n as f32;
                assert!(
                    (integral - acceptance).abs() < 0.01,
                    "{what}: {integral} vs {acceptance}"
                );
                // Pure GGX at normal incidence: the half vectors with tan θh > 1 reflect below
                // the horizon, and P(tan² θh ≤ t) = t / (α² + t) under D·cos θh.
                if mu == 1.0 && metallic == 1.0 {
                    let a2 = roughness.powi(4);
                    assert!(
                        (integral - 1.0 / (1.0 + a2)).abs() < 0.005,
                        "{what}: {integral}"
                    );
                }
                assert!(
                    (expected - mean).abs().max_element() < 0.01,
                    "{what}: {expected} {mean}"
                );
            }
        }
    }

    #[test]
    fn standard_is_reciprocal() {
        let mut rng = Rng(4);
        for _ in 0..10_000 {
            let p = SurfaceParams {
                base_color: Vec3::new(rng.next(), rng.next(), rng.next()),
                roughness: rng.next(),
                metallic: rng.next(),
                specular: rng.next(),
                kind: SurfaceKind::Standard,
            };
            let (a, b) = (rng.upper(), rng.upper());
            let (fab, fba) = (p.bsdf().eval(a, b).0, p.bsdf().eval(b, a).0);
            for c in 0..3 {
                assert_close(fab[c], fba[c], 1e-3, "reciprocity");
            }
        }
    }

    #[test]
    fn no_specular_layer_is_lambert() {
        let mut rng = Rng(5);
        let base = Vec3::new(0.9, 0.4, 0.1);
        for roughness in [0.0, 0.5, 1.0] {
            let p = SurfaceParams {
                specular: 0.0,
                ..standard(base, roughness, 0.0)
            };
            for _ in 0..1000 {
                let (wo, wi) = (rng.upper(), rng.upper());
                let (f, pdf) = p.bsdf().eval(wo, wi);
                assert!((f - base / PI).abs().max_element() < 1e-6, "{f}");
                assert_close(pdf, wi.z / PI, 1e-6, "cosine pdf");
            }
        }
    }

    #[test]
    fn standard_rejects_viewer_below_surface() {
        let p = standard(Vec3::ONE, 0.5, 0.0);
        let below = Vec3::new(0.6, 0.0, -0.8);
        assert!(p.bsdf().sample(below, 0.5, Vec2::splat(0.5)).is_none());
        assert_eq!(p.bsdf().eval(below, Vec3::Z).1, 0.0);
        assert_eq!(p.bsdf().eval(Vec3::Z, below), (Vec3::ZERO, 0.0));
        assert!(!p.bsdf().is_delta());
    }

    /// Reflectance of the glass seen from `wo`: the pdf of the reflection sample.
    fn glass_reflectance(ior: f32, wo: Vec3) -> f32 {
        let s = glass(ior).bsdf().sample(wo, 0.0, Vec2::ZERO).unwrap();
        assert_eq!(s.wi, Vec3::new(-wo.x, -wo.y, wo.z));
        s.pdf
    }

    #[test]
    fn glass_fresnel_matches_hand_values() {
        // ((n-1)/(n+1))² from either side, and 0.5(Rs + Rp) at 45° computed by hand.
        assert_close(glass_reflectance(1.5, Vec3::Z), 0.04, 1e-5, "outside");
        assert_close(glass_reflectance(1.5, -Vec3::Z), 0.04, 1e-5, "inside");
        let w45 = Vec3::new(0.5f32.sqrt(), 0.0, 0.5f32.sqrt());
        assert_close(glass_reflectance(1.5, w45), 0.050_25, 2e-3, "45 degrees");
    }

    #[test]
    fn glass_total_internal_reflection() {
        // Inside ior 1.5 the critical angle is asin(1/1.5) ≈ 41.8°.
        let theta = 60f32.to_radians();
        let wo = Vec3::new(theta.sin(), 0.0, -theta.cos());
        for u_lobe in [0.0, 0.5, 0.999_999, 1.0] {
            let s = glass(1.5).bsdf().sample(wo, u_lobe, Vec2::ZERO).unwrap();
            assert_eq!(s.pdf, 1.0);
            assert!((s.wi - Vec3::new(-wo.x, 0.0, wo.z)).length() < 1e-6);
            assert_close(s.f.x * s.wi.z.abs() / s.pdf, 1.0, 1e-6, "TIR weight");
        }
        let theta = 40f32.to_radians();
        let wo = Vec3::new(theta.sin(), 0.0, -theta.cos());
        assert!(glass(1.5).bsdf().sample(wo, 0.99, Vec2::ZERO).unwrap().wi.z > 0.0);
    }

    #[test]
    fn glass_refraction_obeys_snell() {
        let mut rng = Rng(6);
        let mut refracted = 0;
        for _ in 0..2000 {
            let wo = rng.direction();
            let s = glass(1.5).bsdf().sample(wo, 0.999_9, Vec2::ZERO).unwrap();
            if s.wi.z * wo.z >= 0.0 {
                continue;
            }
            refracted += 1;
            let (n_o, n_i) = if wo.z > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
            let (t_o, t_i) = (wo.truncate(), s.wi.truncate());
            assert_close(s.wi.length(), 1.0, 1e-5, "unit");
            assert!((n_o * t_o.length() - n_i * t_i.length()).abs() < 1e-4);
            // Same plane of incidence, tangential direction continues across the interface.
            assert!(t_o.perp_dot(t_i).abs() < 1e-4 && t_o.dot(t_i) <= 0.0);
        }
        assert!(refracted > 1000);
    }

    #[test]
    fn glass_weights_sum_to_one() {
        let mut rng = Rng(7);
        for _ in 0..1000 {
            let wo = rng.direction();
            let p = glass(1.5);
            let r = p.bsdf().sample(wo, 0.0, Vec2::ZERO).unwrap();
            let Some(t) = p
                .bsdf()
                .sample(wo, 1.0 - 1e-7, Vec2::ZERO)
                .filter(|t| t.wi.z * wo.z < 0.0)
            else {
                continue; // total internal reflection
            };
            let weight = |s: BsdfSample| s.f.x * s.wi.z.abs() / s.pdf;
            // Radiance crossing into the denser side is compressed by (n_i/n_o)²; undo it.
            let eta2 = if wo.z > 0.0 { 2.25 } else { 1.0 / 2.25 };
            assert_close(r.pdf + t.pdf, 1.0, 1e-6, "lobe probabilities");
            assert_close(
                r.pdf * weight(r) + t.pdf * weight(t) * eta2,
                1.0,
                1e-5,
                "energy",
            );
            assert!(r.is_delta && t.is_delta);
        }
        assert!(glass(1.5).bsdf().is_delta());
        assert_eq!(glass(1.5).bsdf().eval(Vec3::Z, -Vec3::Z), (Vec3::ZERO, 0.0));
    }

    #[test]
    fn frame_is_orthonormal() {
        let mut rng = Rng(8);
        let fixed = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(1e-4, 0.0, -1.0).normalize(),
        ];
        let normals = fixed.into_iter().chain((0..1000).map(|_| rng.direction()));
        for n in normals {
            let f = Frame::from_normal(n);
            for v in [f.t, f.b, f.n] {
                assert_close(v.length(), 1.0, 1e-5, "unit");
            }
            assert!(f.t.dot(f.b).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5);
            assert!(f.b.dot(n).abs() < 1e-5);
            assert!((f.t.cross(f.b) - n).length() < 1e-5, "right-handed");
            let v = Vec3::new(0.3, -0.5, 0.8);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-5);
        }
    }

    #[test]
    fn cosine_samples_have_cosine_moments() {
        // Under pdf cos θ / π: E[cos θ] = 2/3, E[cos² θ] = 1/2 and, by azimuthal
        // uniformity, E[x²] = E[sin² θ]/2 = 1/4.
        let n = 256;
        let (mut m1, mut m2, mut mx) = (0.0, 0.0, 0.0);
        for k in 0..n * n {
            let u = (Vec2::new((k % n) as f32, (k / n) as f32) + 0.5) / n as f32;
            let w = cosine_sample_hemisphere(u);
            assert_close(w.length(), 1.0, 1e-5, "unit");
            assert!(w.z >= 0.0);
            m1 += w.z as f64;
            m2 += (w.z * w.z) as f64;
            mx += (w.x * w.x) as f64;
        }
        let count = (n * n) as f64;
        assert!((m1 / count - 2.0 / 3.0).abs() < 1e-3);
        assert!((m2 / count - 0.5).abs() < 1e-3);
        assert!((mx / count - 0.25).abs() < 1e-3);
        assert_eq!(cosine_sample_hemisphere(Vec2::splat(0.5)), Vec3::Z);
    }

    #[test]
    fn power_heuristic_values() {
        let cases = [
            (1.0, 1.0, 0.5),
            (1.0, 2.0, 0.2),
            (3.0, 1.0, 0.9),
            (2.0, 0.0, 1.0),
            (0.0, 2.0, 0.0),
            (0.0, 0.0, 0.0),
            (f32::INFINITY, 5.0, 1.0),
            (5.0, f32::INFINITY, 0.0),
            (f32::INFINITY, f32::INFINITY, 0.5),
            (1e-30, 1e-30, 0.5),
            (3e30, 1e30, 0.9),
        ];
        for (a, b, w) in cases {
            assert_close(power_heuristic(a, b), w, 1e-6, &format!("({a}, {b})"));
        }
    }
}

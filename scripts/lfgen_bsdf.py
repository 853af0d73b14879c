"""lfgen's Standard BSDF (crates/lfrender/src/bsdf.rs) as a Mitsuba 3 plugin, for colour comparisons
with the same reflectance model (README, "Validation"; used by scripts/validate.py).

    import mitsuba as mi; mi.set_variant("llvm_ad_rgb")
    import lfgen_bsdf; lfgen_bsdf.register()           # plugin name "lfgen_standard"
    # parameters as Mitsuba's `principled`: base_color (rgb), roughness, metallic, specular

The formulas are bsdf.rs' line by line: a GGX specular layer (height-correlated Smith G2,
Schlick Fresnel with `F0 = lerp(0.08·specular, base_color, metallic)`, dielectric
`F90 = min(1, 50·F0)`, metals 1; `α = max(roughness², 1e-3)`) over a Lambert base
`(1 − metallic)·base_color/π · (1 − E(μo))(1 − E(μi)) / (1 − E_avg)`, with the specular albedo
`E` tabulated exactly as `AlbedoTable` does (32 × 32 nodes on `sqrt μ` × roughness, 16 × 16
stratified visible-normal samples each, 256-step cosine average of the interpolated row) and
the same one-sample lobe mixture for sampling (probability ∝ each lobe's albedo for `wo`;
visible-normal samples below the horizon are rejected). Only the upper hemisphere is handled:
wrap it in `twosided` as the exporter does for every opaque material.

Works in `scalar_rgb` (slow: Python per call) and in the JIT variants (`llvm_ad_rgb`), where
the calls are traced once into the render kernel.
"""

import math

import drjit as dr
import mitsuba as mi
import numpy as np

TABLE_N = 32
TABLE_STRATA = 16
TABLE_AVG_STEPS = 256
MIN_ALPHA = 1e-3


# ---- the albedo table, in numpy, as AlbedoTable::build --------------------------------------

def _alpha(roughness):
    return max(roughness * roughness, MIN_ALPHA)


def _lambda_np(w, alpha):
    tan2 = (w[..., 0] ** 2 + w[..., 1] ** 2) / (w[..., 2] ** 2)
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * tan2) - 1.0)


def _vndf_np(wo, alpha, u):
    v = np.array([alpha * wo[0], alpha * wo[1], wo[2]])
    v /= np.linalg.norm(v)
    phi = 2.0 * np.pi * u[:, 0]
    z = (1.0 - u[:, 1]) * (1.0 + v[2]) - v[2]
    sin_theta = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    h = np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), z], axis=-1) + v
    h = np.stack([alpha * h[:, 0], alpha * h[:, 1], h[:, 2]], axis=-1)
    n = np.linalg.norm(h, axis=-1, keepdims=True)
    return np.where(n > 0, h / np.where(n > 0, n, 1), 0.0)


def _integrate_specular(mu, alpha):
    mu = min(max(mu, 1e-4), 1.0)
    wo = np.array([math.sqrt(1.0 - mu * mu), 0.0, mu])
    lambda_o = _lambda_np(wo, alpha)
    n = TABLE_STRATA
    k = np.arange(n * n)
    u = np.stack([(k % n + 0.5) / n, (k // n + 0.5) / n], axis=-1)
    h = _vndf_np(wo, alpha, u)
    wo_h = h @ wo
    wi = 2.0 * wo_h[:, None] * h - wo
    ok = wi[:, 2] > 0.0
    wi_safe = np.where(ok[:, None], wi, [0.0, 0.0, 1.0])
    w = (1.0 + lambda_o) / (1.0 + lambda_o + _lambda_np(wi_safe, alpha))
    s5 = np.clip(1.0 - wo_h, 0.0, 1.0) ** 5
    w = np.where(ok, w, 0.0)
    return np.array([np.sum(w * (1.0 - s5)), np.sum(w * s5)]) / (n * n)


def _coord(x):
    f = min(max(x, 0.0), 1.0) * (TABLE_N - 1)
    i = min(int(f), TABLE_N - 2)
    return i, f - i


def _lerp_row_np(row, x):
    i, t = _coord(x)
    return row[i] + (row[i + 1] - row[i]) * t


def _build_table():
    nodes = np.arange(TABLE_N) / (TABLE_N - 1)
    pq = np.array([[_integrate_specular(m * m, _alpha(r)) for m in nodes] for r in nodes])
    mus = (np.arange(TABLE_AVG_STEPS) + 0.5) / TABLE_AVG_STEPS
    avg = np.array([
        np.mean([_lerp_row_np(row, math.sqrt(m)) * 2.0 * m for m in mus], axis=0) for row in pq
    ])
    return pq, avg


_TABLE = None


def table():
    """`(pq[roughness][sqrt μ] = (P, Q), avg[roughness])`, built once per process."""
    global _TABLE
    if _TABLE is None:
        _TABLE = _build_table()
    return _TABLE


# ---- the BSDF ---------------------------------------------------------------------------------

def _lambda(w, alpha):
    tan2 = (dr.square(w.x) + dr.square(w.y)) / dr.square(w.z)
    return 0.5 * (dr.sqrt(1.0 + alpha * alpha * tan2) - 1.0)


def _mean(c):
    return (c.x + c.y + c.z) / 3.0


class LfgenStandard(mi.BSDF):
    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        base = [float(c) for c in props["base_color"]] if props.has_property("base_color") else [0.5] * 3
        roughness = float(props["roughness"]) if props.has_property("roughness") else 0.5
        metallic = float(props["metallic"]) if props.has_property("metallic") else 0.0
        specular = float(props["specular"]) if props.has_property("specular") else 0.5
        roughness = min(max(roughness, 0.0), 1.0)
        metallic = min(max(metallic, 0.0), 1.0)
        f0d = min(max(0.08 * specular, 0.0), 1.0)
        f90d = min(50.0 * f0d, 1.0)
        pq, avg = table()
        i, t = _coord(roughness)
        row = pq[i] + (pq[i + 1] - pq[i]) * t  # this material's (P, Q) row over sqrt μ
        e_avg = float((avg[i] + (avg[i + 1] - avg[i]) * t) @ [f0d, f90d])
        self.params = (base, roughness, metallic, specular)
        self.alpha = _alpha(roughness)
        self.f0d, self.f90d = f0d, f90d
        self.row_p = [float(x) for x in row[:, 0]]
        self.row_q = [float(x) for x in row[:, 1]]
        if dr.is_jit_v(mi.Float):
            self.row_p_jit = mi.Float(self.row_p)
            self.row_q_jit = mi.Float(self.row_q)
        b = mi.Color3f(*base)
        self.f0 = mi.Color3f(f0d) * (1.0 - metallic) + b * metallic
        self.f90 = mi.Color3f(f90d) * (1.0 - metallic) + mi.Color3f(1.0) * metallic
        self.diffuse = b * ((1.0 - metallic) / math.pi / max(1.0 - e_avg, 1e-4))
        flags = (mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.DiffuseReflection
                 | mi.BSDFFlags.FrontSide)
        self.m_components = [mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide,
                             mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide]
        self.m_flags = flags

    def _pq(self, mu):
        """`(P, Q)` of the specular layer at `cos θ = mu` (lerp on the sqrt μ axis)."""
        x = dr.clip(dr.sqrt(dr.maximum(mu, 0.0)), 0.0, 1.0) * (TABLE_N - 1)
        if dr.is_jit_v(mi.Float):
            i = dr.minimum(mi.UInt32(x), TABLE_N - 2)
            t = x - mi.Float(i)
            g = lambda row, k: dr.gather(mi.Float, row, k)
            p = g(self.row_p_jit, i) + (g(self.row_p_jit, i + 1) - g(self.row_p_jit, i)) * t
            q = g(self.row_q_jit, i) + (g(self.row_q_jit, i + 1) - g(self.row_q_jit, i)) * t
            return p, q
        i = min(int(x), TABLE_N - 2)
        t = x - i
        p = self.row_p[i] + (self.row_p[i + 1] - self.row_p[i]) * t
        q = self.row_q[i] + (self.row_q[i + 1] - self.row_q[i]) * t
        return mi.Float(p), mi.Float(q)

    def _p_spec(self, p_o, q_o):
        spec = _mean(self.f0 * p_o + self.f90 * q_o)
        diff = _mean(self.diffuse) * math.pi * (1.0 - (p_o * self.f0d + q_o * self.f90d))
        return spec / dr.maximum(spec + diff, 1e-30)

    def _eval(self, wo, wi):
        """lfgen's f(wo, wi) (no cosine) and mixture pdf; wo toward the viewer."""
        valid = (wo.z > 0.0) & (wi.z > 0.0)
        p_o, q_o = self._pq(wo.z)
        p_i, q_i = self._pq(wi.z)
        coupling = (1.0 - (p_o * self.f0d + q_o * self.f90d)) * (1.0 - (p_i * self.f0d + q_i * self.f90d))
        h = dr.normalize(wo + wi)
        a2 = self.alpha * self.alpha
        t = dr.square(h.z) * (a2 - 1.0) + 1.0
        d = a2 / (math.pi * t * t)
        lambda_o = _lambda(wo, self.alpha)
        g2 = 1.0 / (1.0 + lambda_o + _lambda(wi, self.alpha))
        s5 = dr.power(dr.clip(1.0 - dr.dot(wo, h), 0.0, 1.0), 5)
        fresnel = self.f0 + (self.f90 - self.f0) * s5
        spec_f = fresnel * (d * g2 / (4.0 * wo.z * wi.z))
        spec_pdf = d / ((1.0 + lambda_o) * 4.0 * wo.z)
        p_spec = self._p_spec(p_o, q_o)
        pdf = p_spec * spec_pdf + (1.0 - p_spec) * wi.z / math.pi
        f = spec_f + self.diffuse * coupling
        return dr.select(valid, f, 0.0), dr.select(valid, pdf, 0.0)

    def _vndf(self, wo, u):
        a = self.alpha
        v = dr.normalize(mi.Vector3f(a * wo.x, a * wo.y, wo.z))
        phi = 2.0 * math.pi * u.x
        z = (1.0 - u.y) * (1.0 + v.z) - v.z
        sin_theta = dr.sqrt(dr.maximum(1.0 - z * z, 0.0))
        s, c = dr.sincos(phi)
        h = mi.Vector3f(sin_theta * c, sin_theta * s, z) + v
        h = mi.Vector3f(a * h.x, a * h.y, h.z)
        n = dr.norm(h)
        return dr.select(n > 0.0, h / n, mi.Vector3f(0.0))

    def sample(self, ctx, si, sample1, sample2, active=True):
        wo = si.wi
        p_o, q_o = self._pq(wo.z)
        pick_spec = sample1 < self._p_spec(p_o, q_o)
        h = self._vndf(wo, sample2)
        wi_spec = 2.0 * dr.dot(wo, h) * h - wo
        wi_diff = mi.warp.square_to_cosine_hemisphere(sample2)
        wi = dr.select(pick_spec, wi_spec, wi_diff)
        f, pdf = self._eval(wo, wi)
        ok = active & (wo.z > 0.0) & (pdf > 0.0)
        bs = dr.zeros(mi.BSDFSample3f)
        bs.wo = wi
        bs.pdf = dr.select(ok, pdf, 0.0)
        bs.eta = 1.0
        bs.sampled_type = dr.select(pick_spec, mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                                    mi.UInt32(+mi.BSDFFlags.DiffuseReflection))
        bs.sampled_component = dr.select(pick_spec, mi.UInt32(0), mi.UInt32(1))
        weight = f * (wi.z / dr.select(ok, pdf, 1.0))
        return bs, dr.select(ok, weight, 0.0)

    def eval(self, ctx, si, wo, active=True):
        f, _ = self._eval(si.wi, wo)
        return dr.select(active, f * dr.maximum(wo.z, 0.0), 0.0)

    def pdf(self, ctx, si, wo, active=True):
        _, pdf = self._eval(si.wi, wo)
        return dr.select(active, pdf, 0.0)

    def eval_pdf(self, ctx, si, wo, active=True):
        f, pdf = self._eval(si.wi, wo)
        return dr.select(active, f * dr.maximum(wo.z, 0.0), 0.0), dr.select(active, pdf, 0.0)

    def traverse(self, callback):
        pass

    def to_string(self):
        b, r, m, s = self.params
        return f"LfgenStandard[base_color={b}, roughness={r}, metallic={m}, specular={s}]"


def register():
    mi.register_bsdf("lfgen_standard", lambda props: LfgenStandard(props))

//! The x86-64 kernels: SSE (the baseline every x86-64 CPU has) tests eight boxes as two groups
//! of four; AVX2 tests them in one group of eight. Both test triangle packets four at a time
//! with the same SSE expressions (under AVX2 the compiler encodes them as VEX, same results).

use super::super::Node;
use super::super::traverse::WideRay;
use super::{Lanes, MIN_DET, Packet, ROBUST};
use std::arch::x86_64::*;

pub(in super::super) struct Sse;
pub(in super::super) struct Avx2;

impl Lanes for Sse {
    #[inline(always)]
    unsafe fn node(node: &Node, ray: &WideRay, tmax: f32, near: &mut [f32; 8]) -> u32 {
        // SAFETY: SSE2 is part of x86-64; the offsets 0 and 4 stay inside the 8-lane rows.
        unsafe { node_half(node, ray, tmax, 0, near) | node_half(node, ray, tmax, 4, near) }
    }

    #[inline(always)]
    unsafe fn packet(p: &Packet, ray: &WideRay, tmax: f32, tuv: &mut [[f32; 4]; 3]) -> u32 {
        // SAFETY: SSE2 is part of x86-64.
        unsafe { packet_sse(p, ray, tmax, tuv) }
    }
}

impl Lanes for Avx2 {
    #[inline(always)]
    unsafe fn node(node: &Node, ray: &WideRay, tmax: f32, near: &mut [f32; 8]) -> u32 {
        // SAFETY: the caller runs this kernel only where the CPU has AVX2.
        unsafe { node_avx2(node, ray, tmax, near) }
    }

    #[inline(always)]
    unsafe fn packet(p: &Packet, ray: &WideRay, tmax: f32, tuv: &mut [[f32; 4]; 3]) -> u32 {
        // SAFETY: SSE2 is part of x86-64.
        unsafe { packet_sse(p, ray, tmax, tuv) }
    }
}

/// Children `at..at + 4` of `node`: the scalar reference's slab test, four lanes at once.
#[inline(always)]
unsafe fn node_half(node: &Node, ray: &WideRay, tmax: f32, at: usize, near: &mut [f32; 8]) -> u32 {
    unsafe {
        let slab = |axis: usize, row: usize| {
            let plane = _mm_loadu_ps(node.planes[row].as_ptr().add(at));
            let o = _mm_set1_ps(ray.origin[axis]);
            _mm_mul_ps(_mm_sub_ps(plane, o), _mm_set1_ps(ray.inv_dir[axis]))
        };
        let [n0, n1, n2] = [0, 1, 2].map(|a| slab(a, ray.near[a]));
        let [f0, f1, f2] = [0, 1, 2].map(|a| slab(a, ray.far[a]));
        let t0 = _mm_max_ps(_mm_max_ps(_mm_max_ps(n0, n1), n2), _mm_set1_ps(ray.tmin));
        let t1 = _mm_mul_ps(_mm_min_ps(_mm_min_ps(f0, f1), f2), _mm_set1_ps(ROBUST));
        let t1 = _mm_min_ps(t1, _mm_set1_ps(tmax));
        _mm_storeu_ps(near.as_mut_ptr().add(at), t0);
        (_mm_movemask_ps(_mm_cmple_ps(t0, t1)) as u32) << at
    }
}

/// All eight children of `node` in one 8-lane pass. Written out without closures: a closure
/// inside a `target_feature` function is compiled without the feature and, returning a
/// 256-bit vector, is called through memory instead of inlined (measured: a sixth of the walk).
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn node_avx2(node: &Node, ray: &WideRay, tmax: f32, near: &mut [f32; 8]) -> u32 {
    // SAFETY: `near` and `far` rows are below 6 (`WideRay::new`), the rows of `planes`.
    unsafe {
        let planes = node.planes.as_ptr();
        let row = |r: usize| (*planes.add(r)).as_ptr();
        let (o, inv) = (ray.origin, ray.inv_dir);
        let ox = _mm256_set1_ps(o[0]);
        let oy = _mm256_set1_ps(o[1]);
        let oz = _mm256_set1_ps(o[2]);
        let ix = _mm256_set1_ps(inv[0]);
        let iy = _mm256_set1_ps(inv[1]);
        let iz = _mm256_set1_ps(inv[2]);
        let n0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(row(ray.near[0])), ox), ix);
        let n1 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(row(ray.near[1])), oy), iy);
        let n2 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(row(ray.near[2])), oz), iz);
        let f0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(row(ray.far[0])), ox), ix);
        let f1 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(row(ray.far[1])), oy), iy);
        let f2 = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(row(ray.far[2])), oz), iz);
        let t0 = _mm256_max_ps(
            _mm256_max_ps(_mm256_max_ps(n0, n1), n2),
            _mm256_set1_ps(ray.tmin),
        );
        let t1 = _mm256_mul_ps(
            _mm256_min_ps(_mm256_min_ps(f0, f1), f2),
            _mm256_set1_ps(ROBUST),
        );
        let t1 = _mm256_min_ps(t1, _mm256_set1_ps(tmax));
        _mm256_storeu_ps(near.as_mut_ptr(), t0);
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32
    }
}

/// The scalar reference's Möller–Trumbore test on four lanes.
#[inline(always)]
unsafe fn packet_sse(p: &Packet, ray: &WideRay, tmax: f32, tuv: &mut [[f32; 4]; 3]) -> u32 {
    unsafe {
        let [v0x, v0y, v0z, e1x, e1y, e1z, e2x, e2y, e2z] =
            p.coords.map(|c| _mm_loadu_ps(c.as_ptr()));
        let [ox, oy, oz] = ray.origin.map(|c| _mm_set1_ps(c));
        let [dx, dy, dz] = ray.dir.map(|c| _mm_set1_ps(c));
        let (mul, sub) = (|a, b| _mm_mul_ps(a, b), |a, b| _mm_sub_ps(a, b));
        let dot = |a: [__m128; 3], b: [__m128; 3]| {
            _mm_add_ps(
                _mm_add_ps(mul(a[0], b[0]), mul(a[1], b[1])),
                mul(a[2], b[2]),
            )
        };
        let px = sub(mul(dy, e2z), mul(dz, e2y));
        let py = sub(mul(dz, e2x), mul(dx, e2z));
        let pz = sub(mul(dx, e2y), mul(dy, e2x));
        let det = dot([e1x, e1y, e1z], [px, py, pz]);
        let inv = _mm_div_ps(_mm_set1_ps(1.0), det);
        let (sx, sy, sz) = (sub(ox, v0x), sub(oy, v0y), sub(oz, v0z));
        let u = mul(dot([sx, sy, sz], [px, py, pz]), inv);
        let qx = sub(mul(sy, e1z), mul(sz, e1y));
        let qy = sub(mul(sz, e1x), mul(sx, e1z));
        let qz = sub(mul(sx, e1y), mul(sy, e1x));
        let v = mul(dot([dx, dy, dz], [qx, qy, qz]), inv);
        let t = mul(dot([e2x, e2y, e2z], [qx, qy, qz]), inv);
        let abs_det = _mm_andnot_ps(_mm_set1_ps(-0.0), det);
        let zero = _mm_setzero_ps();
        let in_range = _mm_and_ps(
            _mm_cmpgt_ps(t, _mm_set1_ps(ray.tmin)),
            _mm_cmple_ps(t, _mm_set1_ps(tmax)),
        );
        let miss = _mm_or_ps(
            _mm_or_ps(
                _mm_cmplt_ps(abs_det, _mm_set1_ps(MIN_DET)),
                _mm_cmplt_ps(u, zero),
            ),
            _mm_or_ps(
                _mm_cmplt_ps(v, zero),
                _mm_cmpgt_ps(_mm_add_ps(u, v), _mm_set1_ps(1.0)),
            ),
        );
        for (row, x) in tuv.iter_mut().zip([t, u, v]) {
            _mm_storeu_ps(row.as_mut_ptr(), x);
        }
        (_mm_movemask_ps(_mm_andnot_ps(miss, in_range)) as u32) & 0xf
    }
}

//! One walk of the tree for every query and kernel: a stack of children sorted near to far,
//! culled against an upper bound on `t` that the caller's visitor sets after each hit.

use super::kernel::Lanes;
use super::{Hit, LEAF_BIT, MAX_DEPTH, Node, Packet, WideBvh};
use glam::{Vec2, Vec3A};
use std::mem::MaybeUninit;

/// Stack entries: each level of the tree leaves at most seven siblings behind.
const STACK: usize = 7 * MAX_DEPTH + 1;

/// A ray prepared for the node and triangle tests.
pub(super) struct WideRay {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub inv_dir: [f32; 3],
    /// Per axis, the plane row (`Node::planes`) the ray enters a box through, and leaves it.
    pub near: [usize; 3],
    pub far: [usize; 3],
    pub tmin: f32,
}

impl WideRay {
    pub fn new(origin: Vec3A, dir: Vec3A, tmin: f32) -> Self {
        // A zero component gives an infinite reciprocal: slab distances of ±∞, or NaN for a
        // ray in a box's face plane, which the kernels' min/max rule drops (a NaN first
        // operand yields the second), so the test only loosens there, the same in every kernel.
        // One vector division (bitwise the three scalar ones): its latency is a camera ray's
        // set-up.
        let inv_dir = (Vec3A::ONE / dir).to_array();
        let near = [0, 1, 2].map(|a| if inv_dir[a] >= 0.0 { a } else { a + 3 });
        Self {
            origin: origin.to_array(),
            dir: dir.to_array(),
            inv_dir,
            near,
            far: near.map(|p| (p + 3) % 6),
            tmin,
        }
    }
}

/// Walks the tree with kernel `K`, calling `visit` on each hit in `(ray.tmin, bound]` with
/// `bound` starting at `tmax` and then whatever `visit` returns; a bound below `tmin` ends the
/// walk. Children are visited nearest first: the nearest child of a node is walked next
/// directly, the others wait on the stack, so a node's descent costs no push or pop.
#[inline(always)]
pub(super) fn walk<K: Lanes>(
    bvh: &WideBvh,
    ray: &WideRay,
    tmax: f32,
    mut visit: impl FnMut(&Hit) -> f32,
) {
    let mut stack = [const { MaybeUninit::<(u32, f32)>::uninit() }; STACK];
    let mut len = 0;
    let mut bound = tmax;
    let mut code = 0;
    loop {
        if code & LEAF_BIT == 0 {
            let node = &bvh.nodes[code as usize];
            let mut near = [0.0; 8];
            // SAFETY: `K` is a kernel this CPU runs (the caller's contract).
            let mask = unsafe { K::node(node, ray, bound, &mut near) };
            if mask != 0 {
                code = push_all_but_nearest(&mut stack, &mut len, node, mask, &near);
                continue;
            }
        } else {
            bound = visit_packet::<K>(
                &bvh.packets[(code & !LEAF_BIT) as usize],
                ray,
                bound,
                &mut visit,
            );
            if bound < ray.tmin {
                return;
            }
        }
        // The nearest waiting child still within the bound, if any.
        loop {
            if len == 0 {
                return;
            }
            len -= 1;
            // SAFETY: entries below `len` were written before they were counted.
            let (next, tnear) = unsafe { stack[len].assume_init() };
            if tnear <= bound {
                code = next;
                break;
            }
        }
    }
}

/// Tests a leaf packet and calls `visit` on its hits in lane order; returns the new bound.
#[inline(always)]
fn visit_packet<K: Lanes>(
    packet: &Packet,
    ray: &WideRay,
    mut bound: f32,
    visit: &mut impl FnMut(&Hit) -> f32,
) -> f32 {
    let mut tuv = [[0.0; 4]; 3];
    // SAFETY: `K` is a kernel this CPU runs (the caller's contract).
    let mut mask = unsafe { K::packet(packet, ray, bound, &mut tuv) };
    while mask != 0 {
        let lane = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if tuv[0][lane] <= bound {
            let hit = Hit {
                t: tuv[0][lane],
                tri: packet.tri[lane],
                b: Vec2::new(tuv[1][lane], tuv[2][lane]),
            };
            bound = visit(&hit);
        }
    }
    bound
}

/// [`walk`] compiled for AVX2.
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn walk_avx2(
    bvh: &WideBvh,
    ray: &WideRay,
    tmax: f32,
    visit: impl FnMut(&Hit) -> f32,
) {
    walk::<super::kernel::Avx2>(bvh, ray, tmax, visit)
}

/// Pushes the children in `mask` but the nearest, farthest first, so the nearest waiting is
/// popped first, and returns the nearest; children at one distance keep their slot order.
#[inline(always)]
fn push_all_but_nearest(
    stack: &mut [MaybeUninit<(u32, f32)>; STACK],
    len: &mut usize,
    node: &Node,
    mut mask: u32,
    near: &[f32; 8],
) -> u32 {
    if mask & (mask - 1) == 0 {
        return node.child[mask.trailing_zeros() as usize];
    }
    let mut order = [0usize; 8];
    let mut n = 0;
    while mask != 0 {
        let slot = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        let mut j = n;
        while j > 0 && near[order[j - 1]] < near[slot] {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = slot;
        n += 1;
    }
    for &slot in &order[..n - 1] {
        stack[*len].write((node.child[slot], near[slot]));
        *len += 1;
    }
    node.child[order[n - 1]]
}

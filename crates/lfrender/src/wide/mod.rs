//! The BVH the renderer traces: an 8-wide tree in a layout for CPU SIMD, collapsed from the
//! binary tree obvhs builds (its PLOC build and reinsertion).
//!
//! Each node keeps its eight child boxes as `f32` in structure-of-arrays form, so one SIMD
//! pass tests all eight, and each leaf is one packet of up to four triangles in
//! structure-of-arrays form, tested together (obvhs' own 8-wide traversal decodes 8-bit child
//! boxes one at a time and tests leaf triangles one by one).
//!
//! Kernels: [`Kernel::Scalar`] (any target), [`Kernel::Sse`] (x86-64 baseline) and
//! [`Kernel::Avx2`] (chosen at run time where the CPU has it) compute the same arithmetic lane
//! by lane — no fused multiply-add, the same operand order as the scalar formula, min/max with
//! the same tie rule — so every kernel returns bit-identical hits, and renders are
//! byte-identical whichever the CPU picks. The environment variable `LFGEN_SIMD`
//! (`scalar`, `sse`, `avx2`, `auto`) forces one, for tests and comparisons.

mod build;
mod kernel;
mod traverse;

use super::geometry::Hit;
use anyhow::{Result, bail};
use glam::Vec3A;
use obvhs::aabb::Aabb;

/// Deepest tree the traversal's fixed stack holds: each level pushes at most seven entries.
const MAX_DEPTH: usize = 64;

/// Eight child boxes (`f32`, empty slots inverted: min +∞, max −∞) and what each child is.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Node {
    /// Lower then upper box planes per axis: `planes[axis]` low, `planes[3 + axis]` high.
    planes: [[f32; 8]; 6],
    /// [`Child`] codes.
    child: [u32; 8],
}

/// Up to four triangles as `v0`, `e1 = v1 − v0`, `e2 = v2 − v0`, component by component;
/// unused lanes have zero edges, which the intersection test rejects (zero determinant).
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Packet {
    /// `v0.x, v0.y, v0.z, e1.x, …, e2.z`, four lanes each.
    coords: [[f32; 4]; 9],
    /// Triangle index (the caller's) per lane.
    tri: [u32; 4],
}

/// A child slot: an inner node, a leaf packet (high bit set) or nothing.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Child {
    Node(u32),
    Leaf(u32),
    Empty,
}

const LEAF_BIT: u32 = 1 << 31;
const EMPTY: u32 = u32::MAX;

impl Child {
    fn encode(self) -> u32 {
        match self {
            Child::Node(i) => i,
            Child::Leaf(i) => i | LEAF_BIT,
            Child::Empty => EMPTY,
        }
    }
}

/// Which arithmetic runs the node and triangle tests; every one gives the same bits.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Kernel {
    Scalar,
    #[cfg(target_arch = "x86_64")]
    Sse,
    #[cfg(target_arch = "x86_64")]
    Avx2,
}

impl Kernel {
    /// The fastest kernel this CPU runs, unless `LFGEN_SIMD` names one.
    pub fn from_env() -> Result<Self> {
        match std::env::var("LFGEN_SIMD") {
            Ok(name) => Self::named(&name),
            Err(std::env::VarError::NotPresent) => Ok(Self::best()),
            Err(e) => bail!("LFGEN_SIMD: {e}"),
        }
    }

    /// The kernel called `name` (`scalar`, `sse`, `avx2`, `auto`), if this CPU runs it.
    pub fn named(name: &str) -> Result<Self> {
        let kernel = match name {
            "auto" => return Ok(Self::best()),
            "scalar" => Self::Scalar,
            #[cfg(target_arch = "x86_64")]
            "sse" => Self::Sse,
            #[cfg(target_arch = "x86_64")]
            "avx2" => Self::Avx2,
            _ => bail!("LFGEN_SIMD={name:?}: expected scalar, sse, avx2 or auto (on x86-64)"),
        };
        match Self::available().contains(&kernel) {
            true => Ok(kernel),
            false => bail!("LFGEN_SIMD={name}: this CPU has no {name} instructions"),
        }
    }

    /// The kernel's name, as `LFGEN_SIMD` and [`Self::named`] take it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Scalar => "scalar",
            #[cfg(target_arch = "x86_64")]
            Self::Sse => "sse",
            #[cfg(target_arch = "x86_64")]
            Self::Avx2 => "avx2",
        }
    }

    /// Every kernel this CPU runs, slowest first.
    pub fn available() -> Vec<Self> {
        let mut all = vec![Self::Scalar];
        #[cfg(target_arch = "x86_64")]
        {
            all.push(Self::Sse);
            if std::arch::is_x86_feature_detected!("avx2") {
                all.push(Self::Avx2);
            }
        }
        all
    }

    fn best() -> Self {
        *Self::available()
            .last()
            .expect("the scalar kernel runs anywhere")
    }
}

/// The tree in SIMD layout, with the kernel that traverses it.
pub struct WideBvh {
    nodes: Vec<Node>,
    packets: Vec<Packet>,
    kernel: Kernel,
}

impl WideBvh {
    /// Builds the tree over `tris` (`v0, e1 = v1 − v0, e2 = v2 − v0` per triangle), its
    /// binary tree over `boxes` (one per triangle, containing it). Hits name triangles by their
    /// index in `tris`. Fails on a tree deeper than the traversal stack holds.
    pub fn new(tris: &[[Vec3A; 3]], boxes: &[Aabb], kernel: Kernel) -> Result<Self> {
        let built = build::build(tris, boxes)?;
        Ok(Self {
            nodes: built.nodes,
            packets: built.packets,
            kernel,
        })
    }

    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    /// Closest hit in `(tmin, tmax]` that `accept` keeps; among hits at one distance, the
    /// lowest triangle index: a total order, so the answer depends neither on the order the
    /// tree is walked in nor on the tree.
    pub fn closest(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        tmin: f32,
        tmax: f32,
        mut accept: impl FnMut(&Hit) -> bool,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        // Inlined into the walk: as a call per candidate hit it took 8 % of a camera ray's query.
        self.traverse(
            origin,
            dir,
            tmin,
            tmax,
            #[inline(always)]
            |hit| {
                let closer = best.is_none_or(|b| (hit.t, hit.tri) < (b.t, b.tri));
                if closer && accept(hit) {
                    best = Some(*hit);
                }
                best.map_or(tmax, |b| b.t)
            },
        );
        best.filter(|b| b.t < tmax)
    }

    /// Calls `visit` on every hit in `(0, tmax]` (a triangle in several leaves once per leaf),
    /// in an order fixed by the tree and the ray, until it returns false.
    pub fn each_hit(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        tmax: f32,
        mut visit: impl FnMut(&Hit) -> bool,
    ) {
        self.traverse(origin, dir, 0.0, tmax, |hit| match visit(hit) {
            true => tmax,
            false => f32::NEG_INFINITY,
        });
    }

    /// Walks the tree with the chosen kernel; `visit` returns the new upper bound on `t`.
    fn traverse(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        tmin: f32,
        tmax: f32,
        visit: impl FnMut(&Hit) -> f32,
    ) {
        let ray = traverse::WideRay::new(origin, dir, tmin);
        match self.kernel {
            Kernel::Scalar => traverse::walk::<kernel::Scalar>(self, &ray, tmax, visit),
            #[cfg(target_arch = "x86_64")]
            Kernel::Sse => traverse::walk::<kernel::Sse>(self, &ray, tmax, visit),
            // SAFETY: an `Avx2` kernel exists only where the CPU reported AVX2 (`named`).
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => unsafe { traverse::walk_avx2(self, &ray, tmax, visit) },
        }
    }
}

#[cfg(test)]
mod tests;

//! obvhs' compressed tree rebuilt node for node: same children, same leaves, same triangle
//! order, but exact `f32` boxes (the union of each child's triangles, not the 8-bit quantized
//! boxes, which are up to 1/255 of the parent larger) and one triangle packet per leaf.

use super::{Child, MAX_DEPTH, Node, Packet};
use anyhow::{Result, bail};
use glam::Vec3A;
use obvhs::cwbvh::CwBvh;

/// The tree's nodes (root first) and leaf packets.
pub(super) fn collapse(cw: &CwBvh, tris: &[[Vec3A; 3]]) -> Result<(Vec<Node>, Vec<Packet>)> {
    let mut out = Collapse {
        cw,
        tris,
        nodes: Vec::with_capacity(cw.nodes.len()),
        packets: Vec::new(),
    };
    out.node(0, 1)?;
    Ok((out.nodes, out.packets))
}

struct Collapse<'a> {
    cw: &'a CwBvh,
    tris: &'a [[Vec3A; 3]],
    nodes: Vec<Node>,
    packets: Vec<Packet>,
}

/// An axis-aligned box as (min, max); empty is (+∞, −∞).
type Bounds = (Vec3A, Vec3A);

const EMPTY_BOUNDS: Bounds = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);

impl Collapse<'_> {
    /// Converts obvhs node `index` at `depth` and everything below it; returns its box.
    fn node(&mut self, index: usize, depth: usize) -> Result<Bounds> {
        if depth > MAX_DEPTH {
            bail!("the scene's BVH is deeper than {MAX_DEPTH} levels (degenerate geometry)");
        }
        let slot = self.nodes.len();
        self.nodes.push(Node {
            planes: std::array::from_fn(|k| {
                [if k < 3 {
                    f32::INFINITY
                } else {
                    f32::NEG_INFINITY
                }; 8]
            }),
            child: [Child::Empty.encode(); 8],
        });
        let cw = self.cw.nodes[index];
        let mut total = EMPTY_BOUNDS;
        for i in 0..8 {
            let meta = cw.child_meta[i];
            let (child, (lo, hi)) = if meta == 0 {
                continue;
            } else if cw.imask & (1 << i) != 0 {
                let below = (cw.imask as u32 & ((1 << i) - 1)).count_ones();
                let at = self.nodes.len() as u32;
                let b = self.node((cw.child_base_idx + below) as usize, depth + 1)?;
                (Child::Node(at), b)
            } else {
                let first = cw.primitive_base_idx + (meta & 0b1_1111) as u32;
                let count = (meta >> 5).count_ones();
                (
                    Child::Leaf(self.packets.len() as u32),
                    self.leaf(first, count),
                )
            };
            let node = &mut self.nodes[slot];
            node.child[i] = child.encode();
            for axis in 0..3 {
                node.planes[axis][i] = lo[axis];
                node.planes[3 + axis][i] = hi[axis];
            }
            total = (total.0.min(lo), total.1.max(hi));
        }
        Ok(total)
    }

    /// Packs triangles `first..first + count` (at most 3 in obvhs' leaves) into one packet;
    /// returns their box, one ulp wider on every side: the test meets the triangle spanned by
    /// `v0`, `v0 + e1`, `v0 + e2` in exact arithmetic, whose corners the rounded sums may miss
    /// by half an ulp.
    fn leaf(&mut self, first: u32, count: u32) -> Bounds {
        let mut packet = Packet {
            coords: [[0.0; 4]; 9],
            tri: [u32::MAX; 4],
        };
        let mut b = EMPTY_BOUNDS;
        for lane in 0..count as usize {
            let tri = first + lane as u32;
            let [v0, e1, e2] = self.tris[tri as usize];
            for (k, c) in [v0, e1, e2].iter().flat_map(|v| v.to_array()).enumerate() {
                packet.coords[k][lane] = c;
            }
            packet.tri[lane] = tri;
            for v in [v0, v0 + e1, v0 + e2] {
                b = (b.0.min(v), b.1.max(v));
            }
        }
        self.packets.push(packet);
        (
            b.0.to_array().map(f32::next_down).into(),
            b.1.to_array().map(f32::next_up).into(),
        )
    }
}

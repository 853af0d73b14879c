//! The 8-wide tree built from obvhs' binary tree: each wide node takes the binary tree's
//! children and opens the largest (by surface area) until it has eight, and a subtree of at
//! most four triangles becomes one leaf packet where a surface-area cost prefers it whole.
//! The boxes are exact `f32` unions of each child's triangles.
//!
//! Why not obvhs' own 8-wide tree (CWBVH): its leaves hold at most three triangles (the
//! format's limit) and mostly one or two, so the four lanes of a packet test were 42 % full
//! (1.7 triangles per packet a camera ray tests on the bench scene; 2.7 here).

use super::{Child, MAX_DEPTH, Node, Packet};
use anyhow::{Result, bail};
use glam::Vec3A;
use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::Bvh2, bvh2::builder::build_bvh2};
use std::time::Duration;

/// Triangles in one leaf packet: the lanes of the SSE triangle test.
const PACKET: u32 = 4;

/// The built tree: nodes (root first) and leaf packets.
pub(super) struct Built {
    pub nodes: Vec<Node>,
    pub packets: Vec<Packet>,
}

/// Builds the tree over `tris` (`v0, e1 = v1 − v0, e2 = v2 − v0`, in the caller's order),
/// whose binary tree obvhs builds over `boxes` (one per triangle, containing it).
pub(super) fn build(tris: &[[Vec3A; 3]], boxes: &[Aabb]) -> Result<Built> {
    let params = BvhBuildParams {
        // One triangle per binary leaf: the packets are formed here, by subtree size.
        max_prims_per_leaf: 1,
        ..BvhBuildParams::medium_build()
    };
    let bvh2 = build_bvh2(boxes, params, &mut Duration::default());
    let mut out = Collapse {
        bvh2: &bvh2,
        tris,
        packet: packet_subtrees(&bvh2),
        built: Built {
            nodes: Vec::new(),
            packets: Vec::new(),
        },
    };
    out.node(&[0], 1)?;
    Ok(out.built)
}

/// Which binary subtrees become one leaf packet: those of at most [`PACKET`] triangles that
/// a surface-area cost prefers whole, computed without recursion (a degenerate tree can be
/// thousands of levels deep).
fn packet_subtrees(bvh2: &Bvh2) -> Vec<bool> {
    let mut preorder = Vec::with_capacity(bvh2.nodes.len());
    let mut stack = vec![0];
    while let Some(i) = stack.pop() {
        preorder.push(i);
        let n = &bvh2.nodes[i];
        if !n.is_leaf() {
            stack.extend([n.first_index as usize, n.first_index as usize + 1]);
        }
    }
    let (mut count, mut cost) = (vec![0; bvh2.nodes.len()], vec![0.0; bvh2.nodes.len()]);
    let mut packet = vec![false; bvh2.nodes.len()];
    for &i in preorder.iter().rev() {
        let n = &bvh2.nodes[i];
        let area = n.aabb.half_area();
        if n.is_leaf() {
            // One triangle (`max_prims_per_leaf` above): always within a packet.
            (count[i], cost[i], packet[i]) = (n.prim_count, area, true);
            continue;
        }
        let c = n.first_index as usize;
        count[i] = count[c] + count[c + 1];
        let split = INNER_COST * area + cost[c] + cost[c + 1];
        packet[i] = count[i] <= PACKET && area <= split;
        cost[i] = if packet[i] { area } else { split };
    }
    packet
}

/// The cost of a binary split against one packet test, per unit of box area: a wide node's
/// test costs about a packet's and stands for about seven binary nodes. Not sensitive: 0.1
/// or 1.0 move the node and packet tests per camera ray of the bench scene by at most 6 %.
const INNER_COST: f32 = 0.3;

struct Collapse<'a> {
    bvh2: &'a Bvh2,
    tris: &'a [[Vec3A; 3]],
    packet: Vec<bool>,
    built: Built,
}

/// An axis-aligned box as (min, max); empty is (+∞, −∞).
type Bounds = (Vec3A, Vec3A);

const EMPTY_BOUNDS: Bounds = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);

impl Collapse<'_> {
    /// Whether binary node `i` becomes one leaf packet.
    fn is_packet(&self, i: usize) -> bool {
        self.packet[i]
    }

    /// The up to eight binary nodes a wide node over `start` takes as children: `start`'s
    /// own, then the largest child that is not a packet replaced by its two, until eight.
    fn children_of(&self, start: &[usize]) -> Vec<usize> {
        let mut children = start.to_vec();
        while children.len() < 8 {
            let area = |&&i: &&usize| self.bvh2.nodes[i].aabb.half_area();
            let open = children.iter().filter(|&&i| !self.is_packet(i));
            let Some(&largest) = open.max_by(|a, b| area(a).total_cmp(&area(b))) else {
                break;
            };
            let at = children
                .iter()
                .position(|&i| i == largest)
                .expect("a child");
            children.splice(at..=at, self.open(largest));
        }
        children
    }

    /// Converts the binary nodes `start` (the root alone, or an inner node's two children) at
    /// `depth` into one wide node and everything below it; returns its box.
    fn node(&mut self, start: &[usize], depth: usize) -> Result<Bounds> {
        if depth > MAX_DEPTH {
            bail!("the scene's BVH is deeper than {MAX_DEPTH} levels (degenerate geometry)");
        }
        let slot = self.built.nodes.len();
        self.built.nodes.push(Node {
            planes: std::array::from_fn(|k| [[f32::INFINITY, f32::NEG_INFINITY][k / 3]; 8]),
            child: [Child::Empty.encode(); 8],
        });
        let start = match start {
            [root] if !self.is_packet(*root) => self.open(*root).to_vec(),
            _ => start.to_vec(),
        };
        let mut total = EMPTY_BOUNDS;
        for (i, b) in self.children_of(&start).into_iter().enumerate() {
            let (child, (lo, hi)) = match self.is_packet(b) {
                true => (Child::Leaf(self.built.packets.len() as u32), self.packet(b)),
                false => {
                    let at = Child::Node(self.built.nodes.len() as u32);
                    (at, self.node(&self.open(b), depth + 1)?)
                }
            };
            let node = &mut self.built.nodes[slot];
            node.child[i] = child.encode();
            for axis in 0..3 {
                node.planes[axis][i] = lo[axis];
                node.planes[3 + axis][i] = hi[axis];
            }
            total = (total.0.min(lo), total.1.max(hi));
        }
        Ok(total)
    }

    /// The two children of inner binary node `i`.
    fn open(&self, i: usize) -> [usize; 2] {
        let first = self.bvh2.nodes[i].first_index as usize;
        [first, first + 1]
    }

    /// Packs the triangles under binary node `i` (at most [`PACKET`]) into one packet, in
    /// the binary tree's order; returns their box, one ulp wider on every side: the test meets
    /// the triangle spanned by `v0`, `v0 + e1`, `v0 + e2` in exact arithmetic, whose corners
    /// the rounded sums may miss by half an ulp.
    fn packet(&mut self, i: usize) -> Bounds {
        let mut packet = Packet {
            coords: [[0.0; 4]; 9],
            tri: [u32::MAX; 4],
        };
        let mut b = EMPTY_BOUNDS;
        let mut stack = vec![i];
        let mut lane = 0;
        while let Some(n) = stack.pop() {
            let node = &self.bvh2.nodes[n];
            if !node.is_leaf() {
                stack.extend(self.open(n).into_iter().rev());
                continue;
            }
            let first = node.first_index as usize;
            for &input in &self.bvh2.primitive_indices[first..first + node.prim_count as usize] {
                let [v0, e1, e2] = self.tris[input as usize];
                for (k, c) in [v0, e1, e2].iter().flat_map(|v| v.to_array()).enumerate() {
                    packet.coords[k][lane] = c;
                }
                packet.tri[lane] = input;
                for v in [v0, v0 + e1, v0 + e2] {
                    b = (b.0.min(v), b.1.max(v));
                }
                lane += 1;
            }
        }
        self.built.packets.push(packet);
        (
            b.0.to_array().map(f32::next_down).into(),
            b.1.to_array().map(f32::next_up).into(),
        )
    }
}

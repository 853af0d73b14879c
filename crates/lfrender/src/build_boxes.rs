//! The boxes the BVH is built over: each triangle's own, except where many triangles share one
//! box exactly.
//!
//! Why: obvhs' PLOC builder pairs each node with the neighbour whose merged box is smallest and
//! breaks ties towards one side, so among `n` identical boxes only one pair is mutual per pass:
//! `n` passes over them, quadratic time (50 000 copies of one triangle in an OBJ took 110 s,
//! 4 M took hours). A run of more than [`MAX_SHARED`] identical boxes — coincident copies, or
//! distinct triangles spanning the same box — is spread: each box grows by a small margin on
//! every axis, a pseudo-random share of it towards the low side and the rest towards the high
//! side, so merged sizes differ and most nodes find a mutual partner, as among ordinary
//! triangles. Grown boxes
//! still contain their triangles, so traversal finds the same hits; boxes shared by a few
//! triangles (the two halves of an axis-aligned quad) are left as they are, and with them the
//! BVH of every ordinary scene.

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::triangle::Triangle;

/// Largest run of identical boxes left as it is: a run of `n` costs the builder about `n`
/// extra passes over it.
const MAX_SHARED: usize = 16;

/// The margin a spread box grows by on each axis, relative to its largest coordinate or
/// extent: wide enough that 1/1024 of it still moves an `f32` box edge (2⁻¹⁸ relative against
/// an ulp of at most 2⁻²³), narrow enough to cost traversal little.
const MARGIN: f32 = 1.0 / 256.0;

/// One box per triangle, in order, for the BVH builder.
pub fn build_boxes(tris: &[Triangle]) -> Vec<Aabb> {
    let mut boxes: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
    let keys: Vec<_> = boxes
        .iter()
        .map(|b| {
            (
                b.min.to_array().map(f32::to_bits),
                b.max.to_array().map(f32::to_bits),
            )
        })
        .collect();
    let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (keys[i as usize], i));
    for run in order.chunk_by(|&a, &b| keys[a as usize] == keys[b as usize]) {
        if run.len() > MAX_SHARED {
            for &i in run {
                boxes[i as usize] = spread(boxes[i as usize], i);
            }
        }
    }
    boxes
}

/// `b` grown by [`MARGIN`] of its scale on every axis, split between the low and the high side
/// by a fraction per axis drawn from `index` (a fixed hash, so the BVH is the same on every
/// run). Every spread box of a run has the same size, and two merge into a box the larger the
/// further apart their fractions lie: to the builder they are points scattered in a cube,
/// where nearest neighbours are mostly mutual.
fn spread(b: Aabb, index: u32) -> Aabb {
    let scale = b
        .min
        .abs()
        .max(b.max.abs())
        .max(b.max - b.min)
        .max_element()
        .max(1e-6);
    let h = hash(index);
    let r = Vec3A::new(
        (h >> 22) as f32,
        ((h >> 12) & 1023) as f32,
        ((h >> 2) & 1023) as f32,
    ) / 1024.0;
    let margin = scale * MARGIN;
    Aabb::new(b.min - margin * r, b.max + margin * (Vec3A::ONE - r))
}

/// SplitMix32-style mixing of `x`: neighbouring indices give unrelated bits.
fn hash(x: u32) -> u32 {
    let mut z = x.wrapping_add(0x9e37_79b9);
    z = (z ^ (z >> 16)).wrapping_mul(0x85eb_ca6b);
    z = (z ^ (z >> 13)).wrapping_mul(0xc2b2_ae35);
    z ^ (z >> 16)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
        Triangle {
            v0: a.into(),
            v1: b.into(),
            v2: c.into(),
        }
    }

    #[test]
    fn ordinary_triangles_keep_their_own_boxes() {
        // The two halves of a quad share a box; a few copies stay below the spreading run.
        let mut tris = vec![
            tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]),
            tri([0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]),
        ];
        tris.extend((0..MAX_SHARED).map(|i| tri([i as f32, 2.0, 0.0], [1.0, 3.0, 0.0], [0.0; 3])));
        let first = tris[0];
        tris.extend(std::iter::repeat_n(first, MAX_SHARED - 2));
        let boxes = build_boxes(&tris);
        for (t, b) in tris.iter().zip(&boxes) {
            assert_eq!((b.min, b.max), (t.aabb().min, t.aabb().max));
        }
    }

    #[test]
    fn a_long_run_of_one_box_is_spread_and_still_contains_its_triangles() {
        let t = tri([-3.0, 0.5, 2.0], [-2.0, 0.5, 2.0], [-3.0, 1.5, 2.0]);
        let tris = vec![t; 1000];
        let boxes = build_boxes(&tris);
        let own = t.aabb();
        let mut distinct: Vec<_> = boxes.iter().map(|b| b.min.x.to_bits()).collect();
        distinct.sort_unstable();
        distinct.dedup();
        assert!(distinct.len() > 500, "{} distinct boxes", distinct.len());
        let size = boxes[0].max - boxes[0].min;
        for b in &boxes {
            assert!(b.min.cmple(own.min).all() && b.max.cmpge(own.max).all());
            assert!((b.max - b.min - size).abs().max_element() < 1e-5);
            assert!((b.max - b.min - (own.max - own.min)).max_element() <= 3.0 * MARGIN * 1.001);
        }
    }
}

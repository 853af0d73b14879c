//! Every kernel against brute force over a soup of random, degenerate and tied triangles.

use super::*;
use glam::Vec2;
use obvhs::triangle::Triangle;

/// xorshift32: a fixed stream of test numbers without a dependency.
struct Rng(u32);

impl Rng {
    fn f32(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1 << 24) as f32
    }

    fn vec(&mut self, scale: f32) -> Vec3A {
        Vec3A::new(self.f32(), self.f32(), self.f32()) * 2.0 * scale - scale
    }
}

/// Random triangles, degenerate ones (a point, a line, a needle, a huge one), exact copies,
/// and a grid of unit quads at z = 0 whose shared edges rays can run along.
fn soup() -> Vec<Triangle> {
    let mut rng = Rng(0x1234_5678);
    let mut tris = Vec::new();
    for _ in 0..600 {
        let c = rng.vec(4.0);
        let [v0, v1, v2] = [0, 1, 2].map(|_| c + rng.vec(0.6));
        tris.push(Triangle { v0, v1, v2 });
    }
    let p = Vec3A::new(0.3, -0.2, 0.5);
    let x = Vec3A::X;
    tris.extend([
        Triangle {
            v0: p,
            v1: p,
            v2: p,
        },
        Triangle {
            v0: p,
            v1: p + x,
            v2: p + 2.0 * x,
        },
        Triangle {
            v0: p,
            v1: p + x,
            v2: p + x + Vec3A::Y * 1e-7,
        },
        Triangle {
            v0: Vec3A::splat(-50.0),
            v1: Vec3A::new(60.0, -50.0, 1.0),
            v2: Vec3A::new(0.0, 70.0, -3.0),
        },
    ]);
    let copies: Vec<_> = tris[..40].to_vec();
    tris.extend(copies);
    for i in -3..3 {
        for j in -3..3 {
            let [a, b] = [i, j].map(|k| k as f32);
            let q = |dx: f32, dy: f32| Vec3A::new(a + dx, b + dy, 0.0);
            tris.push(Triangle {
                v0: q(0.0, 0.0),
                v1: q(1.0, 0.0),
                v2: q(1.0, 1.0),
            });
            tris.push(Triangle {
                v0: q(0.0, 0.0),
                v1: q(1.0, 1.0),
                v2: q(0.0, 1.0),
            });
        }
    }
    tris
}

/// Rays from random points in random directions, along the axes, and down the grid's edges
/// and diagonals.
fn rays() -> Vec<(Vec3A, Vec3A)> {
    let mut rng = Rng(0x9e37_79b9);
    let mut rays: Vec<_> = (0..3000).map(|_| (rng.vec(6.0), rng.vec(1.0))).collect();
    rays.extend((0..300).map(|i| (rng.vec(6.0), [Vec3A::X, Vec3A::NEG_Y, Vec3A::Z][i % 3])));
    for i in -3..=3 {
        let a = i as f32;
        rays.push((Vec3A::new(a, 0.37, 5.0), Vec3A::NEG_Z));
        rays.push((Vec3A::new(0.41, a, -5.0), Vec3A::Z));
        rays.push((
            Vec3A::new(a + 0.25, a + 0.25, 2.0),
            Vec3A::new(0.0, 0.0, -1.0),
        ));
        rays.push((Vec3A::new(a, a, 3.0), Vec3A::new(0.1, 0.1, -1.0)));
    }
    rays
}

/// The renderer's Möller–Trumbore test on one triangle, in glam arithmetic.
fn reference(o: Vec3A, d: Vec3A, [v0, e1, e2]: [Vec3A; 3], tmin: f32, tmax: f32) -> Option<Hit> {
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v0;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    let t = e2.dot(q) * inv;
    if u < 0.0 || v < 0.0 || u + v > 1.0 || !(t > tmin && t <= tmax) {
        return None;
    }
    Some(Hit {
        t,
        tri: 0,
        b: Vec2::new(u, v),
    })
}

fn brute(tris: &[[Vec3A; 3]], o: Vec3A, d: Vec3A, tmin: f32, tmax: f32) -> Vec<Hit> {
    let mut hits: Vec<Hit> = (tris.iter().enumerate())
        .filter_map(|(i, &tri)| {
            reference(o, d, tri, tmin, tmax).map(|h| Hit { tri: i as u32, ..h })
        })
        .collect();
    hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.tri.cmp(&b.tri)));
    hits
}

/// The tree of `tris` in each kernel, built as the renderer builds it (over `build_boxes`),
/// and its triangles as `v0, e1, e2`.
fn trees_of(tris: &[Triangle]) -> (Vec<WideBvh>, Vec<[Vec3A; 3]>) {
    let boxes = super::super::build_boxes::build_boxes(tris);
    let edges: Vec<[Vec3A; 3]> = (tris.iter())
        .map(|t| [t.v0, t.v1 - t.v0, t.v2 - t.v0])
        .collect();
    let trees = (Kernel::available().into_iter())
        .map(|k| WideBvh::new(&edges, &boxes, k).unwrap())
        .collect();
    (trees, edges)
}

/// The soup's trees ([`trees_of`]).
fn trees() -> (Vec<WideBvh>, Vec<[Vec3A; 3]>) {
    trees_of(&soup())
}

/// Bits of a hit list, for exact comparison (`==` on floats would equate 0.0 and -0.0).
fn bits(hits: &[Hit]) -> Vec<(u32, u32, u32, u32)> {
    hits.iter()
        .map(|h| (h.t.to_bits(), h.tri, h.b.x.to_bits(), h.b.y.to_bits()))
        .collect()
}

#[test]
fn every_kernel_finds_the_brute_force_hits_bit_for_bit() {
    let (trees, tris) = trees();
    #[cfg(target_arch = "x86_64")]
    assert!(trees.len() >= 2, "the SSE kernel runs on every x86-64 CPU");
    let mut ties = 0;
    for (o, d) in rays() {
        let all = brute(&tris, o, d, 0.0, f32::INFINITY);
        ties += all.windows(2).filter(|w| w[0].t == w[1].t).count();
        let mut orders = Vec::new();
        for bvh in &trees {
            let mut seen = Vec::new();
            bvh.each_hit(o, d, f32::INFINITY, |h| {
                seen.push(*h);
                true
            });
            orders.push(bits(&seen));
            seen.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.tri.cmp(&b.tri)));
            assert_eq!(
                bits(&seen),
                bits(&all),
                "{:?} all hits of {o} {d}",
                bvh.kernel()
            );

            let first = bvh.closest(o, d, 0.0, f32::INFINITY, |_| true);
            assert_eq!(bits(first.as_slice()), bits(&all[..all.len().min(1)]));

            // Stochastic opacity and a near limit: the closest hit among those accepted.
            let tmin = 0.3;
            let keep = |h: &Hit| h.tri % 3 != 1;
            let want = brute(&tris, o, d, tmin, 9.0)
                .into_iter()
                .find(|h| keep(h) && h.t < 9.0);
            let got = bvh.closest(o, d, tmin, 9.0, keep);
            assert_eq!(
                bits(got.as_slice()),
                bits(want.as_slice()),
                "{:?} closest",
                bvh.kernel()
            );

            let mut any = false;
            bvh.each_hit(o, d, 2.0, |_| {
                any = true;
                false
            });
            assert_eq!(any, all.first().is_some_and(|h| h.t <= 2.0), "any hit");
        }
        assert!(
            orders.windows(2).all(|w| w[0] == w[1]),
            "kernels visit hits in one order"
        );
    }
    assert!(
        ties > 20,
        "the rays along shared edges and copies must tie ({ties})"
    );
}

#[test]
fn unknown_or_unsupported_kernels_are_refused_by_name() {
    let err = Kernel::named("avx512").unwrap_err().to_string();
    assert!(err.contains("LFGEN_SIMD=\"avx512\""), "{err}");
    assert_eq!(Kernel::named("scalar").unwrap(), Kernel::Scalar);
    assert_eq!(
        Kernel::named("auto").unwrap(),
        *Kernel::available().last().unwrap()
    );
}

/// 50 000 copies of one triangle (an OBJ that repeats a face; `build_boxes` spreads their
/// boxes for the builder) and 20 000 slivers along one line: the tree stays within the walk's
/// fixed stack, and a ray through them finds the lowest-index copy first.
#[test]
fn degenerate_soups_stay_within_the_stack() {
    let t = Triangle {
        v0: Vec3A::new(-1.0, -1.0, 0.0),
        v1: Vec3A::new(1.0, -1.0, 0.0),
        v2: Vec3A::new(0.0, 1.0, 0.0),
    };
    let mut tris = vec![t; 50_000];
    tris.extend((0..20_000).map(|i| {
        let x = i as f32 * 1e-3;
        Triangle {
            v0: Vec3A::new(x, 2.0, 0.0),
            v1: Vec3A::new(x + 1e-3, 2.0, 0.0),
            v2: Vec3A::new(x + 5e-4, 2.0, 1e-6),
        }
    }));
    let (trees, leaf) = trees_of(&tris);
    for bvh in &trees {
        let (o, d) = (Vec3A::new(0.1, 0.0, 1.0), Vec3A::new(0.0, 0.0, -1.0));
        let hit = bvh.closest(o, d, 0.0, f32::INFINITY, |_| true).unwrap();
        let lowest = (leaf.iter().enumerate())
            .filter_map(|(i, &tri)| reference(o, d, tri, 0.0, f32::INFINITY).map(|_| i as u32))
            .min()
            .unwrap();
        assert_eq!((hit.t, hit.tri), (1.0, lowest), "{:?}", bvh.kernel());
    }
}

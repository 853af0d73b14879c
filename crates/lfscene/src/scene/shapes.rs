//! Tessellation of [`Shape`]s into world-space triangles with normals and metre-scaled UVs
//! (imported meshes keep their own texture coordinates).

use super::assets::{Assets, MeshKey};
use super::{Object, SceneDesc, Shape, Transform};
use anyhow::{Context, Result, ensure};
use glam::{Mat3, Mat4, Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// One world-space triangle with per-vertex shading normals and UVs (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshTri {
    pub p: [Vec3; 3],
    pub n: [Vec3; 3],
    pub uv: [Vec2; 3],
}

impl MeshTri {
    /// `tris` in order without the triangles that repeat an earlier one exactly: the same
    /// corners in the same winding (from any corner). A repeat adds no surface — hits on it
    /// are hits on the first — yet every ray through it tests and collects both, so a file
    /// of millions of copies of one face would take hours to render. A face repeated with the
    /// opposite winding (a two-sided mesh made of back faces) is kept.
    pub fn without_repeats(tris: Vec<MeshTri>) -> Vec<MeshTri> {
        let keys: Vec<[[u32; 3]; 3]> = tris.iter().map(MeshTri::corner_key).collect();
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        order.sort_unstable_by_key(|&i| (keys[i as usize], i));
        let mut repeat = vec![false; tris.len()];
        for run in order.chunk_by(|&a, &b| keys[a as usize] == keys[b as usize]) {
            run[1..].iter().for_each(|&i| repeat[i as usize] = true);
        }
        let mut repeats = repeat.into_iter();
        let mut tris = tris;
        tris.retain(|_| repeats.next() == Some(false));
        tris
    }

    /// The corners' bits, rotated to start at the smallest: equal for the same triangle
    /// whichever corner a file lists first, different for the opposite winding.
    fn corner_key(&self) -> [[u32; 3]; 3] {
        let c = self.p.map(|p| p.to_array().map(f32::to_bits));
        let first = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
        [0, 1, 2].map(|k| c[(first + k) % 3])
    }
}

impl SceneDesc {
    /// Tessellates the objects in order into world-space triangles and hands each to
    /// `each(index, object, triangles)`, after checking its material index; errors name the
    /// object. The renderer and the exporters both build from this, so they see the same
    /// triangles and the same checks.
    pub fn for_each_mesh(
        &self,
        assets: &Assets,
        mut each: impl FnMut(usize, &Object, &[MeshTri]) -> Result<()>,
    ) -> Result<()> {
        let mut mesh = Vec::new();
        for (i, obj) in self.objects.iter().enumerate() {
            ensure!(
                (obj.material as usize) < self.materials.len(),
                "object {:?} refers to missing material {}",
                obj.name,
                obj.material
            );
            mesh.clear();
            tessellate(&obj.shape, &obj.transform, assets, &mut mesh)
                .with_context(|| format!("object {:?}", obj.name))?;
            each(i, obj, &mesh)?;
        }
        Ok(())
    }
}

/// Appends the triangles of `shape` placed by `xf` to `out`; a [`Shape::Mesh`] takes its
/// triangles from `assets`.
pub fn tessellate(
    shape: &Shape,
    xf: &Transform,
    assets: &Assets,
    out: &mut Vec<MeshTri>,
) -> Result<()> {
    let start = out.len();
    let mut m = xf.matrix();
    match *shape {
        Shape::Cuboid { size } => cuboid(size, Vec3::ZERO, false, out),
        Shape::Room { size } => cuboid(size, Vec3::new(0.0, size.y / 2.0, 0.0), true, out),
        Shape::Quad { size } => quad(
            [Vec3::new(-0.5, -0.5, 0.0), Vec3::X, Vec3::Y]
                .map(|v| v * Vec3::new(size[0], size[1], 1.0)),
            out,
        ),
        Shape::Wall { size, ref holes } => wall(size, holes, out),
        Shape::Sphere {
            radius,
            rings,
            segments,
        } => sphere(radius, rings.max(2), segments.max(3), out),
        Shape::Cylinder {
            radius,
            height,
            segments,
        } => cylinder(radius, height, segments.max(3), out),
        Shape::Lathe {
            ref profile,
            segments,
        } => lathe(profile, segments.max(3), out),
        Shape::Mesh { matrix, .. } => {
            let key = MeshKey::of(shape).expect("a mesh shape");
            out.extend_from_slice(assets.mesh(&key)?);
            m *= Mat4::from_cols_array(&matrix);
        }
    }
    let nm = Mat3::from_mat4(m).inverse().transpose();
    // A mirroring transform reverses the winding; swapping two vertices keeps the winding
    // normal on the side of the shading normals (emission and light sampling use it).
    let mirrored = Mat3::from_mat4(m).determinant() < 0.0;
    for t in &mut out[start..] {
        t.p = t.p.map(|p| m.transform_point3(p));
        t.n = t.n.map(|n| (nm * n).normalize_or_zero());
        if mirrored {
            t.p.swap(1, 2);
            t.n.swap(1, 2);
            t.uv.swap(1, 2);
        }
    }
    Ok(())
}

/// A parallelogram `origin + s·edge_u + t·edge_v`, normal `edge_u × edge_v`, UVs in metres.
fn quad([origin, eu, ev]: [Vec3; 3], out: &mut Vec<MeshTri>) {
    let n = eu.cross(ev).normalize();
    let (lu, lv) = (eu.length(), ev.length());
    let c = [origin, origin + eu, origin + eu + ev, origin + ev];
    let uv = [
        Vec2::ZERO,
        Vec2::new(lu, 0.0),
        Vec2::new(lu, lv),
        Vec2::new(0.0, lv),
    ];
    for [a, b, d] in [[0, 1, 2], [0, 2, 3]] {
        out.push(MeshTri {
            p: [c[a], c[b], c[d]],
            n: [n; 3],
            uv: [uv[a], uv[b], uv[d]],
        });
    }
}

/// A `size` rectangle centred at the origin (normal +Z) minus `holes`: a full-height strip
/// between holes, and below and above each hole a strip of its width. UVs in metres from the
/// rectangle's corner, continuous across the strips.
fn wall(size: [f32; 2], holes: &[[f32; 4]], out: &mut Vec<MeshTri>) {
    let [hw, hh] = [size[0] / 2.0, size[1] / 2.0];
    let mut holes: Vec<[f32; 4]> = holes.to_vec();
    holes.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut rect = |x0: f32, y0: f32, x1: f32, y1: f32| {
        if x1 > x0 && y1 > y0 {
            let start = out.len();
            quad(
                [
                    Vec3::new(x0, y0, 0.0),
                    Vec3::X * (x1 - x0),
                    Vec3::Y * (y1 - y0),
                ],
                out,
            );
            for t in &mut out[start..] {
                t.uv = t.uv.map(|uv| uv + Vec2::new(x0 + hw, y0 + hh));
            }
        }
    };
    let mut x = -hw;
    for &[x0, y0, x1, y1] in &holes {
        rect(x, -hh, x0, hh);
        rect(x0, -hh, x1, y0);
        rect(x0, y1, x1, hh);
        x = x1;
    }
    rect(x, -hh, hw, hh);
}

/// Six faces of a box centred at `centre`; `inward` flips every face (a room seen from inside).
fn cuboid(size: Vec3, centre: Vec3, inward: bool, out: &mut Vec<MeshTri>) {
    let h = size / 2.0;
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::AXES[axis] * sign;
            let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
            let (mut eu, ev) = (Vec3::AXES[a1] * size[a1], Vec3::AXES[a2] * size[a2]);
            // Orient each face so eu × ev points along the wanted normal.
            let wanted = if inward { -n } else { n };
            if eu.cross(ev).dot(wanted) < 0.0 {
                eu = -eu;
            }
            let origin = centre + n * h[axis] - eu / 2.0 - ev / 2.0;
            quad([origin, eu, ev], out);
        }
    }
}

fn sphere(radius: f32, rings: u32, segments: u32, out: &mut Vec<MeshTri>) {
    let point = |i: u32, j: u32| {
        let (theta, phi) = (
            PI * i as f32 / rings as f32,
            TAU * j as f32 / segments as f32,
        );
        let n = Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            -theta.sin() * phi.sin(),
        );
        let uv = Vec2::new(phi * radius, theta * radius);
        (n * radius, n, uv)
    };
    grid_mesh(rings, segments, point, out);
}

fn cylinder(radius: f32, height: f32, segments: u32, out: &mut Vec<MeshTri>) {
    let side = |i: u32, j: u32| {
        let phi = TAU * j as f32 / segments as f32;
        let n = Vec3::new(phi.cos(), 0.0, -phi.sin());
        let y = height * i as f32;
        (
            n * radius + Vec3::Y * (height - y),
            n,
            Vec2::new(phi * radius, height - y),
        )
    };
    grid_mesh(1, segments, side, out);
    for (y, n) in [(0.0, -Vec3::Y), (height, Vec3::Y)] {
        let rim = |j: u32| {
            let phi = TAU * j as f32 / segments as f32;
            Vec3::new(radius * phi.cos(), y, -radius * phi.sin())
        };
        let centre = Vec3::new(0.0, y, 0.0);
        for j in 0..segments {
            let (mut a, mut b) = (rim(j), rim(j + 1));
            if (a - centre).cross(b - centre).dot(n) < 0.0 {
                std::mem::swap(&mut a, &mut b);
            }
            let uv = [centre, a, b].map(|p| Vec2::new(p.x, p.z));
            out.push(MeshTri {
                p: [centre, a, b],
                n: [n; 3],
                uv,
            });
        }
    }
}

/// A surface of revolution. The profile's slope gives smooth normals (averaged at interior
/// points so a curved vase shades smoothly); V runs along the profile's arc length in metres.
fn lathe(profile: &[[f32; 2]], segments: u32, out: &mut Vec<MeshTri>) {
    if profile.len() < 2 {
        return;
    }
    let p: Vec<Vec2> = profile.iter().map(|&[r, y]| Vec2::new(r, y)).collect();
    let arc: Vec<f32> = std::iter::once(0.0)
        .chain(p.windows(2).scan(0.0, |s, w| {
            *s += w[0].distance(w[1]);
            Some(*s)
        }))
        .collect();
    // Outward 2-D normal (radius, height) of each profile edge.
    let edge_n: Vec<Vec2> = p
        .windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            Vec2::new(d.y, -d.x).normalize_or_zero()
        })
        .collect();
    // The normal at point `i` of edge `k`: averaged with the neighbouring edge's where the
    // profile bends gently (a curve sampled in points), the edge's own across a crease (a rim,
    // a step), where an average would tilt both faces' shading far from their geometry.
    let point_n = |i: usize, k: usize| {
        let other = if i == k { i.checked_sub(1) } else { Some(i) };
        match other.and_then(|o| edge_n.get(o)) {
            Some(&o) if o.dot(edge_n[k]) >= CREASE_COS => (o + edge_n[k]).normalize_or(edge_n[k]),
            _ => edge_n[k],
        }
    };
    // One band per profile edge, its rows running down the profile (as the cylinder's side),
    // which makes the winding outward.
    for k in 0..p.len() - 1 {
        let f = |i: u32, j: u32| {
            let phi = TAU * j as f32 / segments as f32;
            let (s, c) = phi.sin_cos();
            let at = k + 1 - i as usize;
            let (q, n2) = (p[at], point_n(at, k));
            let pos = Vec3::new(q.x * c, q.y, -q.x * s);
            let n = Vec3::new(n2.x * c, n2.y, -n2.x * s).normalize_or(Vec3::Y);
            let uv = Vec2::new(phi * q.x.abs().max(0.01), arc[at]);
            (pos, n, uv)
        };
        grid_mesh(1, segments, f, out);
    }
}

/// Cosine of the largest bend between two lathe profile edges that still shades smoothly (40°).
const CREASE_COS: f32 = 0.766;

/// Triangulates a `rows × cols` parametric patch; `f(i, j)` gives position, normal and UV.
/// Degenerate triangles (at the poles) are skipped.
fn grid_mesh(
    rows: u32,
    cols: u32,
    f: impl Fn(u32, u32) -> (Vec3, Vec3, Vec2),
    out: &mut Vec<MeshTri>,
) {
    for i in 0..rows {
        for j in 0..cols {
            let v = [f(i, j), f(i + 1, j), f(i + 1, j + 1), f(i, j + 1)];
            for [a, b, c] in [[0, 1, 2], [0, 2, 3]] {
                let p = [v[a].0, v[b].0, v[c].0];
                if !is_sliver(&p) {
                    out.push(MeshTri {
                        p,
                        n: [v[a].1, v[b].1, v[c].1],
                        uv: [v[a].2, v[b].2, v[c].2],
                    });
                }
            }
        }
    }
}

/// Whether a triangle is degenerate: a pole of a sphere or lathe collapses one edge of its
/// grid cells. The test is relative to the triangle's size (twice its area against its
/// longest edge squared, ~ the sine of its widest angle), so small objects keep every face.
fn is_sliver(p: &[Vec3; 3]) -> bool {
    let (e0, e1, e2) = (p[1] - p[0], p[2] - p[0], p[2] - p[1]);
    let longest = e0
        .length_squared()
        .max(e1.length_squared())
        .max(e2.length_squared());
    e0.cross(e1).length() <= 1e-6 * longest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_repeats_are_left_out_and_the_opposite_winding_kept() {
        let tri = |p: [[f32; 3]; 3], u: f32| MeshTri {
            p: p.map(Vec3::from),
            n: [Vec3::Z; 3],
            uv: [Vec2::splat(u); 3],
        };
        let (a, b, c, d) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]);
        let tris = vec![
            tri([a, b, c], 0.0),
            tri([b, d, c], 0.0),
            tri([a, b, c], 1.0), // a repeat: left out, the first one's UVs stay
            tri([b, c, a], 2.0), // the same winding from another corner: left out
            tri([a, c, b], 3.0), // the opposite winding: kept
            tri([b, d, c], 4.0),
        ];
        let kept = MeshTri::without_repeats(tris.clone());
        assert_eq!(kept, [tris[0], tris[1], tris[4]]);
        let many = MeshTri::without_repeats(vec![tris[0]; 100_000]);
        assert_eq!(many, [tris[0]]);
    }

    fn tris(shape: Shape) -> Vec<MeshTri> {
        let mut out = Vec::new();
        let xf = Transform::at(Vec3::new(1.0, 2.0, 3.0));
        tessellate(&shape, &xf, &Assets::default(), &mut out).unwrap();
        out
    }

    /// Signed volume by the divergence theorem: positive for outward-facing closed meshes.
    fn volume(t: &[MeshTri]) -> f32 {
        let c = Vec3::new(1.0, 2.0, 3.0);
        t.iter()
            .map(|t| (t.p[0] - c).dot((t.p[1] - c).cross(t.p[2] - c)) / 6.0)
            .sum()
    }

    #[test]
    fn closed_shapes_have_their_analytic_volume_and_face_outwards() {
        let v = volume(&tris(Shape::Cuboid {
            size: Vec3::new(1.0, 2.0, 3.0),
        }));
        assert!((v - 6.0).abs() < 1e-4, "{v}");
        let v = volume(&tris(Shape::Room {
            size: Vec3::new(2.0, 2.0, 2.0),
        }));
        assert!((v + 8.0).abs() < 1e-4, "room faces inwards: {v}");
        let v = volume(&tris(Shape::Sphere {
            radius: 1.0,
            rings: 64,
            segments: 128,
        }));
        assert!((v - 4.0 / 3.0 * PI).abs() < 0.01, "{v}");
        // A finely tessellated lamp bulb keeps every face but the collapsed ones at the poles
        // (an absolute area threshold once dropped its faces near the poles, or all of them).
        let bulb = tris(Shape::Sphere {
            radius: 0.01,
            rings: 96,
            segments: 192,
        });
        assert_eq!(bulb.len(), 2 * 96 * 192 - 2 * 192);
        let v = volume(&bulb);
        assert!((v / (4.0 / 3.0 * PI * 1e-6) - 1.0).abs() < 1e-3, "{v}");
        let v = volume(&tris(Shape::Cylinder {
            radius: 0.5,
            height: 2.0,
            segments: 256,
        }));
        assert!((v - PI * 0.5).abs() < 0.01, "{v}");
        // A closed lathe cylinder (axis → rim → rim → axis) has the cylinder's volume.
        let v = volume(&tris(Shape::Lathe {
            profile: vec![[0.0, 0.0], [0.5, 0.0], [0.5, 2.0], [0.0, 2.0]],
            segments: 256,
        }));
        assert!((v - PI * 0.5).abs() < 0.01, "{v}");
    }

    #[test]
    fn shading_normals_agree_with_winding() {
        for shape in [
            Shape::Cuboid { size: Vec3::ONE },
            Shape::Sphere {
                radius: 1.0,
                rings: 8,
                segments: 16,
            },
            Shape::Cylinder {
                radius: 1.0,
                height: 1.0,
                segments: 16,
            },
            Shape::Quad { size: [1.0, 2.0] },
            Shape::Wall {
                size: [4.0, 3.0],
                holes: vec![[0.5, -1.5, 1.4, 0.6], [-1.5, -0.5, -0.5, 0.8]],
            },
            Shape::Lathe {
                profile: vec![[0.0, 0.0], [0.3, 0.1], [0.2, 0.5], [0.25, 0.8], [0.0, 0.9]],
                segments: 24,
            },
        ] {
            for t in tris(shape.clone()) {
                let ng = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
                assert!(ng.dot(t.n[0] + t.n[1] + t.n[2]) > 0.0, "{shape:?}");
            }
        }
    }

    #[test]
    fn lathe_normals_are_smooth_along_curves_and_split_at_creases() {
        let segments = 32;
        let tol = (PI / segments as f32).cos() - 1e-4;
        // A cylinder's side and its flat top meet at 90°: each face keeps its own normal (an
        // average would tilt both by 45°, and renderers light such points differently).
        for t in tris(Shape::Lathe {
            profile: vec![[0.5, 0.0], [0.5, 1.0], [0.0, 1.0]],
            segments,
        }) {
            let ng = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize();
            assert!(t.n.iter().all(|n| n.dot(ng) > tol), "{:?} vs {ng}", t.n);
        }
        // A quarter circle in 5° steps shades smoothly: one normal per point, the radial one.
        let arc: Vec<[f32; 2]> = (0..=18)
            .map(|k| (k as f32 * 5.0).to_radians())
            .map(|a| [0.2 + a.cos(), a.sin()])
            .collect();
        for t in tris(Shape::Lathe {
            profile: arc,
            segments,
        }) {
            for (p, n) in t.p.iter().zip(t.n) {
                let local = *p - Vec3::new(1.0, 2.0, 3.0);
                let r = Vec2::new(local.x, -local.z).length();
                let radial = Vec2::new(r - 0.2, local.y).normalize();
                let along = Vec2::new(Vec2::new(n.x, -n.z).length(), n.y);
                assert!(radial.dot(along) > 0.999, "{along} vs {radial} at {p}");
            }
        }
    }

    #[test]
    fn a_mirroring_transform_keeps_winding_and_shading_normals_together() {
        let mirror = Transform {
            scale: Vec3::new(-1.0, 1.0, 1.0),
            ..Transform::at(Vec3::ZERO)
        };
        let mut out = Vec::new();
        tessellate(
            &Shape::Quad { size: [1.0, 1.0] },
            &mirror,
            &Assets::default(),
            &mut out,
        )
        .unwrap();
        for t in out {
            let ng = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
            assert!(ng.dot(t.n[0]) > 0.0 && t.n[0] == Vec3::Z, "{t:?}");
        }
    }

    /// The wall's area is the rectangle's minus its holes, nothing lies inside a hole, and the
    /// UV of every vertex is its position from the corner (continuous texture).
    #[test]
    fn walls_leave_their_holes_open_and_keep_one_uv_frame() {
        let holes = vec![[0.5, -1.5, 1.4, 0.6], [-1.5, -0.5, -0.5, 0.8]];
        let t = tris(Shape::Wall {
            size: [4.0, 3.0],
            holes: holes.clone(),
        });
        let area: f32 = t
            .iter()
            .map(|t| (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length() / 2.0)
            .sum();
        let open: f32 = holes.iter().map(|h| (h[2] - h[0]) * (h[3] - h[1])).sum();
        assert!((area - (12.0 - open)).abs() < 1e-4, "{area}");
        // tris() places the shape at (1, 2, 3).
        for tri in &t {
            let p = tri.p.map(|p| p - Vec3::new(1.0, 2.0, 3.0));
            let c = (p[0] + p[1] + p[2]) / 3.0;
            for h in &holes {
                let inside = c.x > h[0] && c.x < h[2] && c.y > h[1] && c.y < h[3];
                assert!(!inside, "triangle centre {c} in hole {h:?}");
            }
            for (p, uv) in p.iter().zip(tri.uv) {
                assert!((uv - Vec2::new(p.x + 2.0, p.y + 1.5)).length() < 1e-5);
            }
        }
    }

    #[test]
    fn quad_uvs_are_metres() {
        let t = tris(Shape::Quad { size: [2.0, 0.5] });
        let max_u = t
            .iter()
            .flat_map(|t| t.uv)
            .map(|uv| uv.x)
            .fold(0.0, f32::max);
        let max_v = t
            .iter()
            .flat_map(|t| t.uv)
            .map(|uv| uv.y)
            .fold(0.0, f32::max);
        assert_eq!((max_u, max_v), (2.0, 0.5));
    }
}

//! The HCI benchmark's evaluation masks, computed from the rendered geometry.
//!
//! Honauer et al. (ACCV 2016) score depth methods on five regions of each scene:
//! `mask_discontinuities` (around depth edges), `mask_planes` (planar surfaces),
//! `mask_smooth_surfaces` (continuous, non-planar surfaces), `mask_fine` (thin structures)
//! and `mask_fine_surrounding` (the background around them). The benchmark drew them from
//! its scenes' geometry; here they follow from per-pixel maps of the single-valued (HCI)
//! layer: planar depth, geometric normal and object id. Every rule compares a pixel with
//! its 4-neighbours through the tangent plane of each: on one plane, the neighbour's
//! inverse depth is exactly what the plane predicts; across a depth edge it is not, and
//! across a crease the normals differ. Widths are in low-resolution pixels and scale with
//! the map, so the high-resolution masks describe the same regions.

use rayon::prelude::*;

/// Disparity (low-resolution pixels) a neighbour may lie off a pixel's tangent plane before
/// the two are on opposite sides of a depth edge. Creases and curved surfaces stay well
/// below it (their offset over one pixel is a slope difference, ~0.01 px); an edge worth
/// the HCI BadPix threshold (0.07 px) is above it.
pub const EDGE_JUMP_PX: f64 = 0.05;
/// Where two surfaces meet between two pixels (a box on the floor, a room corner), each lies
/// off the other's tangent plane by at most the difference of their slopes; that much is
/// forgiven, up to this many disparity pixels per low-resolution pixel, so a steep surface's
/// silhouette still counts as an edge.
pub const CONTACT_SLOPE_PX: f64 = 0.5;
/// Half-width of the discontinuity band: pixels at most this far (Chebyshev distance, low-res
/// pixels) from a pixel on a depth edge.
pub const DISCONTINUITY_RADIUS: usize = 2;
/// A plane pixel's `(2r+1)²` window lies on one plane of one object (r in low-res pixels).
pub const PLANE_RADIUS: usize = 2;
/// Neighbours on one plane: normals within this angle (degrees) …
pub const PLANE_ANGLE_DEG: f64 = 0.1;
/// … and each on the other's plane within this disparity (low-res pixels).
pub const PLANE_OFFSET_PX: f64 = 1e-3;
/// Neighbours on one smooth surface: normals within this angle (degrees), which admits a
/// tessellated curve and refuses box edges and room corners.
pub const SMOOTH_ANGLE_DEG: f64 = 20.0;
/// A smooth-surface pixel's window (radius in low-res pixels) holds no crease or edge.
pub const SMOOTH_RADIUS: usize = 2;
/// Fine structures: the parts of an object that no `(2r+1)²` square inside the object
/// covers (they vanish under a morphological opening), r in low-res pixels; 2 makes
/// structures narrower than 5 px fine.
pub const FINE_RADIUS: usize = 2;
/// The surrounding of a fine structure reaches this far from it (low-res pixels).
pub const FINE_SURROUNDING_RADIUS: usize = 3;

/// Per-pixel maps of one image's single-valued surface, row-major.
pub struct SurfaceMaps<'a> {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Planar depth `Z` in metres; not finite or ≤ 0 where the pixel sees no surface.
    pub depth: &'a [f32],
    /// Unit geometric normal in the camera frame (x right, y up, z towards the camera).
    pub normal: &'a [[f32; 3]],
    /// Object id (any numbering; equal ids = one object).
    pub object: &'a [u32],
}

/// The pinhole the maps were rendered with, in the maps' own pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    /// Focal length, pixels of the map.
    pub focal_px: f64,
    /// Principal point, pixels from the left edge of the map.
    pub cx: f64,
    /// Principal point, pixels from the top edge of the map.
    pub cy: f64,
    /// Disparity in low-resolution pixels per unit of inverse depth (`baseline · f_low`), so
    /// thresholds mean the same at every resolution.
    pub disparity_per_inverse_depth: f64,
    /// Map pixels per low-resolution pixel (1 for the low-resolution maps).
    pub scale: usize,
}

/// The five HCI masks of one image, row-major, `true` = in the region.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HciMasks {
    /// `mask_discontinuities`.
    pub discontinuities: Vec<bool>,
    /// `mask_planes`.
    pub planes: Vec<bool>,
    /// `mask_smooth_surfaces`.
    pub smooth_surfaces: Vec<bool>,
    /// `mask_fine`.
    pub fine: Vec<bool>,
    /// `mask_fine_surrounding`.
    pub fine_surrounding: Vec<bool>,
}

impl HciMasks {
    /// The masks with the benchmark's file stems, in a fixed order.
    pub fn named(&self) -> [(&'static str, &[bool]); 5] {
        [
            ("mask_discontinuities", &self.discontinuities),
            ("mask_planes", &self.planes),
            ("mask_smooth_surfaces", &self.smooth_surfaces),
            ("mask_fine", &self.fine),
            ("mask_fine_surrounding", &self.fine_surrounding),
        ]
    }
}

/// All five masks of `maps` (see the module docs and the constants for the rules).
///
/// # Panics
/// If a map's length is not `width · height`.
pub fn hci_masks(maps: &SurfaceMaps, cam: &Pinhole) -> HciMasks {
    let (w, h) = (maps.width, maps.height);
    assert!(
        maps.depth.len() == w * h && maps.normal.len() == w * h && maps.object.len() == w * h,
        "hci_masks: maps of another size than {w}x{h}"
    );
    let surface: Vec<bool> = (0..w * h).map(|i| has_surface(maps, i)).collect();
    let edges = classify_edges(maps, cam, &surface);
    let radius = |r: usize| r * cam.scale;
    let near_edge = dilate(&edges.depth, w, h, radius(DISCONTINUITY_RADIUS));
    let discontinuities = and(&near_edge, &surface);
    let off_plane = dilate(&edges.plane, w, h, radius(PLANE_RADIUS));
    let planes: Vec<bool> = (0..w * h)
        .map(|i| surface[i] && !off_plane[i] && !discontinuities[i])
        .collect();
    let creased = dilate(&edges.smooth, w, h, radius(SMOOTH_RADIUS));
    let smooth_surfaces = (0..w * h)
        .map(|i| surface[i] && !creased[i] && !planes[i] && !discontinuities[i])
        .collect();
    let fine = fine_structures(maps, cam, &surface);
    let around = dilate(&fine, w, h, radius(FINE_SURROUNDING_RADIUS));
    let fine_surrounding = (0..w * h)
        .map(|i| around[i] && surface[i] && !fine[i])
        .collect();
    HciMasks {
        discontinuities,
        planes,
        smooth_surfaces,
        fine,
        fine_surrounding,
    }
}

/// Whether pixel `i` sees a surface with a usable depth and normal.
fn has_surface(maps: &SurfaceMaps, i: usize) -> bool {
    let z = maps.depth[i];
    z.is_finite() && z > 0.0 && maps.normal[i].iter().all(|c| c.is_finite())
}

fn and(a: &[bool], b: &[bool]) -> Vec<bool> {
    a.iter().zip(b).map(|(a, b)| *a && *b).collect()
}

/// Pixels at an end of a 4-neighbour pair that breaks each region.
struct EdgePixels {
    /// A depth edge: one side sees nothing, or each lies off the other's tangent plane by
    /// more than [`EDGE_JUMP_PX`] beyond what a meeting of the two planes explains.
    depth: Vec<bool>,
    /// Not one plane: a depth edge, another object, or normals or planes apart.
    plane: Vec<bool>,
    /// Not one smooth surface: a depth edge, another object, or a crease.
    smooth: Vec<bool>,
}

/// Marks both pixels of every right and down neighbour pair by what separates them.
fn classify_edges(maps: &SurfaceMaps, cam: &Pinhole, surface: &[bool]) -> EdgePixels {
    let (w, h) = (maps.width, maps.height);
    let mut edges = EdgePixels {
        depth: vec![false; w * h],
        plane: vec![false; w * h],
        smooth: vec![false; w * h],
    };
    for i in 0..w * h {
        let (x, y) = (i % w, i / w);
        let right = (x + 1 < w).then_some(i + 1);
        let down = (y + 1 < h).then_some(i + w);
        for j in [right, down].into_iter().flatten() {
            if !surface[i] && !surface[j] {
                continue;
            }
            let pair = Pair::new(maps, cam, surface, i, j);
            for (flag, set) in [
                (pair.depth_edge, &mut edges.depth),
                (pair.breaks_plane, &mut edges.plane),
                (pair.breaks_smooth, &mut edges.smooth),
            ] {
                if flag {
                    set[i] = true;
                    set[j] = true;
                }
            }
        }
    }
    edges
}

/// What separates two neighbouring pixels.
struct Pair {
    depth_edge: bool,
    breaks_plane: bool,
    breaks_smooth: bool,
}

impl Pair {
    fn new(maps: &SurfaceMaps, cam: &Pinhole, surface: &[bool], i: usize, j: usize) -> Self {
        if !(surface[i] && surface[j]) {
            return Self {
                depth_edge: true,
                breaks_plane: true,
                breaks_smooth: true,
            };
        }
        let disparity = |k: usize| cam.disparity_per_inverse_depth / f64::from(maps.depth[k]);
        let (d_i, d_j) = (disparity(i), disparity(j));
        // Each tangent plane's disparity change from i to j.
        let slope_i = on_plane(maps, cam, i, j) - d_i;
        let slope_j = d_j - on_plane(maps, cam, j, i);
        let step = d_j - d_i;
        let (off_ij, off_ji) = ((step - slope_i).abs(), (step - slope_j).abs());
        let meeting = (slope_i - slope_j)
            .abs()
            .min(CONTACT_SLOPE_PX / cam.scale as f64);
        let gap = off_ij.min(off_ji);
        let depth_edge = gap.is_nan() || gap > EDGE_JUMP_PX + meeting;
        let angle = normal_angle_deg(maps.normal[i], maps.normal[j]);
        let other_object = maps.object[i] != maps.object[j];
        let coplanar = off_ij <= PLANE_OFFSET_PX && off_ji <= PLANE_OFFSET_PX;
        Self {
            depth_edge,
            breaks_plane: depth_edge || other_object || angle > PLANE_ANGLE_DEG || !coplanar,
            breaks_smooth: depth_edge || other_object || angle > SMOOTH_ANGLE_DEG,
        }
    }
}

/// Disparity (low-res pixels) at pixel `j` of the tangent plane of pixel `i`: on the plane
/// `n · P = n · P_i`, the point on `j`'s ray has inverse depth `(n · r_j) / (n · P_i)`, with
/// `r_j` the ray at unit depth. Not finite when the plane is seen edge-on.
fn on_plane(maps: &SurfaceMaps, cam: &Pinhole, i: usize, j: usize) -> f64 {
    let n = maps.normal[i].map(f64::from);
    let dot = |r: [f64; 3]| n[0] * r[0] + n[1] * r[1] + n[2] * r[2];
    let ray = |k: usize| {
        let (x, y) = ((k % maps.width) as f64 + 0.5, (k / maps.width) as f64 + 0.5);
        [
            (x - cam.cx) / cam.focal_px,
            -(y - cam.cy) / cam.focal_px,
            -1.0,
        ]
    };
    let z_i = f64::from(maps.depth[i]);
    cam.disparity_per_inverse_depth * dot(ray(j)) / (z_i * dot(ray(i)))
}

/// Angle between two unit normals, degrees.
fn normal_angle_deg(a: [f32; 3], b: [f32; 3]) -> f64 {
    let dot: f64 = (0..3).map(|k| f64::from(a[k]) * f64::from(b[k])).sum();
    dot.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Fine structures: surface pixels outside the opening of their object's region by a
/// `(2r+1)²` square, and in front of something (a neighbour within `r` lies farther by more
/// than [`EDGE_JUMP_PX`], or sees nothing). The second rule keeps the gaps of a grid,
/// narrow too but behind the bars, out of the mask.
fn fine_structures(maps: &SurfaceMaps, cam: &Pinhole, surface: &[bool]) -> Vec<bool> {
    let (w, h) = (maps.width, maps.height);
    let r = FINE_RADIUS * cam.scale;
    // Label 0 = no surface, so a region never reaches across the background.
    let labels: Vec<u64> = (0..w * h)
        .map(|i| match surface[i] {
            true => u64::from(maps.object[i]) + 1,
            false => 0,
        })
        .collect();
    let opened = dilate(&uniform_windows(&labels, w, h, r), w, h, r);
    // Disparity-like inverse depth; nothing seen = infinitely far.
    let inverse: Vec<f64> = (0..w * h)
        .map(|i| match surface[i] {
            true => cam.disparity_per_inverse_depth / f64::from(maps.depth[i]),
            false => f64::NEG_INFINITY,
        })
        .collect();
    let farthest = window_min(&inverse, w, h, r);
    (0..w * h)
        .map(|i| surface[i] && !opened[i] && farthest[i] < inverse[i] - EDGE_JUMP_PX)
        .collect()
}

/// Pixels whose `(2r+1)²` window, clipped to the image, holds only their own label (the
/// erosion of each label's region).
fn uniform_windows(labels: &[u64], w: usize, h: usize, r: usize) -> Vec<bool> {
    let rows = runs_cover(labels, w, h, r, &|_| true);
    let transposed_labels = transpose(labels, w, h);
    let transposed_rows = transpose(&rows, w, h);
    let cols = runs_cover(&transposed_labels, h, w, r, &|i| transposed_rows[i]);
    transpose(&cols, h, w)
}

/// Per row: whether pixel `x`'s run of equal labels (among pixels where `ok`) covers
/// `[x − r, x + r]` clipped to the image: a region the image frame cuts is not thin there.
fn runs_cover(
    labels: &[u64],
    w: usize,
    h: usize,
    r: usize,
    ok: &(dyn Fn(usize) -> bool + Sync),
) -> Vec<bool> {
    let mut out = vec![false; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let at = |x: usize| (ok(y * w + x), labels[y * w + x]);
        let mut start = 0;
        while start < w {
            let mut end = start;
            while end + 1 < w && at(end + 1) == at(start) {
                end += 1;
            }
            if at(start).0 {
                let (open_left, open_right) = (start == 0, end + 1 == w);
                for (x, v) in row.iter_mut().enumerate().take(end + 1).skip(start) {
                    *v = (open_left || x >= start + r) && (open_right || x + r <= end);
                }
            }
            start = end + 1;
        }
    });
    out
}

/// Binary dilation by a `(2r+1)²` square.
pub fn dilate(mask: &[bool], w: usize, h: usize, r: usize) -> Vec<bool> {
    let as_f64: Vec<f64> = mask.iter().map(|&m| if m { -1.0 } else { 0.0 }).collect();
    window_min(&as_f64, w, h, r)
        .into_iter()
        .map(|v| v < 0.0)
        .collect()
}

/// Minimum over the `(2r+1)²` window clipped to the image, by two 1-D passes.
fn window_min(values: &[f64], w: usize, h: usize, r: usize) -> Vec<f64> {
    let rows = window_min_rows(values, w, h, r);
    let cols = window_min_rows(&transpose(&rows, w, h), h, w, r);
    transpose(&cols, h, w)
}

/// Minimum over `[x − r, x + r]` (clipped) in every row, by van Herk's block method: O(1)
/// per pixel whatever `r`. The row is padded with `+∞` by `r` at both ends, so every window
/// is exactly one block long and spans at most one block boundary.
fn window_min_rows(values: &[f64], w: usize, h: usize, r: usize) -> Vec<f64> {
    let block = 2 * r + 1;
    let mut out = vec![0.0; w * h];
    out.par_chunks_mut(w)
        .zip(values.par_chunks(w))
        .for_each(|(out, row)| {
            let pad = std::iter::repeat_n(f64::INFINITY, r);
            let padded: Vec<f64> = pad.clone().chain(row.iter().copied()).chain(pad).collect();
            let (mut prefix, mut suffix) = (padded.clone(), padded);
            let n = prefix.len();
            for k in 1..n {
                if k % block != 0 {
                    prefix[k] = prefix[k].min(prefix[k - 1]);
                }
            }
            for k in (0..n - 1).rev() {
                if (k + 1) % block != 0 {
                    suffix[k] = suffix[k].min(suffix[k + 1]);
                }
            }
            for (x, o) in out.iter_mut().enumerate() {
                *o = suffix[x].min(prefix[x + 2 * r]);
            }
        });
    out
}

fn transpose<T: Copy + Default + Send + Sync>(src: &[T], w: usize, h: usize) -> Vec<T> {
    let mut out = vec![T::default(); w * h];
    out.par_chunks_mut(h).enumerate().for_each(|(x, col)| {
        for (y, v) in col.iter_mut().enumerate() {
            *v = src[y * w + x];
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An analytic room seen by a 64×64 pinhole (f = 64 px, centred) at the origin looking
    /// down −z: a back wall at z = −4, a floor at y = −0.5, a box face at z = −2 standing on
    /// the floor, and a bar 0.1 m (2 px) wide at z = −3 standing on it too.
    const N: usize = 64;
    const WALL: u32 = 1;
    const FLOOR: u32 = 2;
    const BOX: u32 = 3;
    const BAR: u32 = 4;

    struct Room {
        depth: Vec<f32>,
        normal: Vec<[f32; 3]>,
        object: Vec<u32>,
    }

    fn camera(scale: usize) -> Pinhole {
        let n = (N * scale) as f64;
        Pinhole {
            focal_px: n,
            cx: n / 2.0,
            cy: n / 2.0,
            disparity_per_inverse_depth: 2.0,
            scale,
        }
    }

    /// Nearest hit of pixel `(x, y)`'s centre ray: (depth, normal, object).
    fn trace(x: usize, y: usize, cam: &Pinhole) -> Hit {
        let u = (x as f64 + 0.5 - cam.cx) / cam.focal_px;
        let v = -(y as f64 + 0.5 - cam.cy) / cam.focal_px;
        // Point at depth z: (u z, v z, −z).
        let mut best = (4.0, [0.0, 0.0, 1.0], WALL);
        if v < 0.0 && 0.5 / -v < best.0 {
            best = (0.5 / -v, [0.0, 1.0, 0.0], FLOOR);
        }
        let fronts = [
            (2.0, (-0.7, -0.1), (-0.5, 0.3), BOX),
            (3.0, (0.6, 0.7), (-0.5, 0.9), BAR),
        ];
        for (z, (x0, x1), (y0, y1), id) in fronts {
            let (px, py) = (u * z, v * z);
            if z < best.0 && (x0..x1).contains(&px) && (y0..y1).contains(&py) {
                best = (z, [0.0, 0.0, 1.0], id);
            }
        }
        (best.0 as f32, best.1, best.2)
    }

    /// What a pixel-centre ray sees: (depth, normal, object).
    type Hit = (f32, [f32; 3], u32);

    /// The maps of the scene `trace` sees through `cam` (`n × n` pixels) and their masks.
    fn traced(
        n: usize,
        cam: &Pinhole,
        trace: fn(usize, usize, &Pinhole) -> Hit,
    ) -> (Room, HciMasks) {
        let hits: Vec<_> = (0..n * n).map(|i| trace(i % n, i / n, cam)).collect();
        let room = Room {
            depth: hits.iter().map(|h| h.0).collect(),
            normal: hits.iter().map(|h| h.1).collect(),
            object: hits.iter().map(|h| h.2).collect(),
        };
        let maps = SurfaceMaps {
            width: n,
            height: n,
            depth: &room.depth,
            normal: &room.normal,
            object: &room.object,
        };
        let masks = hci_masks(&maps, cam);
        (room, masks)
    }

    fn masks(scale: usize) -> (Room, HciMasks) {
        traced(N * scale, &camera(scale), trace)
    }

    /// The analytic depth edges: neighbours on different objects whose disparities differ by
    /// more than [`EDGE_JUMP_PX`] (every surface here is flat along the pairs that cross a
    /// silhouette, so no slope is forgiven), except the wall–floor corner and where the box
    /// and the bar stand on the floor (an upper pixel on them, the lower on the floor).
    fn analytic_edge_pixels(room: &Room, n: usize, cam: &Pinhole) -> Vec<bool> {
        let disparity = |k: usize| cam.disparity_per_inverse_depth / f64::from(room.depth[k]);
        let mut edge = vec![false; n * n];
        for i in 0..n * n {
            let pairs = [
                (i % n + 1 < n).then_some(i + 1),
                (i / n + 1 < n).then_some(i + n),
            ];
            for j in pairs.into_iter().flatten() {
                let (a, b) = (room.object[i], room.object[j]);
                let corner = [a, b].contains(&WALL) && [a, b].contains(&FLOOR);
                let standing = j == i + n && [BOX, BAR].contains(&a) && b == FLOOR;
                let jump = (disparity(i) - disparity(j)).abs() > EDGE_JUMP_PX;
                if a != b && !corner && !standing && jump {
                    edge[i] = true;
                    edge[j] = true;
                }
            }
        }
        edge
    }

    /// The object ids, with `#` where both masks hold, `+` only `got`, `-` only `expected`.
    fn picture(got: &[bool], expected: &[bool], object: &[u32], n: usize) -> String {
        let cell = |i: usize| match (got[i], expected[i]) {
            (true, true) => '#',
            (true, false) => '+',
            (false, true) => '-',
            _ => char::from_digit(object[i], 10).unwrap_or('?'),
        };
        let rows = (0..n).map(|y| (0..n).map(|x| cell(y * n + x)).collect::<String>());
        rows.collect::<Vec<_>>().join("\n")
    }

    #[test]
    fn discontinuities_lie_exactly_along_the_analytic_depth_edges() {
        for scale in [1, 3] {
            let (room, masks) = masks(scale);
            let n = N * scale;
            let expected = dilate(
                &analytic_edge_pixels(&room, n, &camera(scale)),
                n,
                n,
                DISCONTINUITY_RADIUS * scale,
            );
            let same = masks.discontinuities == expected;
            let picture = || picture(&masks.discontinuities, &expected, &room.object, n);
            assert!(same, "scale {scale} (+ extra, - missing):\n{}", picture());
        }
    }

    #[test]
    fn planes_cover_plane_interiors_and_nothing_across_an_edge() {
        // Each object here is one plane, so a plane pixel's window holds no pixel next to
        // another object.
        let (room, masks) = masks(1);
        let mut border = vec![false; N * N];
        for i in 0..N * N {
            let pairs = [
                (i % N + 1 < N).then_some(i + 1),
                (i / N + 1 < N).then_some(i + N),
            ];
            for j in pairs.into_iter().flatten() {
                if room.object[i] != room.object[j] {
                    border[i] = true;
                    border[j] = true;
                }
            }
        }
        let near_border = dilate(&border, N, N, PLANE_RADIUS);
        for (i, &near) in near_border.iter().enumerate() {
            assert_eq!(masks.planes[i], !near, "pixel {},{}", i % N, i / N);
        }
        assert!(masks.planes.iter().filter(|&&p| p).count() > N * N / 2);
        assert!(
            masks.smooth_surfaces.iter().all(|&s| !s),
            "the room has no curved surface"
        );
    }

    #[test]
    fn the_thin_bar_is_fine_and_its_background_surrounds_it() {
        let (room, masks) = masks(1);
        for i in 0..N * N {
            let bar = room.object[i] == BAR;
            assert_eq!(masks.fine[i], bar, "pixel {},{}", i % N, i / N);
        }
        let bar_pixel = room.object.iter().position(|&o| o == BAR).unwrap();
        assert!(masks.fine_surrounding[bar_pixel - 2] && !masks.fine_surrounding[bar_pixel]);
        assert!(
            masks
                .fine_surrounding
                .iter()
                .zip(&masks.fine)
                .all(|(s, f)| !(s & f))
        );
    }

    /// A ball of radius 0.6 centred 2.5 m ahead, in front of the wall at z = −4, with exact
    /// normals: its nearest hit of pixel `(x, y)`'s centre ray, else the wall.
    fn trace_ball(x: usize, y: usize, cam: &Pinhole) -> Hit {
        let (centre, radius) = ([0.0, 0.0, -2.5], 0.6);
        let u = (x as f64 + 0.5 - cam.cx) / cam.focal_px;
        let v = -(y as f64 + 0.5 - cam.cy) / cam.focal_px;
        // Points t·(u, v, −1) at depth t; solve |t·d − c|² = r².
        let d = [u, v, -1.0];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (dd, dc, cc) = (dot(d, d), dot(d, centre), dot(centre, centre));
        let disc = dc * dc - dd * (cc - radius * radius);
        if disc < 0.0 {
            return (4.0, [0.0, 0.0, 1.0], WALL);
        }
        let t = (dc - disc.sqrt()) / dd;
        let n = [0, 1, 2].map(|k| ((t * d[k] - centre[k]) / radius) as f32);
        (t as f32, n, BOX)
    }

    /// A curved surface is smooth, not planar and not an edge inside; its silhouette bands
    /// (discontinuity and the smooth window) are left out, and the flat wall stays a plane.
    #[test]
    fn a_ball_is_a_smooth_surface_inside_its_silhouette() {
        // Disparities of 5 px (wall) and 8 px (ball): the silhouette's jump is well past the
        // slope a grazing surface is forgiven ([`CONTACT_SLOPE_PX`]).
        let cam = Pinhole {
            disparity_per_inverse_depth: 20.0,
            ..camera(1)
        };
        let (ball, masks) = traced(N, &cam, trace_ball);
        let object = &ball.object;
        let not_ball: Vec<bool> = object.iter().map(|&o| o != BOX).collect();
        let band = dilate(&not_ball, N, N, DISCONTINUITY_RADIUS);
        let near = dilate(&not_ball, N, N, DISCONTINUITY_RADIUS + SMOOTH_RADIUS);
        let mut inside = 0;
        for i in 0..N * N {
            let at = format!("pixel {},{}", i % N, i / N);
            if object[i] != BOX {
                assert!(!masks.smooth_surfaces[i], "{at}: the wall is not curved");
                continue;
            }
            assert!(!masks.planes[i], "{at}: the ball is not a plane");
            if !near[i] {
                assert!(
                    masks.smooth_surfaces[i],
                    "{at}: inside the ball, not smooth"
                );
                assert!(
                    !masks.discontinuities[i],
                    "{at}: curvature taken for an edge"
                );
                inside += 1;
            }
            if band[i] {
                assert!(!masks.smooth_surfaces[i], "{at}: on the silhouette band");
                assert!(masks.discontinuities[i], "{at}: the silhouette is an edge");
            }
        }
        assert!(inside > 300, "{inside} interior pixels");
        let wall_planes = (0..N * N).filter(|&i| object[i] == WALL && masks.planes[i]);
        assert!(wall_planes.count() > N * N / 2);
    }

    #[test]
    fn window_minimum_matches_brute_force() {
        let (w, h) = (13, 7);
        let values: Vec<f64> = (0..w * h).map(|i| ((i * 37) % 11) as f64).collect();
        let values = &values;
        for r in [0, 1, 2, 5, 9] {
            let fast = window_min(values, w, h, r);
            for (i, &got) in fast.iter().enumerate() {
                let (x, y) = (i % w, i / w);
                let xs = x.saturating_sub(r)..=(x + r).min(w - 1);
                let ys = y.saturating_sub(r)..=(y + r).min(h - 1);
                let brute = ys
                    .flat_map(|yy| xs.clone().map(move |xx| values[yy * w + xx]))
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(got, brute, "r {r} pixel {x},{y}");
            }
        }
    }
}

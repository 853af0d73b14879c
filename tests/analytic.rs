//! Renders of scenes whose images and depth ground truth are known in closed form, checked
//! against formulas (docs/reference/format.md, Camera; Slices and modes) rather than against the renderer's own output.

mod common;

use common::{
    Harness, Part, camera, cuboid, disparity, emitter, f_px, matte, quad, scene, settings,
};
use glam::{DVec3, Quat, Vec3};
use lfformat::srgb::from_linear as linear_to_srgb;
use lfformat::{Mode, ModeMap};
use lfgen::camera::LightFieldCamera;
use lfgen::output::images::to_srgb8;
use lfgen::render::integrator::GlassLight;
use lfgen::render::slices::SliceAssignment;
use lfgen::render::view::ViewGt;
use lfgen::scene::{Material, SceneDesc, Shape, SurfaceModel, Texture, Transform};

/// Centre camera of the fronto-parallel scenes: planes at world z = 4 − depth.
const EYE: DVec3 = DVec3::new(0.0, 1.0, 4.0);

/// World-space centre of a point at planar `depth` straight ahead of [`EYE`], offset in x, y.
fn ahead(depth: f64, dx: f64, dy: f64) -> Vec3 {
    (EYE + DVec3::new(dx, dy, -depth)).as_vec3()
}

fn gt(out: lfgen::render::view::ViewOutput) -> ViewGt {
    out.gt.expect("ground truth was requested")
}

/// Checks one mode against a surface at planar `depth` contributing `eta` by both definitions.
fn assert_mode(m: &Mode, cam: &LightFieldCamera, depth: f64, eta: f32, tol: f32, at: &str) {
    let rel = (m.depth as f64 - depth).abs() / depth;
    assert!(rel < 1e-4, "{at}: depth {} vs {depth}", m.depth);
    let d = disparity(cam, depth);
    // 1e-4 px: f32 depth error (~1e-7 relative) moves d by far less than that.
    assert!(
        (m.disparity as f64 - d).abs() < 1e-4,
        "{at}: disparity {} vs {d}",
        m.disparity
    );
    assert!((m.eta - eta).abs() < tol, "{at}: eta {} vs {eta}", m.eta);
    assert!(
        (m.eta_exact - eta).abs() < tol,
        "{at}: eta_exact {} vs {eta}",
        m.eta_exact
    );
}

fn pixels(map: &ModeMap) -> impl Iterator<Item = (usize, usize)> + use<> {
    let (w, h) = (map.width, map.height);
    (0..h).flat_map(move |y| (0..w).map(move |x| (x, y)))
}

// ---------------------------------------------------------------------------------------
// 1. A fronto-parallel checker plane.
// ---------------------------------------------------------------------------------------

/// Plane depth and the checker cell width in pixels.
const PLANE_Z: f64 = 2.0;
const CELL_PX: i32 = 4;
const CHECKER: [[f32; 3]; 2] = [[0.8, 0.1, 0.3], [0.1, 0.6, 0.05]];

/// A checker-plane case: image side, disparity (an integer, so views are integer shifts of
/// each other) and baseline.
#[derive(Clone, Copy)]
struct PlaneCase {
    side: u32,
    d: i32,
    baseline_m: f64,
}

/// The narrow case: ±2 px per view step, the HCI benchmark's range.
const NARROW: PlaneCase = PlaneCase {
    side: 64,
    d: 2,
    baseline_m: 0.05,
};

/// The wide case of `--preset wide`: 40 px per view step (±80 px at the corners of the 5×5
/// grid). 256² with a 15 cm baseline keeps every ray within 22° of the plane's normal, where
/// the near-mirror's Schlick term `(1 − cos)^5` stays below 3e-6 (see [`checker_plane`]): far
/// below one 8-bit level.
const WIDE: PlaneCase = PlaneCase {
    side: 256,
    d: 40,
    baseline_m: 0.15,
};

impl PlaneCase {
    /// Cells from the plane's centre to its edge: the half image plus the shift of a corner
    /// view of the 5×5 grid, and one more, so every view sees only the plane.
    fn half_cells(self) -> i32 {
        (self.side as i32 / 2 + 2 * self.d) / CELL_PX + 1
    }
}

/// A smooth metal with the checker as its colour under a white environment.
///
/// Why not a diffuse plane: the Standard BSDF puts a GGX glossy layer over the Lambert base,
/// so a "diffuse" surface reflects `E(μ) + c·(1 − E(μ))` of a constant environment, which
/// depends on the view angle, and its one-sample estimate is noisy. A metal at the minimum
/// roughness (α = 1e-3) reflects `F(wo·h)·G2/G1 ≈ F0 = base colour` per sample: within 14° of
/// the axis the Schlick term `(1 − cos)^5` is below 3e-8 and Λ below 1e-7, so every sample
/// of a pixel inside one cell returns the same radiance to f32 precision.
fn checker_plane(case: PlaneCase) -> SceneDesc {
    let mut cam = camera([case.side; 2], [5, 5], 100.0, EYE);
    cam.baseline_m = case.baseline_m;
    // 1/Zf = 1/Z − d/(f·b) makes the plane's disparity exactly `d`.
    let inv_zf = 1.0 / PLANE_Z - case.d as f64 / (f_px(&cam) * cam.baseline_m);
    assert!(inv_zf > 0.0, "the focus must lie in front of the camera");
    cam.focus_distance_m = 1.0 / inv_zf;
    let cell = (CELL_PX as f64 * PLANE_Z / f_px(&cam)) as f32;
    let [a, b] = CHECKER;
    let mirror = Material {
        base_color: Texture::Checker { a, b, size: cell },
        roughness: 0.0,
        metallic: 1.0,
        ..matte([1.0; 3], 1.0)
    };
    // Centred on the optical axis, so a cell corner (UV multiple of `cell`) projects to the
    // principal point (32, 32), a pixel corner; cell edges then fall on pixel boundaries.
    let size = 2.0 * case.half_cells() as f32 * cell;
    let plane = quad([size, size], ahead(PLANE_Z, 0.0, 0.0), mirror);
    scene(cam, [1.0, 5.0], [1.0; 3], vec![plane])
}

/// The checker colour of centre-view pixel `(i, j)`, from where its centre lands on the plane.
fn expected_checker(i: i32, j: i32, width: i32, height: i32) -> [f32; 3] {
    // Image x grows with world x; image y grows against world y (and against UV v).
    let cu = (2 * i + 1 - width).div_euclid(2 * CELL_PX);
    let cv = (height - 2 * j - 1).div_euclid(2 * CELL_PX);
    CHECKER[(cu + cv).rem_euclid(2) as usize]
}

/// Guards the choice of colours: an 8-bit code that sits near a rounding boundary could flip
/// on an f32 rounding of the radiance, which would make the exact comparisons meaningless.
fn assert_far_from_rounding(colors: &[[f32; 3]]) {
    for v in colors.iter().flatten() {
        let code = linear_to_srgb(*v) * 255.0;
        assert!(
            (code.fract() - 0.5).abs() > 0.05,
            "{v} encodes to {code}, too near .5"
        );
    }
}

/// Every view's GT: one opaque surface at the plane's depth and integer disparity `d`, to
/// 1e-4 px.
fn assert_plane_gt(cam: &LightFieldCamera, g: &ViewGt, d: i32) {
    assert!((disparity(cam, PLANE_Z) - d as f64).abs() < 1e-9);
    assert_every_pixel(cam, g, &[(PLANE_Z, 1.0)], 1e-6);
    assert_hci(g, PLANE_Z);
}

/// An 8-bit sRGB view.
struct Srgb {
    bytes: Vec<u8>,
    w: i32,
    h: i32,
}

impl Srgb {
    fn px(&self, i: i32, j: i32) -> &[u8] {
        let k = 3 * (j * self.w + i) as usize;
        &self.bytes[k..k + 3]
    }
}

/// Pixels of one view allowed to differ from the truth.
///
/// A render is exact up to two rare f32/sampling effects, each ~1e-6 per sample:
/// - a sample position is `x as f32 + offset` (~4e-6 px resolution at x ≈ 60), and the hit
///   and its UV add ~1e-6 px, so a sample that close to a cell edge may read the other cell;
/// - the α = 1e-3 GGX lobe has long tails: a rare half vector far from the normal changes
///   the Fresnel term, or reflects below the horizon, which ends the path black.
///
/// Over 41 seeds × 25 views at 1 spp, two pixels in all differed; a wrong shift or checker
/// phase breaks hundreds of pixels per view. The allowance is per 64² pixels (the cell edges,
/// where these effects strike, grow with the image: the wide case's 256² views had up to 4).
const MAX_OUTLIERS: usize = 3;

/// [`MAX_OUTLIERS`] for an image of `pixels` pixels.
fn max_outliers(pixels: usize) -> usize {
    MAX_OUTLIERS * pixels.div_ceil(64 * 64)
}

/// Counts differing pixel pairs and describes the first.
#[derive(Default)]
struct Diffs {
    count: usize,
    first: Option<String>,
}

impl Diffs {
    fn check(&mut self, got: &[u8], want: &[u8], at: impl FnOnce() -> String) {
        if got != want {
            self.count += 1;
            self.first
                .get_or_insert_with(|| format!("{}: {got:?} vs {want:?}", at()));
        }
    }

    fn assert_few(&self, what: &str, pixels: usize) {
        let n = self.count;
        assert!(
            n <= max_outliers(pixels),
            "{what}: {n} pixels differ, first {:?}",
            self.first
        );
    }
}

/// The centre view shows the analytic checker, pixel for pixel.
fn assert_centre_is_checker(img: &Srgb) {
    let (mut seen, mut diffs) = ([0usize; 2], Diffs::default());
    for (j, i) in (0..img.h).flat_map(|j| (0..img.w).map(move |i| (j, i))) {
        let c = expected_checker(i, j, img.w, img.h);
        seen[usize::from(c != CHECKER[0])] += 1;
        let want = to_srgb8(&[Vec3::from(c)], 1.0);
        diffs.check(img.px(i, j), &want, || format!("pixel ({i}, {j})"));
    }
    diffs.assert_few("centre view", (img.w * img.h) as usize);
    // Not a constant image: both colours cover large areas, so a shift is detectable.
    assert!(seen[0] > 1000 && seen[1] > 1000, "{seen:?}");
}

/// View `(u, v)` equals the centre view shifted by `(u−uc, v−vc)·d`, wherever that stays inside.
fn assert_shifted(view: &Srgb, centre: &Srgb, (du, dv): (i32, i32), d: i32) {
    let (w, h) = (view.w, view.h);
    let (mut compared, mut diffs) = (0, Diffs::default());
    for (j, i) in (0..h).flat_map(|j| (0..w).map(move |i| (j, i))) {
        let (ci, cj) = (i + du * d, j + dv * d);
        if (0..w).contains(&ci) && (0..h).contains(&cj) {
            diffs.check(view.px(i, j), centre.px(ci, cj), || {
                format!("pixel ({i}, {j})")
            });
            compared += 1;
        }
    }
    diffs.assert_few(&format!("view ({du}, {dv})"), (w * h) as usize);
    let (ow, oh) = (w - (du * d).abs(), h - (dv * d).abs());
    assert!(compared >= ow * oh, "only {compared} pixels overlap");
}

#[test]
fn fronto_parallel_plane_disparity_and_view_shift() {
    plane_disparity_and_view_shift(NARROW);
}

/// The same at the wide preset's disparities: the views, the GT disparity and the HCI depth
/// stay exact at 40 px per view step.
#[test]
fn wide_baseline_plane_disparity_and_view_shift() {
    plane_disparity_and_view_shift(WIDE);
}

fn plane_disparity_and_view_shift(case: PlaneCase) {
    assert_far_from_rounding(&CHECKER);
    let h = Harness::new(checker_plane(case));
    let cam = &h.desc.camera;
    // One sample per pixel suffices: a pixel's footprint lies inside one cell, so its value
    // does not depend on where the sample falls.
    let s = settings(1, 2);
    let render = |view| {
        let out = h.render(view, &s, true);
        let (w, h) = (out.image.width as i32, out.image.height as i32);
        let img = Srgb {
            bytes: to_srgb8(&out.image.pixels, 1.0),
            w,
            h,
        };
        assert_plane_gt(cam, &gt(out), case.d);
        img
    };
    let centre = render(cam.center_view());
    assert_centre_is_checker(&centre);
    for view in (0..cam.num_views()).filter(|&v| v != cam.center_view()) {
        assert_shifted(&render(view), &centre, cam.view_offset(view), case.d);
    }
}

// ---------------------------------------------------------------------------------------
// 2. A semi-transparent pane over a wall.
// ---------------------------------------------------------------------------------------

const PANE_Z: f64 = 1.5;
const WALL_Z: f64 = 3.5;

/// A pane of the given opacity at [`PANE_Z`] in front of an opaque wall at [`WALL_Z`], both
/// covering the whole view; the centre view's ground truth.
fn pane_over_wall(opacity: f32) -> (LightFieldCamera, ViewGt) {
    let cam = camera([24, 24], [5, 5], 100.0, EYE);
    let pane = quad(
        [4.0, 4.0],
        ahead(PANE_Z, 0.0, 0.0),
        matte([0.9; 3], opacity),
    );
    let wall = quad([8.0, 8.0], ahead(WALL_Z, 0.0, 0.0), matte([0.5; 3], 1.0));
    let h = Harness::new(scene(cam.clone(), [1.0, 5.0], [1.0; 3], vec![pane, wall]));
    let out = h.render(cam.center_view(), &settings(4, 1), true);
    (cam, gt(out))
}

/// Every pixel has exactly the given modes `(depth, η)`, η within `tol`.
fn assert_every_pixel(cam: &LightFieldCamera, g: &ViewGt, want: &[(f64, f32)], tol: f32) {
    for (x, y) in pixels(&g.modes) {
        let modes = g.modes.pixel(x, y);
        let at = format!("pixel ({x}, {y})");
        assert_eq!(modes.len(), want.len(), "{at}: {modes:?}");
        for (m, &(depth, eta)) in modes.iter().zip(want) {
            assert_mode(m, cam, depth, eta, tol, &at);
        }
    }
}

/// Every pixel's HCI depth (pixel-centre ray) is `depth`.
fn assert_hci(g: &ViewGt, depth: f64) {
    for (i, &got) in g.hci.depth.iter().enumerate() {
        let rel = (got as f64 - depth).abs() / depth;
        assert!(rel < 1e-4, "pixel {i}: hci depth {got} vs {depth}");
    }
}

#[test]
fn pane_over_wall_two_modes() {
    // η = α of the pane, then (1 − α)·1 for the wall; the HCI depth is the first surface with
    // coverage ≥ 0.5.
    let (cam, g) = pane_over_wall(0.4);
    assert_every_pixel(&cam, &g, &[(PANE_Z, 0.4), (WALL_Z, 0.6)], 1e-3);
    assert_hci(&g, WALL_Z);
    // A fully transparent pane contributes nothing and is no mode.
    let (cam, g) = pane_over_wall(0.0);
    assert_every_pixel(&cam, &g, &[(WALL_Z, 1.0)], 1e-3);
    assert_hci(&g, WALL_Z);
    // An opaque pane hides the wall completely: the wall is no mode either.
    let (cam, g) = pane_over_wall(1.0);
    assert_every_pixel(&cam, &g, &[(PANE_Z, 1.0)], 1e-3);
    assert_hci(&g, PANE_Z);
}

// ---------------------------------------------------------------------------------------
// 3. An opaque edge through a column of pixels.
// ---------------------------------------------------------------------------------------

/// The occluder's right edge projects to x = 20.3 in the centre view: pixel column 20 is
/// covered 30 % (from its left side). In view (u, v) it moves to 20.3 − (u − uc)·d.
const EDGE_X: f64 = 20.3;
const OCCLUDER_Z: f64 = 2.0;
const BACK_Z: f64 = 4.0;

/// An opaque quad left of the edge at [`OCCLUDER_Z`], a wall at [`BACK_Z`] behind it.
fn occluder_edge() -> Harness {
    let cam = camera([64, 64], [5, 5], 100.0, EYE);
    let half_w = cam.width() as f64 / 2.0;
    let edge = (EDGE_X - half_w) * OCCLUDER_Z / f_px(&cam);
    let black = matte([0.2; 3], 1.0);
    let occluder = quad([2.0, 4.0], ahead(OCCLUDER_Z, edge - 1.0, 0.0), black);
    let wall = quad([8.0, 8.0], ahead(BACK_Z, 0.0, 0.0), matte([0.7; 3], 1.0));
    Harness::new(scene(cam, [1.0, 5.0], [1.0; 3], vec![occluder, wall]))
}

/// Largest possible error of the covered fraction of a pixel cut at `f` by a vertical edge,
/// with 64 samples in 8 × 8 jittered strata: stratum columns left of the edge are always
/// covered, those right of it never; only the 8 samples of the column holding the edge are
/// random, each covered with p = frac(8f). The count is then fixed + B(8, p), and the error
/// at most 8·max(p, 1 − p)/64 ≤ 0.125 whatever the jitter (0.075 for f = 0.3).
fn edge_bound(f: f64) -> f32 {
    let p = (8.0 * f).fract();
    (8.0 * p.max(1.0 - p) / 64.0) as f32 + 1e-4
}

/// The mean over a column of 64 pixels has σ ≤ √(8·¼)/64/8 ≈ 0.0028; 0.02 is over 7σ.
const EDGE_MEAN_TOL: f32 = 0.02;

#[test]
fn occluder_edge_fraction() {
    let h = occluder_edge();
    let cam = &h.desc.camera;
    // The centre view (edge at 20.3), and side views where it moves by ∓2·1.52 px.
    for view in [cam.center_view(), 0, 14] {
        let edge = EDGE_X - cam.view_offset(view).0 as f64 * disparity(cam, OCCLUDER_Z);
        let g = gt(h.render(view, &settings(64, 1), true));
        let mean = assert_edge_view(cam, &g, edge, &format!("view {view}"));
        let f = edge.fract() as f32;
        assert!(
            (mean - f).abs() < EDGE_MEAN_TOL,
            "view {view}: column mean {mean} vs {f}"
        );
    }
}

/// `gt_spp` gives the ground truth its own samples: one colour sample per pixel, yet the edge
/// column's η as precise as 64 samples make it (the same bound as above), and the colour
/// image bit for bit the one rendered without any GT; and the other way round, 64 colour
/// samples with one GT sample give η of 0 or 1 only.
#[test]
fn gt_spp_sets_the_precision_of_eta_apart_from_the_colour() {
    let h = occluder_edge();
    let cam = &h.desc.camera;
    let view = cam.center_view();
    let mut s = settings(1, 1);
    s.gt_spp = 64;
    let with = h.render(view, &s, true);
    assert!(bits(&with) == bits(&h.render(view, &s, false)));
    let mean = assert_edge_view(cam, with.gt.as_ref().unwrap(), EDGE_X, "gt_spp 64");
    assert!((mean - 0.3).abs() < EDGE_MEAN_TOL, "column mean {mean}");
    let (mut s, col) = (settings(64, 1), EDGE_X as usize);
    s.gt_spp = 1;
    let g = gt(h.render(view, &s, true));
    for y in 0..g.modes.height {
        let modes = g.modes.pixel(col, y);
        assert!(modes.len() == 1 && modes[0].eta == 1.0, "y {y}: {modes:?}");
    }
}

/// Checks every pixel against an edge at image x = `edge`; returns the edge column's mean η.
fn assert_edge_view(cam: &LightFieldCamera, g: &ViewGt, edge: f64, what: &str) -> f32 {
    let (col, f) = (edge.floor() as usize, edge.fract());
    let mut sum = 0.0;
    for (x, y) in pixels(&g.modes) {
        let modes = g.modes.pixel(x, y);
        let at = format!("{what} pixel ({x}, {y})");
        if x == col {
            sum += assert_edge_pixel(cam, modes, f, &at);
            continue;
        }
        // Fully covered pixels see only the occluder; uncovered ones only the wall.
        let depth = if x < col { OCCLUDER_Z } else { BACK_Z };
        assert_eq!(modes.len(), 1, "{at}: {modes:?}");
        assert_mode(&modes[0], cam, depth, 1.0, 1e-6, &at);
    }
    sum / g.modes.height as f32
}

/// An edge pixel: the occluder with η ≈ f, then the wall with the rest. Returns the front η.
fn assert_edge_pixel(cam: &LightFieldCamera, modes: &[Mode], f: f64, at: &str) -> f32 {
    assert_eq!(modes.len(), 2, "{at}: {modes:?}");
    let front = modes[0].eta;
    assert_mode(&modes[0], cam, OCCLUDER_Z, f as f32, edge_bound(f), at);
    // Whatever the sampled coverage, the wall fills the rest of the pixel exactly.
    assert_mode(&modes[1], cam, BACK_Z, 1.0 - front, 1e-5, at);
    assert!((modes[0].eta_exact - front).abs() < 1e-6, "{at}: {modes:?}");
    front
}

// ---------------------------------------------------------------------------------------
// 4. A closed room.
// ---------------------------------------------------------------------------------------

/// Room `[-2, 2] × [0, 3] × [-3, 3]`; the camera stands at z = 2, so the back wall is at
/// planar depth 5.
const ROOM: Vec3 = Vec3::new(4.0, 3.0, 6.0);
const ROOM_EYE: DVec3 = DVec3::new(0.0, 1.5, 2.0);
const ROOM_BACK_Z: f64 = 5.0;

/// The room with two semi-transparent panes (one slanted across many slices), an opaque box
/// on the floor and a ceiling light, seen through a wide lens so floor, ceiling and side walls
/// are in view.
fn room() -> SceneDesc {
    let cam = camera([48, 48], [5, 5], 20.0, ROOM_EYE);
    let slanted = Transform::at(Vec3::new(0.3, 1.2, -0.5)).rotated_y(0.6);
    let ceiling = Transform {
        rotation: Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
        ..Transform::at(Vec3::new(0.0, 2.99, -1.0))
    };
    let parts = vec![
        Part {
            shape: Shape::Room { size: ROOM },
            transform: Transform::at(Vec3::ZERO),
            material: matte([0.7; 3], 1.0),
        },
        quad(
            [1.5, 1.2],
            Vec3::new(-0.4, 1.4, 0.5),
            matte([0.9, 0.3, 0.3], 0.3),
        ),
        Part {
            shape: Shape::Quad { size: [1.4, 1.6] },
            transform: slanted,
            material: matte([0.3, 0.3, 0.9], 0.5),
        },
        cuboid(
            Vec3::new(0.6, 0.8, 0.6),
            Vec3::new(0.5, 0.4, -1.5),
            matte([0.4, 0.8, 0.4], 1.0),
        ),
        Part {
            shape: Shape::Quad { size: [1.0, 1.0] },
            transform: ceiling,
            material: emitter([5.0; 3]),
        },
    ];
    scene(cam, [1.0, 5.2], [0.0; 3], parts)
}

/// Pixels whose whole footprint sees the back wall (its projection is a rectangle).
fn inside_back_wall(cam: &LightFieldCamera, x: usize, y: usize) -> bool {
    let f = f_px(cam);
    let half = ROOM / 2.0;
    let to_px = |metres: f64, centre: u32| centre as f64 / 2.0 + f * metres / ROOM_BACK_Z;
    let (x0, x1) = (
        to_px(-half.x as f64, cam.width()),
        to_px(half.x as f64, cam.width()),
    );
    // Image y grows downwards: the ceiling (1.5 m above the eye) is at the top.
    let up = ROOM.y as f64 - ROOM_EYE.y;
    let (y0, y1) = (to_px(-up, cam.height()), to_px(ROOM_EYE.y, cam.height()));
    x as f64 >= x0 && (x + 1) as f64 <= x1 && y as f64 >= y0 && (y + 1) as f64 <= y1
}

fn assert_sorted_and_finite(modes: &[Mode], at: &str) {
    for m in modes {
        assert!(
            m.disparity.is_finite() && m.depth.is_finite(),
            "{at}: {m:?}"
        );
        assert!(
            (0.0..=1.0).contains(&m.eta) && (0.0..=1.0).contains(&m.eta_exact),
            "{at}: {m:?}"
        );
    }
    for pair in modes.windows(2) {
        assert!(
            pair[0].depth < pair[1].depth,
            "{at}: depths not increasing: {modes:?}"
        );
        // Non-strict: two modes just either side of a slice boundary may round to one f32.
        assert!(
            pair[0].disparity >= pair[1].disparity,
            "{at}: disparities: {modes:?}"
        );
    }
}

#[test]
fn closed_room_eta_sums_to_one_and_modes_sorted() {
    let h = Harness::new(room());
    let cam = &h.desc.camera;
    let g = gt(h.render(cam.center_view(), &settings(16, 2), true));
    let mut back_wall_pixels = 0;
    for (x, y) in pixels(&g.modes) {
        let modes = g.modes.pixel(x, y);
        let at = format!("pixel ({x}, {y})");
        assert_sorted_and_finite(modes, &at);
        // Per sample the hits' T·a add up to 1 once an opaque surface is reached, and every
        // ray in a closed room reaches one.
        let exact: f32 = modes.iter().map(|m| m.eta_exact).sum();
        assert!(
            (exact - 1.0).abs() < 1e-3,
            "{at}: Σ η_exact = {exact}: {modes:?}"
        );
        // The over operator gives Σ η = 1 − Π(1 − α_k): never above 1, and exactly 1 where
        // one slice is opaque in every sample — the back wall, at one depth, behind
        // everything else in its rectangle.
        let eta: f32 = modes.iter().map(|m| m.eta).sum();
        assert!(eta < 1.0 + 1e-4, "{at}: Σ η = {eta}");
        if inside_back_wall(cam, x, y) {
            back_wall_pixels += 1;
            assert!((eta - 1.0).abs() < 1e-3, "{at}: Σ η = {eta}: {modes:?}");
        }
    }
    assert!(back_wall_pixels > 300, "{back_wall_pixels}");
    // With surface slicing a continuous surface is one layer per pixel, so Σ η falls short only
    // where one background is split, with disjoint coverage, between slices (e.g. the floor
    // under a box edge and the wall above it): measured 51 of 2304 pixels. Literal per-sample
    // clipping also cuts every slanted surface at every slice boundary (1936 pixels).
    let short = |g: &ViewGt| {
        pixels(&g.modes)
            .filter(|&(x, y)| eta_sum(g.modes.pixel(x, y)) < 1.0 - 1e-3)
            .count()
    };
    let by_surface = short(&g);
    let mut literal = settings(16, 2);
    literal.slice_assignment = SliceAssignment::Sample;
    let by_sample = short(&gt(h.render(cam.center_view(), &literal, true)));
    let total = g.modes.width * g.modes.height;
    assert!(
        by_surface * 10 < total,
        "Σ η < 1 at {by_surface} of {total} pixels"
    );
    assert!(
        by_sample > 10 * by_surface,
        "sample slicing {by_sample} vs surface {by_surface}"
    );
}

fn eta_sum(modes: &[Mode]) -> f32 {
    modes.iter().map(|m| m.eta).sum()
}

/// A floor-like plane receding from the camera crosses many slice boundaries inside pixels.
/// Surface slicing keeps it one mode with η = 1 everywhere; per-sample clipping splits the
/// boundary pixels into several modes whose over-composited η sum to less than 1.
#[test]
fn slanted_plane_is_one_mode_with_surface_slicing() {
    let cam = camera([32, 32], [5, 5], 100.0, EYE);
    let tilt = Transform {
        rotation: Quat::from_rotation_x(-1.2),
        ..Transform::at(ahead(3.0, 0.0, 0.0))
    };
    let plane = Part {
        shape: Shape::Quad { size: [8.0, 8.0] },
        transform: tilt,
        material: matte([0.5; 3], 1.0),
    };
    let h = Harness::new(scene(cam.clone(), [2.0, 4.0], [1.0; 3], vec![plane]));
    let g = gt(h.render(cam.center_view(), &settings(16, 1), true));
    for (x, y) in pixels(&g.modes) {
        let modes = g.modes.pixel(x, y);
        assert_eq!(modes.len(), 1, "pixel ({x}, {y}): {modes:?}");
        assert!(
            (modes[0].eta - 1.0).abs() < 1e-6,
            "pixel ({x}, {y}): {modes:?}"
        );
    }
    let mut literal = settings(16, 1);
    literal.slice_assignment = SliceAssignment::Sample;
    let g = gt(h.render(cam.center_view(), &literal, true));
    let split = pixels(&g.modes)
        .filter(|&(x, y)| g.modes.pixel(x, y).len() >= 2)
        .count();
    assert!(
        split > 32,
        "per-sample clipping should split boundary pixels, got {split}"
    );
}

// ---------------------------------------------------------------------------------------
// 5. Thin glass.
// ---------------------------------------------------------------------------------------

const GLASS_IOR: f32 = 1.5;
const GLASS_THICKNESS: f64 = 0.01;
const GLASS_TOL: f32 = 3e-4;

/// The GT of a 1 cm glass slab centred at planar depth `centre` in front of a wall at
/// [`WALL_Z`], with slices [1, 5] (boundaries every 1/32 m, one at exactly 2.0).
fn glass_slab(centre: f64) -> (LightFieldCamera, ViewGt) {
    // 16 px at 100 mm: rays stay within 14° of the axis.
    let cam = camera([16, 16], [5, 5], 100.0, EYE);
    let glass = Material {
        model: SurfaceModel::Glass { ior: GLASS_IOR },
        ..matte([1.0; 3], 1.0)
    };
    let size = Vec3::new(4.0, 4.0, GLASS_THICKNESS as f32);
    let slab = cuboid(size, ahead(centre, 0.0, 0.0), glass);
    let wall = quad([8.0, 8.0], ahead(WALL_Z, 0.0, 0.0), matte([0.5; 3], 1.0));
    let h = Harness::new(scene(cam.clone(), [1.0, 5.0], [1.0; 3], vec![slab, wall]));
    let out = h.render(cam.center_view(), &settings(4, 1), true);
    (cam, gt(out))
}

/// Normal-incidence Fresnel reflectance ((n − 1)/(n + 1))² = 0.04. Within 14° of the normal
/// the exact unpolarised value rises by less than 1e-4 (0.04008 at 15°), which moves the
/// composited η by less than 2e-4: the tolerance [`GLASS_TOL`].
fn fresnel_normal() -> f32 {
    ((GLASS_IOR - 1.0) / (GLASS_IOR + 1.0)).powi(2)
}

#[test]
fn glass_coverage_is_fresnel() {
    let r = fresnel_normal();
    let (z1, z2) = (2.0 - GLASS_THICKNESS / 2.0, 2.0 + GLASS_THICKNESS / 2.0);
    // The faces straddle the slice boundary at 2.0: each face is its own mode with the
    // Fresnel coverage; the back face is seen through the front one.
    let (cam, g) = glass_slab(2.0);
    let straddling = [(z1, r), (z2, r * (1.0 - r)), (WALL_Z, (1.0 - r).powi(2))];
    assert_every_pixel(&cam, &g, &straddling, GLASS_TOL);
    // Shifted to the middle of slice 32 ([2.0, 2.03125]): both faces composite into one mode
    // of α = 1 − (1 − R)², at their over-weighted mean depth.
    let mid = 2.0 + 1.0 / 64.0;
    let (z1, z2) = (mid - GLASS_THICKNESS / 2.0, mid + GLASS_THICKNESS / 2.0);
    let alpha = 1.0 - (1.0 - r).powi(2);
    let depth = (r as f64 * z1 + (r * (1.0 - r)) as f64 * z2) / alpha as f64;
    let (cam, g) = glass_slab(mid);
    assert_every_pixel(
        &cam,
        &g,
        &[(depth, alpha), (WALL_Z, (1.0 - r).powi(2))],
        GLASS_TOL,
    );
}

// ---------------------------------------------------------------------------------------
// 6. The GT pass leaves the colour untouched.
// ---------------------------------------------------------------------------------------

fn bits(out: &lfgen::render::view::ViewOutput) -> Vec<[u32; 3]> {
    out.image
        .pixels
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

#[test]
fn gt_and_colour_only_render_identical_images() {
    let h = Harness::new(room());
    // Deep paths with Russian roulette, NEE and stochastic transparency: every random
    // decision of the colour path is exercised.
    let mut s = settings(4, 6);
    s.path.rr_depth = 2;
    for view in [0, h.desc.camera.center_view()] {
        let with = h.render(view, &s, true);
        let without = h.render(view, &s, false);
        assert!(with.gt.is_some() && without.gt.is_none());
        assert!(
            bits(&with) == bits(&without),
            "view {view}: colour differs with GT"
        );
    }
}

/// With `shade_all_hits` (true slice colours) the hidden surfaces are shaded from their own
/// random streams, so the colour image is the same as without GT.
#[test]
fn gt_with_shaded_slices_renders_identical_images() {
    let h = Harness::new(room());
    let mut s = settings(4, 6);
    s.shade_all_hits = true;
    let view = h.desc.camera.center_view();
    let with = h.render(view, &s, true);
    let without = h.render(view, &s, false);
    assert!(
        bits(&with) == bits(&without),
        "colour differs when every GT hit is shaded"
    );
}

// ---------------------------------------------------------------------------------------
// 7. Direct light from area lights, far and near.
// ---------------------------------------------------------------------------------------

/// Direct light on a Lambert plane from a square emitter of radiance `L` facing it at height
/// `h`: the plane sends `ρ·L·F` back, `F` the point-to-rectangle form factor (closed form). The
/// camera looks at the plane from the emitter's side, through the emitter's back (one-sided).
/// Asserts the mean of the centre 8×8 pixels is the closed form there to `tol` (relative).
fn assert_square_light_over_a_plane(half: f32, light_z: f32, plane_z: f32, spp: u32, tol: f64) {
    let (rho, radiance) = (0.5f32, 4.0f32);
    let cam = camera([32, 32], [1, 1], 100.0, DVec3::ZERO);
    let plane = Material {
        model: SurfaceModel::Diffuse,
        ..matte([rho; 3], 1.0)
    };
    let mut light = quad(
        [2.0 * half; 2],
        Vec3::new(0.0, 0.0, light_z),
        emitter([radiance; 3]),
    );
    light.transform.rotation = Quat::from_rotation_y(std::f32::consts::PI);
    let plane = quad([20.0, 20.0], Vec3::new(0.0, 0.0, plane_z), plane);
    let harness = Harness::new(scene(cam, [1.0, 5.0], [0.0; 3], vec![plane, light]));
    let img = harness.render(0, &settings(spp, 1), false).image;
    // Form factor from a point to a parallel rectangle centred above it: four corner terms.
    let x = half as f64 / (light_z - plane_z) as f64;
    let corner = |x: f64, y: f64| {
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
    };
    let expected = rho as f64 * radiance as f64 * 4.0 * corner(x, x);
    // The centre 8×8 pixels see the plane within 1 % of its distance from the axis, where the
    // form factor changes by less than 1e-4 relative.
    let mut sum = 0.0;
    for j in 12..20 {
        for i in 12..20 {
            sum += img.pixels[j * img.width + i].x as f64;
        }
    }
    let mean = sum / 64.0;
    assert!(
        (mean / expected - 1.0).abs() < tol,
        "{mean} vs the closed form {expected}"
    );
}

/// A square light 2.5 m from the plane. With one bounce all the plane's light is direct: a path
/// tracer that MIS-weights its light sample against a BSDF ray it then never follows comes out
/// dark (lfgen did, by 7 %, until this test).
#[test]
fn direct_light_on_a_lambert_plane_matches_the_form_factor() {
    assert_square_light_over_a_plane(1.0, 0.5, -2.0, 256, 0.01);
}

/// The same 2 cm from the plane: shadow rays leave from just off the surface, and one aimed
/// along the direction from the surface point itself reached the light's own surface short of
/// its end and counted the light as its occluder — 80 % of the light was lost here (and 30 %
/// inside the generator's lamp shades) until this test.
#[test]
fn direct_light_from_a_square_light_2_cm_away_matches_the_form_factor() {
    assert_square_light_over_a_plane(0.05, 0.01, -0.01, 1024, 0.015);
}

/// A lamp bulb (a tessellated sphere of radius 3 cm) 1 cm from a Lambert plane: the plane sends
/// `ρ·L·R²·h / D³` back at distance `D` from the centre, `h` the centre's height (closed form
/// for a sphere above the horizon), here averaged over each pixel's footprint.
#[test]
fn sphere_light_near_a_plane_matches_the_closed_form() {
    let (rho, radiance, r, h) = (0.5f64, 10.0f32, 0.03f64, 0.04f64);
    let (w, plane_z) = (64usize, -2.0f64);
    let cam = camera([w as u32, w as u32], [1, 1], 400.0, DVec3::ZERO);
    let plane = Material {
        model: SurfaceModel::Diffuse,
        ..matte([rho as f32; 3], 1.0)
    };
    let bulb = Part {
        shape: Shape::Sphere {
            radius: r as f32,
            rings: 48,
            segments: 96,
        },
        transform: Transform::at(Vec3::new(0.0, 0.0, (plane_z + h) as f32)),
        material: emitter([radiance; 3]),
    };
    let plane = quad([20.0, 20.0], Vec3::new(0.0, 0.0, plane_z as f32), plane);
    let harness = Harness::new(scene(cam.clone(), [1.0, 5.0], [0.0; 3], vec![plane, bulb]));
    let img = harness.render(0, &settings(4096, 1), false).image;
    let f = f_px(&cam);
    let closed_form = |x: f64, y: f64| {
        let d2 = x * x + y * y + h * h;
        rho * radiance as f64 * r * r * h / d2.powf(1.5)
    };
    // Pixel (i, j) sees the plane point ((i − W/2)·2/f, −(j − H/2)·2/f) at its corner; 8×8
    // samples per pixel. Rows 2–17 lie 3–8 cm above the bulb's foot, clear of its silhouette.
    let n = 8;
    let (mut got, mut want) = (0.0, 0.0);
    for j in 2..18 {
        for i in 24..40 {
            got += img.pixels[j * w + i].x as f64;
            for k in 0..n * n {
                let (sx, sy) = ((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
                let x = (i as f64 + sx / n as f64 - w as f64 / 2.0) * plane_z.abs() / f;
                let y = -(j as f64 + sy / n as f64 - w as f64 / 2.0) * plane_z.abs() / f;
                want += closed_form(x, y) / (n * n) as f64;
            }
        }
    }
    assert!(
        (got / want - 1.0).abs() < 0.01,
        "{got} vs the closed form {want}"
    );
}

// ---------------------------------------------------------------------------------------
// 8. Light selection.
// ---------------------------------------------------------------------------------------

/// A ceiling panel, a lamp bulb and a wall panel. For shading points next to the bulb, in the
/// room and by the wall: the selection probabilities that `pdf` implies sum to one over every
/// emitting triangle (MIS divides by them), `sample` picks each triangle as often as they say
/// and reports the same pdf, and next to the bulb the bulb is chosen more often than its share
/// of the power (the point of choosing by power over squared distance).
#[test]
fn light_selection_is_a_normalised_distribution_that_favours_near_lights() {
    let bulb_at = Vec3::new(0.5, 0.8, -1.0);
    let mut panel = quad([2.0, 1.0], Vec3::new(0.0, 2.5, -2.0), emitter([8.0; 3]));
    panel.transform.rotation = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let wall = quad([0.5, 0.5], Vec3::new(0.0, 1.0, -3.0), emitter([2.0; 3]));
    let bulb = Part {
        shape: Shape::Sphere {
            radius: 0.03,
            rings: 8,
            segments: 12,
        },
        transform: Transform::at(bulb_at),
        material: emitter([50.0; 3]),
    };
    let floor = quad([10.0, 10.0], Vec3::ZERO, matte([0.5; 3], 1.0));
    let cam = camera([8, 8], [1, 1], 50.0, DVec3::new(0.0, 1.0, 2.0));
    let desc = scene(cam, [1.0, 5.0], [0.0; 3], vec![floor, panel, wall, bulb]);
    let rs = lfgen::render::RenderScene::build(&desc).unwrap();
    let g = &rs.geometry;
    let area = |t: u32| {
        let v = g.vertices(t);
        0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length() as f64
    };
    let emitting = |t: u32| rs.materials[g.shading[t as usize].material as usize].is_emissive();
    let emitters: Vec<u32> = (0..g.triangle_count() as u32)
        .filter(|&t| emitting(t))
        .collect();
    let is_bulb = |t: u32| g.shading[t as usize].object == 3;
    let bulb_power: f64 = emitters
        .iter()
        .filter(|&&t| is_bulb(t))
        .map(|&t| area(t) * 50.0)
        .sum();
    let power_share = bulb_power / (bulb_power + 2.0 * 8.0 + 0.25 * 2.0);
    let n = 200_000;
    let near_bulb = bulb_at + Vec3::new(0.0, -0.05, 0.0);
    for from in [
        near_bulb,
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, -2.9),
    ] {
        // pdf() at unit distance and cosine is the area pdf: times the area, the probability.
        let prob = |t: u32| rs.lights.pdf(g, t, from, 1.0, 1.0) as f64 * area(t);
        let total: f64 = emitters.iter().map(|&t| prob(t)).sum();
        assert!(
            (total - 1.0).abs() < 1e-5,
            "probabilities sum to {total} at {from}"
        );
        let mut picks = vec![0u32; g.triangle_count()];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let ls = rs
                .lights
                .sample(g, &rs.materials, from, u, glam::Vec2::new(0.3, 0.4));
            picks[ls.tri as usize] += 1;
            let to = ls.p - from;
            let cos = -to.normalize().dot(ls.n);
            if cos > 0.0 {
                let want = ls.pdf_area * to.length_squared() / cos;
                let got = rs.lights.pdf(g, ls.tri, from, to.length(), cos);
                assert!(
                    (got / want - 1.0).abs() < 1e-4,
                    "pdf {got} vs sample {want} at {from}"
                );
            }
        }
        for &t in &emitters {
            // Stratified numbers: each triangle's count is within rounding of its share.
            let expected = prob(t) * n as f64;
            assert!(
                (picks[t as usize] as f64 - expected).abs() <= 2.0,
                "{t}: {} vs {expected}",
                picks[t as usize]
            );
        }
        if from == near_bulb {
            let share: f64 = emitters
                .iter()
                .filter(|&&t| is_bulb(t))
                .map(|&t| prob(t))
                .sum();
            assert!(
                share > 0.9 && power_share < 0.05,
                "bulb chosen {share} (power {power_share})"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// 8. Light through smooth glass (render.glass_light).
// ---------------------------------------------------------------------------------------

/// Mean and standard deviation over the centre 16×16 pixels of a Lambert floor 2.5 m below a
/// 60 cm square light, 1.5 m to the side so the camera does not see it mirrored in the pane,
/// seen and lit through a 2 cm glass pane between (tint 1, IOR 1.5), at `spp` with
/// `glass_light`. Nothing reaches the floor but through the pane, and no Russian roulette:
/// every light path through it is counted (five vertices: pane, pane, floor, pane, pane,
/// then the light).
fn lit_through_a_pane(glass_light: GlassLight, spp: u32) -> (f64, f64) {
    let cam = camera([32, 32], [1, 1], 100.0, DVec3::ZERO);
    let floor = Material {
        model: SurfaceModel::Diffuse,
        ..matte([0.5; 3], 1.0)
    };
    let glass = Material {
        model: SurfaceModel::Glass { ior: GLASS_IOR },
        ..matte([1.0; 3], 1.0)
    };
    // Small enough that a cosine-sampled ray from the floor finds it about once in 100 tries.
    let mut light = quad([0.6; 2], Vec3::new(1.5, 0.0, 0.5), emitter([40.0; 3]));
    light.transform.rotation = Quat::from_rotation_y(std::f32::consts::PI);
    let pane = cuboid(
        Vec3::new(20.0, 20.0, 0.02),
        Vec3::new(0.0, 0.0, -1.0),
        glass,
    );
    let floor = quad([20.0, 20.0], Vec3::new(0.0, 0.0, -2.0), floor);
    let harness = Harness::new(scene(cam, [0.5, 5.0], [0.0; 3], vec![floor, pane, light]));
    let mut s = settings(spp, 5);
    s.path.glass_light = glass_light;
    let img = harness.render(0, &s, false).image;
    let values: Vec<f64> = (8..24)
        .flat_map(|j| (8..24).map(move |i| (i, j)))
        .map(|(i, j)| img.pixels[j * img.width + i].x as f64)
        .collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64;
    (mean, var.sqrt())
}

/// `shadows` sends light samples straight through the pane and drops the caustic paths they
/// replace: it converges to what the unbiased caustic paths give (a pane with parallel faces
/// bends no light away; only its internal reflections, ~0.2 %, are left out; the reference's
/// own noise over these 256 pixels is ~0.7 %) with a fraction of their noise at equal spp.
/// `off` leaves the floor dark: its only light is caustic.
#[test]
fn glass_shadows_converge_to_the_caustic_paths_with_far_less_noise() {
    let (reference, _) = lit_through_a_pane(GlassLight::Caustics, 8192);
    let (caustics, caustic_noise) = lit_through_a_pane(GlassLight::Caustics, 64);
    let (shadows, shadow_noise) = lit_through_a_pane(GlassLight::Shadows, 64);
    let (off, _) = lit_through_a_pane(GlassLight::Off, 64);
    eprintln!(
        "floor through a pane: caustics 8192 spp {reference:.4}; at 64 spp caustics \
         {caustics:.4} ± {caustic_noise:.4}, shadows {shadows:.4} ± {shadow_noise:.4}, off {off:.4}"
    );
    assert!(reference > 0.01, "the floor is lit: {reference}");
    assert!(
        (shadows / reference - 1.0).abs() < 0.03,
        "shadows {shadows} vs caustic paths at 8192 spp {reference} (at 64 spp: {caustics})"
    );
    assert!(
        shadow_noise < caustic_noise / 4.0,
        "pixel noise: shadows {shadow_noise}, caustics {caustic_noise}"
    );
    assert!(off < 0.01 * reference, "off {off} vs {reference}");
}

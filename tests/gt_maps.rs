//! The per-pixel ground truth beside the depths — normals, object ids, the validity mask and
//! the high-resolution HCI layer — checked against scenes whose answer is known in closed form
//! (docs/reference/format.md, Scene folder), and the files a generated scene carries read back
//! through lfformat's readers.

mod bin;
mod common;

use bin::{TINY, lfgen, ok};
use common::{Harness, Part, camera, cuboid, disparity, matte, quad, scene, settings};
use glam::{DVec3, Quat, Vec3};
use lfformat::gt_maps::{read_id_png, read_normals_exr, read_valid_mask};
use lfformat::hci_masks::{DISCONTINUITY_RADIUS, SMOOTH_RADIUS, dilate};
use lfformat::modes::read_modes_exr_with_surfaces;
use lfformat::pfm::read_pfm;
use lfgen::camera::LightFieldCamera;
use lfgen::output::hci_mask_files::centre_masks;
use lfgen::render::RenderScene;
use lfgen::render::view::ViewGt;
use lfgen::scene::{SceneDesc, Shape, Transform};

/// The room: x in ±2, floor at y = 0, ceiling at 3, z in ±3; the eye inside, looking down −Z.
const ROOM: Vec3 = Vec3::new(4.0, 3.0, 6.0);
const EYE: DVec3 = DVec3::new(0.2, 1.4, 2.5);

/// The slanted panel: centre, size and rotation (about y, then x).
const PANEL_AT: Vec3 = Vec3::new(-0.5, 1.2, -1.0);
const PANEL_SIZE: [f32; 2] = [1.2, 1.0];

fn panel_rotation() -> Quat {
    Quat::from_rotation_y(0.6) * Quat::from_rotation_x(-0.4)
}

/// The room, a slanted opaque panel and a box on the floor, seen through a wide lens.
fn room() -> SceneDesc {
    let cam = camera([48, 48], [5, 5], 20.0, EYE);
    let panel = Part {
        shape: Shape::Quad { size: PANEL_SIZE },
        transform: Transform {
            rotation: panel_rotation(),
            ..Transform::at(PANEL_AT)
        },
        material: matte([0.3, 0.3, 0.9], 1.0),
    };
    let parts = vec![
        Part {
            shape: Shape::Room { size: ROOM },
            transform: Transform::at(Vec3::ZERO),
            material: matte([0.7; 3], 1.0),
        },
        panel,
        cuboid(
            Vec3::new(0.6, 0.8, 0.6),
            Vec3::new(0.8, 0.4, -1.5),
            matte([0.4, 0.8, 0.4], 1.0),
        ),
    ];
    scene(cam, [0.5, 8.0], [0.0; 3], parts)
}

/// The nearest analytic surface along a ray, `(distance, world normal)`, over the room's six
/// planes and the panel (the box is left out: rays that meet it are skipped by the caller);
/// `None` for a ray through an edge, where two surfaces lie within 10⁻³ of one distance.
fn analytic_hit(origin: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
    let half = ROOM / 2.0;
    let planes = [
        (Vec3::X, half.x),
        (Vec3::NEG_X, half.x),
        (Vec3::Y, 0.0),
        (Vec3::NEG_Y, ROOM.y),
        (Vec3::Z, half.z),
        (Vec3::NEG_Z, half.z),
    ];
    // Plane n·p + c = 0 with the inward normal n.
    let room = planes.into_iter().filter_map(|(n, c)| {
        let t = -(n.dot(origin) + c) / n.dot(dir);
        (t > 0.0).then_some((t, n))
    });
    let n = panel_rotation() * Vec3::Z;
    let t = n.dot(PANEL_AT - origin) / n.dot(dir);
    let local = panel_rotation().inverse() * (origin + dir * t - PANEL_AT);
    let inside = local.x.abs() <= PANEL_SIZE[0] / 2.0 && local.y.abs() <= PANEL_SIZE[1] / 2.0;
    let panel = (t > 0.0 && inside).then_some((t, n));
    let mut hits: Vec<(f32, Vec3)> = room.chain(panel).collect();
    hits.sort_by(|a, b| a.0.total_cmp(&b.0));
    match hits.as_slice() {
        [a, b, ..] if b.0 - a.0 < 1e-3 * a.0 => None,
        [a, ..] => Some(*a),
        [] => None,
    }
}

/// Whether a ray meets the box (its slab test), so the caller can leave the ray out.
fn meets_box(origin: Vec3, dir: Vec3) -> bool {
    let (lo, hi) = (Vec3::new(0.5, 0.0, -1.8), Vec3::new(1.1, 0.8, -1.2));
    let (a, b) = ((lo - origin) / dir, (hi - origin) / dir);
    let (near, far) = (a.min(b).max_element(), a.max(b).min_element());
    near <= far && far > 0.0
}

/// Angle in degrees between two unit vectors.
fn angle_deg(a: Vec3, b: Vec3) -> f32 {
    a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The analytic normal seen at image point `(x, y)` of the centre view, facing the camera, or
/// `None` where the box is in the way.
fn expected_normal(cam: &LightFieldCamera, x: f32, y: f32) -> Option<Vec3> {
    let ray = cam.view_rays(cam.center_view()).ray(x, y);
    if meets_box(ray.origin, ray.dir) {
        return None;
    }
    let (_, n) = analytic_hit(ray.origin, ray.dir)?;
    Some(if n.dot(ray.dir) > 0.0 { -n } else { n })
}

/// The camera frame of the test camera is the world frame: right +X, up +Y, back +Z.
#[test]
fn normals_match_the_analytic_planes_within_half_a_degree() {
    let desc = room();
    let cam = desc.camera.clone();
    let g = Harness::new(desc).render(cam.center_view(), &settings(4, 1), true);
    let g = g.gt.expect("ground truth");
    let (w, h) = (cam.width() as usize, cam.height() as usize);
    let starts: Vec<usize> = (g.modes.pixels())
        .scan(0, |next, px| {
            let start = *next;
            *next += px.len();
            Some(start)
        })
        .collect();
    let (mut checked, mut pure) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f32, y as f32);
            let Some(want) = expected_normal(&cam, fx + 0.5, fy + 0.5) else {
                continue;
            };
            let got = Vec3::from(g.hci.normal[y * w + x]);
            let at = format!("pixel ({x}, {y})");
            assert!((got.length() - 1.0).abs() < 1e-5, "{at}: {got}");
            assert!(angle_deg(got, want) < 0.5, "{at}: {got} vs {want}");
            checked += 1;
            // A pixel whose corners all see the same plane has one mode with that normal.
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            let same = corners
                .iter()
                .all(|(dx, dy)| expected_normal(&cam, fx + dx, fy + dy).is_some_and(|n| n == want));
            if same {
                let start = starts[y * w + x];
                let modes = g.modes.pixel(x, y);
                assert_eq!(modes.len(), 1, "{at}: {modes:?}");
                let n = Vec3::from(g.surfaces[start].normal);
                assert!(angle_deg(n, want) < 0.5, "{at}: mode normal {n} vs {want}");
                pure += 1;
            }
        }
    }
    assert!(
        checked > w * h * 3 / 4 && pure > w * h / 2,
        "{checked}, {pure}"
    );
}

/// A finely tessellated ball before a wall, through the renderer and the mask writer's own
/// function: its interior (beyond the silhouette's bands) is a smooth surface, no plane and no
/// edge — its facets' creases are neither — and the wall is no smooth surface.
#[test]
fn a_tessellated_ball_is_a_smooth_surface() {
    let eye = DVec3::new(0.0, 1.0, 4.0);
    let cam = camera([48, 48], [3, 3], 50.0, eye);
    let ahead = |z: f64| (eye + DVec3::new(0.0, 0.0, -z)).as_vec3();
    let ball = Part {
        shape: Shape::Sphere {
            radius: 0.35,
            rings: 48,
            segments: 96,
        },
        transform: Transform::at(ahead(1.8)),
        material: matte([0.8, 0.3, 0.3], 1.0),
    };
    let wall = quad([12.0, 12.0], ahead(5.5), matte([0.6; 3], 1.0));
    let desc = scene(cam.clone(), [1.0, 7.0], [1.0; 3], vec![ball, wall]);
    let g = Harness::new(desc).render(cam.center_view(), &settings(1, 1), true);
    let layer = g.gt.expect("ground truth").hci;
    let masks = centre_masks(&cam, &layer, 1);
    let n = 48;
    let ball_id = layer.object[n * n / 2 + n / 2];
    let not_ball: Vec<bool> = layer.object.iter().map(|&o| o != ball_id).collect();
    let near_silhouette = dilate(&not_ball, n, n, DISCONTINUITY_RADIUS + SMOOTH_RADIUS);
    let (mut interior, mut smooth) = (0, 0);
    for (i, &near) in near_silhouette.iter().enumerate() {
        let at = format!("pixel ({}, {})", i % n, i / n);
        if layer.object[i] != ball_id {
            assert!(!masks.smooth_surfaces[i], "{at}: the wall is not curved");
            continue;
        }
        assert!(!masks.planes[i], "{at}: the ball is not a plane");
        if !near {
            assert!(
                !masks.discontinuities[i],
                "{at}: a facet crease taken for an edge"
            );
            interior += 1;
            smooth += usize::from(masks.smooth_surfaces[i]);
        }
    }
    assert!(interior > 200, "{interior} interior pixels");
    assert_eq!(smooth, interior, "interior pixels not smooth");
}

/// Every view's ground truth of the room.
fn all_views(desc: SceneDesc) -> Vec<ViewGt> {
    let h = Harness::new(desc.clone());
    let views = 0..desc.camera.num_views();
    let out = views.map(|v| h.render(v, &settings(4, 1), true));
    out.map(|o| o.gt.expect("ground truth")).collect()
}

/// A valid centre-view pixel, moved by its GT disparity into another view, lands on a pixel
/// of the same object wherever that pixel sees the same depth.
#[test]
fn an_objects_id_is_the_same_in_every_view_that_sees_it() {
    let desc = room();
    let cam = desc.camera.clone();
    let gts = all_views(desc);
    let centre = &gts[cam.center_view() as usize];
    let (w, h) = (cam.width() as usize, cam.height() as usize);
    let mut compared = 0;
    for (view, g) in gts.iter().enumerate() {
        let (du, dv) = cam.view_offset(view as u32);
        for i in (0..w * h).filter(|&i| centre.valid[i]) {
            let z = centre.hci.depth[i] as f64;
            let d = disparity(&cam, z);
            let tx = ((i % w) as f64 + 0.5 - du as f64 * d).floor();
            let ty = ((i / w) as f64 + 0.5 - dv as f64 * d).floor();
            if tx < 0.0 || ty < 0.0 || tx >= w as f64 || ty >= h as f64 {
                continue;
            }
            let j = ty as usize * w + tx as usize;
            let seen = (g.hci.depth[j] as f64 - z).abs() < 0.01 * z;
            if g.valid[j] && seen {
                let at = format!("view {view}, pixel {i} → {j}");
                assert_eq!(g.hci.object[j], centre.hci.object[i], "{at}");
                assert_eq!(g.hci.class[j], centre.hci.class[i], "{at}");
                compared += 1;
            }
        }
    }
    assert!(compared > w * h * 25 / 4, "only {compared} pixels compared");
}

const PANE_Z: f64 = 1.5;
const WALL_Z: f64 = 3.5;

/// A 40 % pane over the left half of a 24² view (its right edge on the optical axis, the
/// boundary between columns 11 and 12), a wall behind everything.
#[test]
fn valid_mask_is_off_on_the_pane_and_on_on_the_plain_wall() {
    let eye = DVec3::new(0.0, 1.0, 4.0);
    let cam = camera([24, 24], [5, 5], 100.0, eye);
    let ahead = |z: f64, dx: f32| (eye + DVec3::new(0.0, 0.0, -z)).as_vec3() + Vec3::X * dx;
    let pane = quad([2.0, 4.0], ahead(PANE_Z, -1.0), matte([0.9; 3], 0.4));
    let wall = quad([8.0, 8.0], ahead(WALL_Z, 0.0), matte([0.5; 3], 1.0));
    let h = Harness::new(scene(cam.clone(), [1.0, 5.0], [1.0; 3], vec![pane, wall]));
    let g = h
        .render(cam.center_view(), &settings(4, 1), true)
        .gt
        .unwrap();
    for y in 0..24 {
        for x in 0..24 {
            let valid = g.valid[y * 24 + x];
            match x {
                0..=11 => assert!(!valid, "pixel ({x}, {y}) behind the pane is valid"),
                _ => assert!(valid, "pixel ({x}, {y}) on the plain wall is not valid"),
            }
        }
    }
}

/// An opaque quad whose right edge projects to x = 20.3 at depth 2, a wall at 4: the
/// high-res disparity averaged over each 10×10 block is the pixel's analytic mean disparity
/// within the quantisation of the block's columns, and equal to the low-res GT off the edge.
#[test]
fn high_res_disparity_box_filtered_matches_the_low_res_gt() {
    const SCALE: u32 = 10;
    let eye = DVec3::new(0.0, 1.0, 4.0);
    let cam = camera([32, 32], [5, 5], 100.0, eye);
    let f = cam.f_px();
    let (front, back) = (2.0, 4.0);
    let edge_px = 20.3;
    let edge_m = ((edge_px - 16.0) / f * front) as f32;
    let ahead = |z: f64, dx: f32| (eye + DVec3::new(0.0, 0.0, -z)).as_vec3() + Vec3::X * dx;
    let occluder = quad([4.0, 8.0], ahead(front, edge_m - 2.0), matte([0.2; 3], 1.0));
    let wall = quad([12.0, 12.0], ahead(back, 0.0), matte([0.6; 3], 1.0));
    let desc = scene(cam.clone(), [1.0, 5.0], [1.0; 3], vec![occluder, wall]);
    let low = Harness::new(desc.clone()).render(cam.center_view(), &settings(4, 1), true);
    let low = low.gt.unwrap();
    let scene = RenderScene::build(&desc).unwrap();
    let high = scene.render_hci_layer(&cam, cam.center_view(), SCALE);
    let s = SCALE as usize;
    assert_eq!((high.width, high.height), (32 * s, 32 * s));
    let (df, db) = (disparity(&cam, front), disparity(&cam, back));
    for y in 0..32 {
        for x in 0..32 {
            let block = (0..s * s).map(|k| high.depth[(y * s + k / s) * 32 * s + x * s + k % s]);
            let mean = block.map(|z| disparity(&cam, z as f64)).sum::<f64>() / (s * s) as f64;
            // Fraction of the pixel left of the edge, and the bound of 10 sub-columns on it.
            let covered = (edge_px - x as f64).clamp(0.0, 1.0);
            let want = covered * df + (1.0 - covered) * db;
            let bound = (df - db).abs() / (2.0 * SCALE as f64) + 1e-4;
            let at = format!("pixel ({x}, {y})");
            assert!((mean - want).abs() <= bound, "{at}: {mean} vs {want}");
            if covered == 0.0 || covered == 1.0 {
                let lowres = disparity(&cam, low.hci.depth[y * 32 + x] as f64);
                assert!(
                    (mean - lowres).abs() < 1e-4,
                    "{at}: {mean} vs low-res {lowres}"
                );
            }
        }
    }
}

/// A generated scene's new files read back through lfformat and agree with each other and
/// with `ids.json` and `stats.json`.
#[test]
fn a_generated_scene_carries_readable_consistent_maps() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let out_s = out.to_str().unwrap();
    let args = [
        "--scenes",
        "1",
        "--out",
        out_s,
        "--set",
        "render.gt_highres=2",
    ];
    ok(lfgen(&[&args[..], TINY].concat()));
    let s = out.join("train/scene_0000");
    let modes_path = s.join("modes.exr");
    let (modes, surfaces) = read_modes_exr_with_surfaces(&modes_path).unwrap();
    let surfaces = surfaces.expect("modes.exr has surface channels");
    assert_eq!(surfaces.len(), modes.total_modes());
    let (w, h) = (modes.width, modes.height);
    let (_, _, objects) = read_id_png(&s.join("objectids_lowres.png")).unwrap();
    let (_, _, classes) = read_id_png(&s.join("classids_lowres.png")).unwrap();
    let (_, _, normals) = read_normals_exr(&s.join("gt_normals_lowres.exr")).unwrap();
    let (vw, vh, valid) = read_valid_mask(&s.join("valid_mask.png")).unwrap();
    assert_eq!((vw, vh, objects.len(), normals.len()), (w, h, w * h, w * h));
    let ids: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.join("ids.json")).unwrap()).unwrap();
    let n_objects = ids["objects"].as_array().unwrap().len() as u16;
    let class_ids: Vec<u64> = (ids["classes"].as_array().unwrap().iter())
        .map(|c| c["id"].as_u64().unwrap())
        .collect();
    // At a valid pixel the dominant mode lies on the HCI surface; its heaviest object is the
    // one on the pixel-centre ray unless two objects touch inside the pixel at one depth.
    let (mut start, mut same, mut all) = (0, 0, 0);
    for (i, px) in modes.pixels().enumerate() {
        assert!((1..=n_objects).contains(&objects[i]) || objects[i] == 0);
        assert!(classes[i] == 0 || class_ids.contains(&(classes[i] as u64)));
        if valid[i] {
            let k = px
                .iter()
                .position(|m| m.eta >= 0.99)
                .expect("valid: one mode");
            same += usize::from(surfaces[start + k].object == objects[i] as u32);
            all += 1;
        }
        start += px.len();
    }
    assert!(same * 20 >= all * 19, "{same} of {all} valid pixels agree");
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.join("stats.json")).unwrap()).unwrap();
    let share = valid.iter().filter(|&&v| v).count() as f64 / (w * h) as f64;
    assert_eq!(stats["valid_fraction"].as_f64().unwrap(), share);
    assert!(share > 0.2, "valid share {share}");
    let high = read_pfm(&s.join("gt_disp_highres.pfm")).unwrap();
    assert_eq!((high.width, high.height), (2 * w, 2 * h));
    let (hw, hh, _) = read_id_png(&s.join("objectids_highres.png")).unwrap();
    assert_eq!((hw, hh), (2 * w, 2 * h));
    let cfg = std::fs::read_to_string(s.join("parameters.cfg")).unwrap();
    assert!(cfg.contains("depth_map_scale = 2.0"), "{cfg}");
}

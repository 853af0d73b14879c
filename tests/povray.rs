//! Independent check of lfgen's HCI depth with POV-Ray 3.7 (issue 4, check 1): a generated
//! default scene is exported with `lfgen export --to pov`, POV-Ray renders exact planar depth of
//! the centre and corner views (a pigment function of the hit position, no antialiasing,
//! 16-bit linear grey plus a second "fine digit" render), and it must agree with
//! `gt_depth_lowres_CamNNN.pfm` to 1e-4 relative on at least 99.9 % of the pixels away from
//! silhouettes.
//!
//! Excluded, and counted in the printed table: silhouette pixels (a pixel corner sees another
//! surface than the centre, so a ray rounding differently may too), pixels whose HCI surface is
//! glass (its coverage is the Fresnel reflectance, ≥ 0.5 only at grazing angles, which a
//! position-only POV-Ray pigment cannot express) and ties: a see-through surface (a cut-out
//! hole) at the same depth as the HCI surface, as back-to-back quads give; which of the two a
//! renderer meets first is arbitrary, and POV-Ray, continuing past the first, skips the other.
//!
//! Needs `povray` on the PATH (`.ci/run` installs it); without it the test prints why and passes.

mod bin;
mod pov;
mod skip;

use glam::Vec3;
use lfformat::pfm::read_pfm;
use lfgen::render::RenderScene;
use lfgen::render::geometry::Hit;
use lfgen::scene::assets::Assets;
use std::path::Path;

const WIDTH: u32 = 128;
const HEIGHT: u32 = 96;
/// Relative depth tolerance and the share of pixels that must meet it.
const TOLERANCE: f64 = 1e-4;
const REQUIRED: f64 = 0.999;

fn lfgen(args: &[&str]) {
    bin::ok(bin::lfgen(args));
}

/// Renders `depth.pov` for one view; `fine` selects the base-256 fine digit.
fn render_depth(pov_dir: &Path, view: u32, fine: bool) -> Vec<f64> {
    let png = pov_dir.join(format!("depth_{view}_{}.png", u8::from(fine)));
    let args = [
        format!("+W{WIDTH}"),
        format!("+H{HEIGHT}"),
        "-A".into(),
        "+FN16".into(),
        "Grayscale_Output=on".into(),
        "File_Gamma=1.0".into(),
        format!("Declare=View={view}"),
        format!("Declare=Fine={}", u8::from(fine)),
        "+WT2".into(),
    ];
    pov::render(pov_dir, "depth.pov", &png, &args);
    let img = image::open(&png).expect("POV-Ray's PNG").into_luma16();
    img.pixels().map(|p| p.0[0] as f64 / 65535.0).collect()
}

/// Depth from the coarse value `c = z/DMax` and the fine digit `f = frac(256·z/DMax)`.
fn decode(coarse: f64, fine: f64, dmax: f64) -> f64 {
    let n = (coarse * 256.0 - fine).round();
    (n + fine) * dmax / 256.0
}

fn dmax(pov_dir: &Path) -> f64 {
    let text = std::fs::read_to_string(pov_dir.join("depth.pov")).unwrap();
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("#declare DMax = "))
        .expect("DMax in depth.pov");
    line.trim_end_matches(';').parse().unwrap()
}

/// Why a pixel is left out of the comparison.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Exclusion {
    Silhouette,
    Glass,
    Tie,
}

/// First surface with coverage ≥ 0.5 along a ray (HCI semantics, re-derived here).
fn hci_hit(scene: &RenderScene, o: Vec3, d: Vec3, hits: &mut Vec<Hit>) -> Option<(usize, Hit)> {
    let g = &scene.geometry;
    g.all_hits(o, d, f32::INFINITY, hits);
    hits.iter()
        .position(|h| g.coverage(&scene.materials, h, d) >= 0.5)
        .map(|i| (i, hits[i]))
}

/// Classifies a pixel by tracing its centre and its four corners.
fn exclusion(
    scene: &RenderScene,
    rays: &lfgen::camera::ViewRays,
    x: u32,
    y: u32,
) -> Option<Exclusion> {
    let g = &scene.geometry;
    let mut hits = Vec::new();
    let c = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
    let first = hci_hit(scene, c.origin, c.dir, &mut hits);
    if let Some((i, h)) = first {
        let mat = g.shading[h.tri as usize].material as usize;
        if scene.materials[mat].glass_ior.is_some() {
            return Some(Exclusion::Glass);
        }
        // A see-through surface at the same depth as the HCI one: which of the two a renderer
        // meets first is a tie, and POV-Ray, passing the see-through one, skips the other.
        let tie = |k: usize| {
            hits.get(k).is_some_and(|o| {
                (o.t - h.t).abs() <= 1e-4 * h.t && g.coverage(&scene.materials, o, c.dir) < 0.5
            })
        };
        if (i > 0 && tie(i - 1)) || tie(i + 1) {
            return Some(Exclusion::Tie);
        }
    }
    for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
        let r = rays.ray(x as f32 + dx, y as f32 + dy);
        let corner = hci_hit(scene, r.origin, r.dir, &mut hits);
        let same = match (first, corner) {
            (None, None) => true,
            (Some((_, a)), Some((_, b))) => g
                .plane_distance(a.tri, r.origin, r.dir)
                .is_some_and(|t| (t - b.t).abs() <= 1e-3 * b.t),
            _ => false,
        };
        if !same {
            return Some(Exclusion::Silhouette);
        }
    }
    None
}

#[test]
fn povray_planar_depth_matches_hci_depth_of_centre_and_corner_views() {
    if !pov::available() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let ds = tmp.path().join("ds");
    let res = format!("camera.resolution=[{WIDTH},{HEIGHT}]");
    lfgen(&[
        "--scenes",
        "1",
        "--out",
        ds.to_str().unwrap(),
        "--set",
        &res,
        "--set",
        "camera.grid=[3,3]",
        "--set",
        "render.spp=1",
        "--set",
        "render.gt_views=all",
        "--set",
        "dataset.date=2026-01-01",
        "--quiet",
    ]);
    let scene_dir = ds.join("train/scene_0000");
    let pov = tmp.path().join("pov");
    let views = [4u32, 0, 2, 6, 8];
    lfgen(&[
        "export",
        "--to",
        "pov",
        scene_dir.to_str().unwrap(),
        "--out",
        pov.to_str().unwrap(),
        "--views",
        "0,2,4,6,8",
    ]);
    let desc = lfgen::scene::SceneDesc::read(&scene_dir.join("scene.json")).unwrap();
    let scene = RenderScene::build_with(&desc, &Assets::load(&desc).unwrap()).unwrap();
    let dmax = dmax(&pov);
    let mut failures = Vec::new();
    let (mut compared, mut agreeing, mut worst) = (0usize, 0usize, 0.0f64);
    println!("view  compared  agree  silhouette  glass  tie");
    for view in views {
        let gt = read_pfm(&scene_dir.join(format!("gt_depth_lowres_Cam{view:03}.pfm"))).unwrap();
        let (coarse, fine) = (
            render_depth(&pov, view, false),
            render_depth(&pov, view, true),
        );
        let rays = desc.camera.view_rays(view);
        let mut excluded = [0usize; 3];
        let (mut n, mut ok) = (0usize, 0usize);
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                if let Some(e) = exclusion(&scene, &rays, x, y) {
                    excluded[e as usize] += 1;
                    continue;
                }
                let i = (y * WIDTH + x) as usize;
                let want = gt.get(x as usize, y as usize) as f64;
                let got = match coarse[i] {
                    0.0 => f64::NAN,
                    c => decode(c, fine[i], dmax),
                };
                n += 1;
                let agree =
                    (want.is_nan() && got.is_nan()) || (got - want).abs() <= TOLERANCE * want;
                if agree {
                    ok += 1;
                    if want.is_finite() {
                        worst = worst.max((got - want).abs() / want);
                    }
                } else {
                    failures.push(format!(
                        "view {view} pixel ({x}, {y}): lfgen {want} POV-Ray {got}"
                    ));
                }
            }
        }
        println!(
            "Cam{view:03}  {n:8}  {:5.1}%  {:10}  {:5}  {:8}",
            100.0 * ok as f64 / n as f64,
            excluded[0],
            excluded[1],
            excluded[2]
        );
        compared += n;
        agreeing += ok;
    }
    let share = agreeing as f64 / compared as f64;
    println!(
        "agreement {:.4}% of {compared} pixels; largest relative difference where they agree: {worst:.2e}",
        100.0 * share
    );
    for f in failures.iter().take(20) {
        println!("  {f}");
    }
    assert!(
        compared > (WIDTH * HEIGHT) as usize * views.len() / 4,
        "too few pixels compared"
    );
    assert!(
        share >= REQUIRED,
        "POV-Ray depth agrees on {:.4}% < {}% of pixels; first failures:\n{}",
        100.0 * share,
        100.0 * REQUIRED,
        failures
            .iter()
            .take(20)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}

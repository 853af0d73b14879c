//! glTF import (`lfgen render SCENE.gltf|.glb`): ground truth of the fixtures in
//! tests/fixtures/gltf (written by make_fixtures.py there) checked against closed-form values,
//! hostile files rejected with errors naming the problem, and the scene folder re-rendered
//! byte for byte from its scene.json.

mod bin;

use bin::{ok, stderr};
use glam::{DVec3, Vec3};
use lfformat::Mode;
use lfgen::config::{BaselineMode, Config, SliceSpacing};
use lfgen::render::RenderScene;
use lfgen::render::integrator::PathSettings;
use lfgen::render::slices::SliceAssignment;
use lfgen::render::view::{Adaptive, RenderSettings, ViewGt, ViewOutput};
use lfgen::scene::gltf::import;
use lfgen::scene::{Light, SceneDesc, SliceRange, SurfaceModel};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::AtomicU64;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/gltf")
        .join(name)
}

/// A small grid with a fixed baseline (5 cm) and focus (3 m), so disparities are known.
fn config(resolution: [u32; 2]) -> Config {
    let mut cfg = Config::default();
    cfg.camera.resolution = resolution;
    cfg.camera.grid = [3, 3];
    cfg.camera.baseline = BaselineMode::Fixed;
    cfg.camera.baseline_mm = 50.0;
    cfg.camera.focus_distance_m = 3.0;
    cfg
}

/// Focal length in pixels from the fixture camera's yfov (glTF camera: f_px = H/2 / tan(yfov/2)).
fn f_px(height: u32, yfov: f64) -> f64 {
    height as f64 / 2.0 / (yfov / 2.0).tan()
}

/// Disparity of planar depth `z` for [`config`]'s baseline and focus.
fn disparity(f: f64, z: f64) -> f64 {
    f * 0.05 * (1.0 / z - 1.0 / 3.0)
}

/// An imported fixture, built and ready to render (slices: 128 of equal depth over [1, 8] m).
struct Loaded {
    desc: SceneDesc,
    scene: RenderScene,
}

fn load(name: &str, cfg: &Config) -> Loaded {
    let imported =
        import(&fixture(name), &cfg.gltf_import()).unwrap_or_else(|e| panic!("{name}: {e:#}"));
    let desc = SceneDesc {
        slices: SliceRange {
            z_near: 1.0,
            z_far: 8.0,
            count: 128,
            spacing: SliceSpacing::Depth,
        },
        ..imported.desc
    };
    let scene = RenderScene::build_with(&desc, &imported.assets).expect("fixture builds");
    Loaded { desc, scene }
}

impl Loaded {
    fn render(&self, spp: u32, with_gt: bool) -> ViewOutput {
        let settings = RenderSettings {
            path: PathSettings {
                max_depth: 1,
                rr_depth: 2,
                footprint: 0.0,
                glass_light: lfgen::render::integrator::GlassLight::Caustics,
                split_glass: true,
            },
            spp,
            gt_spp: spp,
            seed: 3,
            scene_index: 0,
            mode_epsilon: 1e-4,
            shade_all_hits: false,
            slice_assignment: SliceAssignment::Surface,
            adaptive: Adaptive::default(),
        };
        let cam = &self.desc.camera;
        let view = cam.center_view();
        self.scene.render_view(
            cam,
            &self.desc.slices,
            &settings,
            view,
            with_gt,
            &AtomicU64::new(0),
        )
    }

    fn gt(&self, spp: u32) -> ViewGt {
        self.render(spp, true).gt.expect("GT requested")
    }
}

/// `modes` is exactly `want` = [(depth, η)], depth to 1e-5 relative, disparity to 1e-4 px.
fn assert_modes(modes: &[Mode], want: &[(f64, f32)], f: f64, tol: f32, at: &str) {
    assert_eq!(modes.len(), want.len(), "{at}: {modes:?}");
    for (m, &(z, eta)) in modes.iter().zip(want) {
        assert!(
            ((m.depth as f64 - z) / z).abs() < 1e-5,
            "{at}: {m:?} vs depth {z}"
        );
        let d = disparity(f, z);
        assert!(
            (m.disparity as f64 - d).abs() < 1e-4,
            "{at}: {m:?} vs disparity {d}"
        );
        assert!((m.eta - eta).abs() <= tol, "{at}: {m:?} vs eta {eta}");
        assert!((m.eta_exact - eta).abs() <= tol, "{at}: {m:?} vs eta {eta}");
    }
}

fn each_pixel(g: &ViewGt) -> impl Iterator<Item = (usize, usize, &[Mode])> {
    let (w, h) = (g.modes.width, g.modes.height);
    (0..h).flat_map(move |y| (0..w).map(move |x| (x, y, g.modes.pixel(x, y))))
}

#[test]
fn opaque_plane_has_exact_disparity_and_the_cameras_field_of_view() {
    let l = load("plane.gltf", &config([32, 32]));
    let f = f_px(32, 0.5);
    assert!(
        (l.desc.camera.f_px() - f).abs() < 1e-9 * f,
        "{}",
        l.desc.camera.f_px()
    );
    assert_eq!(l.desc.camera.forward, DVec3::NEG_Z);
    // No light in the file: the documented white sky.
    assert_eq!(l.desc.environment, [1.0; 3]);
    let g = l.gt(2);
    for (x, y, modes) in each_pixel(&g) {
        assert_modes(modes, &[(2.0, 1.0)], f, 1e-6, &format!("pixel ({x}, {y})"));
    }
    assert!(g.hci.depth.iter().all(|&z| (z - 2.0).abs() < 2e-6));
}

#[test]
fn blend_pane_alpha_is_factor_times_texture_and_gives_eta() {
    // alpha = 0.5 (baseColorFactor) × 0.8 (embedded PNG) = 0.4: η 0.4 for the pane, 0.6 for
    // the wall behind it; the HCI depth (first coverage ≥ 0.5) is the wall.
    let l = load("pane.glb", &config([24, 24]));
    let f = f_px(24, 0.5);
    let g = l.gt(4);
    for (x, y, modes) in each_pixel(&g) {
        assert_modes(
            modes,
            &[(1.5, 0.4), (3.5, 0.6)],
            f,
            1e-5,
            &format!("pixel ({x}, {y})"),
        );
    }
    assert!(g.hci.depth.iter().all(|&z| (z - 3.5).abs() < 4e-6));
}

#[test]
fn mask_cutout_is_all_or_nothing_at_the_cutoff() {
    // The left half of the cut-out (x < 0, image columns < 16) reads the opaque texel; the
    // right half reads alpha 0.3 < cutoff 0.5 and vanishes, showing the wall.
    let l = load("mask.gltf", &config([32, 32]));
    let f = f_px(32, 0.5);
    let g = l.gt(4);
    let mut outliers = 0;
    for (x, y, modes) in each_pixel(&g) {
        let z = if x < 16 { 2.0 } else { 4.0 };
        let ok = modes.len() == 1 && ((modes[0].depth as f64 - z).abs() < 1e-4);
        if !ok {
            // Only a sample a hair from the boundary may read the other texel.
            assert!(x == 15 || x == 16, "pixel ({x}, {y}): {modes:?}");
            outliers += 1;
            continue;
        }
        assert_modes(modes, &[(z, 1.0)], f, 0.0, &format!("pixel ({x}, {y})"));
    }
    assert!(outliers <= 2, "{outliers} boundary pixels split");
}

#[test]
fn node_hierarchy_with_rotation_scale_and_matrix_places_the_quad() {
    // Net transform: a 2 m square facing the camera at depth 3, edges at ±1 m; behind it a
    // wall placed by a matrix at depth 6.
    let l = load("hierarchy.gltf", &config([32, 32]));
    let f = f_px(32, 1.2);
    let half = f / 3.0;
    let g = l.gt(1);
    let (mut inside, mut outside) = (0, 0);
    for (i, &z) in g.hci.depth.iter().enumerate() {
        let (x, y) = ((i % 32) as f64 + 0.5, (i / 32) as f64 + 0.5);
        let covered = (x - 16.0).abs() < half && (y - 16.0).abs() < half;
        let want = if covered { 3.0 } else { 6.0 };
        assert!(
            (z as f64 - want).abs() < 1e-5,
            "pixel {i}: depth {z} vs {want}"
        );
        if covered { inside += 1 } else { outside += 1 }
    }
    assert!(inside > 200 && outside > 300, "{inside} {outside}");
}

#[test]
fn camera_is_chosen_by_name_and_a_missing_one_is_named() {
    let mut cfg = config([16, 16]);
    cfg.gltf.camera = "offset".into();
    let d = import(&fixture("hierarchy.gltf"), &cfg.gltf_import())
        .unwrap()
        .desc;
    assert!((d.camera.position - DVec3::new(0.25, 0.0, 0.0)).length() < 1e-7);
    cfg.gltf.camera = "nope".into();
    let err = format!(
        "{:#}",
        import(&fixture("hierarchy.gltf"), &cfg.gltf_import())
            .err()
            .unwrap()
    );
    assert!(err.contains("\"nope\"") && err.contains("offset"), "{err}");
    // A file without a camera needs one from the config.
    let err = format!(
        "{:#}",
        import(
            &fixture("hostile/no_camera.gltf"),
            &config([16, 16]).gltf_import()
        )
        .err()
        .unwrap()
    );
    assert!(
        err.contains("no camera") && err.contains("gltf.camera=config"),
        "{err}"
    );
    cfg.gltf.camera = "config".into();
    cfg.gltf.camera_position = [0.0, 0.0, 1.0];
    cfg.gltf.camera_look_at = [0.0, 0.0, -2.0];
    let d = import(&fixture("hostile/no_camera.gltf"), &cfg.gltf_import())
        .unwrap()
        .desc;
    assert_eq!(d.camera.position, DVec3::new(0.0, 0.0, 1.0));
    let f = f_px(16, 40f64.to_radians());
    assert!((d.camera.f_px() - f).abs() < 1e-9 * f);
}

/// KHR_lights_punctual cone attenuation at angle `theta` from the spot's axis.
fn cone(theta: f64) -> f64 {
    let (ci, co) = (0.15f64.cos(), 0.3f64.cos());
    ((theta.cos() - co) / (ci - co)).clamp(0.0, 1.0).powi(2)
}

#[test]
fn spot_light_lights_its_cone_with_the_gltf_falloff() {
    // The spot sits at the camera, so a pixel at distance r px from the image centre is lit
    // from angle atan(r / f). With only direct light (max depth 1) the spot's image is the same
    // point light's image times the cone attenuation: exactly equal well inside the inner
    // cone, exactly black outside the outer one, and between the attenuations of its footprint's
    // nearest and farthest points in between.
    let spot = load("spot.gltf", &config([64, 64]));
    assert_eq!(
        spot.desc.environment, [0.0; 3],
        "a lit scene has no sky by default"
    );
    let Light::Spot {
        position,
        intensity,
        range,
        ..
    } = spot.desc.lights[0].clone()
    else {
        panic!("{:?}", spot.desc.lights)
    };
    let mut desc = spot.desc.clone();
    desc.lights = vec![Light::Point {
        position,
        intensity,
        range,
    }];
    let point = Loaded {
        scene: rebuild(&desc),
        desc,
    };
    let (s, p) = (spot.render(4, false).image, point.render(4, false).image);
    let f = f_px(64, 1.2);
    let mut counts = [0; 3];
    for (i, (a, b)) in s.pixels.iter().zip(&p.pixels).enumerate() {
        let (x, y) = ((i % 64) as f64 + 0.5 - 32.0, (i / 64) as f64 + 0.5 - 32.0);
        let r = (x * x + y * y).sqrt();
        let (near, far) = (((r - 0.71).max(0.0) / f).atan(), ((r + 0.71) / f).atan());
        assert!(b.x > 0.0, "pixel {i}: the point light reaches every pixel");
        if far < 0.15 {
            assert_eq!(a, b, "pixel {i}: inside the inner cone");
            counts[0] += 1;
        } else if near > 0.3 {
            assert_eq!(*a, Vec3::ZERO, "pixel {i}: outside the outer cone");
            counts[2] += 1;
        } else {
            let ratio = (a.x / b.x) as f64;
            assert!(
                ratio >= cone(far) - 1e-4 && ratio <= cone(near) + 1e-4,
                "pixel {i}: ratio {ratio} not in [{}, {}]",
                cone(far),
                cone(near)
            );
            counts[1] += 1;
        }
    }
    assert!(counts.iter().all(|&c| c > 100), "{counts:?}");
}

/// Builds a description that still refers to its glTF source.
fn rebuild(desc: &SceneDesc) -> RenderScene {
    let assets = lfgen::scene::assets::Assets::load(desc).expect("source unchanged");
    RenderScene::build_with(desc, &assets).expect("builds")
}

#[test]
fn hostile_files_are_rejected_with_errors_naming_the_problem() {
    let cases = [
        (
            "index_out_of_range.gltf",
            "index 7 at position 1 is out of range (4 vertices)",
        ),
        ("huge_count.gltf", "accessor 0 (POSITION"),
        (
            "missing_position_accessor.gltf",
            "POSITION: accessor 7 does not exist",
        ),
        ("view_outside_buffer.gltf", "bufferView 0 (offset 100000"),
        ("short_buffer.gltf", "byteLength is 1073741824"),
        ("escaping_uri.gltf", "\"..\" would leave the glTF's folder"),
        ("absolute_uri.gltf", "absolute paths are not read"),
        ("url_uri.gltf", "\"https:\" is a URL"),
        ("node_cycle.gltf", "reached twice"),
        ("draco_required.gltf", "KHR_draco_mesh_compression"),
        ("lines.gltf", "only TRIANGLES"),
        (
            "position_uint.gltf",
            "unsigned int components are for indices only",
        ),
        ("bad_length.glb", "GLB header declares"),
    ];
    let cfg = config([16, 16]);
    for (name, needle) in cases {
        let path = fixture(&format!("hostile/{name}"));
        let err = match import(&path, &cfg.gltf_import()) {
            Ok(_) => panic!("{name} was accepted"),
            Err(e) => format!("{e:#}"),
        };
        assert!(err.contains(needle) && err.contains(name), "{name}: {err}");
    }
}

#[test]
fn ignored_extensions_and_maps_and_an_aspect_mismatch_are_warned_once() {
    let tmp = tempfile::tempdir().unwrap();
    for f in ["plane.bin", "mask.png"] {
        fs::copy(fixture(f), tmp.path().join(f)).unwrap();
    }
    let mut json: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(fixture("plane.gltf")).unwrap()).unwrap();
    json["extensionsUsed"] =
        serde_json::json!(["KHR_materials_clearcoat", "KHR_texture_transform"]);
    json["images"] = serde_json::json!([{ "uri": "mask.png" }]);
    json["textures"] = serde_json::json!([{ "source": 0 }]);
    json["materials"][0]["normalTexture"] = serde_json::json!({ "index": 0 });
    // A second instance of the wall: notes are per feature, not per use.
    json["nodes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({ "mesh": 0 }));
    json["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!(2));
    let path = tmp.path().join("warn.gltf");
    fs::write(&path, json.to_string()).unwrap();
    let warnings = import(&path, &config([24, 20]).gltf_import())
        .unwrap()
        .warnings;
    assert_eq!(warnings.len(), 3, "{warnings:#?}");
    assert_eq!(warnings[0], "extensions ignored: KHR_materials_clearcoat");
    assert!(
        warnings[1].starts_with("normal maps are ignored"),
        "{warnings:#?}"
    );
    assert!(
        warnings[2].contains("aspect ratio 1.000") && warnings[2].contains("24x20"),
        "{warnings:#?}"
    );
}

/// `plane.gltf` with `uris.len()` images (one per entry of `uris`), each the base colour of
/// its own material on its own copy of the wall.
fn many_images(dir: &Path, uris: &[&str]) -> PathBuf {
    fs::copy(fixture("plane.bin"), dir.join("plane.bin")).unwrap();
    let mut json: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(fixture("plane.gltf")).unwrap()).unwrap();
    let n = uris.len();
    json["images"] = uris
        .iter()
        .map(|u| serde_json::json!({ "uri": u }))
        .collect();
    json["textures"] = (0..n).map(|i| serde_json::json!({ "source": i })).collect();
    let material = json["materials"][0].clone();
    let mesh = json["meshes"][0].clone();
    let wall = json["nodes"][1].clone();
    let (mut materials, mut meshes, mut nodes) = (vec![], vec![], vec![]);
    for i in 0..n {
        let mut m = material.clone();
        m["pbrMetallicRoughness"]["baseColorTexture"] = serde_json::json!({ "index": i });
        materials.push(m);
        let mut mesh = mesh.clone();
        mesh["primitives"][0]["material"] = serde_json::json!(i);
        meshes.push(mesh);
        let mut node = wall.clone();
        node["mesh"] = serde_json::json!(i);
        node["translation"] = serde_json::json!([0.0, 0.0, -2.0 - 0.01 * i as f64]);
        nodes.push(node);
    }
    json["materials"] = materials.into();
    json["meshes"] = meshes.into();
    nodes.push(json["nodes"][0].clone());
    json["scenes"][0]["nodes"] = (0..nodes.len()).collect();
    json["nodes"] = nodes.into();
    let path = dir.join("images.gltf");
    fs::write(&path, json.to_string()).unwrap();
    path
}

/// Six glTF images naming one file are decoded once and share one allocation; the total of
/// distinct images is held to a budget, refused with an error naming the file when exceeded.
#[test]
fn images_naming_one_file_are_decoded_once_and_the_total_is_bounded() {
    use lfgen::scene::assets::{Assets, Source};
    let tmp = tempfile::tempdir().unwrap();
    fs::copy(fixture("mask.png"), tmp.path().join("mask.png")).unwrap();
    fs::copy(fixture("mask.png"), tmp.path().join("copy.png")).unwrap();
    let one = image::open(fixture("mask.png")).unwrap();
    let one = one.width() as u64 * one.height() as u64 * 4;

    let same = many_images(
        tmp.path(),
        &[
            "mask.png",
            "./mask.png",
            "mask.png",
            "mask.png",
            "mask.png",
            "mask.png",
        ],
    );
    let imported = import(&same, &config([24, 20]).gltf_import()).unwrap();
    assert_eq!(
        imported.assets.image_bytes(),
        one,
        "six references, one image"
    );
    let open = |desc: &SceneDesc| {
        let files: Vec<Source> = desc
            .sources
            .iter()
            .map(|s| Source::open_unchanged(s).unwrap())
            .collect();
        files
    };
    let files = open(&imported.desc);
    assert!(Assets::from_files_within(&imported.desc, &files, one).is_ok());

    let two = many_images(tmp.path(), &["mask.png", "copy.png"]);
    let imported = import(&two, &config([24, 20]).gltf_import()).unwrap();
    assert_eq!(imported.assets.image_bytes(), 2 * one);
    let files = open(&imported.desc);
    let err = Assets::from_files_within(&imported.desc, &files, one + one / 2)
        .err()
        .expect("two images over a budget of one and a half");
    let err = format!("{err:#}");
    assert!(
        err.contains("images.gltf") && err.contains("decoded"),
        "{err}"
    );
}

/// sRGB code → linear (IEC 61966-2-1), written out here independently of the crate.
fn srgb(code: u8) -> f64 {
    let c = code as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn materials_emission_glass_and_alpha_modes_convert_as_specified() {
    let tmp = tempfile::tempdir().unwrap();
    for f in ["plane.bin", "mask.png"] {
        fs::copy(fixture(f), tmp.path().join(f)).unwrap();
    }
    let mut json: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(fixture("plane.gltf")).unwrap()).unwrap();
    json["extensionsUsed"] = serde_json::json!([
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission",
        "KHR_materials_ior"
    ]);
    json["images"] = serde_json::json!([{ "uri": "mask.png" }]);
    json["textures"] = serde_json::json!([{ "source": 0 }]);
    json["materials"] = serde_json::json!([
        {
            "name": "lamp",
            "emissiveFactor": [1.0, 0.5, 0.0],
            "emissiveTexture": { "index": 0 },
            "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 4.0 } }
        },
        {
            "name": "glass",
            "extensions": {
                "KHR_materials_transmission": { "transmissionFactor": 1.0 },
                "KHR_materials_ior": { "ior": 1.33 }
            }
        },
        { "name": "cut", "alphaMode": "MASK", "pbrMetallicRoughness": { "baseColorFactor": [1, 1, 1, 0.3] } },
        { "name": "veil", "alphaMode": "BLEND", "pbrMetallicRoughness": { "baseColorFactor": [1, 1, 1, 0.3] } },
        { "name": "solid", "alphaMode": "OPAQUE", "pbrMetallicRoughness": { "baseColorFactor": [1, 1, 1, 0.3] } }
    ]);
    let path = tmp.path().join("materials.gltf");
    fs::write(&path, json.to_string()).unwrap();
    let d = import(&path, &config([16, 16]).gltf_import()).unwrap().desc;
    // Emission = factor × strength × the texture's mean linear colour (texels (200, 60, 40)
    // and (40, 60, 200)).
    let mean = |a: u8, b: u8| (srgb(a) + srgb(b)) / 2.0;
    let want = [4.0 * mean(200, 40), 2.0 * mean(60, 60), 0.0];
    for (got, want) in d.materials[0].emission.iter().zip(want) {
        assert!(
            (*got as f64 - want).abs() < 1e-5,
            "{:?} vs {want:?}",
            d.materials[0].emission
        );
    }
    assert_eq!(d.materials[1].model, SurfaceModel::Glass { ior: 1.33 });
    let opacities: Vec<Option<f32>> = d.materials[2..]
        .iter()
        .map(|m| m.opacity.uniform())
        .collect();
    assert_eq!(opacities, [Some(0.0), Some(0.3), Some(1.0)]);
    // An emissive material counts as a light: no white sky.
    assert_eq!(d.environment, [0.0; 3]);
}

// ---------------------------------------------------------------------------------------
// The command line.
// ---------------------------------------------------------------------------------------

const TINY: &[&str] = &[
    "--set",
    "camera.resolution=[24,20]",
    "--set",
    "camera.grid=[3,3]",
    "--set",
    "render.spp=2",
    "--set",
    "dataset.date=2026-01-01",
    "--quiet",
];

fn lfgen(args: &[&str]) -> Output {
    bin::lfgen(&[args, TINY].concat())
}

fn render(input: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    lfgen(&args)
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                fs::read(&p).unwrap(),
            )
        })
        .collect();
    out.sort();
    out
}

fn ini_value(path: &Path, key: &str) -> f64 {
    let text = fs::read_to_string(path).unwrap();
    let line = text
        .lines()
        .find(|l| l.split('=').next().unwrap().trim() == key)
        .unwrap_or_else(|| panic!("{key} missing"));
    line.split('=').nth(1).unwrap().trim().parse().unwrap()
}

#[test]
fn rendering_gltf_writes_a_scene_folder_that_scene_json_reproduces() {
    let tmp = tempfile::tempdir().unwrap();
    let (first, again) = (tmp.path().join("mask"), tmp.path().join("again"));
    ok(render(&fixture("mask.gltf"), &first, &[]));
    let names: Vec<String> = files(&first).into_iter().map(|(n, _)| n).collect();
    assert_eq!(names, bin::scene_files(9));
    // f_px from the camera's yfov (0.5 rad) on the configured 24×20 image, stored HCI-style.
    let cfg = first.join("parameters.cfg");
    let f = ini_value(&cfg, "focal_length_mm") * 24.0 / ini_value(&cfg, "sensor_size_mm");
    assert!((f - f_px(20, 0.5)).abs() < 1e-9, "{f}");
    let json = fs::read_to_string(first.join("scene.json")).unwrap();
    assert!(
        json.contains("mask.png") && json.contains("\"type\": \"mesh\""),
        "{json}"
    );
    ok(render(&first.join("scene.json"), &again, &[]));
    assert!(files(&first) == files(&again), "re-render differs");
}

#[test]
fn a_changed_source_is_reported_when_re_rendering() {
    let tmp = tempfile::tempdir().unwrap();
    for f in ["mask.gltf", "mask.bin", "mask.png"] {
        fs::copy(fixture(f), tmp.path().join(f)).unwrap();
    }
    let out = tmp.path().join("out");
    ok(render(
        &tmp.path().join("mask.gltf"),
        &out,
        &["--camera", "main"],
    ));
    fs::copy(fixture("plane.bin"), tmp.path().join("mask.png")).unwrap();
    let r = render(&out.join("scene.json"), &tmp.path().join("again"), &[]);
    assert!(
        !r.status.success()
            && stderr(&r).contains("\"mask.png\"")
            && stderr(&r).contains("changed"),
        "{}",
        stderr(&r)
    );
}

#[test]
fn command_line_camera_choice_and_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("offset");
    ok(render(
        &fixture("hierarchy.gltf"),
        &out,
        &["--camera", "offset"],
    ));
    assert!((ini_value(&out.join("parameters.cfg"), "center_cam_x_m") - 0.25).abs() < 1e-7);
    let r = render(
        &out.join("scene.json"),
        &tmp.path().join("x"),
        &["--camera", "main"],
    );
    assert!(
        !r.status.success() && stderr(&r).contains("--camera"),
        "{}",
        stderr(&r)
    );
    let r = render(
        &fixture("hostile/escaping_uri.gltf"),
        &tmp.path().join("y"),
        &[],
    );
    assert!(
        !r.status.success()
            && stderr(&r).contains("escaping_uri.gltf")
            && stderr(&r).contains(".."),
        "{}",
        stderr(&r)
    );
    assert!(!tmp.path().join("y").exists());
}

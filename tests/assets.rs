//! The asset catalogue: OBJ/MTL models read with their materials (n-gons, dissolve, `Tr`,
//! `map_Kd`, `map_d` alpha), broken and hostile entries skipped with one line each (or refused
//! with `--strict`), and scenes that place catalogue pieces — scaled to their real size, inside
//! the room, deterministic, re-renderable from scene.json. Fixtures: tests/fixtures/assets
//! (written by make_fixtures.py there).

mod bin;

use bin::{lfgen, ok, stderr};
use glam::{Vec2, Vec3};
use lfgen::config::Config;
use lfgen::procgen::builtin;
use lfgen::procgen::library::AssetLibrary;
use lfgen::scene::assets::Assets;
use lfgen::scene::obj::ObjFile;
use lfgen::scene::shapes::tessellate;
use lfgen::scene::texture_image::{DecodeBudgets, srgb_to_linear};
use lfgen::scene::{Opacity, Shape, Texture};
use std::path::{Path, PathBuf};
use std::process::Command;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/assets")
}

fn catalog() -> PathBuf {
    fixtures().join("catalog.json")
}

fn open(model: &str) -> ObjFile {
    ObjFile::open(&fixtures().join("models").join(model), &fixtures()).unwrap()
}

#[test]
fn obj_faces_are_triangulated_with_uvs_and_normals() {
    let table = open("table.obj");
    // Six quads in two material groups: 4 + 2 quads → 8 + 4 triangles.
    assert_eq!(table.mesh_count(), 2);
    let sides = table.mesh_triangles(0).unwrap();
    let top = table.mesh_triangles(1).unwrap();
    assert_eq!((sides.len(), top.len()), (8, 4));
    // OBJ's V points up, image rows down: vt (0, 1) becomes uv (0, 0).
    let uvs: Vec<Vec2> = sides.iter().flat_map(|t| t.uv).collect();
    assert!(uvs.contains(&Vec2::new(0.0, 0.0)) && uvs.contains(&Vec2::new(1.0, 1.0)));
    // No normals in the file: the face normal, which for the front face (z = 80) is +Z.
    let front = sides
        .iter()
        .find(|t| t.p.iter().all(|p| p.z == 80.0))
        .unwrap();
    assert!(
        front.n.iter().all(|n| (*n - Vec3::Z).length() < 1e-6),
        "{:?}",
        front.n
    );
    // Pentagon caps are fanned into three triangles each: 2·3 + 5·2.
    let vase = open("vase.obj");
    assert_eq!(vase.mesh_triangles(0).unwrap().len(), 16);
    let (lo, hi) = table.bounds(glam::Mat3::IDENTITY);
    assert_eq!((lo, hi), (Vec3::ZERO, Vec3::new(120.0, 75.0, 80.0)));
}

#[test]
fn mtl_colour_dissolve_and_maps_become_materials() {
    let table = open("table.obj").materials(7);
    let (wood, top) = (&table[0], &table[1]);
    match &wood.base_color {
        Texture::Image { image, factor } => {
            assert_eq!((image.source, image.image), (7, 0));
            assert_eq!(*factor, [1.0; 3]);
        }
        other => panic!("map_Kd with options: {other:?}"),
    }
    // Ns 100 with Ks > 0: α = sqrt(2/102), roughness = sqrt(α).
    let want = (2.0f32 / 102.0).sqrt().sqrt();
    assert!((wood.roughness - want).abs() < 1e-6);
    // Kd is sRGB; Tr 0.6 is 1 − d.
    let grey = srgb_to_linear(0.5);
    assert_eq!(top.base_color, Texture::constant([grey; 3]));
    assert!((top.opacity.uniform().unwrap() - 0.4).abs() < 1e-6);
    assert_eq!(top.roughness, 0.9, "no Ks: matte");
    assert!((open("vase.obj").materials(0)[0].opacity.uniform().unwrap() - 0.3).abs() < 1e-6);
    // map_d: a grey image without alpha gives its grey level as alpha.
    let leaf = open("leaf.obj");
    let Opacity::Image { image, factor, .. } = &leaf.materials(0)[0].opacity else {
        panic!("map_d is an image opacity");
    };
    assert_eq!(*factor, 1.0);
    let budgets = DecodeBudgets::for_images_alone().unwrap();
    let alpha = leaf.texture_image(image.image, &budgets).unwrap();
    let at = |u: f32| alpha.sample(image, Vec2::new(u, 0.5)).w;
    assert_eq!((at(0.1), at(0.9)), (1.0, 0.0));
}

#[test]
fn broken_and_hostile_entries_are_skipped_with_one_line_each() {
    let lib = AssetLibrary::open(&catalog(), false).unwrap();
    assert_eq!(lib.len(), 4, "table, vase, leaf card, wall leaf");
    let expect = [
        ("bad_index", "out of bounds"),
        ("nan_vertex", "not a finite number"),
        ("missing_texture", "nowhere.png"),
        ("escape", "would leave"),
        ("corrupt_texture", "cannot decode"),
        ("empty", "no faces"),
        ("absurd_size", "size"),
        ("outside", "not a relative path"),
        ("not_obj", "only OBJ"),
    ];
    assert_eq!(lib.skipped.len(), expect.len(), "{:#?}", lib.skipped);
    for ((id, why), line) in expect.iter().zip(&lib.skipped) {
        assert!(line.starts_with(id) && line.contains(why), "{id}: {line}");
        assert!(!line.contains('\n'), "one line: {line}");
    }
    let strict = AssetLibrary::open(&catalog(), true).err().unwrap();
    let msg = format!("{strict:#}");
    assert!(
        msg.contains("catalog.json") && msg.contains("bad_index"),
        "{msg}"
    );
}

/// A catalogue piece is scaled to its entry's size, bottom on the floor, centred on its
/// footprint; a model rotation turns it first.
#[test]
fn pieces_take_the_catalogue_size_and_rotation() {
    let lib = AssetLibrary::open(&catalog(), false).unwrap();
    let extent = |i: usize| {
        let piece = lib.piece(i, 0, &mut |_| 0);
        let desc_sources = [lib.source(i).clone()];
        let mut desc = builtin::generate(
            &Config::default().scene,
            &Config::default().scene_start(),
            0,
            None,
        );
        desc.sources = desc_sources.to_vec();
        desc.objects.clear();
        for p in &piece.parts {
            desc.objects.push(lfgen::scene::Object {
                name: "p".into(),
                shape: p.shape.clone(),
                transform: p.transform,
                material: 0,
            });
        }
        let assets = Assets::load(&desc).unwrap();
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        let mut tris = Vec::new();
        for p in &piece.parts {
            tessellate(&p.shape, &p.transform, &assets, &mut tris).unwrap();
        }
        for q in tris.iter().flat_map(|t| t.p) {
            (lo, hi) = (lo.min(q), hi.max(q));
        }
        (lo, hi, piece)
    };
    let near = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-5;
    let (lo, hi, table) = extent(0);
    assert!(near(lo, Vec3::new(-0.6, 0.0, -0.4)) && near(hi, Vec3::new(0.6, 0.75, 0.4)));
    assert_eq!(table.surfaces.len(), 1);
    assert_eq!((table.surfaces[0].y, table.height), (0.75, 0.75));
    // The leaf card lies along X in the file; rotated, its 2 m side runs along Z, then it is
    // scaled to 0.3 × 0.6 × 0.02 (flat along X: kept flat).
    let (lo, hi, _) = extent(2);
    assert!(
        near(lo, Vec3::new(0.0, 0.0, -0.01)) && near(hi, Vec3::new(0.0, 0.6, 0.01)),
        "{lo} {hi}"
    );
    // Wall-hung: raised by its elevation.
    let (lo, hi, leaf) = extent(3);
    assert!((lo.y - 1.2).abs() < 1e-5 && (hi.y - 1.6).abs() < 1e-5);
    assert_eq!((leaf.elevation, leaf.height), (1.2, 1.6));
}

fn catalog_config(seed: u64) -> Config {
    let mut cfg = Config::default();
    cfg.dataset.seed = seed;
    cfg.scene.catalog = catalog().display().to_string();
    cfg.scene.catalog_share = 0.6;
    cfg
}

/// Many seeds: catalogue pieces are placed, every vertex of every object (catalogue meshes
/// included) is inside the room, and a scene is a pure function of (seed, index).
#[test]
fn scenes_with_catalogue_pieces_stay_inside_the_room_and_are_deterministic() {
    let lib = AssetLibrary::open(&catalog(), false).unwrap();
    let mut from_catalog = 0;
    for seed in 0..8 {
        let cfg = catalog_config(seed);
        let desc = builtin::generate(&cfg.scene, &cfg.scene_start(), seed, Some(&lib));
        assert_eq!(
            desc,
            builtin::generate(&cfg.scene, &cfg.scene_start(), seed, Some(&lib))
        );
        let report = desc.placement.clone().unwrap();
        from_catalog += report.from_catalog;
        let meshes = desc
            .objects
            .iter()
            .filter(|o| matches!(o.shape, Shape::Mesh { .. }));
        assert!(meshes.count() as u32 >= report.from_catalog);
        let room = match desc
            .objects
            .iter()
            .find(|o| o.name == "floor")
            .unwrap()
            .shape
        {
            Shape::Quad { size } => Vec2::from(size),
            _ => unreachable!(),
        };
        let height = desc
            .objects
            .iter()
            .find(|o| o.name == "ceiling")
            .unwrap()
            .transform
            .translation
            .y;
        let assets = Assets::load(&desc).unwrap();
        let mut tris = Vec::new();
        for o in &desc.objects {
            tris.clear();
            tessellate(&o.shape, &o.transform, &assets, &mut tris).unwrap();
            for p in tris.iter().flat_map(|t| t.p) {
                let inside = o.name.starts_with("outside_")
                    || p.x.abs() <= room.x / 2.0 + 1e-3
                        && p.z.abs() <= room.y / 2.0 + 1e-3
                        && (-1e-3..=height + 1e-3).contains(&p.y);
                assert!(inside, "seed {seed}: {} has a vertex at {p}", o.name);
            }
        }
    }
    assert!(
        from_catalog >= 8 * 10,
        "only {from_catalog} catalogue pieces in 8 scenes"
    );
    // Without a catalogue the procedural scenes are exactly those of the generator alone.
    let plain = Config::default();
    assert_eq!(
        builtin::generate(&plain.scene, &plain.scene_start(), 2, None)
            .placement
            .unwrap()
            .from_catalog,
        0
    );
}

#[test]
fn the_cli_warns_once_per_skipped_entry_renders_and_rerenders_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let cat = format!("scene.catalog={}", catalog().display());
    let args = |strict: bool| {
        let mut a = vec![
            "--scenes",
            "1",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
            "--set",
            &cat,
            "--set",
            "camera.resolution=[48,32]",
            "--set",
            "camera.grid=[3,3]",
            "--set",
            "render.spp=2",
            "--set",
            "scene.catalog_share=0.7",
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        if strict {
            a.push("--strict".into());
        }
        a
    };
    let run = |a: Vec<String>| lfgen(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let strict = run(args(true));
    assert!(!strict.status.success());
    assert!(stderr(&strict).contains("bad_index"), "{}", stderr(&strict));
    assert!(
        !out.join("train/scene_0000").exists(),
        "no scene after a strict failure"
    );
    let done = ok(run(args(false)));
    let err = stderr(&done);
    assert_eq!(err.matches("warning:").count(), 9, "{err}");
    assert!(err.contains("4 assets usable, 9 skipped"), "{err}");
    let scene = out.join("train/scene_0000");
    let json = std::fs::read_to_string(scene.join("scene.json")).unwrap();
    assert!(json.contains("table.obj") || json.contains("vase.obj") || json.contains("leaf.obj"));
    let again = dir.path().join("again");
    ok(lfgen(&[
        "render",
        scene.join("scene.json").to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
        "--quiet",
        "--set",
        "render.spp=2",
    ]));
    for f in ["input_Cam004.png", "gt_disp_lowres.pfm", "modes.exr"] {
        assert_eq!(
            std::fs::read(scene.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap(),
            "{f} re-rendered from scene.json"
        );
    }
}

/// A catalogue named by a bare file name, from its own folder (`--set
/// scene.catalog=catalog.json`), has its entries resolved against the working folder instead of
/// failing every one of them with "cannot resolve : No such file or directory".
#[test]
fn a_catalogue_named_relative_to_the_working_folder_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let r = Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .current_dir(fixtures())
        .args([
            "--no-config",
            "--scenes",
            "1",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .args([
            "--set",
            "scene.catalog=catalog.json",
            "--set",
            "camera.resolution=[16,12]",
        ])
        .args(["--set", "camera.grid=[1,1]", "--set", "render.spp=1"])
        .output()
        .unwrap();
    let err = stderr(&r);
    assert!(
        r.status.success() && err.contains("4 assets usable, 9 skipped"),
        "{err}"
    );
}

/// Copies the folder `from` into `to` (created), files and subfolders.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// The default `scene.catalog = "auto"` draws from `assets/sweethome3d/catalog.json` where
/// `lfgen assets fetch sweethome3d` puts it, says so, and records the resolved path in the
/// manifest's config; without that file it says the furniture is procedural and records "".
#[test]
fn the_default_catalogue_is_sweet_home_3d_when_installed() {
    for installed in [true, false] {
        let dir = tempfile::tempdir().unwrap();
        if installed {
            copy_tree(&fixtures(), &dir.path().join("assets/sweethome3d"));
        }
        let r = Command::new(env!("CARGO_BIN_EXE_lfgen"))
            .current_dir(dir.path())
            .args(["--no-config", "--scenes", "1", "--out", "ds"])
            .args([
                "--set",
                "camera.resolution=[16,12]",
                "--set",
                "camera.grid=[1,1]",
            ])
            .args(["--set", "render.spp=1", "--set", "render.adaptive_spp=0"])
            .output()
            .unwrap();
        let err = stderr(&r);
        assert!(r.status.success(), "{err}");
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("ds/manifest.json")).unwrap())
                .unwrap();
        let recorded = &manifest["config"]["scene"]["catalog"];
        if installed {
            assert!(err.contains("Sweet Home 3D catalogue"), "{err}");
            assert!(err.contains("4 assets usable, 9 skipped"), "{err}");
            assert_eq!(recorded, "assets/sweethome3d/catalog.json");
            let stats = ["train", "val"]
                .map(|split| {
                    dir.path()
                        .join("ds")
                        .join(split)
                        .join("scene_0000/stats.json")
                })
                .into_iter()
                .find(|p| p.exists())
                .expect("the scene's stats.json");
            let stats: serde_json::Value =
                serde_json::from_slice(&std::fs::read(stats).unwrap()).unwrap();
            let placed = stats["placement"]["from_catalog"].as_u64().unwrap();
            assert!(placed > 0, "no catalogue piece placed");
        } else {
            assert!(err.contains("procedural furniture only"), "{err}");
            assert_eq!(recorded, "");
        }
    }
}

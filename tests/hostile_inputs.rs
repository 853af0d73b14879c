//! Valid but awkward and hostile inputs that used to panic, abort or fail a whole run: OBJ faces
//! mixing vertices with and without `vt`/`vn`, an MTL colour that is not a number, and inputs
//! whose memory must be estimated and refused before it is allocated — textures of 16384²,
//! views of 16384² × 33², a sphere of 19.9 M triangles, a glTF instancing 21 M triangles and a
//! scene name that is no name. The binary runs under a 4 GiB address-space limit, as a user's
//! `ulimit -v` or a cluster's memory limit would hold it.

mod bin;
mod skip;

use lfgen::config::Config;
use lfgen::procgen::library::AssetLibrary;
use lfgen::scene::memory::Budget;
use lfgen::scene::obj::ObjFile;
use lfgen::scene::texture_image::{DecodeBudgets, TextureImage};
use serde_json::{Value, json};
use std::fs;
use std::path::{Path, PathBuf};

/// Four corners of a unit square, two texture coordinates and a normal, then `faces`.
fn square_obj(faces: &str) -> String {
    format!("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n{faces}\n")
}

/// Faces that mix vertices with and without `vt` or `vn` are valid OBJ: they load, every
/// triangle with finite unit normals and finite UVs (the face normal and UV 0 where the file
/// has none for a vertex).
#[test]
fn obj_faces_mixing_texture_coordinates_and_normals_load() {
    let variants = [
        ("vt on one corner", "f 1/1 2 3"),
        ("vn on one corner", "f 1//1 2 3"),
        ("vt and vn on some corners", "f 1/1/1 2/2 3"),
        ("vt on one face only", "f 1/1 2/2 3/3\nf 1 3 4"),
        ("vn on one face only", "f 1//1 2//1 3//1\nf 1 3 4"),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (what, faces) in variants {
        let path = dir.path().join("mixed.obj");
        fs::write(&path, square_obj(faces)).unwrap();
        let obj = ObjFile::open(&path, dir.path()).unwrap_or_else(|e| panic!("{what}: {e:#}"));
        let tris = obj.mesh_triangles(0).unwrap();
        assert_eq!(tris.len(), faces.lines().count(), "{what}");
        for t in &tris {
            assert!(
                t.n.iter().all(|n| (n.length() - 1.0).abs() < 1e-5)
                    && t.uv.iter().all(|uv| uv.is_finite()),
                "{what}: {t:?}"
            );
        }
    }
}

/// A catalogue of `entries` (id, OBJ file) in `dir`, every entry a 0.5 m cube on the floor.
fn catalogue(dir: &Path, entries: &[(&str, &str)]) -> PathBuf {
    let assets: Vec<Value> = (entries.iter())
        .map(|(id, file)| {
            json!({"id": id, "name": id, "file": file, "category": "Miscellaneous",
                   "size": [0.5, 0.5, 0.5], "placement": "floor", "surfaces": [],
                   "license": "CC0-1.0", "author": "lfgen tests"})
        })
        .collect();
    let path = dir.join("catalog.json");
    fs::write(&path, json!({"version": 1, "assets": assets}).to_string()).unwrap();
    path
}

/// A cube OBJ using material `material` of `mtl` (none when empty).
fn cube_obj(mtl: &str, material: &str) -> String {
    let mut s = String::new();
    if !mtl.is_empty() {
        s += &format!("mtllib {mtl}\nusemtl {material}\n");
    }
    for v in 0..8 {
        s += &format!("v {} {} {}\n", v & 1, (v >> 1) & 1, (v >> 2) & 1);
    }
    s + "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n"
}

/// An MTL colour that is not a number is a broken catalogue entry like any other: skipped with
/// a warning naming the catalogue, the entry, its file and the material (refused with
/// `--strict`), never an invalid scene that fails the run.
#[test]
fn an_mtl_colour_that_is_not_a_number_skips_its_entry() {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("plain.obj"), cube_obj("", "")).unwrap();
    fs::write(dir.path().join("nan.mtl"), "newmtl paint\nKd -1 1e39 nan\n").unwrap();
    fs::write(dir.path().join("nan.obj"), cube_obj("nan.mtl", "paint")).unwrap();
    let cat = catalogue(dir.path(), &[("plain", "plain.obj"), ("nan_kd", "nan.obj")]);
    let lib = AssetLibrary::open(&cat, false).unwrap();
    assert_eq!(lib.len(), 1);
    let line = &lib.skipped[0];
    assert!(
        line.starts_with("nan_kd (nan.obj)") && line.contains("\"paint\""),
        "{line}"
    );
    let strict = format!("{:#}", AssetLibrary::open(&cat, true).err().unwrap());
    assert!(
        strict.contains("catalog.json") && strict.contains("nan_kd"),
        "{strict}"
    );

    let out = dir.path().join("ds");
    let set = format!("scene.catalog={}", cat.display());
    let r = bin::lfgen(&[
        "--scenes",
        "1",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--set",
        &set,
        "--set",
        "scene.catalog_share=1",
        "--set",
        "camera.resolution=[16,12]",
        "--set",
        "camera.grid=[1,1]",
        "--set",
        "render.spp=1",
    ]);
    let err = bin::stderr(&r);
    assert!(r.status.success(), "{err}");
    assert!(
        err.contains("warning: ") && err.contains("catalog.json: skipped nan_kd (nan.obj)"),
        "{err}"
    );
}

/// A PNG of `width × height` black, fully transparent texels, written without ever holding
/// them: a zlib stream of fixed-Huffman back-references (258 zero bytes each), so a 16384²
/// image (1 GiB decoded) is a 7 MB file made in a blink.
fn blank_png(path: &Path, width: u32, height: u32) {
    let raw = height as u64 * (1 + 4 * width as u64); // a filter byte per row, then RGBA
    let mut bits = Bits::default();
    bits.put(0b011, 3); // final block, fixed Huffman
    bits.code(0x30, 8); // literal 0
    let mut left = raw - 1;
    while left >= 258 {
        bits.code(0xC5, 8); // length 258
        bits.code(0, 5); // distance 1
        left -= 258;
    }
    for _ in 0..left {
        bits.code(0x30, 8);
    }
    bits.code(0, 7); // end of block
    let mut zlib = vec![0x78, 0x01];
    zlib.extend(bits.finish());
    let adler = ((raw % 65521) << 16) | 1; // of zeros: a = 1, b = the byte count
    zlib.extend((adler as u32).to_be_bytes());
    let mut ihdr = Vec::new();
    ihdr.extend(width.to_be_bytes());
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([8, 6, 0, 0, 0]); // 8-bit RGBA
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [(b"IHDR", &ihdr), (b"IDAT", &zlib), (b"IEND", &Vec::new())] {
        png.extend((data.len() as u32).to_be_bytes());
        let start = png.len();
        png.extend(kind);
        png.extend(data);
        let crc = crc32(&png[start..]);
        png.extend(crc.to_be_bytes());
    }
    fs::write(path, png).unwrap();
}

/// Deflate's bit order: values least significant bit first, Huffman codes most significant
/// bit first.
#[derive(Default)]
struct Bits {
    bytes: Vec<u8>,
    acc: u32,
    n: u32,
}

impl Bits {
    fn put(&mut self, value: u32, count: u32) {
        self.acc |= value << self.n;
        self.n += count;
        while self.n >= 8 {
            self.bytes.push(self.acc as u8);
            (self.acc, self.n) = (self.acc >> 8, self.n - 8);
        }
    }

    fn code(&mut self, code: u32, count: u32) {
        self.put(code.reverse_bits() >> (32 - count), count);
    }

    fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            self.bytes.push(self.acc as u8);
        }
        self.bytes
    }
}

fn crc32(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in data {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

/// A texture's size is read from its header and refused before decoding, naming the image,
/// its dimensions, the estimate and the limit; a small one still decodes.
#[test]
fn a_texture_over_the_budgets_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.png");
    blank_png(&path, 16384, 16384);
    let bytes = fs::read(&path).unwrap();
    let budgets = |textures: u64, memory: u64| DecodeBudgets {
        textures: Budget::textures(textures),
        memory: Budget::new(memory),
    };
    let err = TextureImage::decode(&bytes, "texture \"huge.png\"", &budgets(4 << 30, 1 << 30))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("huge.png")
            && err.contains("16384×16384")
            && err.contains("2048 MiB")
            && err.contains("memory limit of 1024 MiB"),
        "{err}"
    );
    let err = TextureImage::decode(&bytes, "texture \"huge.png\"", &budgets(1 << 29, 4 << 30))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("1024 MiB") && err.contains("decoded-texture budget of 512 MiB"),
        "{err}"
    );
    blank_png(&path, 3, 2);
    let small = TextureImage::decode(&fs::read(&path).unwrap(), "small", &budgets(64, 1 << 20));
    assert_eq!(small.unwrap().texel_bytes(), 24);
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/gltf")
        .join(name)
}

/// tests/fixtures/gltf/plane.gltf (camera + one textured wall) as JSON, its buffer copied
/// into `dir`.
fn plane(dir: &Path) -> Value {
    fs::copy(fixture("plane.bin"), dir.join("plane.bin")).unwrap();
    serde_json::from_str(&fs::read_to_string(fixture("plane.gltf")).unwrap()).unwrap()
}

/// `lfgen args` under the 4 GiB bound of [`bin::bounded`]: exit 1 with one error naming every
/// one of `needles`, no panic, no abort, no time-out.
fn refused_within_4_gib(args: &[&str], needles: &[&str]) {
    let r = bin::bounded(args);
    let err = bin::stderr(&r);
    assert!(
        r.status.code() == Some(1)
            && err.lines().any(|l| l.starts_with("error: "))
            && !err.contains("panicked")
            && needles.iter().all(|n| err.contains(n)),
        "{args:?}: {:?}: {err}",
        r.status
    );
}

/// `json` with `nodes` as its scene, written to `dir/name` and rendered (with `extra`) under
/// [`refused_within_4_gib`]: refused naming the file and every one of `needles`. Returns the
/// output folder the refused run was given.
fn gltf_refused(
    dir: &Path,
    name: &str,
    mut json: Value,
    nodes: Vec<Value>,
    extra: &[&str],
    needles: &[&str],
) -> PathBuf {
    json["scenes"][0]["nodes"] = (0..nodes.len()).collect();
    json["nodes"] = nodes.into();
    let gltf = dir.join(name);
    fs::write(&gltf, json.to_string()).unwrap();
    let out = dir.join("out");
    let mut args = vec![
        "render",
        gltf.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let mut all = vec![name];
    all.extend(needles);
    refused_within_4_gib(&args, &all);
    out
}

/// Eight distinct 16384² textures in a glTF under a 4 GiB limit: the first ones decode, the
/// one that no longer fits is refused from its header with its size, the estimate and the
/// limit — not a panic inside the decoder.
#[test]
fn eight_16k_textures_are_refused_before_they_exhaust_memory() {
    if !bin::can_bound() {
        return skip::skip(bin::NO_PRLIMIT);
    }
    let dir = tempfile::tempdir().unwrap();
    let mut json = plane(dir.path());
    blank_png(&dir.path().join("t0.png"), 16384, 16384);
    for i in 1..8 {
        fs::copy(
            dir.path().join("t0.png"),
            dir.path().join(format!("t{i}.png")),
        )
        .unwrap();
    }
    json["images"] = (0..8)
        .map(|i| json!({"uri": format!("t{i}.png")}))
        .collect();
    json["textures"] = (0..8).map(|i| json!({"source": i})).collect();
    let (material, wall) = (json["materials"][0].clone(), json["nodes"][1].clone());
    json["materials"] = (0..8)
        .map(|i| {
            let mut m = material.clone();
            m["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": i});
            m
        })
        .collect();
    json["meshes"] = (0..8)
        .map(|i| {
            let mut mesh = json["meshes"][0].clone();
            mesh["primitives"][0]["material"] = json!(i);
            mesh
        })
        .collect();
    let mut nodes: Vec<Value> = (0..8)
        .map(|i| {
            let mut node = wall.clone();
            node["mesh"] = json!(i);
            node["translation"] = json!([0.0, 0.0, -2.0 - 0.01 * i as f64]);
            node
        })
        .collect();
    nodes.push(json["nodes"][0].clone());
    let out = gltf_refused(
        dir.path(),
        "textures.gltf",
        json,
        nodes,
        &[
            "--quiet",
            "--set",
            "camera.resolution=[16,16]",
            "--set",
            "camera.grid=[1,1]",
        ],
        &["16384×16384", "MiB", "memory limit of"],
    );
    assert!(!out.exists());
}

/// A saved scene with `change` applied, written to `dir/name`.
fn scene_file(dir: &Path, name: &str, change: impl Fn(&mut Value)) -> PathBuf {
    let cfg = Config::load(
        None,
        &[],
        &[
            "camera.resolution=[16,12]".into(),
            "camera.grid=[1,1]".into(),
            "scene.objects=4".into(),
        ],
    )
    .unwrap();
    let (desc, _) = lfgen::pipeline::generate_scene(&cfg, 0, None).unwrap();
    let mut v = serde_json::to_value(desc).unwrap();
    change(&mut v);
    let path = dir.join(name);
    fs::write(&path, v.to_string()).unwrap();
    path
}

/// Views of 16384² × 33² and a sphere of 19.9 M triangles are refused by their memory
/// estimate, naming the field, the estimate and the limit, before anything is allocated; so
/// is the same resolution in the config.
#[test]
fn views_and_shapes_that_cannot_fit_are_refused_by_their_estimate() {
    if !bin::can_bound() {
        return skip::skip(bin::NO_PRLIMIT);
    }
    let dir = tempfile::tempdir().unwrap();
    let views = scene_file(dir.path(), "views.json", |v| {
        v["camera"]["resolution"] = json!([16384, 16384]);
        v["camera"]["grid"] = json!([33, 33]);
    });
    let sphere = scene_file(dir.path(), "sphere.json", |v| {
        let shape = json!({"type": "sphere", "radius": 0.5, "rings": 3155, "segments": 3155});
        v["objects"][0]["shape"] = shape;
    });
    let out = dir.path().join("out");
    for (file, needles) in [
        (
            &views,
            &["views.json", "camera.resolution [16384, 16384]"][..],
        ),
        (&sphere, &["sphere.json", "the shapes (1990"][..]),
    ] {
        let mut all = needles.to_vec();
        all.extend(["MiB", "memory limit of"]);
        refused_within_4_gib(
            &[
                "render",
                file.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            &all,
        );
        assert!(!out.exists());
    }
    let ds = dir.path().join("ds");
    refused_within_4_gib(
        &[
            "--scenes",
            "1",
            "--out",
            ds.to_str().unwrap(),
            "--set",
            "camera.resolution=[16384,16384]",
        ],
        &["camera.resolution [16384, 16384]", "memory limit of"],
    );
}

/// A glTF mesh of 1 M triangles instanced 21 times is refused from its accessor counts, naming
/// the file and the count, before its triangles are read (under a 4 GiB limit the memory
/// estimate refuses it before the count of 20 M triangles would).
#[test]
fn gltf_triangles_are_counted_from_the_accessors_before_they_are_read() {
    if !bin::can_bound() {
        return skip::skip(bin::NO_PRLIMIT);
    }
    let dir = tempfile::tempdir().unwrap();
    let mut json = plane(dir.path());
    let count = 3_000_000usize;
    let indices: Vec<u8> = [0u8, 1, 2].iter().copied().cycle().take(count).collect();
    fs::write(dir.path().join("indices.bin"), &indices).unwrap();
    json["buffers"]
        .as_array_mut()
        .unwrap()
        .push(json!({"uri": "indices.bin", "byteLength": count}));
    json["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 1, "byteOffset": 0, "byteLength": count}));
    json["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 4, "componentType": 5121, "count": count, "type": "SCALAR"}));
    json["meshes"][0]["primitives"][0]["indices"] = json!(4);
    let wall = json["nodes"][1].clone();
    let mut nodes = vec![json["nodes"][0].clone()];
    nodes.extend((0..21).map(|i| {
        let mut node = wall.clone();
        node["translation"] = json!([0.0, 0.0, -2.0 - 0.01 * i as f64]);
        node
    }));
    gltf_refused(
        dir.path(),
        "instances.gltf",
        json,
        nodes,
        &[],
        &["(1000000 triangles)", "memory limit of"],
    );
}

/// A name is one short line: not a gigabyte, no control characters, no path separators.
#[test]
fn a_scene_name_that_is_no_name_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (name, needle) in [
        ("x".repeat(256), "name must be 1 to 255 bytes, not 256"),
        ("a\nb".into(), "control characters or path separators"),
        ("../up".into(), "control characters or path separators"),
        (String::new(), "name must be 1 to 255 bytes, not 0"),
    ] {
        let path = scene_file(dir.path(), "named.json", |v| v["name"] = json!(name));
        let out = dir.path().join("out");
        let r = bin::lfgen(&[
            "render",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = bin::stderr(&r);
        assert!(
            r.status.code() == Some(1) && err.contains("named.json") && err.contains(needle),
            "{name:?}: {err}"
        );
    }
}

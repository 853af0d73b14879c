//! Wavefront OBJ + MTL models, the format of most furniture libraries (Sweet Home 3D's among
//! them), read with `tobj`: faces triangulated (n-gons as fans), one mesh per object / material
//! group, and materials converted — `Kd` × `map_Kd` base colour, `d` (or `1 − Tr`) × `map_d`
//! opacity, `Ns` as roughness, `Ke` emission.
//!
//! Reading is as defensive as the glTF reader: bounded file sizes, material libraries and
//! textures only from inside the model's `root` folder, face indices checked (by `tobj`),
//! non-finite coordinates, material values that make no material (`Kd nan`), missing libraries
//! and missing textures refused with an error that names the problem. Faces that mix vertices
//! with and without `vt` or `vn` are valid OBJ and are read (see [`drop_partial_attributes`]).

use super::files::{read_limited, resolve_inside};
use super::shapes::MeshTri;
use super::texture_image::{DecodeBudgets, Filter, ImageMap, TextureImage, Wrap, srgb_to_linear};
use super::validate::check_material;
use super::{Material, Opacity, Resource, SourceFile, SurfaceModel, Texture};
use anyhow::{Context, Result, bail, ensure};
use glam::{Mat3, Vec2, Vec3};
use lfformat::manifest::hex_sha256;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Most triangles one file may have.
const MAX_TRIANGLES: u64 = 4 << 20;

/// A texture a material uses, and whether as colour or as opacity (`map_d`).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct TextureRef {
    /// Path relative to the root folder.
    rel: String,
    alpha: bool,
}

/// An opened, validated OBJ file with its material libraries.
pub struct ObjFile {
    /// Canonical path of the file and the folder its references may point into.
    path: PathBuf,
    root: PathBuf,
    models: Vec<tobj::Model>,
    materials: Vec<tobj::Material>,
    /// Image index `i` of this source is `textures[i]`.
    textures: Vec<TextureRef>,
    /// Per material: indices into `textures` of its colour and opacity maps.
    maps: Vec<[Option<u32>; 2]>,
    sha256: String,
    /// SHA-256 of every material library and texture read, by path relative to `root`.
    read_log: RefCell<BTreeMap<String, String>>,
}

impl ObjFile {
    /// Reads and validates `path`; its material libraries and textures may come from `root`
    /// (a folder containing it) or below. Errors name the problem; the caller adds the file.
    pub fn open(path: &Path, root: &Path) -> Result<Self> {
        let bytes = read_limited(path)?;
        let path = path
            .canonicalize()
            .with_context(|| format!("cannot resolve {}", path.display()))?;
        let root = root
            .canonicalize()
            .with_context(|| format!("cannot resolve {}", root.display()))?;
        ensure!(
            path.starts_with(&root),
            "the file lies outside {}",
            root.display()
        );
        let dir = path
            .parent()
            .context("the file has no folder")?
            .to_path_buf();
        let triangles = face_triangles(&bytes);
        ensure!(
            triangles <= MAX_TRIANGLES,
            "{triangles} triangles, more than the {MAX_TRIANGLES} lfgen reads from one model"
        );
        let read_log = RefCell::new(BTreeMap::new());
        let problem = RefCell::new(None);
        let loader = |mtl: &Path| match load_mtl(&dir, &root, mtl, &read_log) {
            Ok(parsed) => parsed,
            Err(e) => {
                problem.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        };
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ignore_points: true,
            ignore_lines: true,
        };
        let parsed = tobj::load_obj_buf(&mut std::io::Cursor::new(&bytes), &options, loader);
        if let Some(e) = problem.into_inner() {
            return Err(e);
        }
        let (mut models, materials) =
            parsed.map_err(|e| anyhow::anyhow!("not a readable OBJ: {e}"))?;
        let materials = materials.map_err(|e| anyhow::anyhow!("material library: {e}"))?;
        check_models(&models, materials.len())?;
        for m in &mut models {
            drop_partial_attributes(&mut m.mesh);
        }
        let mut file = Self {
            path,
            root,
            models,
            materials,
            textures: Vec::new(),
            maps: Vec::new(),
            sha256: hex_sha256(&bytes),
            read_log,
        };
        file.index_textures(&dir)?;
        file.check_materials()?;
        Ok(file)
    }

    /// Opens the source of a saved scene, refusing it if it or any file it read changed.
    pub fn open_unchanged(src: &SourceFile) -> Result<Self> {
        let path = Path::new(&src.path);
        let root = match &src.root {
            Some(root) => PathBuf::from(root),
            None => path
                .parent()
                .context("the file has no folder")?
                .to_path_buf(),
        };
        let file = Self::open(path, &root)
            .with_context(|| format!("{} (a source of this scene)", src.path))?;
        ensure!(
            file.sha256 == src.sha256,
            "{} changed since the scene was made (SHA-256 {} instead of {})",
            src.path,
            file.sha256,
            src.sha256
        );
        for r in &src.resources {
            let now = hex_sha256(&read_limited(&resolve_inside(
                &file.root,
                &file.root,
                &r.uri,
                "the model's",
            )?)?);
            ensure!(
                now == r.sha256,
                "{:?}, used by {}, changed since the scene was made",
                r.uri,
                src.path
            );
        }
        Ok(file)
    }

    /// The description of this file for `scene.json`: path, root, checksum and every material
    /// library and texture read so far.
    pub fn source_file(&self) -> Result<SourceFile> {
        let utf8 = |p: &Path| p.to_str().map(String::from).context("path is not UTF-8");
        Ok(SourceFile {
            path: utf8(&self.path)?,
            sha256: self.sha256.clone(),
            resources: (self.read_log.borrow().iter())
                .map(|(uri, sha256)| Resource {
                    uri: uri.clone(),
                    sha256: sha256.clone(),
                })
                .collect(),
            root: Some(utf8(&self.root)?),
        })
    }

    /// Number of meshes (object / material groups).
    pub fn mesh_count(&self) -> usize {
        self.models.len()
    }

    /// Triangles of mesh `mesh` (faces are triangulated when the file is read).
    pub fn mesh_triangle_count(&self, mesh: u32) -> Result<u64> {
        let m = (self.models.get(mesh as usize))
            .with_context(|| format!("mesh {mesh} does not exist"))?;
        Ok(m.mesh.indices.len() as u64 / 3)
    }

    /// Material of mesh `mesh`: an index into [`Self::materials`], or `None` for the default.
    pub fn mesh_material(&self, mesh: u32) -> Option<usize> {
        self.models[mesh as usize].mesh.material_id
    }

    /// Axis-aligned bounds `(min, max)` of every vertex after the rotation `rot`.
    pub fn bounds(&self, rot: Mat3) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for m in &self.models {
            for p in m.mesh.positions.chunks_exact(3) {
                let p = rot * Vec3::from_slice(p);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo, hi)
    }

    /// Triangles of mesh `mesh` in file coordinates; UVs with V pointing down (image rows),
    /// shading normals from the file or, where it has none, the face normal.
    pub fn mesh_triangles(&self, mesh: u32) -> Result<Vec<MeshTri>> {
        let m = &self
            .models
            .get(mesh as usize)
            .with_context(|| format!("mesh {mesh} does not exist"))?
            .mesh;
        let vec3 = |a: &[f32], i: u32| Vec3::from_slice(&a[3 * i as usize..3 * i as usize + 3]);
        let mut out = Vec::with_capacity(m.indices.len() / 3);
        for f in m.indices.chunks_exact(3) {
            let p = [0, 1, 2].map(|k| vec3(&m.positions, f[k]));
            let face = (p[1] - p[0]).cross(p[2] - p[0]);
            if face.length_squared() == 0.0 {
                continue;
            }
            let n = [0, 1, 2].map(|k| match m.normals.is_empty() {
                true => face.normalize(),
                false => vec3(&m.normals, f[k])
                    .try_normalize()
                    .unwrap_or(face.normalize()),
            });
            let uv = [0, 1, 2].map(|k| match m.texcoords.is_empty() {
                true => Vec2::ZERO,
                false => {
                    let i = 2 * f[k] as usize;
                    Vec2::new(m.texcoords[i], 1.0 - m.texcoords[i + 1])
                }
            });
            out.push(MeshTri { p, n, uv });
        }
        Ok(out)
    }

    /// The file's materials as lfgen materials, in MTL order; `source` is this file's index
    /// among the scene's sources.
    pub fn materials(&self, source: u32) -> Vec<Material> {
        (self.materials.iter().zip(&self.maps))
            .map(|(m, maps)| convert(m, maps, source))
            .collect()
    }

    /// The material of meshes without one: light grey, matte.
    pub fn default_material() -> Material {
        Material {
            name: "OBJ default".into(),
            model: SurfaceModel::Standard,
            base_color: Texture::constant([0.5; 3]),
            roughness: 0.9,
            metallic: 0.0,
            opacity: Opacity::constant(1.0),
            emission: [0.0; 3],
            emission_map: None,
        }
    }

    /// Decodes image `index` within `budgets` (charged by the caller); an opacity map without
    /// an alpha channel gives its grey level as alpha (`map_d` is a scalar texture).
    pub fn texture_image(&self, index: u32, budgets: &DecodeBudgets) -> Result<TextureImage> {
        let t = self
            .textures
            .get(index as usize)
            .with_context(|| format!("image {index} does not exist"))?;
        let what = format!("texture {:?}", t.rel);
        let path = resolve_inside(&self.root, &self.root, &t.rel, "the model's")
            .with_context(|| what.clone())?;
        let bytes = read_limited(&path).with_context(|| what.clone())?;
        self.read_log
            .borrow_mut()
            .insert(t.rel.clone(), hex_sha256(&bytes));
        let image = TextureImage::decode(&bytes, &what, budgets)?;
        Ok(match t.alpha && image.is_opaque() {
            true => image.grey_as_alpha(),
            false => image,
        })
    }

    /// Refuses a material whose MTL values make no lfgen material (`Kd nan`), with the scene
    /// check's message: caught here, a catalogue entry is skipped instead of failing a scene.
    fn check_materials(&self) -> Result<()> {
        for m in self.materials(0) {
            check_material(&m).with_context(|| format!("material {:?}", m.name))?;
        }
        Ok(())
    }

    /// Decodes every texture once (a library check: a corrupt image, or textures that alone
    /// do not fit the budgets of a scene, fail here, not while a scene renders).
    pub fn check_textures(&self) -> Result<()> {
        let mut budgets = DecodeBudgets::for_images_alone()?;
        for (i, t) in self.textures.iter().enumerate() {
            let image = self.texture_image(i as u32, &budgets)?;
            budgets.charge(&format!("texture {:?}", t.rel), &image)?;
        }
        Ok(())
    }

    /// Finds every texture the materials use (relative to the OBJ's folder), refusing missing
    /// ones, and numbers them.
    fn index_textures(&mut self, dir: &Path) -> Result<()> {
        let mut maps = Vec::with_capacity(self.materials.len());
        for m in &self.materials {
            let mut slot = |name: &Option<String>, alpha: bool| -> Result<Option<u32>> {
                let Some(name) = name.as_deref().map(map_file).filter(|n| !n.is_empty()) else {
                    return Ok(None);
                };
                let path = resolve_inside(dir, &self.root, name, "the model's")
                    .with_context(|| format!("material {:?}: texture {name:?}", m.name))?;
                let rel = relative(&path, &self.root)?;
                let t = TextureRef { rel, alpha };
                let i = match self.textures.iter().position(|x| *x == t) {
                    Some(i) => i,
                    None => {
                        self.textures.push(t);
                        self.textures.len() - 1
                    }
                };
                Ok(Some(i as u32))
            };
            maps.push([
                slot(&m.diffuse_texture, false)?,
                slot(&m.dissolve_texture, true)?,
            ]);
        }
        self.maps = maps;
        Ok(())
    }
}

/// Reads one material library referenced by `mtllib` (relative to the OBJ's folder `dir`)
/// and hands it to `tobj`'s parser.
fn load_mtl(
    dir: &Path,
    root: &Path,
    mtl: &Path,
    log: &RefCell<BTreeMap<String, String>>,
) -> Result<tobj::MTLLoadResult> {
    let name = mtl.to_str().context("material library name is not UTF-8")?;
    let what = || format!("material library {name:?}");
    let path = resolve_inside(dir, root, name, "the model's").with_context(what)?;
    let bytes = read_limited(&path).with_context(what)?;
    log.borrow_mut()
        .insert(relative(&path, root)?, hex_sha256(&bytes));
    Ok(tobj::load_mtl_buf(&mut std::io::Cursor::new(bytes)))
}

/// `path` relative to `root` with `/` separators.
fn relative(path: &Path, root: &Path) -> Result<String> {
    let rel = path.strip_prefix(root).context("outside the root folder")?;
    let parts: Vec<&str> = rel
        .components()
        .map(|c| c.as_os_str().to_str().context("path is not UTF-8"))
        .collect::<Result<_>>()?;
    Ok(parts.join("/"))
}

/// The file name of a texture statement, without its options (`-s 1 1 1 wood.png` → the last
/// word).
fn map_file(statement: &str) -> &str {
    let s = statement.trim();
    match s.starts_with('-') {
        true => s.split_whitespace().last().unwrap_or(""),
        false => s,
    }
}

/// `tobj` gives a vertex a normal (texture coordinate) only where its face names one, so a
/// mesh whose faces mix `f 1/1/1 …` with `f 1 2 3` has fewer normals than vertices and no
/// record of which vertex they belong to: such a mesh is read without that attribute — face
/// normals, UV (0, 0) — as a mesh whose file has none.
fn drop_partial_attributes(mesh: &mut tobj::Mesh) {
    let vertices = mesh.positions.len() / 3;
    if mesh.normals.len() != 3 * vertices {
        mesh.normals.clear();
    }
    if mesh.texcoords.len() != 2 * vertices {
        mesh.texcoords.clear();
    }
}

/// Triangles the face lines (`f …`) of an OBJ make, an n-gon counting n − 2: known before
/// `tobj` builds them, so an oversized model is refused before it takes memory.
fn face_triangles(bytes: &[u8]) -> u64 {
    bytes
        .split(|&b| b == b'\n')
        .filter_map(|line| {
            let rest = line.trim_ascii_start().strip_prefix(b"f")?;
            rest.first().filter(|b| b.is_ascii_whitespace())?;
            let corners = (rest.split(u8::is_ascii_whitespace)).filter(|w| !w.is_empty());
            Some(corners.count().saturating_sub(2) as u64)
        })
        .sum()
}

/// Refuses what would make the renderer misbehave: non-finite
/// coordinates, dangling material ids, no geometry at all (`tobj` already refuses face indices
/// out of bounds).
fn check_models(models: &[tobj::Model], materials: usize) -> Result<()> {
    let mut triangles = 0;
    for m in models {
        let mesh = &m.mesh;
        let what = || format!("object {:?}", m.name);
        ensure!(mesh.indices.len() % 3 == 0, "{}: not triangulated", what());
        triangles += mesh.indices.len() / 3;
        ensure!(
            mesh.positions.iter().all(|v| v.is_finite()),
            "{}: a vertex coordinate is not a finite number",
            what()
        );
        ensure!(
            mesh.normals
                .iter()
                .chain(&mesh.texcoords)
                .all(|v| v.is_finite()),
            "{}: a normal or texture coordinate is not a finite number",
            what()
        );
        if let Some(id) = mesh.material_id {
            ensure!(id < materials, "{}: material {id} does not exist", what());
        }
    }
    if triangles == 0 {
        bail!("no faces");
    }
    Ok(())
}

/// One MTL material as an lfgen material. Colours in MTL files are display values (sRGB).
fn convert(m: &tobj::Material, maps: &[Option<u32>; 2], source: u32) -> Material {
    let linear = |c: [f32; 3]| c.map(|v| srgb_to_linear(v.clamp(0.0, 1.0)));
    let kd = linear(m.diffuse.unwrap_or([0.8; 3]));
    let image = |index: u32| ImageMap {
        source,
        image: index,
        wrap: [Wrap::Repeat; 2],
        filter: Filter::Linear,
        transform: None,
    };
    let base_color = match maps[0] {
        Some(i) => Texture::Image {
            image: image(i),
            factor: kd,
        },
        None => Texture::constant(kd),
    };
    let tr = m
        .unknown_param
        .get("Tr")
        .and_then(|v| v.trim().parse::<f32>().ok());
    let dissolve = m.dissolve.or(tr.map(|t| 1.0 - t)).unwrap_or(1.0);
    let dissolve = if dissolve.is_finite() {
        dissolve.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let opacity = match maps[1] {
        Some(i) => Opacity::Image {
            image: image(i),
            factor: dissolve,
            cutoff: None,
        },
        None => Opacity::constant(dissolve),
    };
    let glossy = m.specular.is_some_and(|ks| ks.iter().any(|&v| v > 0.0));
    // Blinn-Phong exponent → GGX: α = sqrt(2 / (Ns + 2)), roughness = sqrt(α).
    let roughness = match (glossy, m.shininess) {
        (true, Some(ns)) if ns.is_finite() => (2.0 / (ns.max(0.0) + 2.0)).sqrt().sqrt(),
        _ => 0.9,
    };
    let emission = m
        .unknown_param
        .get("Ke")
        .map(|v| {
            let c: Vec<f32> = v
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            match c[..] {
                [r, g, b] if [r, g, b].iter().all(|x| x.is_finite()) => linear([r, g, b]),
                _ => [0.0; 3],
            }
        })
        .unwrap_or([0.0; 3]);
    Material {
        name: m.name.clone(),
        model: SurfaceModel::Standard,
        base_color,
        roughness: roughness.clamp(0.05, 1.0),
        metallic: 0.0,
        opacity,
        emission,
        emission_map: None,
    }
}

//! The data a scene description refers to instead of holding: triangles of glTF mesh
//! primitives and OBJ meshes (in mesh space) and decoded texture images, loaded once per scene
//! and shared by every object and material that uses them.

use super::gltf::GltfFile;
use super::memory::{self, Budget};
use super::obj::ObjFile;
use super::shapes::MeshTri;
use super::texture_image::{DecodeBudgets, ImageMap, TextureImage};
use super::{Material, Opacity, SceneDesc, Shape, SourceFile, Texture};
use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::collections::btree_map::Entry;
use std::sync::Arc;

/// Identifies the triangles of one mesh primitive with one UV set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct MeshKey {
    pub source: u32,
    pub mesh: u32,
    pub primitive: u32,
    pub uv_set: u32,
}

impl MeshKey {
    /// The key of a [`Shape::Mesh`]; `None` for parametric shapes.
    pub fn of(shape: &Shape) -> Option<Self> {
        match *shape {
            Shape::Mesh {
                source,
                mesh,
                primitive,
                uv_set,
                ..
            } => Some(Self {
                source,
                mesh,
                primitive,
                uv_set,
            }),
            _ => None,
        }
    }
}

/// Most decoded texel bytes one scene may hold (four 16384² RGBA images): images are checked
/// one at a time against their own limit, so without a total a file naming many large images
/// (or one image many times) could take all memory.
pub const MAX_IMAGE_BYTES: u64 = 4 << 30;

/// Loaded meshes and images of a scene (empty for the built-in generator's scenes).
#[derive(Default)]
pub struct Assets {
    meshes: BTreeMap<MeshKey, Vec<MeshTri>>,
    images: BTreeMap<(u32, u32), Arc<TextureImage>>,
    image_bytes: u64,
}

impl Assets {
    /// Opens every source file of `desc` — refusing one that changed since the scene was
    /// written — and loads what the scene refers to.
    pub fn load(desc: &SceneDesc) -> Result<Self> {
        let files: Vec<Source> = desc
            .sources
            .iter()
            .map(Source::open_unchanged)
            .collect::<Result<_>>()?;
        Self::from_files(desc, &files)
    }

    /// Loads what `desc` refers to from its already opened source files (`files[i]` is source
    /// `i`).
    pub fn from_files(desc: &SceneDesc, files: &[Source]) -> Result<Self> {
        Self::from_files_within(desc, files, MAX_IMAGE_BYTES)
    }

    /// [`Assets::from_files`] with at most `image_budget` decoded texel bytes. Every
    /// instance's triangles are counted from the files, and every image's size read from its
    /// header, against the scene's [`memory::scene_budget`] before anything is loaded or
    /// decoded. Images that are the same data (glTF images naming one file or one buffer
    /// view) are decoded once and count once.
    pub fn from_files_within(
        desc: &SceneDesc,
        files: &[Source],
        image_budget: u64,
    ) -> Result<Self> {
        let file = |source: u32| {
            files
                .get(source as usize)
                .with_context(|| format!("the scene refers to missing source file {source}"))
        };
        // "image 2 of /models/chair.obj": the source's path, where the description has it.
        let of = |what: String, source: u32| match desc.sources.get(source as usize) {
            Some(s) => format!("{what} of {}", s.path),
            None => what,
        };
        let mut memory = memory::scene_budget(desc)?;
        for o in &desc.objects {
            if let Some(key) = MeshKey::of(&o.shape) {
                let what = of(
                    format!("object {:?}: mesh {}", o.name, key.mesh),
                    key.source,
                );
                memory.charge_triangles(&what, file(key.source)?.triangle_count(key)?)?;
            }
        }
        let mut assets = Self::default();
        for key in desc.objects.iter().filter_map(|o| MeshKey::of(&o.shape)) {
            if let Entry::Vacant(slot) = assets.meshes.entry(key) {
                let file = file(key.source)?;
                slot.insert(file.primitive_triangles(key)?);
            }
        }
        let mut budgets = DecodeBudgets {
            textures: Budget::textures(image_budget),
            memory,
        };
        let mut decoded: BTreeMap<(u32, String), Arc<TextureImage>> = BTreeMap::new();
        for map in desc.materials.iter().flat_map(image_maps) {
            if let Entry::Vacant(slot) = assets.images.entry((map.source, map.image)) {
                let src = file(map.source)?;
                let same = (map.source, src.image_identity(map.image)?);
                let image = match decoded.entry(same) {
                    Entry::Occupied(e) => e.get().clone(),
                    Entry::Vacant(e) => {
                        let what = of(format!("image {}", map.image), map.source);
                        let image = (src.texture_image(map.image, &budgets))
                            .with_context(|| what.clone())?;
                        budgets.charge(&what, &image)?;
                        assets.image_bytes += image.texel_bytes();
                        e.insert(Arc::new(image)).clone()
                    }
                };
                slot.insert(image);
            }
        }
        Ok(assets)
    }

    /// Decoded texel bytes of the scene's distinct images.
    pub fn image_bytes(&self) -> u64 {
        self.image_bytes
    }

    /// Mesh-space triangles of a mesh primitive.
    pub fn mesh(&self, key: &MeshKey) -> Result<&[MeshTri]> {
        self.meshes
            .get(key)
            .map(Vec::as_slice)
            .with_context(|| format!("mesh {key:?} was not loaded"))
    }

    /// The decoded image a texture refers to.
    pub fn image(&self, map: &ImageMap) -> Result<Arc<TextureImage>> {
        self.images
            .get(&(map.source, map.image))
            .cloned()
            .with_context(|| {
                format!(
                    "image {} of source {} was not loaded",
                    map.image, map.source
                )
            })
    }
}

/// An opened source file of either format.
pub enum Source {
    Gltf(Box<GltfFile>),
    Obj(ObjFile),
}

impl Source {
    /// Opens a saved scene's source by its file extension, refusing it if anything changed.
    pub fn open_unchanged(src: &SourceFile) -> Result<Self> {
        match src.path.to_ascii_lowercase().ends_with(".obj") {
            true => ObjFile::open_unchanged(src).map(Source::Obj),
            false => GltfFile::open_unchanged(src).map(|f| Source::Gltf(Box::new(f))),
        }
    }

    /// Mesh-space triangles of a mesh (an OBJ has one primitive and one UV set per mesh),
    /// exact repeats left out.
    fn primitive_triangles(&self, key: MeshKey) -> Result<Vec<MeshTri>> {
        let tris = match self {
            Source::Gltf(f) => f.primitive_triangles(key.mesh, key.primitive, key.uv_set),
            Source::Obj(f) => f.mesh_triangles(key.mesh),
        };
        tris.map(MeshTri::without_repeats)
    }

    /// The description for `scene.json`, with every file read so far.
    pub fn source_file(&self) -> Result<SourceFile> {
        match self {
            Source::Gltf(f) => f.source_file(),
            Source::Obj(f) => f.source_file(),
        }
    }

    fn texture_image(&self, image: u32, budgets: &DecodeBudgets) -> Result<TextureImage> {
        match self {
            Source::Gltf(f) => f.texture_image(image, budgets),
            Source::Obj(f) => f.texture_image(image, budgets),
        }
    }

    /// Triangles of a mesh as its file declares them, before they are read.
    fn triangle_count(&self, key: MeshKey) -> Result<u64> {
        match self {
            Source::Gltf(f) => f.primitive_triangle_count(key.mesh, key.primitive),
            Source::Obj(f) => f.mesh_triangle_count(key.mesh),
        }
    }

    /// What image `image` is made of: equal for two images of the file that decode the same
    /// data (an OBJ's textures are numbered per distinct file already).
    fn image_identity(&self, image: u32) -> Result<String> {
        match self {
            Source::Gltf(f) => f.image_identity(image),
            Source::Obj(_) => Ok(format!("texture {image}")),
        }
    }
}

/// The images a material samples.
fn image_maps(m: &Material) -> impl Iterator<Item = &ImageMap> {
    fn image(t: &Texture) -> Option<&ImageMap> {
        match t {
            Texture::Image { image, .. } => Some(image),
            _ => None,
        }
    }
    let alpha = match &m.opacity {
        Opacity::Image { image, .. } => Some(image),
        _ => None,
    };
    let emission = m.emission_map.as_ref().and_then(image);
    image(&m.base_color)
        .into_iter()
        .chain(alpha)
        .chain(emission)
}

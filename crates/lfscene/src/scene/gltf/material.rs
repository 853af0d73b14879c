//! glTF materials as lfgen materials: metallic-roughness factors, base colour (factor ×
//! texture), the alpha modes as opacity, emission, and `KHR_materials_transmission` as glass.

use super::Notes;
use super::source::GltfFile;
use crate::scene::texture_image::{DecodeBudgets, Filter, ImageMap, UvTransform, Wrap};
use crate::scene::{Material, Opacity, SurfaceModel, Texture};
use ::gltf::material::AlphaMode;
use ::gltf::texture::{self, MagFilter, WrappingMode};
use anyhow::{Context, Result};
use glam::Vec3;

/// The converted materials, in glTF order, and the UV set each one's base colour reads.
pub(super) struct Materials {
    pub list: Vec<Material>,
    pub uv_sets: Vec<u32>,
}

/// glTF's default material (for primitives without one): white, fully metallic and rough.
pub(super) fn default_material() -> Material {
    Material {
        name: "glTF default".into(),
        model: SurfaceModel::Standard,
        base_color: Texture::constant([1.0; 3]),
        roughness: 1.0,
        metallic: 1.0,
        opacity: Opacity::constant(1.0),
        emission: [0.0; 3],
        emission_map: None,
    }
}

/// Converts every material of `file` (`source` is the file's index among the scene's sources).
pub(super) fn materials(file: &GltfFile, source: u32, notes: &mut Notes) -> Result<Materials> {
    let mut out = Materials {
        list: Vec::new(),
        uv_sets: Vec::new(),
    };
    for m in file.doc.materials() {
        let index = m.index().expect("document materials have indices");
        let what = match m.name() {
            Some(name) => format!("material {index} {name:?}"),
            None => format!("material {index}"),
        };
        let (material, uv_set) = material(file, source, &m, notes).with_context(|| what)?;
        out.list.push(material);
        out.uv_sets.push(uv_set);
    }
    Ok(out)
}

fn material(
    file: &GltfFile,
    source: u32,
    m: &::gltf::Material,
    notes: &mut Notes,
) -> Result<(Material, u32)> {
    note_ignored_maps(m, notes);
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, alpha] = pbr.base_color_factor();
    let texture = pbr.base_color_texture();
    let map = texture.as_ref().map(|t| image_map(t, source));
    let uv_set = texture.as_ref().map_or(0, uv_set_of);
    let base_color = match &map {
        Some(image) => Texture::Image {
            image: image.clone(),
            factor: [r, g, b],
        },
        None => Texture::constant([r, g, b]),
    };
    let material = Material {
        name: m.name().unwrap_or("unnamed").to_string(),
        model: match m.transmission() {
            Some(t) if t.transmission_factor() > 0.0 => SurfaceModel::Glass {
                // KHR_materials_ior's range is [1, ∞) (0 is a legacy "unset"); lfgen's
                // glass takes [1, 4], which holds every real material, else the default.
                ior: m.ior().filter(|i| (1.0..=4.0).contains(i)).unwrap_or(1.5),
            },
            _ => SurfaceModel::Standard,
        },
        base_color,
        roughness: pbr.roughness_factor(),
        metallic: pbr.metallic_factor(),
        opacity: opacity(m.alpha_mode(), m.alpha_cutoff(), alpha, map),
        emission: emission(file, m)?.to_array(),
        emission_map: None,
    };
    Ok((material, uv_set))
}

/// OPAQUE ignores alpha; BLEND makes base-colour alpha (factor × texture) the coverage; MASK
/// turns it into all-or-nothing at the cutoff (default 0.5).
fn opacity(mode: AlphaMode, cutoff: Option<f32>, factor: f32, map: Option<ImageMap>) -> Opacity {
    let cutoff = match mode {
        AlphaMode::Opaque => return Opacity::constant(1.0),
        AlphaMode::Blend => None,
        AlphaMode::Mask => Some(cutoff.unwrap_or(0.5)),
    };
    match map {
        Some(image) => Opacity::Image {
            image,
            factor,
            cutoff,
        },
        None => Opacity::constant(Opacity::from_alpha(1.0, factor, cutoff)),
    }
}

/// `emissiveFactor × emissive_strength × mean(emissiveTexture)`: an emissive texture counts as
/// its average, so emitters stay constant per material (what light sampling needs).
fn emission(file: &GltfFile, m: &::gltf::Material) -> Result<Vec3> {
    let factor = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
    let Some(info) = m.emissive_texture().filter(|_| factor.max_element() > 0.0) else {
        return Ok(factor);
    };
    let image = info.texture().source().index() as u32;
    let budgets = DecodeBudgets::for_images_alone()?;
    let texture = (file.texture_image(image, &budgets)).context("emissiveTexture")?;
    Ok(factor * texture.mean_linear_rgb())
}

fn note_ignored_maps(m: &::gltf::Material, notes: &mut Notes) {
    let pbr = m.pbr_metallic_roughness();
    if pbr.metallic_roughness_texture().is_some() {
        notes.add("metallicRoughnessTexture is ignored: the material's factors are used");
    }
    if m.normal_texture().is_some() {
        notes.add("normal maps are ignored: shading uses the mesh normals");
    }
    if m.emissive_texture().is_some() {
        notes.add("an emissive texture counts as its mean colour (constant emission per material)");
    }
    if m.transmission()
        .is_some_and(|t| t.transmission_texture().is_some())
    {
        notes.add("transmissionTexture is ignored: transmission > 0 makes a material glass");
    }
}

/// Which image, wrap modes, filter and `KHR_texture_transform` a texture reference uses.
fn image_map(info: &texture::Info, source: u32) -> ImageMap {
    let tex = info.texture();
    let sampler = tex.sampler();
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::Clamp,
        WrappingMode::MirroredRepeat => Wrap::Mirror,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    ImageMap {
        source,
        image: tex.source().index() as u32,
        wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
        filter: match sampler.mag_filter() {
            Some(MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        },
        transform: info.texture_transform().map(|t| UvTransform {
            offset: t.offset(),
            rotation: t.rotation(),
            scale: t.scale(),
        }),
    }
}

/// The UV set of a texture reference (`KHR_texture_transform` may override it).
fn uv_set_of(info: &texture::Info) -> u32 {
    info.texture_transform()
        .and_then(|t| t.tex_coord())
        .unwrap_or(info.tex_coord())
}

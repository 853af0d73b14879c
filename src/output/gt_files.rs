//! The per-pixel ground-truth images of a view's HCI layer beside its depth maps — normals,
//! object, material and class ids, the validity mask — and the scene's `ids.json`, which names
//! every id (docs/reference/format.md, Scene folder).

use crate::scene::SceneDesc;
use crate::scene::labels::SceneClasses;
use anyhow::Result;
use lfformat::gt_maps::HciLayer;
use lfformat::gt_maps::{write_id_png, write_normals_exr, write_valid_mask};
use lfformat::pfm::{FloatImage, write_pfm};
use serde::Serialize;
use std::path::Path;

/// Writes the HCI layer's normals and ids, named `{map}_{res}{suffix}` as the HCI add-on names
/// its maps (`objectids_highres.png`, `gt_disp_lowres_Cam040.pfm`), `res` being `lowres` or
/// `highres`.
pub fn write_surface_maps(dir: &Path, res: &str, suffix: &str, layer: &HciLayer) -> Result<()> {
    let (w, h) = (layer.width, layer.height);
    let name = |map: &str, ext: &str| dir.join(format!("{map}_{res}{suffix}.{ext}"));
    write_normals_exr(&name("gt_normals", "exr"), w, h, &layer.normal)?;
    write_id_png(&name("objectids", "png"), w, h, &layer.object)?;
    write_id_png(&name("materialids", "png"), w, h, &layer.material)?;
    write_id_png(&name("classids", "png"), w, h, &layer.class)?;
    Ok(())
}

/// `objectids_highres{suffix}.png`, the HCI add-on's high-resolution object-id map (the other
/// maps stay low-resolution: at 10× they would take gigabytes per scene).
pub fn write_objectids_highres(dir: &Path, suffix: &str, layer: &HciLayer) -> Result<()> {
    let path = dir.join(format!("objectids_highres{suffix}.png"));
    Ok(write_id_png(
        &path,
        layer.width,
        layer.height,
        &layer.object,
    )?)
}

/// Writes `gt_depth_{res}{suffix}.pfm` and `gt_disp_{res}{suffix}.pfm` of the layer's depth;
/// `disparity` converts a depth.
pub fn write_depth_maps(
    dir: &Path,
    res: &str,
    suffix: &str,
    layer: &HciLayer,
    disparity: impl Fn(f32) -> f32,
) -> Result<()> {
    let (w, h) = (layer.width, layer.height);
    let disp = layer.depth.iter().map(|&z| disparity(z)).collect();
    let depth = FloatImage::new(w, h, layer.depth.clone());
    write_pfm(&dir.join(format!("gt_depth_{res}{suffix}.pfm")), &depth)?;
    write_pfm(
        &dir.join(format!("gt_disp_{res}{suffix}.pfm")),
        &FloatImage::new(w, h, disp),
    )?;
    Ok(())
}

/// `valid_mask{suffix}.png`.
pub fn write_valid(
    dir: &Path,
    suffix: &str,
    width: usize,
    height: usize,
    valid: &[bool],
) -> Result<()> {
    let path = dir.join(format!("valid_mask{suffix}.png"));
    Ok(write_valid_mask(&path, width, height, valid)?)
}

/// `ids.json`: what every object, material and class id of the scene's ground truth names.
#[derive(Serialize)]
struct Ids {
    objects: Vec<ObjectId>,
    materials: Vec<Named>,
    classes: Vec<Named>,
}

#[derive(Serialize)]
struct ObjectId {
    id: u32,
    name: String,
    material: u32,
    class: u32,
}

#[derive(Serialize)]
struct Named {
    id: u32,
    name: String,
}

/// Writes `ids.json` of `desc`: object id = index in `objects` + 1, material id = index in
/// `materials` + 1, class ids as [`SceneClasses`] numbers them; 0 is "no surface" everywhere.
pub fn write_ids_json(path: &Path, desc: &SceneDesc) -> Result<()> {
    let classes = SceneClasses::new(desc.objects.iter().map(|o| o.name.as_str()));
    let objects = (desc.objects.iter().zip(&classes.of_object).enumerate())
        .map(|(i, (o, &class))| ObjectId {
            id: i as u32 + 1,
            name: o.name.clone(),
            material: o.material + 1,
            class,
        })
        .collect();
    let materials = (desc.materials.iter().enumerate())
        .map(|(i, m)| Named {
            id: i as u32 + 1,
            name: m.name.clone(),
        })
        .collect();
    let classes = (classes.names.into_iter())
        .map(|(id, name)| Named { id, name })
        .collect();
    let ids = Ids {
        objects,
        materials,
        classes,
    };
    super::scene_dir::write_json(path, &ids)
}

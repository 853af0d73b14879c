//! The CPU renderer: path-traced colour and single-pass multimodal depth ground truth.
//!
//! It consumes a [`SceneDesc`] and produces images and mode maps in memory; it knows nothing about
//! files.

// The scene layer under the names the renderer's modules use (`crate::scene::…`), so the
// renderer reads like the rest of lfgen; private, so they are not re-exported from here.
use lfscene::{camera, scene, textures, util};

mod bsdf;
mod build_boxes;
pub mod cache;
pub mod framing;
pub mod geometry;
pub mod integrator;
pub mod light_field;
mod lights;
mod material;
pub mod probe;
mod sampler;
pub mod sensor;
pub mod slices;
mod valid;
pub mod view;
mod wide;

/// The BVH kernels (`LFGEN_SIMD` picks one): every kernel gives the same bits.
pub use wide::Kernel;

use crate::scene::assets::Assets;
use crate::scene::labels::SceneClasses;
use crate::scene::{MAX_TRIANGLES, SceneDesc};
use anyhow::{Result, bail, ensure};
use geometry::{Geometry, SceneTri};
use glam::Vec3;
use lights::{Lights, PunctualLight};
use material::RenderMaterial;
use rayon::prelude::*;

/// A scene ready to trace: triangles in a BVH, resolved materials and lights.
pub struct RenderScene {
    pub geometry: Geometry,
    pub materials: Vec<RenderMaterial>,
    /// Emissive triangles.
    pub lights: Lights,
    pub punctual_lights: Vec<PunctualLight>,
    pub environment: Vec3,
    /// Semantic class id of each object ([`SceneClasses`]).
    pub classes: Vec<u32>,
}

impl RenderScene {
    /// Tessellates and indexes every object of a scene that refers to no external data.
    pub fn build(desc: &SceneDesc) -> Result<Self> {
        Self::build_with(desc, &Assets::default())
    }

    /// Tessellates and indexes every object of `desc`, taking meshes and images from `assets`.
    pub fn build_with(desc: &SceneDesc, assets: &Assets) -> Result<Self> {
        if let Some(bad) = desc.lights.iter().position(|l| !l.is_valid()) {
            bail!("light {bad} has non-finite or negative values or a degenerate direction");
        }
        let mut tris = Vec::new();
        desc.for_each_mesh(assets, |i, obj, mesh| {
            ensure!(
                tris.len() + mesh.len() <= MAX_TRIANGLES,
                "the scene has more than {MAX_TRIANGLES} triangles (at object {:?})",
                obj.name
            );
            tris.extend(mesh.iter().map(|&tri| SceneTri {
                tri,
                material: obj.material,
                object: i as u32,
            }));
            Ok(())
        })?;
        let names: Vec<String> = desc.objects.iter().map(|o| o.name.clone()).collect();
        let classes = SceneClasses::new(names.iter().map(String::as_str)).of_object;
        // In parallel: library textures are drawn into tiles here.
        let materials = desc
            .materials
            .par_iter()
            .map(|m| RenderMaterial::new(m, assets))
            .collect::<Result<Vec<_>>>()?;
        let geometry = Geometry::build(&tris, &names, &materials)?;
        let lights = Lights::new(&geometry, &materials);
        Ok(Self {
            geometry,
            materials,
            lights,
            punctual_lights: desc.lights.iter().map(PunctualLight::new).collect(),
            environment: Vec3::from(desc.environment),
            classes,
        })
    }
}

//! The CPU renderer: path-traced colour and single-pass multimodal depth ground truth.
//!
//! It consumes a [`SceneDesc`] and produces images and mode maps in memory; it knows nothing about
//! files.

pub mod bsdf;
pub mod framing;
pub mod geometry;
pub mod integrator;
pub mod lights;
pub mod material;
pub mod sampler;
pub mod slices;
pub mod view;

use crate::scene::SceneDesc;
use crate::scene::shapes::tessellate;
use anyhow::Result;
use geometry::{Geometry, SceneTri};
use glam::Vec3;
use lights::Lights;
use material::RenderMaterial;

/// A scene ready to trace: triangles in a BVH, resolved materials and lights.
pub struct RenderScene {
    pub geometry: Geometry,
    pub materials: Vec<RenderMaterial>,
    pub lights: Lights,
    pub environment: Vec3,
}

impl RenderScene {
    /// Tessellates and indexes every object of `desc`.
    pub fn build(desc: &SceneDesc) -> Result<Self> {
        let mut tris = Vec::new();
        let mut mesh = Vec::new();
        for (i, obj) in desc.objects.iter().enumerate() {
            anyhow::ensure!(
                (obj.material as usize) < desc.materials.len(),
                "object {:?} refers to missing material {}",
                obj.name,
                obj.material
            );
            mesh.clear();
            tessellate(&obj.shape, &obj.transform, &mut mesh);
            tris.extend(mesh.iter().map(|&tri| SceneTri {
                tri,
                material: obj.material,
                object: i as u32,
            }));
        }
        let names: Vec<String> = desc.objects.iter().map(|o| o.name.clone()).collect();
        let geometry = Geometry::build(&tris, &names)?;
        let materials: Vec<RenderMaterial> =
            desc.materials.iter().map(RenderMaterial::new).collect();
        let lights = Lights::new(&geometry, &materials);
        Ok(Self {
            geometry,
            materials,
            lights,
            environment: Vec3::from(desc.environment),
        })
    }
}

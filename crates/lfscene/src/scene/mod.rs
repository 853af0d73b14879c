//! The scene description: everything needed to render a scene again (`scene.json`).
//!
//! A scene is data, not code: shapes with parameters, transforms, materials and lights, plus the
//! camera. [`shapes`] turns it into world-space triangles; the renderer never sees this module's
//! serialisation, and the writers never see the triangles.
//!
//! Imported scenes ([`gltf`]) refer to meshes and images of their source file instead of
//! holding them; [`assets::Assets`] loads what a description refers to.

pub mod assets;
pub mod files;
pub mod gltf;
pub mod labels;
pub mod light;
pub mod material;
pub mod memory;
pub mod obj;
pub mod shapes;
pub mod texture_image;
mod validate;

use crate::camera::LightFieldCamera;
use glam::{Quat, Vec3};
pub use light::Light;
pub use material::{Material, Opacity, SurfaceModel, Texture};
use serde::{Deserialize, Serialize};

/// A complete, re-renderable scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// `lfgen <version>` that produced it.
    pub generator: String,
    pub name: String,
    /// Scene index within the dataset and the dataset seed (RNG streams derive from both).
    pub index: u64,
    pub seed: u64,
    pub camera: LightFieldCamera,
    /// The slice partition of the ground truth; fixed per scene so every view uses the same one.
    pub slices: SliceRange,
    /// Radiance of rays leaving the scene (linear RGB).
    pub environment: [f32; 3],
    /// Linear scale applied before sRGB encoding (chosen from the centre view when automatic).
    pub exposure: f32,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
    /// Punctual lights (imported scenes); emissive materials are the area lights.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lights: Vec<Light>,
    /// How the built-in generator's placement went (absent for imported scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<PlacementReport>,
    /// Files that [`Shape::Mesh`] and image textures refer to (imported scenes).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<SourceFile>,
}

/// A file the scene's meshes and images are read from, with checksums so that a re-render
/// notices when it changed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceFile {
    /// Absolute path of the glTF, GLB or OBJ file.
    pub path: String,
    /// SHA-256 of that file (lowercase hex).
    pub sha256: String,
    /// External files it references that were read (buffers, images, material libraries), by
    /// their URI (glTF: relative to the file's folder; OBJ: relative to `root`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub resources: Vec<Resource>,
    /// OBJ files: the folder their material libraries and textures may be read from (the
    /// asset catalogue's folder).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub root: Option<String>,
}

/// An external file referenced by a glTF, by its URI relative to the glTF's folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Resource {
    pub uri: String,
    pub sha256: String,
}

/// How the depth range is cut into slices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SliceSpacing {
    /// Equal depth (the thesis' choice).
    Depth,
    /// Equal disparity (equal 1/Z).
    Disparity,
}

/// Largest camera grid side (HCI uses 9; 33 × 33 views is already 1 089 renders).
pub const MAX_GRID: u32 = 33;
/// Largest slice count (every pixel of a thread keeps a few values per slice).
pub const MAX_SLICES: u32 = 4096;
/// Most triangles a scene may have after instancing (a bound on memory: ~0.4 KB each with
/// the BVH).
pub const MAX_TRIANGLES: usize = 20_000_000;

/// Counts of the placement, recorded in `scene.json` and `stats.json`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlacementReport {
    /// Pieces drawn from the library.
    pub requested: u32,
    pub placed: u32,
    /// Pieces for which no free, in-room, in-view spot was found.
    pub rejected: u32,
    /// Of the placed, how many stand on another piece.
    pub on_top: u32,
    /// Of the placed, how many come from the asset catalogue (`scene.catalog`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub from_catalog: u32,
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

/// What a new scene description starts with, from the caller's settings: the camera rig (the
/// scene's builder aims it), the dataset seed, the slice count and spacing (their range is
/// provisional until the renderer frames the scene) and the exposure.
#[derive(Clone, Debug)]
pub struct SceneStart {
    pub rig: LightFieldCamera,
    pub seed: u64,
    pub slices: SliceRange,
    pub exposure: f32,
}

/// The depth range `[z_near, z_far]` cut into `count` slices.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SliceRange {
    pub z_near: f64,
    pub z_far: f64,
    pub count: u32,
    pub spacing: SliceSpacing,
}

impl SliceRange {
    /// The partition a new scene carries until the renderer frames it (measures its depth
    /// range); only the count and spacing are known before.
    pub fn unframed(count: u32, spacing: SliceSpacing) -> Self {
        Self {
            z_near: 0.1,
            z_far: 100.0,
            count,
            spacing,
        }
    }

    /// The boundaries `z_0 < … < z_S` of the slices in planar depth, as [`Self::index`] cuts
    /// them (equal steps in depth or in 1/depth); the POV-Ray slice export clips by them.
    pub fn boundaries(&self) -> Vec<f64> {
        let n = self.count as f64;
        (0..=self.count)
            .map(|k| {
                let s = k as f64 / n;
                match self.spacing {
                    SliceSpacing::Depth => self.z_near + s * (self.z_far - self.z_near),
                    SliceSpacing::Disparity => {
                        1.0 / (1.0 / self.z_near + s * (1.0 / self.z_far - 1.0 / self.z_near))
                    }
                }
            })
            .collect()
    }

    /// Slice of planar depth `z`; depths outside the range go to the first / last slice.
    #[inline]
    pub fn index(&self, z: f32) -> usize {
        let (a, b, v) = match self.spacing {
            SliceSpacing::Depth => (self.z_near, self.z_far, z as f64),
            SliceSpacing::Disparity => (1.0 / self.z_near, 1.0 / self.z_far, 1.0 / z as f64),
        };
        let k = ((v - a) / (b - a) * self.count as f64).floor();
        k.clamp(0.0, (self.count - 1) as f64) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every slab `[z_k, z_{k+1})` is the set of depths `index` puts in slice k.
    #[test]
    fn slice_boundaries_cut_where_the_slice_index_changes() {
        for spacing in [SliceSpacing::Depth, SliceSpacing::Disparity] {
            let r = SliceRange {
                z_near: 1.3,
                z_far: 9.7,
                count: 128,
                spacing,
            };
            let z = r.boundaries();
            assert_eq!(z.len(), 129);
            assert!((z[0] - 1.3).abs() < 1e-12 && (z[128] - 9.7).abs() < 1e-9);
            for k in 0..128 {
                let (a, b) = (z[k], z[k + 1]);
                assert!(a < b);
                for t in [1e-5, 0.5, 1.0 - 1e-5] {
                    let inside = (a + t * (b - a)) as f32;
                    assert_eq!(r.index(inside), k, "{spacing:?} slice {k}");
                }
            }
        }
    }

    #[test]
    fn slice_index_in_depth_and_disparity_spacing() {
        let depth = SliceRange {
            z_near: 1.0,
            z_far: 5.0,
            count: 4,
            spacing: SliceSpacing::Depth,
        };
        assert_eq!(
            [0.5, 1.5, 2.5, 4.99, 9.0].map(|z| depth.index(z)),
            [0, 0, 1, 3, 3]
        );
        // Equal 1/Z: boundaries at 1/Z = 1, 0.8, 0.6, 0.4, 0.2 → Z = 1, 1.25, 1.667, 2.5, 5.
        let disp = SliceRange {
            spacing: SliceSpacing::Disparity,
            ..depth
        };
        assert_eq!(
            [1.1, 1.3, 2.0, 3.0, 4.9].map(|z| disp.index(z)),
            [0, 1, 2, 3, 3]
        );
    }
}

/// One placed shape.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Object {
    pub name: String,
    pub shape: Shape,
    pub transform: Transform,
    /// Index into [`SceneDesc::materials`].
    pub material: u32,
}

/// Parametric shapes, in local coordinates (metres).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Shape {
    /// Axis-aligned box centred at the origin, outward normals.
    Cuboid { size: Vec3 },
    /// Inward-facing box from `(-w/2, 0, -d/2)` to `(w/2, h, d/2)`: floor, walls, ceiling.
    Room { size: Vec3 },
    /// Rectangle in the local XY plane centred at the origin, normal +Z.
    Quad { size: [f32; 2] },
    /// A [`Shape::Quad`] with rectangular holes (window and door openings), each
    /// `[x0, y0, x1, y1]` in the quad's frame (origin at its centre); holes may not overlap
    /// along X. UVs are those of the whole quad, so a texture runs on across the openings.
    Wall {
        size: [f32; 2],
        holes: Vec<[f32; 4]>,
    },
    /// UV sphere centred at the origin.
    Sphere {
        radius: f32,
        rings: u32,
        segments: u32,
    },
    /// Closed cylinder standing on the origin along +Y.
    Cylinder {
        radius: f32,
        height: f32,
        segments: u32,
    },
    /// Surface of revolution about +Y: the polyline `profile` of `[radius, height]` points
    /// (bottom to top) swept around the axis in `segments` steps. Vases, bottles, glasses,
    /// lamp shades and pots; a point with radius 0 closes the surface there. Normals face away
    /// from the axis when the profile runs upwards.
    Lathe {
        profile: Vec<[f32; 2]>,
        segments: u32,
    },
    /// Triangles of primitive `primitive` of mesh `mesh` in [`SceneDesc::sources`]`[source]`
    /// (a glTF), placed by `matrix` — the instancing node's world transform, column-major as
    /// in glTF (it may shear, which a [`Transform`] cannot) — before the object's transform.
    /// UVs are the primitive's `TEXCOORD_<uv_set>`.
    Mesh {
        source: u32,
        mesh: u32,
        primitive: u32,
        uv_set: u32,
        matrix: [f32; 16],
    },
}

/// Scale, then rotate, then translate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
}

impl Transform {
    pub fn at(translation: Vec3) -> Self {
        Self {
            translation,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
        }
    }

    pub fn rotated_y(mut self, angle: f32) -> Self {
        self.rotation = Quat::from_rotation_y(angle) * self.rotation;
        self
    }

    pub fn matrix(&self) -> glam::Mat4 {
        glam::Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

//! Building small analytic scenes directly with the library, and rendering their views.
//!
//! Every object gets its own material (object `i` uses material `i`), which is all the
//! analytic tests need and keeps scene construction to one list of parts.
#![allow(dead_code)]

use glam::{DVec3, Vec3};
use lfgen::camera::LightFieldCamera;
use lfgen::config::SliceSpacing;
use lfgen::render::RenderScene;
use lfgen::render::cache::{CacheParams, RadianceCache};
use lfgen::render::integrator::{PathSettings, Shading};
use lfgen::render::slices::SliceAssignment;
use lfgen::render::view::{Adaptive, RenderSettings, ViewOutput};
use lfgen::scene::{
    Material, Object, Opacity, SceneDesc, Shape, SliceRange, SurfaceModel, Texture, Transform,
};
use std::sync::atomic::AtomicU64;

/// Slices of the ground truth (the product's default).
pub const SLICES: u32 = 128;

/// A camera grid looking down −Z with +Y up, on a 35 mm sensor.
pub fn camera(
    resolution: [u32; 2],
    grid: [u32; 2],
    focal_length_mm: f64,
    position: DVec3,
) -> LightFieldCamera {
    LightFieldCamera {
        resolution,
        grid,
        focal_length_mm,
        sensor_size_mm: 35.0,
        baseline_m: 0.05,
        focus_distance_m: 3.0,
        position,
        forward: DVec3::NEG_Z,
        up: DVec3::Y,
    }
}

/// The default cache parameters (`render.cache_cell`, `render.glossy_share`,
/// `render.fill_vertices`).
pub const CACHE: CacheParams = CacheParams {
    cell_px: 1.0,
    glossy_share: 4.0,
    glossy_min_width: 0.1,
    fill_vertices: 5,
    fill_light_samples: 1,
    shrink: false,
    final_gather: false,
};

/// Focal length in pixels, from docs/reference/format.md, Camera (not from the code under test).
pub fn f_px(cam: &LightFieldCamera) -> f64 {
    let max_side = cam.resolution[0].max(cam.resolution[1]) as f64;
    cam.focal_length_mm * max_side / cam.sensor_size_mm
}

/// Disparity of planar depth `z`, from docs/reference/format.md, Camera.
pub fn disparity(cam: &LightFieldCamera, z: f64) -> f64 {
    f_px(cam) * cam.baseline_m * (1.0 / z - 1.0 / cam.focus_distance_m)
}

/// A matte Standard material with constant opacity.
pub fn matte(color: [f32; 3], opacity: f32) -> Material {
    Material {
        name: "matte".into(),
        model: SurfaceModel::Standard,
        base_color: Texture::constant(color),
        roughness: 0.8,
        metallic: 0.0,
        opacity: Opacity::constant(opacity),
        emission: [0.0; 3],
        emission_map: None,
    }
}

/// An opaque emitter (area light).
pub fn emitter(emission: [f32; 3]) -> Material {
    Material {
        name: "light".into(),
        emission,
        ..matte([0.8; 3], 1.0)
    }
}

/// A shape, where it is, and what it is made of.
pub struct Part {
    pub shape: Shape,
    pub transform: Transform,
    pub material: Material,
}

/// A `w × h` rectangle facing +Z (towards the camera), centred at `centre`.
pub fn quad(size: [f32; 2], centre: Vec3, material: Material) -> Part {
    Part {
        shape: Shape::Quad { size },
        transform: Transform::at(centre),
        material,
    }
}

/// An axis-aligned box centred at `centre`.
pub fn cuboid(size: Vec3, centre: Vec3, material: Material) -> Part {
    Part {
        shape: Shape::Cuboid { size },
        transform: Transform::at(centre),
        material,
    }
}

/// A scene from its camera, the GT depth range, the environment radiance and its parts.
pub fn scene(
    camera: LightFieldCamera,
    [z_near, z_far]: [f64; 2],
    environment: [f32; 3],
    parts: Vec<Part>,
) -> SceneDesc {
    let slices = SliceRange {
        z_near,
        z_far,
        count: SLICES,
        spacing: SliceSpacing::Depth,
    };
    let (mut materials, mut objects) = (Vec::new(), Vec::new());
    for (i, p) in parts.into_iter().enumerate() {
        materials.push(p.material);
        let name = format!("part{i}");
        objects.push(Object {
            name,
            shape: p.shape,
            transform: p.transform,
            material: i as u32,
        });
    }
    SceneDesc {
        generator: "analytic tests".into(),
        name: "analytic".into(),
        index: 0,
        seed: 7,
        camera,
        slices,
        environment,
        exposure: 1.0,
        materials,
        objects,
        lights: Vec::new(),
        placement: None,
        sources: Vec::new(),
    }
}

/// Render settings; Russian roulette is pushed past `max_depth` so path weights stay exact.
pub fn settings(spp: u32, max_depth: u32) -> RenderSettings {
    RenderSettings {
        path: PathSettings {
            max_depth,
            rr_depth: max_depth + 1,
            footprint: 0.0,
            glass_light: lfgen::render::integrator::GlassLight::Caustics,
            split_glass: true,
        },
        spp,
        gt_spp: spp,
        seed: 11,
        scene_index: 0,
        mode_epsilon: 1e-4,
        shade_all_hits: false,
        slice_assignment: SliceAssignment::Surface,
        adaptive: Adaptive::default(),
    }
}

/// A scene description together with its built BVH, so several views share one build.
pub struct Harness {
    pub desc: SceneDesc,
    scene: RenderScene,
}

impl Harness {
    pub fn new(desc: SceneDesc) -> Self {
        let scene = RenderScene::build(&desc).expect("the analytic scene builds");
        Self { desc, scene }
    }

    pub fn render(&self, view: u32, settings: &RenderSettings, with_gt: bool) -> ViewOutput {
        let (cam, slices) = (&self.desc.camera, &self.desc.slices);
        self.scene
            .render_view(cam, slices, settings, view, with_gt, &AtomicU64::new(0))
    }

    /// The shared-shading cache from `spp` fill samples per pixel of every view, with the
    /// default cells and sharing ([`CACHE`]).
    pub fn cache(&self, settings: &RenderSettings, spp: u32) -> RadianceCache {
        self.cache_with(settings, spp, CACHE)
    }

    /// A shared-shading cache with its own cache parameters.
    pub fn cache_with(
        &self,
        settings: &RenderSettings,
        spp: u32,
        params: CacheParams,
    ) -> RadianceCache {
        let cam = &self.desc.camera;
        (self.scene).fill_cache(cam, settings, spp, params, &AtomicU64::new(0))
    }

    /// A view with shared shading from `cache`.
    pub fn render_shared(
        &self,
        view: u32,
        settings: &RenderSettings,
        cache: &RadianceCache,
        with_gt: bool,
    ) -> ViewOutput {
        let (cam, slices) = (&self.desc.camera, &self.desc.slices);
        let shading = Shading::read(cache);
        let done = AtomicU64::new(0);
        (self.scene).render_view_with(cam, slices, settings, view, with_gt, shading, &done)
    }
}

//! What a scene description must satisfy before anything is built from it.
//!
//! A `scene.json` may be hand-edited or hostile; the renderer assumes sane values (an odd view
//! grid, a positive focal length, a bounded slice count and tessellation). Each check names the
//! field and the value, so the error points at the line to fix, and the bounds keep a bad
//! number from allocating gigabytes or looping for hours.

use super::memory;
use super::{MAX_GRID, MAX_SLICES};
use super::{Material, Object, Opacity, SceneDesc, Shape, SliceRange, SurfaceModel, Texture};
use crate::camera::LightFieldCamera;
use anyhow::{Context, Result, bail, ensure};
use std::path::Path;

/// Longest scene name, in bytes (a file name's limit on common filesystems).
const MAX_NAME_BYTES: usize = 255;
/// Largest image side (as `camera.resolution` of the config).
const MAX_RESOLUTION: u32 = 16384;
/// Finest tessellation of a parametric shape along one direction.
const MAX_SEGMENTS: u32 = 65536;
/// Largest coordinate, size or scale (metres): a room is metres, a building 1e2; past ~1e25
/// the BVH's quantised nodes overflow (an obvhs panic), long before which f32 precision is
/// gone at the scale of a pixel.
const MAX_EXTENT: f32 = 1e6;

/// `bytes` as a scene description; a value of the wrong type names its field
/// (`camera.resolution[0]: invalid value: integer `-32`, expected u32`), not only its line and
/// column.
fn parse(bytes: &[u8]) -> Result<SceneDesc> {
    let mut json = serde_json::Deserializer::from_slice(bytes);
    let desc =
        serde_path_to_error::deserialize(&mut json).map_err(|e| match e.path().iter().next() {
            Some(_) => anyhow::anyhow!("{}: {}", e.path(), e.inner()),
            None => anyhow::anyhow!("{}", e.inner()),
        })?;
    json.end()?;
    Ok(desc)
}

impl SceneDesc {
    /// Reads a saved `scene.json` and validates it, naming the file in errors: the scene
    /// layer owns both the type and its checks, so no reader can skip them.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = super::files::read_limited(path)?;
        let desc = parse(&bytes)
            .with_context(|| format!("{}: not a valid lfgen scene", path.display()))?;
        desc.validate()
            .with_context(|| format!("{}: not a valid lfgen scene", path.display()))?;
        Ok(desc)
    }

    /// Checks every field the renderer relies on, the error naming the field, and that what
    /// the description sizes itself (views, parametric shapes) fits the memory limit.
    pub fn validate(&self) -> Result<()> {
        check_name(&self.name)?;
        check_camera(&self.camera)?;
        check_slices(&self.slices)?;
        ensure!(
            rgb(&self.environment),
            "environment {:?} must be finite and non-negative",
            self.environment
        );
        ensure!(
            self.exposure.is_finite() && self.exposure > 0.0,
            "exposure {} must be positive",
            self.exposure
        );
        for (i, m) in self.materials.iter().enumerate() {
            check_material(m).map_err(|e| e.context(format!("materials[{i}] ({:?})", m.name)))?;
        }
        for (i, o) in self.objects.iter().enumerate() {
            check_object(o, self.materials.len(), self.sources.len())
                .map_err(|e| e.context(format!("objects[{i}] ({:?})", o.name)))?;
        }
        for (i, l) in self.lights.iter().enumerate() {
            ensure!(
                l.is_valid(),
                "lights[{i}]: numbers must be finite, colours non-negative, directions unit"
            );
        }
        memory::scene_budget(self).map(drop)
    }
}

/// The name goes into `parameters.cfg` and file listings: one short line.
fn check_name(name: &str) -> Result<()> {
    ensure!(
        !name.is_empty() && name.len() <= MAX_NAME_BYTES,
        "name must be 1 to {MAX_NAME_BYTES} bytes, not {}",
        name.len()
    );
    ensure!(
        !name
            .chars()
            .any(|c| c.is_control() || c == '/' || c == '\\'),
        "name {name:?} must not hold control characters or path separators"
    );
    Ok(())
}

fn check_camera(c: &LightFieldCamera) -> Result<()> {
    if c.grid.iter().any(|&n| n == 0 || n % 2 == 0 || n > MAX_GRID) {
        bail!(
            "camera.grid {:?} must be odd counts of at most {MAX_GRID}",
            c.grid
        );
    }
    if c.resolution.iter().any(|&n| n == 0 || n > MAX_RESOLUTION) {
        bail!(
            "camera.resolution {:?} must be 1 to {MAX_RESOLUTION} pixels a side",
            c.resolution
        );
    }
    let positive = [
        ("focal_length_mm", c.focal_length_mm),
        ("sensor_size_mm", c.sensor_size_mm),
        ("focus_distance_m", c.focus_distance_m),
    ];
    for (name, v) in positive {
        ensure!(
            v.is_finite() && v > 0.0,
            "camera.{name} {v} must be positive"
        );
    }
    ensure!(
        c.baseline_m.is_finite() && c.baseline_m >= 0.0,
        "camera.baseline_m {} must be finite and non-negative",
        c.baseline_m
    );
    ensure!(
        c.position.is_finite() && c.position.abs().max_element() <= MAX_EXTENT as f64,
        "camera.position {} must be within {MAX_EXTENT} m",
        c.position
    );
    let unit = |v: glam::DVec3| v.is_finite() && (v.length() - 1.0).abs() < 1e-6;
    ensure!(
        unit(c.forward) && unit(c.up),
        "camera.forward {} and camera.up {} must be unit vectors",
        c.forward,
        c.up
    );
    ensure!(
        c.forward.dot(c.up).abs() < 1e-6,
        "camera.up {} must be orthogonal to camera.forward {}",
        c.up,
        c.forward
    );
    Ok(())
}

fn check_slices(s: &SliceRange) -> Result<()> {
    ensure!(
        (1..=MAX_SLICES).contains(&s.count),
        "slices.count {} must be 1 to {MAX_SLICES}",
        s.count
    );
    ensure!(
        s.z_near.is_finite() && s.z_far.is_finite() && 0.0 < s.z_near && s.z_near < s.z_far,
        "slices: need 0 < z_near < z_far, got {} and {}",
        s.z_near,
        s.z_far
    );
    Ok(())
}

/// Checks one material's values (also of a model's materials when its file is opened).
pub(super) fn check_material(m: &Material) -> Result<()> {
    ensure!(
        unit_interval(m.roughness) && unit_interval(m.metallic),
        "roughness {} and metallic {} must be in [0, 1]",
        m.roughness,
        m.metallic
    );
    ensure!(
        rgb(&m.emission),
        "emission {:?} must be finite and non-negative",
        m.emission
    );
    if let SurfaceModel::Glass { ior } = m.model {
        ensure!(
            ior.is_finite() && (1.0..=4.0).contains(&ior),
            "glass ior {ior} must be in [1, 4]"
        );
    }
    let opacity_ok = match &m.opacity {
        Opacity::Constant { value } => unit_interval(*value),
        Opacity::Grid { value, period, bar } => {
            unit_interval(*value) && positive(*period) && unit_interval(*bar)
        }
        Opacity::Leaves { period } => period.iter().all(|&p| positive(p)),
        Opacity::Image { factor, cutoff, .. } => {
            unit_interval(*factor) && cutoff.is_none_or(unit_interval)
        }
    };
    ensure!(
        opacity_ok,
        "opacity {:?}: values must be in [0, 1] and periods positive",
        m.opacity
    );
    ensure!(
        m.base_color.is_valid(),
        "base_color {:?}: colours must be finite and non-negative, sizes positive",
        m.base_color
    );
    ensure!(
        m.emission_map.as_ref().is_none_or(Texture::is_valid),
        "emission_map {:?}: colours must be finite and non-negative, sizes positive",
        m.emission_map
    );
    Ok(())
}

/// Checks one object (its triangles are counted by [`memory::scene_budget`]).
fn check_object(o: &Object, materials: usize, sources: usize) -> Result<()> {
    ensure!(
        (o.material as usize) < materials,
        "material {} does not exist ({materials} materials)",
        o.material
    );
    let t = &o.transform;
    ensure!(
        t.translation.is_finite() && t.rotation.is_finite() && t.scale.is_finite(),
        "transform is not finite"
    );
    ensure!(
        t.rotation.is_normalized(),
        "transform.rotation {} is not a unit quaternion",
        t.rotation
    );
    let max_scale = t
        .scale
        .abs()
        .max_element()
        .max(t.translation.abs().max_element());
    ensure!(
        max_scale <= MAX_EXTENT,
        "transform places the object {max_scale} m away or scales it by that: at most \
         {MAX_EXTENT}"
    );
    let segments = |n: u32| {
        ensure!(
            n <= MAX_SEGMENTS,
            "segments/rings {n} is more than {MAX_SEGMENTS}"
        );
        Ok(())
    };
    let size = |v: &[f32]| v.iter().all(|&x| (0.0..=MAX_EXTENT).contains(&x));
    match &o.shape {
        Shape::Cuboid { size: s } | Shape::Room { size: s } => {
            ensure!(size(&s.to_array()), "size {s} must be 0 to {MAX_EXTENT}");
        }
        Shape::Quad { size: s } => {
            ensure!(size(s), "size {s:?} must be 0 to {MAX_EXTENT}");
        }
        Shape::Wall { size: s, holes } => {
            ensure!(size(s), "size {s:?} must be 0 to {MAX_EXTENT}");
            ensure!(
                within(holes.iter().flatten()) && holes.len() <= 1024,
                "holes must be within {MAX_EXTENT} and at most 1024"
            );
        }
        Shape::Sphere {
            radius,
            rings,
            segments: n,
        } => {
            ensure!(
                size(&[*radius]),
                "radius {radius} must be 0 to {MAX_EXTENT}"
            );
            segments(*rings)?;
            segments(*n)?;
        }
        Shape::Cylinder {
            radius,
            height,
            segments: n,
        } => {
            ensure!(
                size(&[*radius, *height]),
                "radius {radius} and height {height} must be 0 to {MAX_EXTENT}"
            );
            segments(*n)?;
        }
        Shape::Lathe {
            profile,
            segments: n,
        } => {
            ensure!(
                within(profile.iter().flatten()) && profile.len() <= 65536,
                "profile must be within {MAX_EXTENT} and at most 65536 points"
            );
            segments(*n)?;
        }
        Shape::Mesh { source, matrix, .. } => {
            ensure!(
                (*source as usize) < sources,
                "source {source} does not exist ({sources} sources)"
            );
            ensure!(within(matrix), "matrix entries must be within {MAX_EXTENT}");
        }
    }
    Ok(())
}

/// Whether every value is within ±[`MAX_EXTENT`] (NaN is not).
fn within<'a>(values: impl IntoIterator<Item = &'a f32>) -> bool {
    values.into_iter().all(|x| x.abs() <= MAX_EXTENT)
}

fn rgb(c: &[f32; 3]) -> bool {
    c.iter().all(|v| v.is_finite() && *v >= 0.0)
}

fn unit_interval(v: f32) -> bool {
    (0.0..=1.0).contains(&v)
}

fn positive(v: f32) -> bool {
    v.is_finite() && v > 0.0
}

//! What every exporter needs, computed once: world-space triangles per object (from the same
//! tessellation the renderer uses) and every light-field view as an explicit off-axis pinhole.
//!
//! Each target renderer only converts these to its own conventions; none of them looks at
//! [`LightFieldCamera`] or re-implements tessellation.

use crate::camera::LightFieldCamera;
use crate::scene::assets::Assets;
use crate::scene::shapes::MeshTri;
use crate::scene::{Material, Opacity, SceneDesc, SurfaceModel, Texture};
use anyhow::{Context, Result};
use glam::{DVec3, Vec3};

/// One object's triangles in world space (our right-handed, +Y-up world).
pub struct ExportMesh {
    /// Index of the object in the scene description.
    pub object: usize,
    /// A file-name-safe identifier, unique in the scene: `o{index}_{name}`.
    pub id: String,
    pub material: u32,
    pub tris: Vec<MeshTri>,
}

/// One view of the grid as an off-axis pinhole camera (world space, metres).
#[derive(Clone, Debug, PartialEq)]
pub struct ExportCamera {
    /// HCI file index (`Cam{view:03}`).
    pub view: u32,
    pub origin: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub forward: DVec3,
    pub width: u32,
    pub height: u32,
    pub f_px: f64,
    /// Principal point minus image centre, in pixels (x right, y down): the sensor shift that
    /// keeps the focus plane in register, `f_px·(u−uc)·b/Z_f` and `f_px·(v−vc)·b/Z_f`.
    pub principal_offset_px: [f64; 2],
}

impl ExportCamera {
    /// The off-axis camera of `view`; `cam.view_rays` is the source of truth and a unit test
    /// checks that both project every point to the same pixel.
    pub fn of(cam: &LightFieldCamera, view: u32) -> Self {
        let (du, dv) = cam.view_offset(view);
        let f_px = cam.f_px();
        let shift = f_px * cam.baseline_m / cam.focus_distance_m;
        Self {
            view,
            origin: cam.view_origin(view),
            right: cam.right(),
            up: cam.up,
            forward: cam.forward,
            width: cam.width(),
            height: cam.height(),
            f_px,
            principal_offset_px: [du as f64 * shift, dv as f64 * shift],
        }
    }

    /// `CamNNN`, as the HCI file names.
    pub fn name(&self) -> String {
        format!("Cam{:03}", self.view)
    }

    /// Image position `(x, y)` of world point `p` and its planar depth.
    pub fn project(&self, p: DVec3) -> (f64, f64, f64) {
        let rel = p - self.origin;
        let z = rel.dot(self.forward);
        let x = self.width as f64 / 2.0
            + self.principal_offset_px[0]
            + self.f_px * rel.dot(self.right) / z;
        let y = self.height as f64 / 2.0 + self.principal_offset_px[1]
            - self.f_px * rel.dot(self.up) / z;
        (x, y, z)
    }

    /// Horizontal field of view (radians) of the unshifted frustum.
    pub fn fov_x(&self) -> f64 {
        2.0 * (self.width as f64 / 2.0 / self.f_px).atan()
    }
}

/// Which views to export.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ViewSelection {
    All,
    Center,
    List(Vec<u32>),
}

impl ViewSelection {
    /// Parses `all`, `center` or a comma-separated list of view indices (`0,40,80`).
    pub fn parse(s: &str) -> Result<Self> {
        match s.trim() {
            "all" => Ok(Self::All),
            "center" | "centre" => Ok(Self::Center),
            list => list
                .split(',')
                .map(|v| {
                    let v = v.trim();
                    v.strip_prefix("Cam")
                        .unwrap_or(v)
                        .parse()
                        .with_context(|| format!("--views {s:?}: {v:?} is not a view index"))
                })
                .collect::<Result<_>>()
                .map(Self::List),
        }
    }

    /// The selected view indices of `cam`, checked against its grid.
    pub fn resolve(&self, cam: &LightFieldCamera) -> Result<Vec<u32>> {
        let views = match self {
            Self::All => (0..cam.num_views()).collect(),
            Self::Center => vec![cam.center_view()],
            Self::List(v) => v.clone(),
        };
        if let Some(bad) = views.iter().find(|&&v| v >= cam.num_views()) {
            anyhow::bail!(
                "view {bad} does not exist: the grid has {} views",
                cam.num_views()
            );
        }
        Ok(views)
    }
}

/// A scene ready to be written for another renderer.
pub struct ExportScene<'a> {
    pub desc: &'a SceneDesc,
    pub meshes: Vec<ExportMesh>,
    pub cameras: Vec<ExportCamera>,
}

impl<'a> ExportScene<'a> {
    /// Tessellates every object of `desc` and sets up the selected views.
    pub fn new(desc: &'a SceneDesc, assets: &Assets, views: &[u32]) -> Result<Self> {
        let mut meshes = Vec::with_capacity(desc.objects.len());
        desc.for_each_mesh(assets, |i, obj, tris| {
            meshes.push(ExportMesh {
                object: i,
                id: format!("o{i}_{}", sanitize(&obj.name)),
                material: obj.material,
                tris: tris.to_vec(),
            });
            Ok(())
        })?;
        let cameras = views
            .iter()
            .map(|&v| ExportCamera::of(&desc.camera, v))
            .collect();
        Ok(Self {
            desc,
            meshes,
            cameras,
        })
    }

    pub fn material(&self, mesh: &ExportMesh) -> &Material {
        &self.desc.materials[mesh.material as usize]
    }

    /// Farthest planar depth of any vertex from any exported camera: the scale of the
    /// depth encodings (slightly enlarged so depths stay below it).
    pub fn max_depth(&self) -> f64 {
        let mut far = 0.0f64;
        for c in &self.cameras {
            for t in self.meshes.iter().flat_map(|m| &m.tris) {
                for p in t.p {
                    far = far.max((p.as_dvec3() - c.origin).dot(c.forward));
                }
            }
        }
        (far * 1.01).max(1e-3)
    }
}

/// Whether a material hides what is behind it in the HCI depth (coverage ≥ 0.5 on the
/// pixel-centre ray, see `render::view`): opaque enough and not glass (whose coverage is its
/// Fresnel reflectance, below 0.5 except at grazing angles).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthVisibility {
    Solid,
    Invisible,
    /// Opacity varies over the surface (a cut-out pattern or an image's alpha).
    Partial,
}

impl DepthVisibility {
    pub fn of(m: &Material) -> Self {
        if matches!(m.model, SurfaceModel::Glass { .. }) {
            return Self::Invisible;
        }
        match m.opacity.uniform() {
            Some(a) if a >= 0.5 => Self::Solid,
            Some(_) => Self::Invisible,
            None => Self::Partial,
        }
    }
}

/// Points per side of the 1 m × 1 m UV patch that [`mean_color`] and [`mean_opacity`] average
/// (every lfgen pattern repeats within a metre or is noise of a smaller feature size).
const MEAN_GRID: u32 = 64;

fn uv_mean<T: std::ops::Add<Output = T> + std::ops::Div<f32, Output = T>>(
    zero: T,
    f: impl Fn(glam::Vec2) -> T,
) -> T {
    let n = MEAN_GRID as f32;
    let mut sum = zero;
    for j in 0..MEAN_GRID {
        for i in 0..MEAN_GRID {
            sum = sum + f(glam::Vec2::new((i as f32 + 0.5) / n, (j as f32 + 0.5) / n));
        }
    }
    sum / (n * n)
}

/// Mean linear base colour of a texture: what a renderer gets where lfgen's procedural
/// patterns are not exported (images: their factor).
pub fn mean_color(t: &Texture) -> Vec3 {
    uv_mean(Vec3::ZERO, |uv| t.eval(uv))
}

/// Mean emitted radiance of a material: what the references get, which have no emission
/// textures here.
pub fn mean_emission(m: &Material) -> Vec3 {
    let map = m.emission_map.as_ref().map_or(Vec3::ONE, mean_color);
    Vec3::from(m.emission) * map
}

/// Mean opacity of a material's surface, for renderers that get a uniform opacity instead of
/// a cut-out pattern.
pub fn mean_opacity(o: &Opacity) -> f32 {
    uv_mean(0.0, |uv| o.eval(uv))
}

/// Letters, digits and `_` only.
fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> LightFieldCamera {
        LightFieldCamera {
            resolution: [64, 48],
            grid: [9, 7],
            focal_length_mm: 80.0,
            sensor_size_mm: 35.0,
            baseline_m: 0.04,
            focus_distance_m: 2.5,
            position: DVec3::new(0.3, 1.2, 0.5),
            forward: DVec3::new(0.1, -0.1, -1.0).normalize(),
            up: DVec3::new(0.0, 1.0, -0.1).normalize(),
        }
    }

    /// The exported pinhole and the renderer's ray generator agree: the ray through a point's
    /// projected position passes through the point, at its planar depth.
    #[test]
    fn export_camera_projects_as_view_rays_trace() {
        let mut cam = camera();
        cam.up = (cam.up - cam.forward * cam.up.dot(cam.forward)).normalize();
        let points = [
            DVec3::new(-0.4, 1.5, -4.0),
            DVec3::new(1.0, 0.2, -1.5),
            DVec3::new(0.3, 1.2, -9.0),
        ];
        for view in [0, 8, cam.center_view(), 54, 62] {
            let e = ExportCamera::of(&cam, view);
            let rays = cam.view_rays(view);
            for p in points {
                let (x, y, z) = e.project(p);
                let r = rays.ray(x as f32, y as f32);
                let hit = r.origin.as_dvec3() + r.dir.as_dvec3() * z;
                assert!((hit - p).length() < 1e-5 * z, "view {view}: {hit} vs {p}");
            }
        }
    }

    /// A point on the focus plane keeps its pixel in every view; others move by the view
    /// offset times their disparity (docs/reference/format.md, Camera).
    #[test]
    fn focus_plane_stays_in_register() {
        let mut cam = camera();
        cam.forward = DVec3::NEG_Z;
        cam.up = DVec3::Y;
        let centre = ExportCamera::of(&cam, cam.center_view());
        for z in [cam.focus_distance_m, 1.3] {
            let p = cam.position + DVec3::new(0.2, -0.1, -z);
            let (xc, yc, _) = centre.project(p);
            for view in [0, 8, 62] {
                let (du, dv) = cam.view_offset(view);
                let (x, y, _) = ExportCamera::of(&cam, view).project(p);
                let disp = cam.disparity(z);
                assert!(
                    (x - (xc - du as f64 * disp)).abs() < 1e-9,
                    "view {view} z {z}"
                );
                assert!(
                    (y - (yc - dv as f64 * disp)).abs() < 1e-9,
                    "view {view} z {z}"
                );
            }
        }
    }

    #[test]
    fn view_selection_parses_and_checks_the_grid() {
        let cam = camera();
        assert_eq!(
            ViewSelection::parse("all")
                .unwrap()
                .resolve(&cam)
                .unwrap()
                .len(),
            63
        );
        assert_eq!(
            ViewSelection::parse("center")
                .unwrap()
                .resolve(&cam)
                .unwrap(),
            vec![31]
        );
        assert_eq!(
            ViewSelection::parse("0, Cam008,62")
                .unwrap()
                .resolve(&cam)
                .unwrap(),
            vec![0, 8, 62]
        );
        assert!(ViewSelection::parse("0,x").is_err());
        let err = ViewSelection::parse("63")
            .unwrap()
            .resolve(&cam)
            .unwrap_err();
        assert!(err.to_string().contains("63 views"), "{err}");
    }
}

//! The node hierarchy of one glTF scene: world transforms, and the objects, lights and camera
//! the nodes place.

use super::Notes;
use super::material::default_material;
use super::settings::GltfSettings;
use super::source::GltfFile;
use crate::camera::LightFieldCamera;
use crate::scene::{Light, Material, Object, Shape, Transform};
use ::gltf::camera::Projection;
use ::gltf::khr_lights_punctual::Kind;
use anyhow::{Context, Result, bail, ensure};
use glam::{DVec3, Mat4, Vec3};

/// A node with its world transform.
pub(super) struct Placed<'a> {
    pub node: ::gltf::Node<'a>,
    pub world: Mat4,
}

impl Placed<'_> {
    fn label(&self) -> String {
        match self.node.name() {
            Some(name) => format!("node {} {name:?}", self.node.index()),
            None => format!("node {}", self.node.index()),
        }
    }
}

/// The scene `which` names: `"default"` (the file's `scene`, else its first), a name or an index.
pub(super) fn pick_scene<'a>(file: &'a GltfFile, which: &str) -> Result<::gltf::Scene<'a>> {
    let doc = &file.doc;
    let found = match which {
        "default" => doc.default_scene().or_else(|| doc.scenes().next()),
        _ => doc.scenes().find(|s| s.name() == Some(which)).or_else(|| {
            let index = which.parse::<usize>().ok()?;
            doc.scenes().nth(index)
        }),
    };
    found.with_context(|| {
        let names: Vec<String> = doc
            .scenes()
            .map(|s| format!("{} {:?}", s.index(), s.name().unwrap_or("")))
            .collect();
        match names.is_empty() {
            true => "the file has no scene".to_string(),
            false => format!(
                "no scene {which:?} (gltf.scene; scenes: {})",
                names.join(", ")
            ),
        }
    })
}

/// Every node of `scene`, parents before children, with its world transform. A node reached
/// twice (a cycle, or a child shared by two parents) is an error: glTF nodes form trees.
pub(super) fn flatten<'a>(
    file: &'a GltfFile,
    scene: &::gltf::Scene<'a>,
) -> Result<Vec<Placed<'a>>> {
    let mut seen = vec![false; file.doc.nodes().len()];
    let mut out = Vec::new();
    let mut stack: Vec<(::gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        ensure!(
            !std::mem::replace(&mut seen[node.index()], true),
            "node {} is reached twice from scene {} (the node hierarchy must be a tree)",
            node.index(),
            scene.index()
        );
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        let first_child = stack.len();
        stack.extend(node.children().map(|c| (c, world)));
        stack[first_child..].reverse();
        out.push(Placed { node, world });
    }
    Ok(out)
}

/// One object per mesh primitive of every placed node. Primitives without a material get
/// glTF's default material, appended to `materials` once.
pub(super) fn objects(
    placed: &[Placed],
    uv_sets: &[u32],
    materials: &mut Vec<Material>,
    notes: &mut Notes,
) -> Vec<Object> {
    let mut default = None;
    let mut objects = Vec::new();
    for p in placed {
        let Some(mesh) = p.node.mesh() else { continue };
        if p.node.skin().is_some() {
            notes.add("skins are ignored: skinned meshes are placed by their node, unposed");
        }
        let count = mesh.primitives().len();
        for prim in mesh.primitives() {
            if prim.morph_targets().len() > 0 {
                notes.add("morph targets are ignored: the base mesh is rendered");
            }
            let gltf_material = prim.material().index();
            let material = gltf_material.unwrap_or_else(|| {
                *default.get_or_insert_with(|| {
                    materials.push(default_material());
                    materials.len() - 1
                })
            });
            let name = match count {
                1 => p.label(),
                _ => format!("{} primitive {}", p.label(), prim.index()),
            };
            objects.push(Object {
                name,
                shape: Shape::Mesh {
                    source: 0,
                    mesh: mesh.index() as u32,
                    primitive: prim.index() as u32,
                    uv_set: gltf_material.map_or(0, |i| uv_sets[i]),
                    matrix: p.world.to_cols_array(),
                },
                transform: Transform::at(Vec3::ZERO),
                material: material as u32,
            });
        }
    }
    objects
}

/// The `KHR_lights_punctual` lights of the placed nodes: at the node's origin, shining along
/// its local −Z.
pub(super) fn lights(placed: &[Placed]) -> Result<Vec<Light>> {
    let mut lights = Vec::new();
    for p in placed {
        let Some(l) = p.node.light() else { continue };
        let position = p.world.w_axis.truncate();
        let direction = (-p.world.z_axis.truncate()).normalize_or_zero();
        let color = (Vec3::from(l.color()) * l.intensity()).to_array();
        let light = match l.kind() {
            Kind::Point => Light::Point {
                position,
                intensity: color,
                range: l.range(),
            },
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => Light::Spot {
                position,
                direction,
                intensity: color,
                inner_cone: inner_cone_angle,
                outer_cone: outer_cone_angle,
                range: l.range(),
            },
            Kind::Directional => Light::Directional {
                direction,
                irradiance: color,
            },
        };
        ensure!(
            light.is_valid(),
            "light {} on {}: non-finite or negative values, or a degenerate direction",
            l.index(),
            p.label()
        );
        lights.push(light);
    }
    Ok(lights)
}

/// The centre camera: the pose of `gltf.camera` ("first" perspective camera, a name, or
/// "config"), with the configured grid, resolution and sensor.
pub(super) fn camera(
    placed: &[Placed],
    g: &GltfSettings,
    rig: &LightFieldCamera,
    notes: &mut Notes,
) -> Result<LightFieldCamera> {
    if g.camera == "config" {
        let position = DVec3::from(g.camera_position);
        let forward = DVec3::from(g.camera_look_at) - position;
        let yfov = g.camera_yfov_deg.to_radians();
        return rig
            .looking(position, forward, DVec3::from(g.camera_up), yfov)
            .context("gltf.camera = \"config\"");
    }
    let cameras: Vec<(&Placed, ::gltf::Camera)> = placed
        .iter()
        .filter_map(|p| p.node.camera().map(|c| (p, c)))
        .collect();
    let is_perspective = |c: &::gltf::Camera| matches!(c.projection(), Projection::Perspective(_));
    let chosen = match g.camera.as_str() {
        "first" => cameras.iter().find(|(_, c)| is_perspective(c)),
        name => cameras
            .iter()
            .find(|(p, c)| p.node.name() == Some(name) || c.name() == Some(name)),
    };
    let Some((p, cam)) = chosen else {
        bail!(no_camera(&cameras, &g.camera));
    };
    let Projection::Perspective(persp) = cam.projection() else {
        bail!(
            "{} has an orthographic camera: a light field needs a perspective one",
            p.label()
        );
    };
    let [w, h] = rig.resolution;
    let aspect = w as f64 / h as f64;
    if let Some(a) = persp
        .aspect_ratio()
        .filter(|&a| (a as f64 - aspect).abs() > 0.01 * aspect)
    {
        notes.add(format!(
            "the camera's aspect ratio {a:.3} differs from camera.resolution {w}x{h} \
             ({aspect:.3}): its vertical field of view is kept"
        ));
    }
    let m = p.world.as_dmat4();
    let (position, forward, up) = (
        m.w_axis.truncate(),
        -m.z_axis.truncate(),
        m.y_axis.truncate(),
    );
    rig.looking(position, forward, up, persp.yfov() as f64)
        .with_context(|| format!("camera on {}", p.label()))
}

/// Why no camera was found, and what to do about it.
fn no_camera(cameras: &[(&Placed, ::gltf::Camera)], wanted: &str) -> String {
    if cameras.is_empty() {
        return "the scene has no camera: add one (Blender: export with Include → Cameras), \
                or set gltf.camera=config and gltf.camera_position, camera_look_at, camera_yfov_deg"
            .into();
    }
    let names: Vec<String> = cameras
        .iter()
        .map(|(p, c)| format!("{:?} on {}", c.name().unwrap_or(""), p.label()))
        .collect();
    match wanted {
        "first" => format!(
            "the scene has only orthographic cameras ({}): a light field needs a perspective one",
            names.join(", ")
        ),
        _ => format!("no camera named {wanted:?} (cameras: {})", names.join(", ")),
    }
}

//! Blender (Cycles) scene: `blender_scene.json` (cameras, materials, lights, objects),
//! `meshes/*.obj`, and `scene.py`, which builds the scene and renders one view:
//! `blender -b -P scene.py -- --view 40 --out cam040.exr [--depth] [--spp 64]`.
//!
//! Conventions: Blender's world is Z-up, lfgen's Y-up: `(x, y, z)` becomes `(x, −z, y)` (the
//! OBJ importer does this with `forward = −Z, up = Y`; the cameras are converted here). The
//! sensor shift is Blender's `shift_x/shift_y` in units of the larger sensor side
//! (`sensor_fit = 'AUTO'`, as HCI): `shift_x = −px / max(W, H)`, `shift_y = py / max(W, H)` with
//! `(px, py)` the principal-point offset in pixels (y down). Depth uses the Z pass (planar depth
//! of the pixel-centre sample at 1 spp).

use super::extract::{
    DepthVisibility, ExportCamera, ExportScene, mean_color, mean_emission, mean_opacity,
};
use super::obj;
use crate::scene::{Light, SurfaceModel};
use anyhow::Result;
use glam::DVec3;
use serde_json::{Value, json};
use std::path::Path;

/// The Blender script that reads `blender_scene.json`; fixed, so it lives as a Python file.
const SCENE_PY: &str = include_str!("blender_scene.py");

/// lfgen world → Blender world.
pub fn to_blender(v: DVec3) -> [f64; 3] {
    [v.x, -v.z, v.y]
}

/// Writes the Blender files of `scene` into `out`; `max_depth` is lfgen's path vertex limit.
pub fn write(scene: &ExportScene, out: &Path, max_depth: u32) -> Result<()> {
    super::write_meshes(scene, out)?;
    let cam = &scene.desc.camera;
    let data = json!({
        "generator": scene.desc.generator,
        "resolution": cam.resolution,
        "sensor_mm": cam.sensor_size_mm,
        "focal_mm": cam.focal_length_mm,
        // Cycles counts bounces after the first hit: lfgen's vertex limit minus one.
        "max_bounces": max_depth.saturating_sub(1),
        "environment": scene.desc.environment,
        "cameras": scene.cameras.iter().map(camera).collect::<Vec<_>>(),
        "materials": scene.desc.materials.iter().map(|m| json!({
            "name": m.name,
            "kind": match m.model {
                SurfaceModel::Glass { .. } => "glass",
                SurfaceModel::Standard => "standard",
                SurfaceModel::Diffuse => "diffuse",
            },
            "ior": match m.model { SurfaceModel::Glass { ior } => ior, _ => 1.5 },
            "color": mean_color(&m.base_color).to_array(),
            "roughness": m.roughness,
            "metallic": m.metallic,
            "opacity": mean_opacity(&m.opacity),
            "emission": mean_emission(m).to_array(),
            "depth": match DepthVisibility::of(m) {
                DepthVisibility::Solid => "solid",
                DepthVisibility::Invisible => "invisible",
                DepthVisibility::Partial => "cutout",
            },
        })).collect::<Vec<_>>(),
        "objects": scene.meshes.iter().map(|m| json!({
            "id": m.id, "mesh": obj::path(m), "material": m.material,
        })).collect::<Vec<_>>(),
        "lights": scene.desc.lights.iter().map(light).collect::<Vec<_>>(),
    });
    let text = serde_json::to_string_pretty(&data)?;
    super::write_file(&out.join("blender_scene.json"), &text)?;
    super::write_file(&out.join("scene.py"), SCENE_PY)
}

/// Pose (Blender world matrix: columns right, up, −forward) and sensor shift of one view.
fn camera(c: &ExportCamera) -> Value {
    let side = c.width.max(c.height) as f64;
    let [px, py] = c.principal_offset_px;
    let cols = [c.right, c.up, -c.forward].map(to_blender);
    let rows: Vec<[f64; 3]> = (0..3)
        .map(|r| [cols[0][r], cols[1][r], cols[2][r]])
        .collect();
    json!({
        "name": c.name(),
        "view": c.view,
        "location": to_blender(c.origin),
        "rotation": rows,
        "shift_x": -px / side,
        "shift_y": py / side,
        "forward": to_blender(c.forward),
    })
}

/// Punctual lights in Blender's units: a point or spot light of power `P` W has radiant
/// intensity `P / 4π` per steradian on Cycles' scale, a sun's strength is its irradiance.
fn light(l: &Light) -> Value {
    let four_pi = 4.0 * std::f32::consts::PI;
    match l {
        Light::Point {
            position,
            intensity,
            ..
        } => json!({"type": "POINT", "location": to_blender(position.as_dvec3()),
                    "color": intensity, "power_scale": four_pi}),
        Light::Spot {
            position,
            direction,
            intensity,
            inner_cone,
            outer_cone,
            ..
        } => json!({"type": "SPOT", "location": to_blender(position.as_dvec3()),
                    "direction": to_blender(direction.as_dvec3()), "color": intensity,
                    "power_scale": four_pi, "spot_size": 2.0 * outer_cone,
                    "spot_blend": 1.0 - inner_cone / outer_cone.max(1e-6)}),
        Light::Directional {
            direction,
            irradiance,
        } => json!({"type": "SUN", "direction": to_blender(direction.as_dvec3()),
                    "color": irradiance, "power_scale": 1.0}),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::LightFieldCamera;

    /// A Blender camera with `shift` in units of the larger sensor side puts the optical axis at
    /// `centre − shift·max(W, H)` (x, to the right) and `centre + shift_y·max(W, H)` (y, down):
    /// the exported pinhole's principal point. HCI's own formula gives the same numbers.
    #[test]
    fn blender_shift_matches_hci_formula() {
        let cam = LightFieldCamera {
            resolution: [64, 48],
            grid: [9, 9],
            focal_length_mm: 100.0,
            sensor_size_mm: 35.0,
            baseline_m: 0.05,
            focus_distance_m: 3.0,
            position: DVec3::ZERO,
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        for view in [0, 40, 80, 17] {
            let c = ExportCamera::of(&cam, view);
            let v = camera(&c);
            let (du, dv) = cam.view_offset(view);
            // HCI: shift = −pos·f_mm / sensor_mm / focus, pos the camera's x (or y, up).
            let (x_pos, y_pos) = (du as f64 * 0.05, -dv as f64 * 0.05);
            let hci_x = -x_pos * 100.0 / 35.0 / 3.0;
            let hci_y = -y_pos * 100.0 / 35.0 / 3.0;
            assert!(
                (v["shift_x"].as_f64().unwrap() - hci_x).abs() < 1e-12,
                "view {view}"
            );
            assert!(
                (v["shift_y"].as_f64().unwrap() - hci_y).abs() < 1e-12,
                "view {view}"
            );
        }
        // Looking down lfgen's −Z is looking down Blender's +Y; the camera's local −Z column.
        let v = camera(&ExportCamera::of(&cam, 40));
        let r = &v["rotation"];
        assert_eq!(
            [r[0][2].as_f64(), r[1][2].as_f64(), r[2][2].as_f64()],
            [Some(0.0), Some(-1.0), Some(0.0)]
        );
    }
}

//! Mitsuba 3 scene (`scene.xml` + `meshes/*.obj`): one `perspective` sensor per view, in file
//! order of the exported views (`mi.render(scene, sensor=i)`).
//!
//! Conventions (Mitsuba 3's world is right-handed and +Y up like lfgen's, so nothing is
//! mirrored): the sensor shift is `principal_point_offset_x = −px / W` and
//! `principal_point_offset_y = −py / H` in film units, `(px, py)` the principal point's offset
//! from the image centre in pixels (x right, y down) — Mitsuba offsets the frustum, the
//! opposite sign (checked against lfgen's per-view depth by scripts/validate.py); one-sided BSDFs are wrapped in `twosided` (lfgen shades both sides); opacity below 1
//! is a `mask`. `$spp`, `$max_depth`, `$rr_depth` and `$jitter` are parameters with defaults, e.g.
//! `mi.load_file("scene.xml", spp=1, jitter=False)` for the pixel-centre position AOV.

use super::PathLimits;
use super::extract::{
    DepthVisibility, ExportCamera, ExportScene, mean_color, mean_emission, mean_opacity,
};
use super::obj;
use crate::scene::{Light, Material, SurfaceModel};
use anyhow::Result;
use glam::{DVec3, Vec3};
use std::fmt::Write as _;
use std::path::Path;

/// Writes `scene.xml`, `depth.xml` (only the surfaces lfgen's HCI depth counts, for the
/// position AOV) and the meshes into `out`.
pub fn write(scene: &ExportScene, out: &Path, limits: PathLimits) -> Result<()> {
    super::write_meshes(scene, out)?;
    super::write_file(&out.join("scene.xml"), &xml(scene, limits, false))?;
    super::write_file(&out.join("depth.xml"), &xml(scene, limits, true))
}

fn v3(v: DVec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

fn rgb(c: Vec3) -> String {
    format!("{}, {}, {}", c.x, c.y, c.z)
}

/// The scene document. Mitsuba's `max_depth` counts path edges (lfgen's vertex count + 1);
/// its `rr_depth` is the vertex from which Russian roulette may end a path, as lfgen's, with
/// the same survival probability (the throughput's largest component, at most 0.95).
/// `depth_only` leaves out surfaces that do not hide what is behind them in the HCI depth.
fn xml(scene: &ExportScene, limits: PathLimits, depth_only: bool) -> String {
    let (max_depth, rr_depth) = (limits.max_depth + 1, limits.rr_depth);
    let mut s = format!(
        "<scene version=\"3.0.0\">\n  <default name=\"spp\" value=\"64\"/>\n  \
         <default name=\"max_depth\" value=\"{max_depth}\"/>\n  \
         <default name=\"rr_depth\" value=\"{rr_depth}\"/>\n  \
         <default name=\"jitter\" value=\"true\"/>\n  \
         <integrator type=\"path\"><integer name=\"max_depth\" value=\"$max_depth\"/>\
         <integer name=\"rr_depth\" value=\"$rr_depth\"/></integrator>\n"
    );
    for c in &scene.cameras {
        sensor(c, &mut s);
    }
    for (i, m) in scene.desc.materials.iter().enumerate() {
        bsdf(i, m, &mut s);
    }
    for m in &scene.meshes {
        let mat = scene.material(m);
        if depth_only && DepthVisibility::of(mat) == DepthVisibility::Invisible {
            continue;
        }
        // The depth scene needs no materials; it keeps the OBJ's UVs unflipped so a script can
        // evaluate lfgen's cut-out patterns at a hit (load it with `optimize=False` so shapes
        // are not merged and hits name their object).
        let bsdf = match depth_only {
            true => {
                "<bsdf type=\"diffuse\"/>\n    <boolean name=\"flip_tex_coords\" value=\"false\"/>"
                    .to_string()
            }
            false => format!("<ref id=\"mat{}\"/>", m.material),
        };
        let _ = writeln!(
            s,
            "  <shape type=\"obj\" id=\"{}\">\n    <string name=\"filename\" value=\"{}\"/>\n    {bsdf}",
            m.id,
            obj::path(m),
        );
        if mat.is_emissive() && !depth_only {
            let _ = writeln!(
                s,
                "    <emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                rgb(mean_emission(mat))
            );
        }
        s.push_str("  </shape>\n");
    }
    let env = Vec3::from(scene.desc.environment);
    if env.max_element() > 0.0 {
        let _ = writeln!(
            s,
            "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
            rgb(env)
        );
    }
    for l in &scene.desc.lights {
        light(l, &mut s);
    }
    s.push_str("</scene>\n");
    s
}

/// A `perspective` sensor equal to the off-axis pinhole `c`: horizontal field of view of the
/// unshifted frustum, the shift as principal-point offset.
fn sensor(c: &ExportCamera, s: &mut String) {
    let [px, py] = c.principal_offset_px;
    let _ = writeln!(
        s,
        "  <sensor type=\"perspective\" id=\"{name}\">\n    \
         <string name=\"fov_axis\" value=\"x\"/>\n    <float name=\"fov\" value=\"{fov}\"/>\n    \
         <float name=\"principal_point_offset_x\" value=\"{ox}\"/>\n    \
         <float name=\"principal_point_offset_y\" value=\"{oy}\"/>\n    \
         <float name=\"near_clip\" value=\"0.001\"/>\n    <float name=\"far_clip\" value=\"10000\"/>\n    \
         <transform name=\"to_world\"><lookat origin=\"{o}\" target=\"{t}\" up=\"{u}\"/></transform>\n    \
         <sampler type=\"stratified\"><integer name=\"sample_count\" value=\"$spp\"/>\
         <boolean name=\"jitter\" value=\"$jitter\"/></sampler>\n    \
         <film type=\"hdrfilm\"><integer name=\"width\" value=\"{w}\"/><integer name=\"height\" value=\"{h}\"/>\
         <string name=\"pixel_format\" value=\"rgb\"/><rfilter type=\"box\"/></film>\n  </sensor>",
        name = c.name(),
        fov = c.fov_x().to_degrees(),
        ox = -px / c.width as f64,
        oy = -py / c.height as f64,
        o = v3(c.origin),
        t = v3(c.origin + c.forward),
        u = v3(c.up),
        w = c.width,
        h = c.height,
    );
}

/// lfgen's Standard model (Lambert under GGX, `F0 = 0.04` for dielectrics, `α = roughness²`)
/// is written as Mitsuba's `principled` with `specular = 0.5` (the same parameters; its diffuse
/// is Disney's, not lfgen's energy-compensated Lambert: `scripts/lfgen_bsdf.py` registers
/// lfgen's own model under the same parameter names); Diffuse is `diffuse`; glass is a smooth
/// `dielectric`.
fn bsdf(i: usize, m: &Material, s: &mut String) {
    let c = mean_color(&m.base_color);
    let inner = match m.model {
        SurfaceModel::Glass { ior } => format!(
            "<bsdf type=\"dielectric\"><float name=\"int_ior\" value=\"{ior}\"/>\
             <float name=\"ext_ior\" value=\"1\"/><rgb name=\"specular_transmittance\" value=\"{}\"/></bsdf>",
            rgb(c)
        ),
        SurfaceModel::Diffuse => format!(
            "<bsdf type=\"twosided\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf></bsdf>",
            rgb(c)
        ),
        SurfaceModel::Standard => format!(
            "<bsdf type=\"twosided\"><bsdf type=\"principled\"><rgb name=\"base_color\" value=\"{}\"/>\
             <float name=\"roughness\" value=\"{}\"/><float name=\"metallic\" value=\"{}\"/>\
             <float name=\"specular\" value=\"0.5\"/></bsdf></bsdf>",
            rgb(c),
            m.roughness,
            m.metallic
        ),
    };
    let a = mean_opacity(&m.opacity);
    let _ = if a < 1.0 {
        writeln!(
            s,
            "  <bsdf type=\"mask\" id=\"mat{i}\"><float name=\"opacity\" value=\"{a}\"/>{inner}</bsdf>"
        )
    } else {
        let inner = inner.replacen("<bsdf type=", &format!("<bsdf id=\"mat{i}\" type="), 1);
        writeln!(s, "  {inner}")
    };
}

fn light(l: &Light, s: &mut String) {
    let pos = |p: Vec3| v3(p.as_dvec3());
    let _ = match l {
        Light::Point {
            position,
            intensity,
            ..
        } => writeln!(
            s,
            "  <emitter type=\"point\"><point name=\"position\" value=\"{}\"/>\
             <rgb name=\"intensity\" value=\"{}\"/></emitter>",
            pos(*position),
            rgb(Vec3::from(*intensity))
        ),
        Light::Spot {
            position,
            direction,
            intensity,
            inner_cone,
            outer_cone,
            ..
        } => writeln!(
            s,
            "  <emitter type=\"spot\"><rgb name=\"intensity\" value=\"{}\"/>\
             <float name=\"cutoff_angle\" value=\"{}\"/><float name=\"beam_width\" value=\"{}\"/>\
             <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\"/></transform></emitter>",
            rgb(Vec3::from(*intensity)),
            outer_cone.to_degrees(),
            inner_cone.to_degrees(),
            pos(*position),
            pos(*position + *direction)
        ),
        Light::Directional {
            direction,
            irradiance,
        } => writeln!(
            s,
            "  <emitter type=\"directional\"><vector name=\"direction\" value=\"{}\"/>\
             <rgb name=\"irradiance\" value=\"{}\"/></emitter>",
            pos(*direction),
            rgb(Vec3::from(*irradiance))
        ),
    };
}

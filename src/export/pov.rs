//! POV-Ray 3.7 scene files: `geometry.inc` (meshes), `cameras.inc` (every view, chosen with
//! `Declare=View=N`), `scene.pov` (colour, direct lighting), `depth.pov` (exact planar depth
//! as a pigment, for the depth check) and `slices.pov` (the geometry of one ground-truth depth
//! slice alone, chosen with `Declare=Slice=K`, its coverage as alpha: the thesis' S clipped
//! renders).
//!
//! # Handedness
//!
//! POV-Ray is left-handed (+Y up, +Z into the screen); lfgen's world is right-handed (+Y up).
//! Every point and vector is written as `(x, y, −z)`, a mirror, so the scene looks the same.
//! The cameras are written with explicit `right`, `up` and `direction` (no `look_at`, which
//! re-orthogonalises): POV-Ray traces `direction + sx·right + sy·up` for the screen position
//! `sx, sy ∈ [−½, ½]` (right, up), so `right = r·W/f`, `up = u·H/f` and the sensor shift goes
//! into `direction = f̂ − r·px/f + u·py/f` (`px, py` the principal-point offset, y down). A
//! mirror keeps dot products, so planar depth is the same expression in both worlds.

use super::extract::{
    DepthVisibility, ExportCamera, ExportMesh, ExportScene, mean_color, mean_emission, mean_opacity,
};
use crate::scene::{Light, Opacity, SurfaceModel};
use anyhow::Result;
use glam::{DVec3, Vec3};
use std::fmt::Write as _;
use std::path::Path;

/// lfgen world → POV-Ray world (the z mirror).
pub fn to_pov(v: DVec3) -> DVec3 {
    DVec3::new(v.x, v.y, -v.z)
}

fn vec(v: DVec3) -> String {
    format!("<{}, {}, {}>", v.x, v.y, v.z)
}

fn pvec(v: Vec3) -> String {
    vec(to_pov(v.as_dvec3()))
}

/// Writes the POV-Ray files of `scene` into `out`.
pub fn write(scene: &ExportScene, out: &Path) -> Result<()> {
    super::write_file(&out.join("geometry.inc"), &geometry(scene))?;
    super::write_file(&out.join("cameras.inc"), &cameras(scene))?;
    super::write_file(&out.join("depth.pov"), &depth_scene(scene))?;
    super::write_file(&out.join("slices.pov"), &slice_scene(scene))?;
    super::write_file(&out.join("scene.pov"), &colour_scene(scene))?;
    Ok(())
}

/// `#declare`s one `mesh2` per object (untextured; the scenes add textures).
fn geometry(scene: &ExportScene) -> String {
    let mut s =
        String::from("// lfgen export: world-space meshes, z mirrored (POV-Ray is left-handed)\n");
    for m in &scene.meshes {
        mesh2(m, &mut s);
    }
    s
}

fn mesh2(m: &ExportMesh, s: &mut String) {
    let n = m.tris.len() * 3;
    let list = |s: &mut String, name: &str, items: Vec<String>| {
        let _ = writeln!(s, "  {name} {{ {n},");
        for chunk in items.chunks(4) {
            let _ = writeln!(s, "    {},", chunk.join(", "));
        }
        s.pop();
        s.pop();
        s.push_str("\n  }\n");
    };
    let _ = writeln!(s, "#declare {} = mesh2 {{", m.id);
    let pts = m.tris.iter().flat_map(|t| t.p).map(pvec).collect();
    list(s, "vertex_vectors", pts);
    let normals = m.tris.iter().flat_map(|t| t.n).map(|n| {
        // A degenerate shading normal would make POV-Ray reject the mesh: use the winding one.
        if n.length_squared() > 0.0 {
            pvec(n)
        } else {
            pvec(Vec3::Y)
        }
    });
    list(s, "normal_vectors", normals.collect());
    let uvs = m
        .tris
        .iter()
        .flat_map(|t| t.uv)
        .map(|uv| format!("<{}, {}>", uv.x, uv.y));
    list(s, "uv_vectors", uvs.collect());
    let faces = (0..m.tris.len()).map(|i| format!("<{}, {}, {}>", 3 * i, 3 * i + 1, 3 * i + 2));
    let _ = writeln!(s, "  face_indices {{ {},", m.tris.len());
    let faces: Vec<String> = faces.collect();
    for chunk in faces.chunks(6) {
        let _ = writeln!(s, "    {},", chunk.join(", "));
    }
    s.pop();
    s.pop();
    s.push_str("\n  }\n}\n");
}

/// One camera per view, selected by `View` (default: the first exported view), with the
/// planar-depth frame `CamO*` (origin) and `CamF*` (unit forward) the depth pigment reads.
fn cameras(scene: &ExportScene) -> String {
    let first = scene.cameras.first().map_or(0, |c| c.view);
    let mut s = format!("#ifndef (View) #declare View = {first}; #end\n#switch (View)\n");
    for c in &scene.cameras {
        let _ = writeln!(s, "#case ({})  // {}", c.view, c.name());
        s.push_str(&camera(c));
        let (o, f) = (to_pov(c.origin), to_pov(c.forward));
        let _ = writeln!(
            s,
            "  #declare CamOx = {}; #declare CamOy = {}; #declare CamOz = {};",
            o.x, o.y, o.z
        );
        let _ = writeln!(
            s,
            "  #declare CamFx = {}; #declare CamFy = {}; #declare CamFz = {};",
            f.x, f.y, f.z
        );
        s.push_str("#break\n");
    }
    s.push_str("#else\n  #error \"View is not one of the exported views\"\n#end\n");
    s
}

/// A POV-Ray perspective camera equal to the off-axis pinhole `c` (see the module doc).
pub fn camera(c: &ExportCamera) -> String {
    let [px, py] = c.principal_offset_px;
    let right = c.right * (c.width as f64 / c.f_px);
    let up = c.up * (c.height as f64 / c.f_px);
    let dir = c.forward - c.right * (px / c.f_px) + c.up * (py / c.f_px);
    format!(
        "  camera {{ perspective\n    location {}\n    right {}\n    up {}\n    direction {}\n  }}\n",
        vec(to_pov(c.origin)),
        vec(to_pov(right)),
        vec(to_pov(up)),
        vec(to_pov(dir)),
    )
}

const HEADER: &str = "#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 64 }\n";

/// Planar depth as colour: `(p − o)·f̂ / DMax` (grey, linear), or with `Declare=Fine=1` the
/// next base-256 digit `mod(256·depth/DMax, 1)`. Only surfaces that hide what is behind them in
/// the HCI depth are present; render with `-A +FN16 Grayscale_Output=on File_Gamma=1.0`.
fn depth_scene(scene: &ExportScene) -> String {
    let mut s = String::from(HEADER);
    s.push_str("#include \"cameras.inc\"\n#include \"geometry.inc\"\n");
    let _ = writeln!(s, "#declare DMax = {};", scene.max_depth());
    s.push_str(
        "#ifndef (Fine) #declare Fine = 0; #end\n\
         #declare Depth = function(x, y, z) { ((x - CamOx) * CamFx + (y - CamOy) * CamFy + (z - CamOz) * CamFz) / DMax }\n\
         #if (Fine)\n  #declare Encoded = function(x, y, z) { mod(Depth(x, y, z) * 256, 1) }\n\
         #else\n  #declare Encoded = function(x, y, z) { Depth(x, y, z) }\n#end\n\
         #declare DepthPigment = pigment { function { Encoded(x, y, z) } color_map { [0 rgb 0] [1 rgb 1] } }\n\
         #declare DepthFinish = finish { emission 1 ambient 0 diffuse 0 specular 0 }\n\
         background { rgb 0 }\n",
    );
    for m in &scene.meshes {
        let mat = scene.material(m);
        let texture = match DepthVisibility::of(mat) {
            DepthVisibility::Invisible => continue,
            DepthVisibility::Solid => None,
            DepthVisibility::Partial => cutout_depth_texture(&mat.opacity),
        };
        let texture = texture
            .unwrap_or_else(|| "pigment { DepthPigment } finish { DepthFinish }".to_string());
        let _ = writeln!(s, "object {{ {} texture {{ {texture} }} }}", m.id);
    }
    s
}

/// The depth texture with the holes of a cut-out: a `pigment_pattern` evaluates the opacity
/// pattern on the mesh's UVs (metres, as lfgen's), and where it is below ½ the pigment fully
/// transmits, so the ray continues to what is behind (HCI semantics); elsewhere the depth
/// pigment is evaluated at the world point as for solid surfaces. `None` for patterns POV-Ray
/// is not given (image alpha).
fn cutout_depth_texture(opacity: &Opacity) -> Option<String> {
    let pattern = cutout_pattern(opacity)?;
    Some(format!(
        "pigment {{ pigment_pattern {{ uv_mapping function {{ {pattern} }} }}\n    \
         pigment_map {{ [0 rgbt <0, 0, 0, 1>] [0.5 rgbt <0, 0, 0, 1>] [0.5 DepthPigment] [1 DepthPigment] }} }}\n  \
         finish {{ DepthFinish }}"
    ))
}

/// lfgen's cut-out patterns as POV-Ray functions of the UV (`x`, `y`): 0.75 where the surface
/// is (opacity ≥ ½), 0.25 in the holes (values away from 0 and 1, which POV-Ray may wrap).
fn cutout_pattern(opacity: &Opacity) -> Option<String> {
    match *opacity {
        Opacity::Grid { value, .. } if value < 0.5 => Some("0.25".to_string()),
        _ => cutout_shape(opacity).map(|(pattern, _)| pattern),
    }
}

/// The shape of a cut-out as a POV-Ray function of the UV: 0.75 on the surface, 0.25 in the
/// holes; with the opacity on the surface.
fn cutout_shape(opacity: &Opacity) -> Option<(String, f32)> {
    let frac = |c: &str, period: f32| format!("({c} / {period} - floor({c} / {period}))");
    match *opacity {
        Opacity::Grid { period, bar, value } => Some((
            format!(
                "select({} - {bar}, 0.75, select({} - {bar}, 0.75, 0.25))",
                frac("x", period),
                frac("y", period)
            ),
            value,
        )),
        Opacity::Leaves { period: [pu, pv] } => Some((
            format!(
                "select(abs({} - 0.5) - 0.42 * pow(sin(pi * {}), 0.8), 0.75, 0.25)",
                frac("x", pu),
                frac("y", pv)
            ),
            1.0,
        )),
        _ => None,
    }
}

/// One depth slice alone (the thesis' ground truth renders slice `k` by itself): every object
/// is clipped to the planar-depth slab `[z_k, z_{k+1})` of the view's camera (the first and
/// last slices extend to the camera and to infinity, as [`SliceRange::index`] clamps), shown
/// white and unlit, with the transmittance `1 − opacity` (cut-outs: fully transmitting holes),
/// so the output alpha (`+UA`) is the coverage of the slice's geometry: `1 − Π(1 − a)` over
/// the surfaces a ray meets in the slab. Glass is left out (its coverage is its Fresnel
/// reflectance, which a pigment cannot express); images' alpha gets its mean opacity.
/// Render with `Declare=Slice=K -A +UA +FN16 File_Gamma=1.0`, at a multiple of the resolution
/// for the pixel coverage.
fn slice_scene(scene: &ExportScene) -> String {
    let mut s = String::from(
        "#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 256 adc_bailout 0 }\n",
    );
    s.push_str("#include \"cameras.inc\"\n#include \"geometry.inc\"\n");
    s.push_str("#ifndef (Slice) #error \"declare the slice: Declare=Slice=K\" #end\n");
    let r = &scene.desc.slices;
    let z: Vec<String> = r.boundaries().iter().map(f64::to_string).collect();
    let _ = writeln!(
        s,
        "#declare SliceCount = {};\n#declare SliceZ = array[{}] {{ {} }}",
        r.count,
        z.len(),
        z.join(", ")
    );
    s.push_str(
        "#declare CamF = <CamFx, CamFy, CamFz>;\n\
         #declare CamD = vdot(<CamOx, CamOy, CamOz>, CamF);\n\
         #declare Near = (Slice = 0 ? -1e9 : SliceZ[Slice]);\n\
         #declare Far = (Slice = SliceCount - 1 ? 1e9 : SliceZ[Slice + 1]);\n\
         #declare SliceClip = intersection { plane { -CamF, -(Near + CamD) } plane { CamF, Far + CamD } }\n\
         #declare SliceFinish = finish { emission 1 ambient 0 diffuse 0 specular 0 }\n",
    );
    for m in &scene.meshes {
        let mat = scene.material(m);
        if matches!(mat.model, SurfaceModel::Glass { .. }) {
            continue;
        }
        let pigment = match cutout_shape(&mat.opacity) {
            Some((pattern, a)) => format!(
                "pigment_pattern {{ uv_mapping function {{ {pattern} }} }}\n    \
                 pigment_map {{ [0 rgbt 1] [0.5 rgbt 1] [0.5 rgbt <1, 1, 1, {t}>] [1 rgbt <1, 1, 1, {t}>] }}",
                t = 1.0 - a
            ),
            None => {
                let a = mat.opacity.uniform();
                format!(
                    "rgbt <1, 1, 1, {}>",
                    1.0 - a.unwrap_or_else(|| mean_opacity(&mat.opacity))
                )
            }
        };
        let _ = writeln!(
            s,
            "object {{ {} clipped_by {{ SliceClip }} texture {{ pigment {{ {pigment} }} finish {{ SliceFinish }} }} }}",
            m.id
        );
    }
    s
}

/// Colour scene for direct-light comparisons: mean base colours and opacities, Lambert
/// shading, emitters as area lights. POV-Ray's diffuse term is `k·colour·I·cos θ` for a light
/// of colour `I`, so `diffuse 1/π` gives the radiance `albedo/π · E` lfgen computes.
fn colour_scene(scene: &ExportScene) -> String {
    let mut s = String::from(HEADER);
    s.push_str("#include \"cameras.inc\"\n#include \"geometry.inc\"\n");
    let env = Vec3::from(scene.desc.environment);
    let _ = writeln!(s, "background {{ rgb <{}, {}, {}> }}", env.x, env.y, env.z);
    for m in &scene.meshes {
        let mat = scene.material(m);
        let c = mean_color(&mat.base_color);
        let finish = if mat.is_emissive() {
            let e = mean_emission(mat);
            format!(
                "finish {{ emission <{}, {}, {}> diffuse 0 }}",
                e.x, e.y, e.z
            )
        } else {
            format!(
                "finish {{ ambient 0 diffuse {} }}",
                std::f64::consts::FRAC_1_PI
            )
        };
        let (pigment, interior) = match mat.model {
            SurfaceModel::Glass { ior } => (
                format!("rgbf <{}, {}, {}, 1>", c.x, c.y, c.z),
                format!(" interior {{ ior {ior} }}"),
            ),
            SurfaceModel::Standard | SurfaceModel::Diffuse => {
                let t = 1.0 - mean_opacity(&mat.opacity);
                (
                    format!("rgbt <{}, {}, {}, {t}>", c.x, c.y, c.z),
                    String::new(),
                )
            }
        };
        let _ = writeln!(
            s,
            "object {{ {} texture {{ pigment {{ {pigment} }} {finish} }}{interior} }}",
            m.id
        );
        if mat.is_emissive() {
            area_light(m, mean_emission(mat), &mut s);
        }
    }
    for light in &scene.desc.lights {
        punctual_light(light, &mut s);
    }
    s
}

/// Inverse-square falloff: POV-Ray attenuates by `2 / (1 + (d/fd)²)`, which for a tiny
/// `fade_distance` is `2·fd²/d²`; the colour is scaled by `1/(2·fd²)` to compensate.
const FADE: f64 = 1e-3;

/// An emissive object as a 4×4 area light spanning the edges of its first triangle, with the
/// intensity `L·A` a Lambertian emitter of radiance `L` and area `A` has along its normal.
/// POV-Ray's area lights shine equally in all directions: the emitter's cosine is not
/// modelled, an approximation for direct light well in front of the emitter.
fn area_light(m: &ExportMesh, emission: Vec3, s: &mut String) {
    let Some(t0) = m.tris.first() else { return };
    let area: f32 = m
        .tris
        .iter()
        .map(|t| (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length() / 2.0)
        .sum();
    let centre = m.tris.iter().flat_map(|t| t.p).sum::<Vec3>() / (3 * m.tris.len()) as f32;
    let (a, b) = (t0.p[1] - t0.p[0], t0.p[2] - t0.p[1]);
    let scale = area as f64 / (2.0 * FADE * FADE);
    let c = emission.as_dvec3() * scale;
    let _ = writeln!(
        s,
        "light_source {{ {} rgb {} area_light {}, {}, 4, 4 adaptive 1 jitter \
         fade_distance {FADE} fade_power 2 }}",
        pvec(centre),
        vec(c),
        pvec(a),
        pvec(b)
    );
}

fn punctual_light(light: &Light, s: &mut String) {
    let k = 1.0 / (2.0 * FADE * FADE);
    let rgb = |c: [f32; 3]| vec(Vec3::from(c).as_dvec3() * k);
    let _ = match light {
        Light::Point {
            position,
            intensity,
            ..
        } => writeln!(
            s,
            "light_source {{ {} rgb {} fade_distance {FADE} fade_power 2 }}",
            pvec(*position),
            rgb(*intensity)
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
            "light_source {{ {} rgb {} spotlight point_at {} radius {} falloff {} \
             fade_distance {FADE} fade_power 2 }}",
            pvec(*position),
            rgb(*intensity),
            pvec(*position + *direction),
            inner_cone.to_degrees(),
            outer_cone.to_degrees()
        ),
        Light::Directional {
            direction,
            irradiance,
        } => writeln!(
            s,
            "light_source {{ {} rgb {} parallel point_at <0, 0, 0> }}",
            pvec(-*direction * 1e4),
            vec(Vec3::from(*irradiance).as_dvec3())
        ),
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::LightFieldCamera;

    /// Traces POV-Ray's ray for a pixel centre in the mirrored world, mirrors it back and checks
    /// it points at what lfgen's exported camera projects there.
    #[test]
    fn pov_camera_rays_match_the_off_axis_pinhole() {
        let cam = LightFieldCamera {
            resolution: [40, 30],
            grid: [5, 5],
            focal_length_mm: 60.0,
            sensor_size_mm: 35.0,
            baseline_m: 0.08,
            focus_distance_m: 2.0,
            position: DVec3::new(0.1, 1.5, 2.0),
            forward: DVec3::new(0.2, -0.1, -1.0).normalize(),
            up: DVec3::Y,
        };
        let mut cam = cam;
        cam.up = (cam.up - cam.forward * cam.up.dot(cam.forward)).normalize();
        let p = DVec3::new(0.7, 0.9, -1.5);
        for view in [0, 4, 12, 24] {
            let c = ExportCamera::of(&cam, view);
            let (x, y, _) = c.project(p);
            let [px, py] = c.principal_offset_px;
            let (right, up) = (c.right * (40.0 / c.f_px), c.up * (30.0 / c.f_px));
            let dir = c.forward - c.right * (px / c.f_px) + c.up * (py / c.f_px);
            let (sx, sy) = (x / 40.0 - 0.5, 0.5 - y / 30.0);
            let pov_ray = to_pov(dir) + to_pov(right) * sx + to_pov(up) * sy;
            let to_p = to_pov(p - c.origin);
            let cos = pov_ray.normalize().dot(to_p.normalize());
            assert!(cos > 1.0 - 1e-12, "view {view}: cos {cos}");
        }
        // The mirror flips handedness: right = forward × up in lfgen's world becomes
        // up × forward in POV-Ray's, i.e. POV-Ray's left-handed convention.
        let (r, u, f) = (to_pov(cam.right()), to_pov(cam.up), to_pov(cam.forward));
        assert!((r - u.cross(f)).length() < 1e-12);
    }

    #[test]
    fn camera_block_has_explicit_vectors_and_no_look_at() {
        let cam = LightFieldCamera {
            resolution: [8, 8],
            grid: [3, 3],
            focal_length_mm: 50.0,
            sensor_size_mm: 35.0,
            baseline_m: 0.1,
            focus_distance_m: 2.0,
            position: DVec3::ZERO,
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        let text = camera(&ExportCamera::of(&cam, 0));
        assert!(text.contains("right") && text.contains("direction") && !text.contains("look_at"));
        // Looking down lfgen's −Z is looking down POV-Ray's +Z.
        assert!(text.contains("location <-0.1, 0.1, -0>"), "{text}");
    }
}

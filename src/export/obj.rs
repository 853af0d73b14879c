//! Wavefront OBJ meshes in lfgen's world (right-handed, +Y up, metres), one file per object:
//! the mesh format both Mitsuba 3 and Blender read without conversion plugins.

use super::extract::ExportMesh;
use std::fmt::Write as _;

/// File name of an object's mesh, relative to the export folder.
pub fn path(mesh: &ExportMesh) -> String {
    format!("meshes/{}.obj", mesh.id)
}

/// The OBJ text of one object: positions, UVs and shading normals per corner (triangles do not
/// share vertices, as tessellation hands them out).
pub fn text(mesh: &ExportMesh) -> String {
    let mut s = format!("# lfgen export: object {}\n", mesh.id);
    for t in &mesh.tris {
        for p in t.p {
            let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
        }
    }
    for t in &mesh.tris {
        for uv in t.uv {
            let _ = writeln!(s, "vt {} {}", uv.x, uv.y);
        }
    }
    for t in &mesh.tris {
        let ng = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize_or_zero();
        for n in t.n {
            let n = if n.length_squared() > 0.0 { n } else { ng };
            let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
        }
    }
    for i in 0..mesh.tris.len() {
        let [a, b, c] = [3 * i + 1, 3 * i + 2, 3 * i + 3];
        let _ = writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
    }
    s
}

//! glTF mesh primitives as triangles in mesh space.

use super::source::GltfFile;
use crate::scene::shapes::MeshTri;
use ::gltf::Semantic;
use ::gltf::mesh::Mode;
use anyhow::{Context, Result, bail, ensure};
use glam::{Vec2, Vec3};

impl GltfFile {
    /// The triangles of one primitive in mesh space, with the mesh's normals (flat ones when it
    /// has none, as glTF prescribes) and `TEXCOORD_<uv_set>` (zero when absent). Degenerate
    /// triangles are dropped: they cover nothing.
    pub fn primitive_triangles(
        &self,
        mesh: u32,
        primitive: u32,
        uv_set: u32,
    ) -> Result<Vec<MeshTri>> {
        let (p, of) = self.primitive(mesh, primitive)?;
        check_mode(p.mode(), &of)?;
        let pos_acc = p
            .get(&Semantic::Positions)
            .with_context(|| format!("{of} has no POSITION"))?;
        let positions = self.read_floats::<3>(&pos_acc, &format!("POSITION of {of}"))?;
        if let Some(i) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            bail!(
                "accessor {} (POSITION of {of}): vertex {i} is not finite",
                pos_acc.index()
            );
        }
        let n = positions.len();
        let normals = self.vertex_attribute::<3>(&p, Semantic::Normals, n, &of)?;
        let uvs = self.vertex_attribute::<2>(&p, Semantic::TexCoords(uv_set), n, &of)?;
        let indices = self.triangle_indices(&p, n, &of)?;
        let positions: Vec<Vec3> = positions.into_iter().map(Vec3::from).collect();
        let normals: Option<Vec<Vec3>> = normals.map(|v| v.into_iter().map(Vec3::from).collect());
        let uvs: Option<Vec<Vec2>> = uvs.map(|v| v.into_iter().map(Vec2::from).collect());
        Ok(indices
            .chunks_exact(3)
            .filter_map(|t| {
                let idx = [t[0] as usize, t[1] as usize, t[2] as usize];
                triangle(idx, &positions, normals.as_deref(), uvs.as_deref())
            })
            .collect())
    }

    /// Triangles of one primitive as its accessors declare them (indices, else vertices, over
    /// three): known before any of its data is read, so memory can be checked first.
    pub fn primitive_triangle_count(&self, mesh: u32, primitive: u32) -> Result<u64> {
        let (p, of) = self.primitive(mesh, primitive)?;
        let count = match (p.indices(), p.get(&Semantic::Positions)) {
            (Some(acc), _) | (None, Some(acc)) => acc.count(),
            (None, None) => bail!("{of} has no POSITION"),
        };
        Ok(count as u64 / 3)
    }

    /// Primitive `primitive` of mesh `mesh`, with its description for errors.
    fn primitive(&self, mesh: u32, primitive: u32) -> Result<(::gltf::Primitive<'_>, String)> {
        let m = self
            .doc
            .meshes()
            .nth(mesh as usize)
            .with_context(|| format!("mesh {mesh} does not exist"))?;
        let p = m
            .primitives()
            .nth(primitive as usize)
            .with_context(|| format!("mesh {mesh} has no primitive {primitive}"))?;
        let of = match m.name() {
            Some(name) => format!("mesh {mesh} {name:?} primitive {primitive}"),
            None => format!("mesh {mesh} primitive {primitive}"),
        };
        Ok((p, of))
    }

    /// An optional per-vertex attribute, which must have one element per vertex.
    fn vertex_attribute<const N: usize>(
        &self,
        p: &::gltf::Primitive,
        semantic: Semantic,
        n: usize,
        of: &str,
    ) -> Result<Option<Vec<[f32; N]>>> {
        let Some(acc) = p.get(&semantic) else {
            return Ok(None);
        };
        let what = format!("{} of {of}", semantic.to_string());
        let v = self.read_floats::<N>(&acc, &what)?;
        ensure!(
            v.len() == n,
            "accessor {} ({what}): {} elements, but POSITION has {n}",
            acc.index(),
            v.len()
        );
        Ok(Some(v))
    }

    /// Vertex indices of the primitive's triangles, every one checked against `n` vertices.
    fn triangle_indices(&self, p: &::gltf::Primitive, n: usize, of: &str) -> Result<Vec<u32>> {
        let Some(acc) = p.indices() else {
            ensure!(
                n.is_multiple_of(3),
                "{of}: {n} vertices do not make whole triangles"
            );
            return Ok((0..n as u32).collect());
        };
        let what = format!("indices of {of}");
        let indices = self.read_indices(&acc, &what)?;
        if let Some((at, i)) = indices.iter().enumerate().find(|&(_, &i)| i as usize >= n) {
            bail!(
                "accessor {} ({what}): index {i} at position {at} is out of range ({n} vertices)",
                acc.index()
            );
        }
        ensure!(
            indices.len() % 3 == 0,
            "accessor {} ({what}): {} indices do not make whole triangles",
            acc.index(),
            indices.len()
        );
        Ok(indices)
    }
}

fn check_mode(mode: Mode, of: &str) -> Result<()> {
    ensure!(
        mode == Mode::Triangles,
        "{of} has mode {mode:?}: only TRIANGLES are read (points and lines have no surface; \
         re-export strips and fans as triangles)"
    );
    Ok(())
}

/// One triangle, or `None` when it has no area.
fn triangle(
    idx: [usize; 3],
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    uvs: Option<&[Vec2]>,
) -> Option<MeshTri> {
    let p = idx.map(|i| positions[i]);
    let face = (p[1] - p[0]).cross(p[2] - p[0]);
    let flat = face.try_normalize()?;
    Some(MeshTri {
        p,
        n: normals.map_or([flat; 3], |n| idx.map(|i| n[i])),
        uv: uvs.map_or([Vec2::ZERO; 3], |uv| idx.map(|i| uv[i])),
    })
}

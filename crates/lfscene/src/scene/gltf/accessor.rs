//! Reading glTF accessors with every offset, stride and count checked against the buffer
//! view before anything is allocated, so a malformed or hostile file gives an error naming the
//! accessor instead of a panic or an out-of-memory.

use super::source::GltfFile;
use ::gltf::Accessor;
use ::gltf::accessor::DataType;
use anyhow::{Context, Result, bail, ensure};

/// Where an accessor's elements lie: `count` elements of `elem` bytes, `stride` apart, from the
/// start of `bytes`.
struct Layout<'a> {
    bytes: &'a [u8],
    stride: usize,
    count: usize,
    component: DataType,
}

impl Layout<'_> {
    /// Component `c` of element `i` (both in range, checked by [`GltfFile::layout`]).
    #[inline]
    fn component(&self, i: usize, c: usize) -> &[u8] {
        let size = self.component.size();
        let at = i * self.stride + c * size;
        &self.bytes[at..at + size]
    }
}

impl GltfFile {
    /// Elements of `acc` as `N` floats each: float data as is, integer data converted (and
    /// normalised to [0, 1] or [-1, 1] where the accessor says so, as glTF defines).
    /// `what` names the accessor's role in errors.
    pub(super) fn read_floats<const N: usize>(
        &self,
        acc: &Accessor,
        what: &str,
    ) -> Result<Vec<[f32; N]>> {
        let label = label(acc, what);
        let layout = self.layout(acc, N, &label)?;
        ensure!(
            acc.data_type() != DataType::U32,
            "{label}: unsigned int components are for indices only (glTF allows float, byte \
             and short attributes)"
        );
        let normalized = acc.normalized();
        ensure!(
            !(normalized && acc.data_type() == DataType::F32),
            "{label}: normalized {:?} data is not allowed",
            acc.data_type()
        );
        Ok((0..layout.count)
            .map(|i| {
                std::array::from_fn(|c| {
                    to_f32(layout.component(i, c), layout.component, normalized)
                })
            })
            .collect())
    }

    /// Vertex indices: unsigned byte, short or int scalars.
    pub(super) fn read_indices(&self, acc: &Accessor, what: &str) -> Result<Vec<u32>> {
        let label = label(acc, what);
        let layout = self.layout(acc, 1, &label)?;
        ensure!(
            matches!(
                acc.data_type(),
                DataType::U8 | DataType::U16 | DataType::U32
            ) && !acc.normalized(),
            "{label}: indices must be unsigned integers, not {:?}",
            acc.data_type()
        );
        Ok((0..layout.count)
            .map(|i| to_u32(layout.component(i, 0)))
            .collect())
    }

    /// Checks the accessor against its buffer view: dense, `n` components, every element in
    /// bounds (with overflow-checked arithmetic).
    fn layout(&self, acc: &Accessor, n: usize, label: &str) -> Result<Layout<'_>> {
        ensure!(
            acc.sparse().is_none(),
            "{label}: sparse accessors are not read"
        );
        let dims = acc.dimensions();
        ensure!(
            dims.multiplicity() == n,
            "{label}: is {dims:?}, expected {n} component(s)"
        );
        let view = acc
            .view()
            .with_context(|| format!("{label}: has no bufferView"))?;
        let bytes = self.view_bytes(&view).with_context(|| label.to_string())?;
        let elem = acc.data_type().size() * n;
        let stride = view.stride().unwrap_or(elem);
        ensure!(
            stride >= elem,
            "{label}: byteStride {stride} is smaller than an element ({elem} bytes)"
        );
        let (offset, count) = (acc.offset(), acc.count());
        let end = match count {
            0 => Some(offset),
            _ => (count - 1)
                .checked_mul(stride)
                .and_then(|s| s.checked_add(offset))
                .and_then(|s| s.checked_add(elem)),
        };
        match end {
            Some(end) if end <= bytes.len() => Ok(Layout {
                bytes: &bytes[offset..end],
                stride,
                count,
                component: acc.data_type(),
            }),
            _ => bail!(
                "{label}: {count} elements of {elem} bytes (stride {stride}) from byte \
                 {offset} do not fit in bufferView {} ({} bytes)",
                view.index(),
                bytes.len()
            ),
        }
    }
}

/// "accessor 3 (POSITION of mesh 0 primitive 1)".
fn label(acc: &Accessor, what: &str) -> String {
    format!("accessor {} ({what})", acc.index())
}

fn to_f32(b: &[u8], ty: DataType, normalized: bool) -> f32 {
    match (ty, normalized) {
        (DataType::F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U8, true) => b[0] as f32 / 255.0,
        (DataType::I8, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
        (DataType::U16, true) => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
        (DataType::I16, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        (DataType::U8, false) => b[0] as f32,
        (DataType::I8, false) => b[0] as i8 as f32,
        (DataType::U16, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
        (DataType::I16, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
        (DataType::U32, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
    }
}

fn to_u32(b: &[u8]) -> u32 {
    match b.len() {
        1 => b[0] as u32,
        2 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn component_conversion_follows_gltf_normalisation() {
        assert_eq!(to_f32(&[255], DataType::U8, true), 1.0);
        assert_eq!(to_f32(&[0x80], DataType::I8, true), -1.0);
        assert_eq!(to_f32(&[0x81], DataType::I8, true), -1.0);
        assert_eq!(to_f32(&[0xff, 0xff], DataType::U16, true), 1.0);
        assert_eq!(to_f32(&[0xff, 0x7f], DataType::I16, true), 1.0);
        assert_eq!(to_f32(&[7, 0], DataType::U16, false), 7.0);
        assert_eq!(to_f32(&1.5f32.to_le_bytes(), DataType::F32, false), 1.5);
        assert_eq!(to_u32(&[1, 1]), 257);
    }
}

//! Named float arrays in numpy `.npz` archives: what Python users write with
//! `numpy.savez_compressed` and read with `numpy.load`.
//!
//! Readers accept float32 and float64 (numpy's default) in C order and hand out f32, the
//! precision of every other file in the dataset.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use npyz::npz::{NpzArchive, file_name_from_array_name};
use npyz::zip::result::ZipError;
use npyz::zip::{DateTime, write::FileOptions};
use npyz::{DType, NpyFile, Order, TypeChar, WriterBuilder};

/// An n-dimensional array, C order.
#[derive(Clone, Debug, PartialEq)]
pub struct Array {
    /// Extent of each axis.
    pub shape: Vec<usize>,
    /// `shape.iter().product()` values.
    pub data: Vec<f32>,
}

/// An open archive; errors name its path and the array.
pub struct NpzReader {
    path: PathBuf,
    archive: NpzArchive<BufReader<File>>,
    /// `[height, width]` every image-shaped array must have (see [`Self::expect_image`]).
    image: Option<[usize; 2]>,
}

/// Most values per pixel an image-shaped array may hold (bins, modes, components).
const MAX_VALUES_PER_PIXEL: usize = 4096;

impl NpzReader {
    /// Opens `path`.
    pub fn open(path: &Path) -> Result<Self> {
        let file = BufReader::new(lfformat::read::open(path)?);
        let archive = NpzArchive::new(file)
            .with_context(|| format!("{}: cannot open as .npz", path.display()))?;
        Ok(Self {
            path: path.to_path_buf(),
            archive,
            image: None,
        })
    }

    /// Arrays of two or more axes must start with `[height, width]`: checked from the header,
    /// before any data is read, so a file claiming a huge shape is refused at once.
    pub fn expect_image(mut self, height: usize, width: usize) -> Self {
        self.image = Some([height, width]);
        self
    }

    /// Whether the archive holds an array called `name`.
    pub fn has(&self, name: &str) -> bool {
        self.archive.array_names().any(|n| n == name)
    }

    /// The names of all arrays, for error messages.
    pub fn names(&self) -> Vec<String> {
        self.archive.array_names().map(str::to_string).collect()
    }

    /// Reads array `name` as f32.
    pub fn read(&mut self, name: &str) -> Result<Array> {
        let at = format!("{}: array {name:?}", self.path.display());
        let file = match self
            .archive
            .zip_archive()
            .by_name(&file_name_from_array_name(name))
        {
            Ok(file) => file,
            Err(ZipError::FileNotFound) => bail!("{at} is missing"),
            Err(e) => return Err(anyhow!(e).context(at)),
        };
        // npyz reads element by element; buffering avoids a decompressor call per value.
        let npy = NpyFile::new(BufReader::new(file)).with_context(|| at.clone())?;
        if npy.order() != Order::C {
            bail!("{at} is Fortran-ordered; save numpy.ascontiguousarray(a) instead");
        }
        let shape: Vec<usize> = npy.shape().iter().map(|&n| n as usize).collect();
        if let (Some([h, w]), [sh, sw, ..]) = (self.image, &shape[..]) {
            let values = shape.iter().try_fold(1usize, |n, &d| n.checked_mul(d));
            if (*sh, *sw) != (h, w) || values.is_none_or(|n| n > h * w * MAX_VALUES_PER_PIXEL) {
                bail!("{at} is {sw}x{sh} (shape {shape:?}), but the ground truth is {w}x{h}");
            }
        }
        let data = match float_size(&npy.dtype()) {
            Some(4) => npy.into_vec::<f32>(),
            Some(8) => npy
                .into_vec::<f64>()
                .map(|v| v.into_iter().map(|x| x as f32).collect()),
            _ => bail!(
                "{at} has dtype {:?}, expected float32 or float64",
                npy.dtype()
            ),
        }
        .with_context(|| at.clone())?;
        Ok(Array { shape, data })
    }
}

/// Byte size of a plain float dtype, `None` for anything else.
fn float_size(dtype: &DType) -> Option<u64> {
    match dtype {
        DType::Plain(t) if t.type_char() == TypeChar::Float => Some(t.size_field()),
        _ => None,
    }
}

/// Writes `(name, shape, data)` arrays as a deflate-compressed npz of little-endian float32.
///
/// # Panics
/// If a shape does not match its data length (a caller bug, not a user error).
pub fn write_npz(path: &Path, arrays: &[(&str, &[usize], &[f32])]) -> Result<()> {
    let write = || -> std::io::Result<()> {
        let mut zip = npyz::zip::ZipWriter::new(BufWriter::new(File::create(path)?));
        // A fixed timestamp (zip's epoch): the same prediction must give the same bytes.
        let options = FileOptions::default().last_modified_time(DateTime::default());
        for &(name, shape, data) in arrays {
            assert_eq!(shape.iter().product::<usize>(), data.len(), "{name}: shape");
            zip.start_file(file_name_from_array_name(name), options)?;
            let shape: Vec<u64> = shape.iter().map(|&n| n as u64).collect();
            let mut array = npyz::WriteOptions::new()
                .dtype(DType::new_scalar("<f4".parse().expect("valid type string")))
                .shape(&shape)
                .writer(BufWriter::new(&mut zip))
                .begin_nd()?;
            array.extend(data.iter().copied())?;
            array.finish()?;
        }
        zip.finish()?.flush()
    };
    write().with_context(|| format!("{}: cannot write", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_round_trip_and_missing_names_are_reported() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npz");
        write_npz(
            &path,
            &[
                ("x", &[2, 3], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
                ("r", &[2], &[-3.5, 3.5]),
            ],
        )
        .unwrap();
        let mut r = NpzReader::open(&path).unwrap();
        assert!(r.has("x") && r.has("r") && !r.has("y"));
        let x = r.read("x").unwrap();
        assert_eq!(x.shape, vec![2, 3]);
        assert_eq!(x.data, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let err = r.read("y").unwrap_err().to_string();
        assert!(err.contains("a.npz") && err.contains("\"y\""), "{err}");
    }
}

//! The multimodal ground truth in the layout the thesis' public training code reads:
//! `gt_mpi_lowres.npz`, key `mpi`, float32 `(H, W, L, 5)`.
//!
//! Channels per layer are `R, G, B, η, disparity`, layers front to back, rows stored
//! bottom-up (that loader flips axis 0, as for PFM), NaN where a pixel has fewer than `L`
//! layers (the loader reads NaN as 0).

use std::io::{BufReader, BufWriter, Cursor};
use std::path::Path;

use npyz::npz::{NpzArchive, NpzWriter, file_name_from_array_name};
use npyz::zip::result::ZipError;
use npyz::zip::{DateTime, write::FileOptions};
use npyz::{DType, NpyFile, Order, WriteOptions, WriterBuilder};

use crate::error::{Error, Result};
use crate::flip_rows;
use crate::modes::ModeMap;

/// Values per layer: `R, G, B, η, disparity`.
pub const CHANNELS: usize = 5;

/// Layers the thesis' training loader keeps (`mpi[..., :12]`). It batches crops of different
/// scenes together, so every scene must give it the same `L`: writers pad to at least this
/// many layers (NaN), and a scene with more is cut to these by the loader itself.
pub const LOADER_LAYERS: usize = 12;

/// Name of the array inside the npz archive.
const KEY: &str = "mpi";

/// A multi-plane image: per pixel `layers` entries of `R, G, B, η, disparity`.
#[derive(Clone, Debug, PartialEq)]
pub struct Mpi {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Layers per pixel (`L`).
    pub layers: usize,
    /// Top-down, index `((y * width + x) * layers + l) * CHANNELS + c`.
    pub data: Vec<f32>,
}

impl Mpi {
    /// Lays out `map` with `L = max(map.slot_count(), min_layers)` layers (pass
    /// [`LOADER_LAYERS`] for files the thesis' loader reads), using the over-operator `η`
    /// (the thesis' definition) as the weight.
    ///
    /// `colours`, when given, holds the linear RGB of each mode's slice, one entry per mode in
    /// the order the modes were pushed into `map` (pixel order, front to back within a pixel),
    /// so `colours.len() == map.total_modes()`. Without colours the RGB of present layers is 0:
    /// the loader only needs weights and disparities, and 0 keeps present layers distinct
    /// from the NaN of absent ones.
    ///
    /// # Panics
    /// If `map` is incomplete or `colours` has the wrong length.
    pub fn from_modes(map: &ModeMap, colours: Option<&[[f32; 3]]>, min_layers: usize) -> Self {
        assert!(map.is_complete(), "Mpi::from_modes: incomplete ModeMap");
        if let Some(c) = colours {
            assert_eq!(
                c.len(),
                map.total_modes(),
                "Mpi::from_modes: one colour per mode"
            );
        }
        let layers = map.slot_count().max(min_layers);
        let mut data = vec![f32::NAN; map.width * map.height * layers * CHANNELS];
        let mut mode_index = 0;
        for (pixel, modes) in map.pixels().enumerate() {
            for (l, mode) in modes.iter().enumerate() {
                let [r, g, b] = colours.map_or([0.0; 3], |c| c[mode_index]);
                mode_index += 1;
                let start = (pixel * layers + l) * CHANNELS;
                data[start..start + CHANNELS].copy_from_slice(&[r, g, b, mode.eta, mode.disparity]);
            }
        }
        Self {
            width: map.width,
            height: map.height,
            layers,
            data,
        }
    }

    /// The `CHANNELS` values of layer `l` at pixel `(x, y)` (y from the top).
    ///
    /// # Panics
    /// If `(x, y, l)` is out of range.
    pub fn get(&self, x: usize, y: usize, l: usize) -> [f32; CHANNELS] {
        assert!(
            x < self.width && y < self.height && l < self.layers,
            "MPI entry ({x}, {y}, {l}) out of range"
        );
        let start = ((y * self.width + x) * self.layers + l) * CHANNELS;
        std::array::from_fn(|c| self.data[start + c])
    }

    /// Values per image row, the unit that is flipped on disk.
    fn row_len(&self) -> usize {
        self.width * self.layers * CHANNELS
    }
}

/// Writes `mpi` as a deflate-compressed npz that `numpy.load` reads.
pub fn write_mpi_npz(path: &Path, mpi: &Mpi) -> Result<()> {
    let io = |e| Error::io(path, e);
    let shape = [mpi.height, mpi.width, mpi.layers, CHANNELS].map(|n| n as u64);
    let mut npz = NpzWriter::new(Cursor::new(Vec::new()));
    let zip = npz.zip_writer();
    // A fixed timestamp (1980-01-01, zip's epoch): the same data must give the same bytes.
    let options = FileOptions::default().last_modified_time(DateTime::default());
    zip.start_file(file_name_from_array_name(KEY), options)
        .map_err(|e| io(e.into()))?;
    // npyz writes element by element; buffering keeps that from reaching the compressor.
    let mut array = WriteOptions::new()
        .dtype(DType::new_scalar("<f4".parse().expect("valid type string")))
        .shape(&shape)
        .writer(BufWriter::new(&mut *zip))
        .begin_nd()
        .map_err(io)?;
    array
        .extend(flip_rows(&mpi.data, mpi.row_len()).flatten().copied())
        .map_err(io)?;
    array.finish().map_err(io)?;
    let bytes = zip.finish().map_err(|e| io(e.into()))?.into_inner();
    crate::files::write_file(path, &bytes)
}

/// Reads the `mpi` array of an npz written by [`write_mpi_npz`] (or by numpy), top-down.
pub fn read_mpi_npz(path: &Path) -> Result<Mpi> {
    let npz_err = |e| npz_error(path, e);
    let file = BufReader::new(crate::read::open(path)?);
    let mut npz = NpzArchive::new(file).map_err(npz_err)?;
    let file = match npz.zip_archive().by_name(&file_name_from_array_name(KEY)) {
        Ok(file) => file,
        Err(ZipError::FileNotFound) => {
            return Err(Error::format(path, format!("no array named {KEY:?}")));
        }
        Err(e) => return Err(npz_err(e.into())),
    };
    // npyz reads element by element; buffering avoids a decompressor call per float.
    let npy = NpyFile::new(BufReader::new(file)).map_err(npz_err)?;
    let [height, width, layers] =
        check_shape(npy.shape(), npy.order()).map_err(|m| Error::format(path, m))?;
    let file_order = npy.into_vec::<f32>().map_err(npz_err)?;
    let mut mpi = Mpi {
        width,
        height,
        layers,
        data: Vec::new(),
    };
    mpi.data = flip_rows(&file_order, mpi.row_len())
        .flatten()
        .copied()
        .collect();
    Ok(mpi)
}

/// `[H, W, L]` of a C-ordered `(H, W, L, 5)` array, or what is wrong with it.
fn check_shape(shape: &[u64], order: Order) -> std::result::Result<[usize; 3], String> {
    let bad = || format!("array {KEY:?} has shape {shape:?}, expected (H, W, L, {CHANNELS})");
    let [h, w, l, c] = *shape else {
        return Err(bad());
    };
    if c != CHANNELS as u64 {
        return Err(bad());
    }
    if order != Order::C {
        return Err(format!(
            "array {KEY:?} is Fortran-ordered, expected C order"
        ));
    }
    let to_usize = |n: u64| usize::try_from(n).map_err(|_| bad());
    Ok([to_usize(h)?, to_usize(w)?, to_usize(l)?])
}

/// Corrupt archives and wrong dtypes arrive as `InvalidData`/`UnexpectedEof` I/O errors from
/// npyz; they are problems of the file, not of the operating system.
fn npz_error(path: &Path, e: std::io::Error) -> Error {
    match e.kind() {
        std::io::ErrorKind::InvalidData | std::io::ErrorKind::UnexpectedEof => {
            Error::format(path, e.to_string())
        }
        _ => Error::io(path, e),
    }
}

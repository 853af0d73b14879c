//! Per-pixel multimodal depth ground truth and its `modes.exr` file.
//!
//! A pixel sees a variable number of depths (semi-transparent surfaces, sub-pixel edges), so
//! the in-memory map stores them compactly (CSR: one offset per pixel into a flat list). On
//! disk a fixed number `K` of channel groups `mode{k}.*` holds them, because EXR channels are
//! per image, not per pixel.

use std::collections::BTreeMap;
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, ReadChannels,
    ReadLayers, WritableImage,
};

use crate::error::{Error, Result};

/// One depth that contributes to a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Mode {
    /// Disparity in pixels per view step (positive in front of the focus plane).
    pub disparity: f32,
    /// Planar depth along the optical axis, metres.
    pub depth: f32,
    /// Contribution to the pixel by the over operator (the thesis' definition).
    pub eta: f32,
    /// Contribution as the exact per-sample visible fraction.
    pub eta_exact: f32,
}

/// Channel suffixes in the order of [`Mode::to_array`].
const FIELDS: [&str; 4] = ["disparity", "depth", "eta", "eta_exact"];

/// What an unused `mode{k}` slot holds on disk: no contribution, and NaN depths so that a
/// reader which ignores `eta` cannot mistake the slot for a surface at disparity 0.
const UNUSED: Mode = Mode {
    disparity: f32::NAN,
    depth: f32::NAN,
    eta: 0.0,
    eta_exact: 0.0,
};

impl Mode {
    /// The fields in the order of [`FIELDS`], so channel loops need no per-field code.
    fn to_array(self) -> [f32; 4] {
        [self.disparity, self.depth, self.eta, self.eta_exact]
    }

    /// Inverse of [`Mode::to_array`].
    fn from_array([disparity, depth, eta, eta_exact]: [f32; 4]) -> Self {
        Self {
            disparity,
            depth,
            eta,
            eta_exact,
        }
    }

    /// A slot that contributes nothing by either definition is padding, not a mode.
    fn is_unused(&self) -> bool {
        self.eta == 0.0 && self.eta_exact == 0.0
    }
}

/// Variable number of modes per pixel, front to back, compact (CSR) storage.
///
/// Filled in pixel order (row-major, top row first) with [`ModeMap::push_pixel`]; tiles of
/// whole rows rendered separately are joined with [`ModeMap::append`].
#[derive(Clone, Debug, PartialEq)]
pub struct ModeMap {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `offsets[i]..offsets[i + 1]` indexes pixel `i`'s modes; one entry per pushed pixel + 1.
    offsets: Vec<u32>,
    /// All modes, pixel after pixel.
    modes: Vec<Mode>,
}

impl ModeMap {
    /// An empty `width × height` map, to be filled with [`ModeMap::push_pixel`].
    pub fn new(width: usize, height: usize) -> Self {
        let mut offsets = Vec::with_capacity(width * height + 1);
        offsets.push(0);
        Self {
            width,
            height,
            offsets,
            modes: Vec::new(),
        }
    }

    /// Appends the next pixel's modes (front to back).
    ///
    /// # Panics
    /// If all `width * height` pixels were already pushed, or past `u32::MAX` modes in total.
    pub fn push_pixel(&mut self, modes: &[Mode]) {
        assert!(
            !self.is_complete(),
            "ModeMap {}x{}: all pixels already pushed",
            self.width,
            self.height
        );
        self.modes.extend_from_slice(modes);
        self.offsets.push(to_offset(self.modes.len()));
    }

    /// Puts the rows of `other` below the rows of `self` (joins tiles of whole rows).
    ///
    /// Start from `ModeMap::new(width, 0)` to join any number of tiles in order.
    ///
    /// # Panics
    /// If the widths differ or either map is incomplete (pixels would land in wrong places).
    pub fn append(&mut self, other: ModeMap) {
        assert_eq!(self.width, other.width, "ModeMap::append: widths differ");
        assert!(
            self.is_complete() && other.is_complete(),
            "ModeMap::append: both maps must be complete"
        );
        let base = self.modes.len();
        let shifted = other.offsets[1..]
            .iter()
            .map(|&o| to_offset(base + o as usize));
        self.offsets.extend(shifted);
        self.modes.extend(other.modes);
        self.height += other.height;
    }

    /// The modes of pixel `(x, y)` (y from the top), front to back.
    ///
    /// # Panics
    /// If `(x, y)` is outside the map or the pixel has not been pushed yet.
    pub fn pixel(&self, x: usize, y: usize) -> &[Mode] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside map"
        );
        let i = y * self.width + x;
        &self.modes[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// The modes of every pushed pixel, in pixel order.
    pub fn pixels(&self) -> impl Iterator<Item = &[Mode]> {
        self.offsets
            .windows(2)
            .map(|w| &self.modes[w[0] as usize..w[1] as usize])
    }

    /// The largest number of modes at any pixel (0 for an empty map).
    pub fn max_modes(&self) -> usize {
        self.pixels().map(<[Mode]>::len).max().unwrap_or(0)
    }

    /// Number of modes over all pixels (the length of per-mode side arrays such as the
    /// colours of [`crate::mpi::Mpi::from_modes`]).
    pub fn total_modes(&self) -> usize {
        self.modes.len()
    }

    /// Number of mode slots a file needs: [`ModeMap::max_modes`], but at least 1 because a
    /// file with no channels (EXR) or an empty layer axis (MPI) is useless to readers.
    pub fn slot_count(&self) -> usize {
        self.max_modes().max(1)
    }

    /// Whether every pixel has been pushed.
    pub fn is_complete(&self) -> bool {
        self.offsets.len() == self.width * self.height + 1
    }
}

/// A mode count as a CSR offset; `u32` halves the offset table of a full-resolution map.
fn to_offset(n: usize) -> u32 {
    u32::try_from(n).expect("ModeMap holds more than u32::MAX modes")
}

/// Writes `map` as `modes.exr`: ZIP-compressed float32 channels `mode{k}.disparity`,
/// `mode{k}.depth`, `mode{k}.eta` and `mode{k}.eta_exact` for `k = 0..K`,
/// `K = map.slot_count()`, row 0 at the top (EXR convention).
///
/// Slots beyond a pixel's modes hold `eta = eta_exact = 0` and NaN disparity and depth.
///
/// # Panics
/// If `map` is incomplete.
pub fn write_modes_exr(path: &Path, map: &ModeMap) -> Result<()> {
    assert!(map.is_complete(), "write_modes_exr: incomplete ModeMap");
    let slots = map.slot_count();
    let mut planes = vec![vec![0.0f32; map.width * map.height]; slots * FIELDS.len()];
    for (i, modes) in map.pixels().enumerate() {
        for k in 0..slots {
            let values = modes.get(k).copied().unwrap_or(UNUSED).to_array();
            for (f, v) in values.into_iter().enumerate() {
                planes[k * FIELDS.len() + f][i] = v;
            }
        }
    }
    let channels: Vec<_> = planes
        .into_iter()
        .enumerate()
        .map(|(index, plane)| {
            AnyChannel::new(channel_name(index).as_str(), FlatSamples::F32(plane))
        })
        .collect();
    let layer = Layer::new(
        (map.width, map.height),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| exr_error(path, e))?;
    crate::files::write_file(path, bytes.get_ref())
}

/// Reads a `modes.exr`; slots with `eta == 0` and `eta_exact == 0` are dropped.
///
/// Channels are matched by name, not position: EXR stores them sorted alphabetically
/// (`mode10` before `mode2`). Channels not named `mode{k}.{field}` are ignored.
pub fn read_modes_exr(path: &Path) -> Result<ModeMap> {
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_unbuffered(crate::read::open(path)?)
        .map_err(|e| exr_error(path, e))?;
    let layer = image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let planes =
        mode_planes(&layer.channel_data, width * height).map_err(|m| Error::format(path, m))?;
    let mut map = ModeMap::new(width, height);
    let mut modes = Vec::with_capacity(planes.len() / FIELDS.len());
    for i in 0..width * height {
        modes.clear();
        let slots = planes
            .chunks_exact(FIELDS.len())
            .map(|p| Mode::from_array(std::array::from_fn(|f| p[f][i])));
        modes.extend(slots.filter(|m| !m.is_unused()));
        map.push_pixel(&modes);
    }
    Ok(map)
}

/// The sample planes of all `mode{k}.*` channels in [`channel_name`] order, each `pixels` long.
fn mode_planes(
    channels: &AnyChannels<FlatSamples>,
    pixels: usize,
) -> std::result::Result<Vec<Vec<f32>>, String> {
    let mut by_index = BTreeMap::new();
    for channel in &channels.list {
        let name = channel.name.to_string();
        if let Some(index) = parse_channel_name(&name) {
            if channel.sample_data.len() != pixels {
                return Err(format!("channel {name} is subsampled"));
            }
            by_index.insert(index, &channel.sample_data);
        }
    }
    let last = by_index.keys().last().ok_or("no mode{k}.* channels")?;
    let slots = last / FIELDS.len() + 1;
    (0..slots * FIELDS.len())
        .map(|index| match by_index.get(&index) {
            Some(samples) => Ok(samples.values_as_f32().collect()),
            None => Err(format!("missing channel {}", channel_name(index))),
        })
        .collect()
}

/// Name of channel `index`: field `index % 4` of slot `index / 4`.
fn channel_name(index: usize) -> String {
    let (slot, field) = (index / FIELDS.len(), FIELDS[index % FIELDS.len()]);
    format!("mode{slot}.{field}")
}

/// Inverse of [`channel_name`]; `None` for names of other channels.
fn parse_channel_name(name: &str) -> Option<usize> {
    let (slot, field) = name.strip_prefix("mode")?.split_once('.')?;
    if slot.is_empty() || !slot.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let field = FIELDS.iter().position(|&f| f == field)?;
    slot.parse::<usize>()
        .ok()?
        .checked_mul(FIELDS.len())?
        .checked_add(field)
}

/// Keeps operating-system failures as I/O errors and reports everything else as a format
/// problem of the file.
fn exr_error(path: &Path, e: exr::error::Error) -> Error {
    match e {
        exr::error::Error::Io(io) => Error::io(path, io),
        other => Error::format(path, other.to_string()),
    }
}

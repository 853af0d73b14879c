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

/// What surface a mode is: its geometric normal and its ids, one per mode beside the
/// [`ModeMap`] (same storage order), so readers that want only depths never see them.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ModeSurface {
    /// Unit geometric (triangle) normal in the camera frame shared by every view: x right,
    /// y up, z towards the camera; turned to face the camera (z > 0 seen head-on). NaN where
    /// the mode has no surface (an unused slot).
    pub normal: [f32; 3],
    /// Object id: the object's index in `scene.json`'s `objects` plus 1 (0: none).
    pub object: u32,
    /// Material id: the index in `scene.json`'s `materials` plus 1 (0: none).
    pub material: u32,
    /// Semantic class id, named in the scene's `ids.json` (0: none).
    pub class: u32,
}

impl ModeSurface {
    /// No surface: NaN normal, ids 0 (unused slots, pixels that see nothing).
    pub const NONE: Self = Self {
        normal: [f32::NAN; 3],
        object: 0,
        material: 0,
        class: 0,
    };
}

/// Channel suffixes of a [`ModeSurface`]: three float normal components, then three u32 ids.
const SURFACE_FIELDS: [&str; 6] = [
    "normal.X", "normal.Y", "normal.Z", "object", "material", "class",
];

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
    write_modes(path, map, None)
}

/// [`write_modes_exr`] plus each mode's surface: float32 `mode{k}.normal.X|Y|Z` and uint32
/// `mode{k}.object|material|class` (unused slots: NaN normal, ids 0). The depth channels are
/// the same as without them, so readers of depths alone read the file unchanged.
///
/// # Panics
/// If `map` is incomplete or `surfaces` is not one per mode.
pub fn write_modes_exr_with_surfaces(
    path: &Path,
    map: &ModeMap,
    surfaces: &[ModeSurface],
) -> Result<()> {
    assert_eq!(surfaces.len(), map.total_modes(), "one surface per mode");
    write_modes(path, map, Some(surfaces))
}

fn write_modes(path: &Path, map: &ModeMap, surfaces: Option<&[ModeSurface]>) -> Result<()> {
    assert!(map.is_complete(), "write_modes_exr: incomplete ModeMap");
    let mut channels = mode_channels(map);
    if let Some(surfaces) = surfaces {
        channels.extend(surface_channels(map, surfaces));
    }
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

/// The `mode{k}.{field}` channels of `map`.
fn mode_channels(map: &ModeMap) -> Vec<AnyChannel<FlatSamples>> {
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
    let named = planes.into_iter().enumerate();
    named
        .map(|(index, plane)| {
            AnyChannel::new(channel_name(index).as_str(), FlatSamples::F32(plane))
        })
        .collect()
}

/// The `mode{k}.normal.*` and id channels of `surfaces` (in `map`'s storage order).
fn surface_channels(map: &ModeMap, surfaces: &[ModeSurface]) -> Vec<AnyChannel<FlatSamples>> {
    let (slots, pixels) = (map.slot_count(), map.width * map.height);
    let mut normals = vec![vec![0.0f32; pixels]; slots * 3];
    let mut ids = vec![vec![0u32; pixels]; slots * 3];
    let mut next = 0;
    for (i, modes) in map.pixels().enumerate() {
        for k in 0..slots {
            let s = match k < modes.len() {
                true => surfaces[next + k],
                false => ModeSurface::NONE,
            };
            for c in 0..3 {
                normals[k * 3 + c][i] = s.normal[c];
            }
            for (c, id) in [s.object, s.material, s.class].into_iter().enumerate() {
                ids[k * 3 + c][i] = id;
            }
        }
        next += modes.len();
    }
    let name = |k: usize, f: usize| format!("mode{k}.{}", SURFACE_FIELDS[f]);
    let floats = normals
        .into_iter()
        .enumerate()
        .map(|(j, p)| AnyChannel::new(name(j / 3, j % 3).as_str(), FlatSamples::F32(p)));
    let uints = ids
        .into_iter()
        .enumerate()
        .map(|(j, p)| AnyChannel::new(name(j / 3, 3 + j % 3).as_str(), FlatSamples::U32(p)));
    floats.chain(uints).collect()
}

/// Reads a `modes.exr`; slots with `eta == 0` and `eta_exact == 0` are dropped.
///
/// Channels are matched by name, not position: EXR stores them sorted alphabetically
/// (`mode10` before `mode2`). Channels not named `mode{k}.{field}` are ignored.
pub fn read_modes_exr(path: &Path) -> Result<ModeMap> {
    Ok(read_modes_exr_with_surfaces(path)?.0)
}

/// [`read_modes_exr`] and each kept mode's [`ModeSurface`], in the map's storage order; `None`
/// for a file written without surfaces. A file with some surface channels must have all six
/// for every slot.
pub fn read_modes_exr_with_surfaces(path: &Path) -> Result<(ModeMap, Option<Vec<ModeSurface>>)> {
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
    let channels = &layer.channel_data;
    let planes = mode_planes(channels, width * height).map_err(|m| Error::format(path, m))?;
    let slots = planes.len() / FIELDS.len();
    let surface =
        surface_planes(channels, width * height, slots).map_err(|m| Error::format(path, m))?;
    let mut map = ModeMap::new(width, height);
    let mut surfaces = surface.as_ref().map(|_| Vec::new());
    let mut modes = Vec::with_capacity(slots);
    for i in 0..width * height {
        modes.clear();
        for (k, p) in planes.chunks_exact(FIELDS.len()).enumerate() {
            let mode = Mode::from_array(std::array::from_fn(|f| p[f][i]));
            if mode.is_unused() {
                continue;
            }
            modes.push(mode);
            if let (Some(out), Some(s)) = (surfaces.as_mut(), surface.as_ref()) {
                out.push(s.at(k, i));
            }
        }
        map.push_pixel(&modes);
    }
    Ok((map, surfaces))
}

/// The surface channels of a `modes.exr`: per slot three normal planes and three id planes.
struct SurfacePlanes {
    normals: Vec<Vec<f32>>,
    ids: Vec<Vec<u32>>,
}

impl SurfacePlanes {
    fn at(&self, slot: usize, i: usize) -> ModeSurface {
        let n = |c: usize| self.normals[slot * 3 + c][i];
        let id = |c: usize| self.ids[slot * 3 + c][i];
        ModeSurface {
            normal: [n(0), n(1), n(2)],
            object: id(0),
            material: id(1),
            class: id(2),
        }
    }
}

/// The surface planes of `slots` slots, or `None` when the file has no surface channel.
fn surface_planes(
    channels: &AnyChannels<FlatSamples>,
    pixels: usize,
    slots: usize,
) -> std::result::Result<Option<SurfacePlanes>, String> {
    let is_surface = |name: &str| {
        let rest = name.strip_prefix("mode").and_then(|r| r.split_once('.'));
        rest.is_some_and(|(_, field)| SURFACE_FIELDS.contains(&field))
    };
    if !channels
        .list
        .iter()
        .any(|c| is_surface(&c.name.to_string()))
    {
        return Ok(None);
    }
    let find = |name: String| {
        let channel = channels.list.iter().find(|c| c.name.to_string() == name);
        let channel = channel.ok_or_else(|| format!("missing channel {name}"))?;
        match channel.sample_data.len() == pixels {
            true => Ok(&channel.sample_data),
            false => Err(format!("channel {name} is subsampled")),
        }
    };
    let mut planes = SurfacePlanes {
        normals: Vec::new(),
        ids: Vec::new(),
    };
    for k in 0..slots {
        for (f, field) in SURFACE_FIELDS.iter().enumerate() {
            let name = format!("mode{k}.{field}");
            match (f < 3, find(name.clone())?) {
                (true, samples) => planes.normals.push(samples.values_as_f32().collect()),
                (false, FlatSamples::U32(ids)) => planes.ids.push(ids.clone()),
                (false, _) => return Err(format!("channel {name} is not uint32")),
            }
        }
    }
    Ok(Some(planes))
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

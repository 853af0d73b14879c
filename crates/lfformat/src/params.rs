//! The HCI `parameters.cfg` (INI) and the camera formulas that depend on it.
//!
//! Key names, sections and value styles match the HCI benchmark's Blender add-on, because its
//! evaluation toolkit parses the file with Python's `configparser` and `int()`/`float()`:
//! integer keys must be written without a decimal point, float keys always with one.

use std::collections::HashMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Defines [`HciParameters`] and its INI conversion from one list of sections and keys, so a
/// key cannot be added to the struct and forgotten in the reader or writer.
macro_rules! hci_parameters {
    ($( [$section:literal] { $( $(#[doc = $doc:literal])* $field:ident: $ty:ty, )+ } )+) => {
        /// The contents of an HCI `parameters.cfg`; field names are the INI keys.
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        pub struct HciParameters {
            $( $( $(#[doc = $doc])* pub $field: $ty, )+ )+
        }

        impl HciParameters {
            /// The `parameters.cfg` text: HCI's sections in HCI's order, `key = value` lines,
            /// floats in the shortest form that parses back to the same value.
            pub fn to_ini(&self) -> String {
                let sections = [$({
                    let mut text = format!("[{}]\n", $section);
                    $( text.push_str(&format!(
                        "{} = {}\n",
                        stringify!($field),
                        IniValue::format(&self.$field)
                    )); )+
                    text
                }),+];
                sections.join("\n")
            }

            /// Builds the struct from parsed entries, failing on the first missing or bad key.
            fn from_entries(entries: &Entries, path: &Path) -> Result<Self> {
                Ok(Self { $( $( $field: entries.get($section, stringify!($field), path)?, )+ )+ })
            }
        }
    };
}

hci_parameters! {
    ["intrinsics"] {
        /// Focal length in millimetres (HCI: 100).
        focal_length_mm: f64,
        /// Image width in pixels.
        image_resolution_x_px: u32,
        /// Image height in pixels.
        image_resolution_y_px: u32,
        /// The larger sensor side in millimetres (HCI: 35).
        sensor_size_mm: f64,
        /// Aperture; HCI uses 100 for a pinhole-like camera.
        fstop: f64,
    }
    ["extrinsics"] {
        /// Cameras per row (odd).
        num_cams_x: u32,
        /// Cameras per column (odd).
        num_cams_y: u32,
        /// Distance between adjacent cameras in millimetres.
        baseline_mm: f64,
        /// Depth of the zero-disparity plane in metres.
        focus_distance_m: f64,
        /// Centre camera position, Blender world X (metres).
        center_cam_x_m: f64,
        /// Centre camera position, Blender world Y (metres).
        center_cam_y_m: f64,
        /// Centre camera position, Blender world Z, up (metres).
        center_cam_z_m: f64,
        /// Centre camera rotation, Blender XYZ Euler X (radians).
        center_cam_rx_rad: f64,
        /// Centre camera rotation, Blender XYZ Euler Y (radians).
        center_cam_ry_rad: f64,
        /// Centre camera rotation, Blender XYZ Euler Z (radians).
        center_cam_rz_rad: f64,
    }
    ["meta"] {
        /// Scene name.
        scene: String,
        /// Split or category (`training`, `test`, …).
        category: String,
        /// Creation date, `YYYY-MM-DD`.
        date: String,
        /// Dataset version string.
        version: String,
        /// Seed of the render.
        cycles_seed: u64,
        /// Lower disparity bound, rounded as by [`hci_disp_bounds`].
        disp_min: f64,
        /// Upper disparity bound, rounded as by [`hci_disp_bounds`].
        disp_max: f64,
        /// Disparity of the far end of the camera frustum used.
        frustum_disp_min: f64,
        /// Disparity of the near end of the camera frustum used.
        frustum_disp_max: f64,
        /// Ratio of the high-res GT resolution to the views (1 when only low-res GT exists).
        depth_map_scale: f64,
    }
}

impl HciParameters {
    /// Parses `parameters.cfg` text; `path` only names the file in errors.
    ///
    /// Like `configparser`: whitespace around keys and values, full-line `#`/`;` comments,
    /// any key order and unknown keys are accepted, keys are case-insensitive.
    pub fn parse_ini(text: &str, path: &Path) -> Result<Self> {
        let entries = Entries::parse(text).map_err(|m| Error::format(path, m))?;
        Self::from_entries(&entries, path)
    }

    /// Reads and parses the file at `path`.
    pub fn read(path: &Path) -> Result<Self> {
        Self::parse_ini(&crate::read::text(path)?, path)
    }

    /// Writes [`HciParameters::to_ini`] to `path`.
    pub fn write(&self, path: &Path) -> Result<()> {
        crate::files::write_file(path, self.to_ini().as_bytes())
    }

    /// Focal length in pixels; HCI's sensor size is the larger side, so is the pixel count.
    pub fn f_px(&self) -> f64 {
        let pixels = self.image_resolution_x_px.max(self.image_resolution_y_px);
        self.focal_length_mm * f64::from(pixels) / self.sensor_size_mm
    }

    /// Disparity in pixels per view step of planar depth `z_m` (metres); positive in front
    /// of the focus plane.
    pub fn disparity_from_depth(&self, z_m: f64) -> f64 {
        self.baseline_f_px() * (1.0 / z_m - 1.0 / self.focus_distance_m)
    }

    /// Planar depth in metres of disparity `d` (inverse of [`Self::disparity_from_depth`]).
    pub fn depth_from_disparity(&self, d: f64) -> f64 {
        1.0 / (d / self.baseline_f_px() + 1.0 / self.focus_distance_m)
    }

    /// Baseline in metres times focal length in pixels: disparity per unit of inverse depth.
    fn baseline_f_px(&self) -> f64 {
        self.baseline_mm / 1000.0 * self.f_px()
    }
}

/// HCI's `disp_min`/`disp_max`: the range widened to tenths plus a 0.1 margin,
/// `floor(min*10)/10 - 0.1` and `ceil(max*10)/10 + 0.1`.
///
/// Computed as `(floor(min*10) - 1) / 10` so that the result is the float nearest the
/// decimal value (`-2.3`, not `-2.3000000000000003`) and the file stays readable.
pub fn hci_disp_bounds(min: f64, max: f64) -> (f64, f64) {
    (
        ((min * 10.0).floor() - 1.0) / 10.0,
        ((max * 10.0).ceil() + 1.0) / 10.0,
    )
}

/// A value type that can appear in `parameters.cfg`.
trait IniValue: Sized {
    /// What the value should be, for error messages.
    const KIND: &'static str;
    /// The value as written after `key = `.
    fn format(&self) -> String;
    /// The value from the text after `key = `, `None` if it is malformed.
    fn parse(text: &str) -> Option<Self>;
}

impl IniValue for f64 {
    const KIND: &'static str = "a finite number";

    /// Shortest round-trip form, with `.0` added to integral values as HCI writes them
    /// (Rust's `Display` never uses an exponent, so a `.` is all that can be missing).
    fn format(&self) -> String {
        let text = self.to_string();
        if self.is_finite() && !text.contains('.') {
            text + ".0"
        } else {
            text
        }
    }

    /// `nan` and `inf` parse as `f64` but are no camera value, size or disparity.
    fn parse(text: &str) -> Option<Self> {
        text.parse().ok().filter(|v: &f64| v.is_finite())
    }
}

/// Integers are written bare because Python's `int("512.0")` fails.
macro_rules! ini_integer {
    ($($ty:ty),+) => {$(
        impl IniValue for $ty {
            const KIND: &'static str = "a non-negative integer";

            fn format(&self) -> String {
                self.to_string()
            }

            fn parse(text: &str) -> Option<Self> {
                text.parse().ok()
            }
        }
    )+};
}

ini_integer!(u32, u64);

impl IniValue for String {
    const KIND: &'static str = "text";

    fn format(&self) -> String {
        self.clone()
    }

    fn parse(text: &str) -> Option<Self> {
        Some(text.to_string())
    }
}

/// The `(section, key) → value` pairs of an INI text.
struct Entries(HashMap<(String, String), String>);

impl Entries {
    /// Splits `text` into entries, or says which line is malformed.
    fn parse(text: &str) -> std::result::Result<Self, String> {
        let mut entries = HashMap::new();
        let mut section = None;
        for (index, raw) in text.lines().enumerate() {
            let line = raw.trim();
            let at = |message: String| format!("line {}: {message}", index + 1);
            if line.is_empty() || line.starts_with(['#', ';']) {
                continue;
            }
            if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                section = Some(name.trim().to_string());
                continue;
            }
            let (key, value) = line
                .split_once('=')
                .ok_or_else(|| at(format!("expected `key = value`, found {line:?}")))?;
            let section = section
                .clone()
                .ok_or_else(|| at("key before any [section]".into()))?;
            let key = key.trim().to_ascii_lowercase();
            if entries
                .insert((section, key.clone()), value.trim().to_string())
                .is_some()
            {
                return Err(at(format!("duplicate key {key:?}")));
            }
        }
        Ok(Self(entries))
    }

    /// The value of `key` in `[section]` as `T`, with an error naming the key.
    fn get<T: IniValue>(&self, section: &str, key: &str, path: &Path) -> Result<T> {
        let value = self
            .0
            .get(&(section.to_string(), key.to_string()))
            .ok_or_else(|| Error::format(path, format!("missing key {key:?} in [{section}]")))?;
        T::parse(value).ok_or_else(|| {
            Error::format(
                path,
                format!("[{section}] {key} = {value:?} is not {}", T::KIND),
            )
        })
    }
}

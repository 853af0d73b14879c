//! Single-channel float maps in the PFM format, HCI convention.
//!
//! The HCI benchmark stores ground truth as `Pf` files with a negative scale (little-endian)
//! and rows bottom-up; its evaluation toolkit flips them back. We write exactly that and read
//! it back top-down, accepting big-endian files too because other tools write them.

use std::path::Path;

use crate::error::{Error, Result};
use crate::flip_rows;

/// A single-channel float image, row-major and top-down (row 0 is the top image row).
#[derive(Clone, Debug, PartialEq)]
pub struct FloatImage {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width * height` values, index `y * width + x`.
    pub data: Vec<f32>,
}

impl FloatImage {
    /// Wraps `data` as a `width × height` image.
    ///
    /// # Panics
    /// If `data.len() != width * height`, which would make every later index wrong.
    pub fn new(width: usize, height: usize, data: Vec<f32>) -> Self {
        assert_eq!(
            data.len(),
            width * height,
            "FloatImage::new: {width}x{height} image needs {} values",
            width * height
        );
        Self {
            width,
            height,
            data,
        }
    }

    /// The value at column `x`, row `y` (from the top).
    ///
    /// # Panics
    /// If `(x, y)` is outside the image (an out-of-range `x` would silently wrap otherwise).
    pub fn get(&self, x: usize, y: usize) -> f32 {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{} image",
            self.width,
            self.height
        );
        self.data[y * self.width + x]
    }
}

/// The complete PFM file for `img`: `Pf` header with scale -1, little-endian rows bottom-up.
pub fn encode_pfm(img: &FloatImage) -> Vec<u8> {
    let header = format!("Pf\n{} {}\n-1\n", img.width, img.height);
    let mut out = Vec::with_capacity(header.len() + 4 * img.data.len());
    out.extend_from_slice(header.as_bytes());
    for v in flip_rows(&img.data, img.width).flatten() {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Parses a complete PFM file; `path` only names the file in errors.
pub fn decode_pfm(bytes: &[u8], path: &Path) -> Result<FloatImage> {
    let (header, pixels) = parse_header(bytes).map_err(|m| Error::format(path, m))?;
    let (width, height) = (header.width, header.height);
    let expected = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(4))
        .ok_or_else(|| Error::format(path, format!("PFM size {width}x{height} is too large")))?;
    if pixels.len() != expected {
        return Err(Error::format(path, size_mismatch(expected, pixels.len())));
    }
    let file_order: Vec<f32> = pixels
        .chunks_exact(4)
        .map(|c| {
            let b = [c[0], c[1], c[2], c[3]];
            if header.little_endian {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            }
        })
        .collect();
    // The HCI toolkit multiplies by |scale| (PFM's scale factor; HCI's own files use ±1).
    let scale = header.scale.abs() as f32;
    let data = flip_rows(&file_order, width)
        .flatten()
        .map(|v| if scale == 1.0 { *v } else { v * scale })
        .collect();
    Ok(FloatImage::new(width, height, data))
}

/// Writes `img` to `path` as an HCI-style PFM.
pub fn write_pfm(path: &Path, img: &FloatImage) -> Result<()> {
    crate::files::write_file(path, &encode_pfm(img))
}

/// Reads a single-channel PFM from `path`, top-down.
pub fn read_pfm(path: &Path) -> Result<FloatImage> {
    decode_pfm(&crate::read::bytes(path)?, path)
}

/// What the header says about the pixel block that follows it.
struct Header {
    width: usize,
    height: usize,
    little_endian: bool,
    /// The scale field: its sign is the byte order, its magnitude multiplies every value.
    scale: f64,
}

/// Splits `bytes` into the parsed header and the pixel bytes, or says what is wrong.
fn parse_header(bytes: &[u8]) -> std::result::Result<(Header, &[u8]), String> {
    let mut pos = 0;
    match next_token(bytes, &mut pos) {
        Some("Pf") => {}
        Some("PF") => return Err("3-channel PFM (\"PF\") is not supported, expected \"Pf\"".into()),
        _ => return Err("not a single-channel PFM file (does not start with \"Pf\")".into()),
    }
    let width = parse_field(bytes, &mut pos, "width")?;
    let height = parse_field(bytes, &mut pos, "height")?;
    let scale: f64 = parse_field(bytes, &mut pos, "scale")?;
    if scale == 0.0 || !scale.is_finite() {
        return Err(format!(
            "PFM scale {scale} is neither negative nor positive"
        ));
    }
    // The header ends with exactly one whitespace byte; the pixels start right after it.
    if !bytes.get(pos).is_some_and(u8::is_ascii_whitespace) {
        return Err("truncated PFM header (no pixel data after the scale)".into());
    }
    let header = Header {
        width,
        height,
        little_endian: scale < 0.0,
        scale,
    };
    Ok((header, &bytes[pos + 1..]))
}

/// The next header field parsed as `T`, with an error naming the field.
fn parse_field<T: std::str::FromStr>(
    bytes: &[u8],
    pos: &mut usize,
    name: &str,
) -> std::result::Result<T, String> {
    let token = next_token(bytes, pos).ok_or(format!("truncated PFM header (no {name})"))?;
    token.parse().map_err(|_| {
        // A garbage "header" can be megabytes long: show its start only.
        let shown: String = token.chars().take(40).collect();
        let more = if shown.len() < token.len() { "…" } else { "" };
        format!("bad PFM header: {name} {shown:?}{more} is not a number")
    })
}

/// The next whitespace-separated header token, or `None` at the end of the data or on
/// non-UTF-8 bytes (both mean the header is broken). A `#` starts a comment to the end of its
/// line, which is skipped (some writers put one after the magic, and the toolkit reads them).
fn next_token<'a>(bytes: &'a [u8], pos: &mut usize) -> Option<&'a str> {
    let mut start = *pos;
    loop {
        start += (bytes.get(start..)?.iter())
            .take_while(|b| b.is_ascii_whitespace())
            .count();
        if bytes.get(start) != Some(&b'#') {
            break;
        }
        start += bytes[start..].iter().take_while(|&&b| b != b'\n').count();
    }
    let len = bytes[start..]
        .iter()
        .take_while(|b| !b.is_ascii_whitespace())
        .count();
    *pos = start + len;
    (len > 0).then(|| std::str::from_utf8(&bytes[start..start + len]).ok())?
}

/// Describes a pixel block of the wrong size.
fn size_mismatch(expected: usize, found: usize) -> String {
    if found < expected {
        format!("truncated PFM: expected {expected} bytes of pixel data, found {found}")
    } else {
        format!(
            "{} unexpected bytes after the PFM pixel data",
            found - expected
        )
    }
}

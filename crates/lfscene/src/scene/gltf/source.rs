//! Opening a glTF or GLB file safely: size limits, the GLB header, required extensions, the
//! crate's index validation, and buffers and images resolved by lfgen itself — a URI may only
//! name a file beside the glTF (or below its folder) or be a base64 `data:` URI of bounded size.

use crate::scene::files::{read_limited, resolve_inside};
use crate::scene::texture_image::{DecodeBudgets, TextureImage};
use crate::scene::{Resource, SourceFile};
use ::gltf::buffer::View;
use anyhow::{Context, Result, anyhow, bail, ensure};
use base64::Engine;
use lfformat::manifest::hex_sha256;
use std::borrow::Cow;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Largest decoded `data:` URI.
const MAX_DATA_URI_BYTES: usize = 512 << 20;

/// Extensions lfgen reads (all others are ignored with a warning, or refused when required).
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
];

/// An opened, validated glTF document with its buffers loaded.
pub struct GltfFile {
    /// Canonical path of the file, and its folder (the only place URIs may point into).
    path: PathBuf,
    dir: PathBuf,
    pub(super) doc: ::gltf::Document,
    /// Buffer contents, each exactly `byteLength` long.
    buffers: Vec<Vec<u8>>,
    sha256: String,
    /// SHA-256 of every external file read so far, by URI.
    read_log: RefCell<BTreeMap<String, String>>,
}

impl GltfFile {
    /// Reads and validates `path` and loads its buffers. Errors name the problem; the caller
    /// adds the file name.
    pub fn open(path: &Path) -> Result<Self> {
        let bytes = read_limited(path)?;
        let path = path
            .canonicalize()
            .with_context(|| format!("cannot resolve {}", path.display()))?;
        let dir = path
            .parent()
            .context("the file has no folder")?
            .to_path_buf();
        check_glb_header(&bytes)?;
        let ::gltf::Gltf { document, blob } =
            ::gltf::Gltf::from_slice_without_validation(&bytes).map_err(describe)?;
        let mut json = document.into_json();
        check_version(&json.asset)?;
        check_required_extensions(&json.extensions_required)?;
        check_position_accessors(&json)?;
        // Checked above; the crate would refuse the ones it has no types for.
        json.extensions_required.clear();
        let doc = ::gltf::Document::from_json(json).map_err(describe)?;
        let mut file = Self {
            path,
            dir,
            doc,
            buffers: Vec::new(),
            sha256: hex_sha256(&bytes),
            read_log: RefCell::new(BTreeMap::new()),
        };
        file.buffers = file.load_buffers(blob)?;
        Ok(file)
    }

    /// Opens the source of a saved scene, refusing it if it or any file it read changed.
    pub fn open_unchanged(src: &SourceFile) -> Result<Self> {
        let file = Self::open(Path::new(&src.path))
            .with_context(|| format!("{} (a source of this scene)", src.path))?;
        ensure!(
            file.sha256 == src.sha256,
            "{} changed since the scene was imported (SHA-256 {} instead of {}): render the \
             glTF itself again",
            src.path,
            file.sha256,
            src.sha256
        );
        for r in &src.resources {
            let sha = file.resource_sha256(&r.uri)?;
            ensure!(
                sha == r.sha256,
                "{:?}, referenced by {}, changed since the scene was imported",
                r.uri,
                src.path
            );
        }
        Ok(file)
    }

    /// The description of this file for `scene.json`: path, checksum and every external file
    /// read so far.
    pub fn source_file(&self) -> Result<SourceFile> {
        let path = self.path.to_str().context("the path is not valid UTF-8")?;
        let log = self.read_log.borrow();
        Ok(SourceFile {
            path: path.to_string(),
            sha256: self.sha256.clone(),
            resources: log
                .iter()
                .map(|(uri, sha256)| Resource {
                    uri: uri.clone(),
                    sha256: sha256.clone(),
                })
                .collect(),
            root: None,
        })
    }

    /// Extensions the file uses that lfgen ignores.
    pub fn unsupported_extensions(&self) -> Vec<String> {
        self.doc
            .extensions_used()
            .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
            .map(String::from)
            .collect()
    }

    fn load_buffers(&self, mut blob: Option<Vec<u8>>) -> Result<Vec<Vec<u8>>> {
        let mut buffers = Vec::new();
        for b in self.doc.buffers() {
            let what = format!("buffer {}", b.index());
            let mut data = match b.source() {
                ::gltf::buffer::Source::Bin => blob.take().with_context(|| {
                    format!("{what} has no uri, and there is no (unused) GLB binary chunk")
                })?,
                ::gltf::buffer::Source::Uri(uri) => self.read_uri(uri, &what)?,
            };
            ensure!(
                data.len() >= b.length(),
                "{what}: byteLength is {} but only {} bytes are there",
                b.length(),
                data.len()
            );
            data.truncate(b.length());
            buffers.push(data);
        }
        Ok(buffers)
    }

    /// The bytes of a buffer view, checked against its buffer.
    pub(super) fn view_bytes(&self, view: &View) -> Result<&[u8]> {
        let buffer = &self.buffers[view.buffer().index()];
        let (offset, len) = (view.offset(), view.length());
        offset
            .checked_add(len)
            .filter(|&end| end <= buffer.len())
            .map(|end| &buffer[offset..end])
            .with_context(|| {
                format!(
                    "bufferView {} (offset {offset}, length {len}) lies outside buffer {} \
                     ({} bytes)",
                    view.index(),
                    view.buffer().index(),
                    buffer.len()
                )
            })
    }

    /// Image `index` of the document.
    fn image(&self, index: u32) -> Result<::gltf::Image<'_>> {
        self.doc
            .images()
            .nth(index as usize)
            .with_context(|| format!("image {index} does not exist"))
    }

    /// Decodes image `index` (PNG or JPEG, from a buffer view, a file or a data URI) within
    /// `budgets` (charged by the caller).
    pub fn texture_image(&self, index: u32, budgets: &DecodeBudgets) -> Result<TextureImage> {
        let image = self.image(index)?;
        let what = match image.name() {
            Some(name) => format!("image {index} ({name:?})"),
            None => format!("image {index}"),
        };
        let bytes: Cow<[u8]> = match image.source() {
            ::gltf::image::Source::View { view, .. } => {
                Cow::Borrowed(self.view_bytes(&view).with_context(|| what.clone())?)
            }
            ::gltf::image::Source::Uri { uri, .. } => Cow::Owned(self.read_uri(uri, &what)?),
        };
        TextureImage::decode(&bytes, &what, budgets)
    }

    /// What image `index` decodes: its buffer view, or the file or data URI it names (two
    /// images with equal identities are the same texels).
    pub fn image_identity(&self, index: u32) -> Result<String> {
        let image = self.image(index)?;
        Ok(match image.source() {
            ::gltf::image::Source::View { view, .. } => format!("view {}", view.index()),
            ::gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
                format!("data {}", hex_sha256(uri.as_bytes()))
            }
            ::gltf::image::Source::Uri { uri, .. } => {
                let path = local_path(&self.dir, uri).with_context(|| format!("image {index}"))?;
                let path = std::fs::canonicalize(&path).unwrap_or(path);
                format!("file {}", path.display())
            }
        })
    }

    /// The contents of a buffer or image URI; external files are logged with their checksum.
    fn read_uri(&self, uri: &str, what: &str) -> Result<Vec<u8>> {
        if let Some(rest) = uri.strip_prefix("data:") {
            return decode_data_uri(rest, MAX_DATA_URI_BYTES).with_context(|| what.to_string());
        }
        let path = local_path(&self.dir, uri).with_context(|| format!("{what}: uri {uri:?}"))?;
        let bytes = read_limited(&path).with_context(|| format!("{what}: uri {uri:?}"))?;
        let sha = hex_sha256(&bytes);
        self.read_log.borrow_mut().insert(uri.to_string(), sha);
        Ok(bytes)
    }

    /// SHA-256 of the external file at `uri` (from the log when it was read already).
    fn resource_sha256(&self, uri: &str) -> Result<String> {
        if let Some(sha) = self.read_log.borrow().get(uri) {
            return Ok(sha.clone());
        }
        let path = local_path(&self.dir, uri).with_context(|| format!("uri {uri:?}"))?;
        Ok(hex_sha256(&read_limited(&path)?))
    }
}

/// GLB: magic, version 2 and a total length that fits the file. (The crate subtracts the
/// header size from the declared length unchecked.)
fn check_glb_header(bytes: &[u8]) -> Result<()> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let word = |i: usize| {
        bytes
            .get(i..i + 4)
            .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        bail!("the GLB header is truncated ({} bytes)", bytes.len());
    };
    ensure!(version == 2, "GLB version {version} is not 2 (glTF 2.0)");
    ensure!(
        (20..=bytes.len() as u64).contains(&(length as u64)),
        "GLB header declares {length} bytes, but the file has {}",
        bytes.len()
    );
    Ok(())
}

fn check_version(asset: &::gltf::json::Asset) -> Result<()> {
    let major = |v: &str| v.split('.').next().and_then(|m| m.parse::<u32>().ok());
    ensure!(
        major(&asset.version) == Some(2),
        "asset.version is {:?}: only glTF 2.x is read",
        asset.version
    );
    if let Some(min) = &asset.min_version {
        ensure!(
            min.as_str() <= "2.0",
            "asset.minVersion {min:?} is newer than glTF 2.0"
        );
    }
    Ok(())
}

fn check_required_extensions(required: &[String]) -> Result<()> {
    let missing: Vec<&str> = required
        .iter()
        .map(String::as_str)
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    ensure!(
        missing.is_empty(),
        "requires extensions lfgen does not support: {} (supported: {}; re-export without \
         them, e.g. without Draco mesh compression)",
        missing.join(", "),
        SUPPORTED_EXTENSIONS.join(", ")
    );
    Ok(())
}

/// Every primitive's `POSITION` accessor exists. The crate's validation reads that accessor
/// without a bounds check (gltf-json 1.4.1 panics on a bad index), so this runs first.
fn check_position_accessors(json: &::gltf::json::Root) -> Result<()> {
    use ::gltf::json::validation::Checked;
    let positions = Checked::Valid(::gltf::Semantic::Positions);
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(index) = prim.attributes.get(&positions) {
                ensure!(
                    index.value() < json.accessors.len(),
                    "meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} does not \
                     exist ({} accessors)",
                    index.value(),
                    json.accessors.len()
                );
            }
        }
    }
    Ok(())
}

/// The crate's error, readable: validation errors list their JSON paths.
fn describe(e: ::gltf::Error) -> anyhow::Error {
    match e {
        ::gltf::Error::Validation(errors) => {
            let shown: Vec<String> = errors
                .iter()
                .take(8)
                .map(|(path, err)| format!("{}: {err}", path.as_str()))
                .collect();
            let more = errors.len().saturating_sub(shown.len());
            let more = if more > 0 {
                format!(" (and {more} more)")
            } else {
                String::new()
            };
            anyhow!("invalid glTF: {}{more}", shown.join("; "))
        }
        other => anyhow!("not a readable glTF 2.0 file: {other}"),
    }
}

/// Resolves a relative URI inside `dir`: no scheme, no absolute path, no `..`, and after
/// following symbolic links still inside `dir`.
fn local_path(dir: &Path, uri: &str) -> Result<PathBuf> {
    let colon = uri.find(':');
    let slash = uri.find(['/', '\\']);
    if let Some(c) = colon.filter(|&c| slash.is_none_or(|s| c < s)) {
        bail!(
            "{:?} is a URL or an absolute path: only files beside the glTF are read",
            &uri[..=c]
        );
    }
    resolve_inside(dir, dir, &percent_decode(uri)?, "the glTF's")
}

/// `%XX` escapes of a URI decoded (glTF URIs are RFC 3986 references).
fn percent_decode(uri: &str) -> Result<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .context("malformed %-escape in the URI")?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).context("the URI is not UTF-8 once decoded")
}

/// The payload of a `data:[<mime>];base64,<data>` URI (`rest` follows `data:`), refusing
/// more than `limit` decoded bytes before decoding anything.
fn decode_data_uri(rest: &str, limit: usize) -> Result<Vec<u8>> {
    let (meta, data) = rest
        .split_once(',')
        .context("malformed data URI (no comma)")?;
    ensure!(
        meta.ends_with(";base64"),
        "data URI is not base64-encoded ({meta:?})"
    );
    let decoded_len = data.len() / 4 * 3;
    ensure!(
        decoded_len <= limit,
        "data URI holds about {decoded_len} bytes, more than the limit of {limit}"
    );
    base64::engine::general_purpose::STANDARD
        .decode(data)
        .context("data URI is not valid base64")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_stay_beside_the_gltf() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().canonicalize().unwrap();
        std::fs::create_dir(root.join("tex")).unwrap();
        std::fs::write(root.join("tex/a b.png"), b"x").unwrap();
        std::fs::write(dir.path().join("outside.bin"), b"x").unwrap();
        let inner = root.join("inner");
        std::fs::create_dir(&inner).unwrap();
        assert_eq!(
            local_path(&root, "tex/a%20b.png").unwrap(),
            root.join("tex/a b.png")
        );
        assert_eq!(
            local_path(&root, "./tex/a b.png").unwrap(),
            root.join("tex/a b.png")
        );
        for (uri, needle) in [
            ("../outside.bin", ".."),
            ("tex/../../outside.bin", ".."),
            ("/etc/passwd", "absolute"),
            ("http://example.com/a.bin", "URL"),
            ("file:///etc/passwd", "URL"),
            ("C:\\data\\a.bin", "URL"),
            ("%2E%2E/outside.bin", ".."),
            ("missing.bin", "cannot open"),
            ("", "empty"),
        ] {
            let err = local_path(&inner, uri).unwrap_err();
            assert!(format!("{err:#}").contains(needle), "{uri}: {err:#}");
        }
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(root.join("outside.bin"), inner.join("link.bin")).unwrap();
            let err = local_path(&inner, "link.bin").unwrap_err();
            assert!(format!("{err:#}").contains("outside"), "{err:#}");
        }
    }

    #[test]
    fn data_uris_are_base64_and_bounded() {
        assert_eq!(
            decode_data_uri("application/octet-stream;base64,AAEC", 16).unwrap(),
            [0, 1, 2]
        );
        let err = decode_data_uri("application/octet-stream;base64,AAECAAEC", 4).unwrap_err();
        assert!(format!("{err:#}").contains("limit"), "{err:#}");
        assert!(decode_data_uri("text/plain,hello", 16).is_err());
        assert!(decode_data_uri("application/octet-stream;base64,@@@@", 16).is_err());
    }

    #[test]
    fn glb_headers_are_checked_before_the_crate_reads_them() {
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(4u32.to_le_bytes());
        glb.extend([0; 12]);
        let err = check_glb_header(&glb).unwrap_err();
        assert!(format!("{err}").contains("declares"), "{err}");
        glb[4] = 1;
        assert!(format!("{}", check_glb_header(&glb).unwrap_err()).contains("version"));
        assert!(format!("{}", check_glb_header(b"glTF\x02").unwrap_err()).contains("truncated"));
        assert!(check_glb_header(b"{\"asset\":{}}").is_ok());
    }
}

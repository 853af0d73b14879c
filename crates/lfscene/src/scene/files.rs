//! Reading the files a scene refers to (glTF buffers and images, OBJ material libraries and
//! textures) safely: bounded sizes, and relative references that cannot leave their folder.

use anyhow::{Context, Result, bail, ensure};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest file (model, buffer or image) that is read.
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// Reads a whole regular file of at most [`MAX_FILE_BYTES`]. Devices, FIFOs and sockets are
/// refused before they are opened (their size reads 0, `/dev/zero` never ends and opening a
/// FIFO blocks), and the read itself stops past the limit in case the file grows meanwhile.
pub fn read_limited(path: &Path) -> Result<Vec<u8>> {
    let meta =
        std::fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?;
    ensure!(
        meta.is_file(),
        "{} is not a regular file (a device, FIFO or folder): not read",
        path.display()
    );
    let too_big = || {
        anyhow::anyhow!(
            "{} is more than the {} GiB lfgen reads",
            path.display(),
            MAX_FILE_BYTES >> 30
        )
    };
    if meta.len() > MAX_FILE_BYTES {
        return Err(too_big());
    }
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("cannot read {}", path.display()))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_big());
    }
    Ok(bytes)
}

/// Resolves the relative path `rel` (`/` or `\\` separated) from the folder `base` inside the
/// canonical folder `root` (`base` is `root` or below it): no absolute path, no `..` above
/// `root`, and after following symbolic links still inside `root`. `owner` names whose folder
/// `root` is in errors ("the glTF's").
pub fn resolve_inside(base: &Path, root: &Path, rel: &str, owner: &str) -> Result<PathBuf> {
    ensure!(!rel.is_empty(), "the reference is empty");
    ensure!(
        !rel.starts_with(['/', '\\']),
        "absolute paths are not read, only files inside {owner} folder"
    );
    let mut path = base.to_path_buf();
    for part in rel.split(['/', '\\']) {
        match part {
            "" | "." => {}
            ".." if path.starts_with(root) && path != root => {
                path.pop();
            }
            ".." => bail!("\"..\" would leave {owner} folder: only files inside it are read"),
            _ => path.push(part),
        }
    }
    let resolved = path
        .canonicalize()
        .with_context(|| format!("cannot open {}", path.display()))?;
    ensure!(
        resolved.starts_with(root),
        "{} leads outside {owner} folder (a symbolic link?)",
        path.display()
    );
    Ok(resolved)
}

//! Writers: a rendered scene's images and ground truth into an HCI-compatible scene folder.
//!
//! They see pixels, mode maps and the scene description, never rays. A scene is written into a
//! hidden temporary folder beside its final place and renamed when complete, so a killed run or a
//! full disk never leaves a half-written scene under the final name.

pub mod images;
pub mod preview;
pub mod scene_dir;

use sha2::{Digest, Sha256};

/// Lowercase hex SHA-256 of `bytes`.
pub fn hex_sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

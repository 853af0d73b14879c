//! Writers: a rendered scene's images and ground truth into an HCI-compatible scene folder.
//!
//! They see pixels, mode maps and the scene description, never rays. A scene is written into a
//! hidden temporary folder beside its final place and renamed when complete, so a killed run or a
//! full disk never leaves a half-written scene under the final name.

pub mod gt_files;
pub mod hci_mask_files;
pub mod images;
pub mod preview;
pub mod scene_dir;
pub mod texture_library;

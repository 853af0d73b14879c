//! On-disk format of an lfgen scene folder and dataset.
//!
//! Readers and writers only, no renderer, so that training and evaluation code can depend on
//! this crate without pulling in the path tracer. The HCI-compatible files (`parameters.cfg`,
//! PFM ground truth) follow the HCI 4D Light Field Benchmark conventions so existing tools read
//! them unchanged; the multimodal files (`modes.exr`, `gt_mpi_lowres.npz`) carry every depth
//! that contributes to a pixel, and `manifest.json` ties a dataset's scenes together.

pub mod catalog;
pub mod cli;
pub mod console;
pub mod dataset;
pub mod error;
pub mod files;
pub mod gt_maps;
pub mod hci_masks;
pub mod lock;
pub mod manifest;
pub mod modes;
pub mod mpi;
pub mod params;
pub mod pfm;
pub mod png;
pub mod read;
pub mod region_masks;
pub mod results;
pub mod rgb_exr;
pub mod srgb;
pub mod views;

pub use error::{Error, Result};
pub use modes::{Mode, ModeMap, ModeSurface};
pub use params::HciParameters;

/// The rows (`row_len` elements each) of `data`, last row first.
///
/// PFM and the thesis' MPI layout both store images bottom-up while this crate keeps them
/// top-down in memory; flipping is its own inverse, so readers and writers share this.
/// An empty row length only occurs with empty data, hence the `max(1)` guard.
fn flip_rows<T>(data: &[T], row_len: usize) -> impl Iterator<Item = &[T]> {
    data.rchunks_exact(row_len.max(1))
}

//! lfgen: multimodal light-field depth datasets.
//!
//! Data flows one way. From the bottom: the `lfscene` crate, re-exported here under the same
//! names — [`util`] (hashing, colour) → [`camera`], [`textures`] → [`scene`] (the
//! re-renderable description and its import); then [`procgen`] (random rooms; the
//! `lfprocgen` crate, drawing on the asset [`catalog`]: its schema in `lfformat`, the Sweet
//! Home 3D converter in `lfassets`) and [`render`] (the
//! `lfrender` crate: colour and 128-slice ground truth in memory) → [`output`] (scene
//! folders), [`export`], [`stats`] → [`config`] (the CLI's settings, mapped onto each layer's
//! own) → [`pipeline`] (one scene through those stages) → [`dataset`] (many scenes, shards,
//! manifest). The crate graph and `tests/layers.rs` keep every module from naming a layer above
//! it.

pub use lfprocgen as procgen;
pub use lfrender as render;
pub use lfscene::{camera, scene, textures, util};

/// The asset catalogue: `catalog.json`'s schema (from `lfformat`) and the converters that write
/// one (from `lfassets`), under the one name the CLI and the tests use.
pub mod catalog {
    pub use lfassets::sweethome3d;
    pub use lfformat::catalog::*;
}

pub mod appearance;
pub mod bench;
pub mod config;
pub mod dataset;
pub mod export;
pub mod output;
pub mod pipeline;
pub mod reference;
pub mod stats;

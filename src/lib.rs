//! lfgen: multimodal light-field depth datasets.
//!
//! Data flows one way. From the bottom, in the `lfscene` crate (re-exported here under the same
//! names): [`util`] (hashing, colour) → [`camera`], [`textures`] → [`scene`] (the
//! re-renderable description and its import); in this crate → [`procgen`] (random rooms) and
//! [`render`] (colour and 128-slice ground truth in memory) → [`output`] (scene folders),
//! [`export`], [`stats`] → [`config`] (the CLI's settings, mapped onto each layer's own) →
//! [`pipeline`] (one scene through those stages) → [`dataset`] (many scenes, shards, manifest).
//! `tests/layers.rs` keeps every module from naming a layer above it.

pub use lfscene::{camera, scene, textures, util};

pub mod bench;
pub mod catalog;
pub mod config;
pub mod dataset;
pub mod export;
pub mod output;
pub mod pipeline;
pub mod procgen;
pub mod render;
pub mod stats;

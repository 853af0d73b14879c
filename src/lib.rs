//! lfgen: multimodal light-field depth datasets.
//!
//! Data flows one way. From the bottom: [`util`] (hashing, colour) → [`camera`], [`textures`]
//! → [`scene`] (the re-renderable description and its import) → [`procgen`] (random rooms) and
//! [`render`] (colour and 128-slice ground truth in memory) → [`output`] (scene folders),
//! [`export`], [`stats`] → [`config`] (the CLI's settings, mapped onto each layer's own) →
//! [`pipeline`] (one scene through those stages) → [`dataset`] (many scenes, shards, manifest).
//! `tests/layers.rs` keeps every module from naming a layer above it.

pub mod bench;
pub mod camera;
pub mod catalog;
pub mod config;
pub mod dataset;
pub mod export;
pub mod output;
pub mod pipeline;
pub mod procgen;
pub mod render;
pub mod scene;
pub mod stats;
pub mod textures;
pub mod util;

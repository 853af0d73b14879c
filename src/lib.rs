//! lfgen: multimodal light-field depth datasets.
//!
//! Data flows one way: [`config`] → [`scene`] (a re-renderable description) → [`render`]
//! (colour and 128-slice ground truth in memory) → [`output`] (scene folders) → [`dataset`]
//! (many scenes, shards, manifest). [`pipeline`] drives one scene through those stages.

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

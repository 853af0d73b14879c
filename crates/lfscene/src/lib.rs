//! The scene layer of lfgen: everything a scene *is*, with no renderer, generator, writer or
//! CLI inside.
//!
//! From the bottom: [`util`] (hashing, colour) → [`camera`] (the HCI light-field camera grid)
//! and [`textures`] (procedural seamless textures) → [`scene`] (the re-renderable description,
//! its limits, reader and checks, and import from glTF and OBJ). The renderer (`lfgen::render`),
//! the procedural generator (`lfgen::procgen`) and the writers build on it; the crate graph
//! keeps this crate from reaching up into them.

pub mod camera;
pub mod scene;
pub mod textures;
pub mod util;

//! The procedural generator: random rooms with openings, furniture (built-in pieces and
//! catalogue assets), placement, materials and lights, written as a [`SceneDesc`] that the
//! renderer frames and renders. Nothing here renders or writes files.
//!
//! [`builtin`] draws one room; [`furniture`] builds pieces from primitives, [`library`] from
//! an asset catalogue; [`placement`] keeps them apart and in view; [`openings`] cuts doors and
//! windows.
//!
//! [`SceneDesc`]: crate::scene::SceneDesc

// The layers below under the names the generator's modules use (`crate::scene::…`); private,
// so they are not re-exported from here.
use lfformat::catalog;
use lfscene::{camera, scene, textures, util};

pub mod builtin;
pub mod furniture;
pub mod library;
pub mod openings;
pub mod placement;
pub mod settings;

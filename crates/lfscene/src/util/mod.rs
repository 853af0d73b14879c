//! Small shared maths with no knowledge of scenes, rendering or files (pbrt's `util/`): every
//! layer may use it, it uses none of them.

pub mod colour;
pub mod hash;

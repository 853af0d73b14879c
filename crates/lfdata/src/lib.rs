//! The data layer under `lfeval` and `lftrain` (crate `lfdata`): everything that reads a
//! dataset, writes a prediction or compares the two, once.
//!
//! Layout: [`lightfield`] the views in memory (loading, crop, rotation), [`stacks`] the view
//! stacks through the centre view and the bilinear EPI shift, [`cost`] the plane-sweep cost
//! (the classical baseline's volume and a stack's network input), [`denoise`] the test-time
//! cross-view denoising; [`bins`] and [`laplace`] the
//! discretisation maths, [`posterior`] the predicted distributions, [`prediction`] (with
//! [`npz`]) the prediction files, [`truth`] the ground truth (modes, front-most mode, masks);
//! [`metrics`] the pure metric functions and [`scene_eval`] every metric of one method on one
//! scene; [`camera`] what a real camera adds (vignetting, JPEG, sensor noise) for the
//! robustness benchmark and the trainer's augmentation; [`progress`] and [`font`] the
//! terminal's progress bar and the charts' font that the binaries share. Scene discovery and the file formats themselves are `lfformat`'s.

pub mod bins;
pub mod camera;
pub mod cost;
pub mod denoise;
pub mod font;
pub mod laplace;
pub mod lightfield;
pub mod metrics;
pub mod npz;
pub mod posterior;
pub mod prediction;
pub mod progress;
pub mod regions;
pub mod scene_eval;
pub mod stacks;
pub mod truth;

pub use bins::Bins;

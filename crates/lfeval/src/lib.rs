//! Evaluation of light-field depth predictions (crate `lfeval`).
//!
//! Reads datasets written by `lfgen` (HCI scene folders plus multimodal ground truth) and plain
//! HCI benchmark scenes, reads predictions in the HCI submission layout extended by optional
//! uncertainty maps and posteriors, and computes the HCI toolkit metrics, the thesis' posterior
//! metrics (KLD over disparity bins, sparsification, AuSE), and reports with plots. A classical
//! cost-volume estimator ([`baseline`]) gives every dataset a yardstick that needs no training.
//!
//! Layout: [`bins`] and [`laplace`] are the discretisation maths, [`posterior`] the predicted
//! distributions, [`truth`] the ground truth, [`metrics`] the pure metric functions,
//! [`scene_eval`] one method on one scene, [`summary`] one method over a dataset,
//! [`prediction`] (with [`npz`]) the files read (scene discovery and views: `lfformat`), [`pipeline`] the dataset
//! loops with I/O and progress, [`report`] the output files.

pub mod baseline;
pub mod bins;
pub mod laplace;
pub mod metrics;
pub mod npz;
pub mod pipeline;
pub mod posterior;
pub mod prediction;
pub mod report;
pub mod scene_eval;
pub mod summary;
pub mod truth;

pub use bins::Bins;

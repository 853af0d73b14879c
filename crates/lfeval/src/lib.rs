//! Evaluation of light-field depth predictions (crate `lfeval`).
//!
//! Reads datasets written by `lfgen` (HCI scene folders plus multimodal ground truth) and plain
//! HCI benchmark scenes, reads predictions in the HCI submission layout extended by optional
//! uncertainty maps and posteriors, and computes the HCI toolkit metrics, the thesis' posterior
//! metrics (KLD over disparity bins, sparsification, AuSE), and reports with plots. A classical
//! cost-volume estimator ([`baseline`]) gives every dataset a yardstick that needs no training.
//!
//! Layout: the data it reads and the metric functions are `lfdata`'s (the ground truth, the
//! prediction and posterior formats, bins, the metrics of one method on one scene, shared
//! with `lftrain`'s validation); [`summary`] is one method over a dataset, [`pipeline`] the
//! dataset loops with I/O and progress, [`report`] the output files.

pub mod baseline;
pub mod pipeline;
pub mod report;
pub mod robust;
pub mod slfc;
pub mod summary;

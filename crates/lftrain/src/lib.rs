//! Training of the thesis' light-field posterior models (crate `lftrain`).
//!
//! Trains the four models of thesis §5.2.1 — BASE (a disparity), UPR (a Laplacian), ESE (the
//! UPR network with a masked loss, ensembled over EPI shifts at inference) and DPP (a softmax
//! over disparity bins) — on an EPINET-style network (appendix B.1), which reads either the
//! views or their plane-sweep cost volume (not in the thesis), and EPI-Shift (chapter 4:
//! a classification and an offset per integer EPI shift, a U-Net) with burn, on lfgen
//! datasets (multimodal ground truth) or plain HCI scenes, and writes predictions in the
//! formats `lfeval` reads.
//!
//! Layout: the light field, its four stacks, the EPI shift and a stack's cost volume are
//! `lfdata`'s (shared with `lfeval`); the data pipeline is [`input`] (the stacks or their cost
//! volume, the alternative network input, which [`costnet`] can aggregate), [`augment`]
//! (colours), [`scene`] (targets), [`sample`] (one augmented crop, batches) and [`loader`]
//! (background prefetch);
//! the learning side is [`model`], [`loss`] and [`tensors`]; EPI-Shift's own parts are
//! [`shift_sample`], [`unet`], [`epishift`], [`shift_loss`] and [`shift_predict`]; [`train`],
//! [`validate`], [`predict`], [`run`] (the run folder) and [`log`] are the commands'
//! machinery; [`config`] holds every setting.

pub mod augment;
pub mod config;
pub mod costnet;
pub mod epishift;
pub mod input;
pub mod loader;
pub mod log;
pub mod loss;
pub mod mask;
pub mod model;
pub mod predict;
pub mod run;
pub mod sample;
pub mod scene;
pub mod shift_loss;
pub mod shift_predict;
pub mod shift_sample;
pub mod synthetic;
pub mod tensors;
pub mod train;
pub mod unet;
pub mod validate;

//! One training or validation scene in memory: its star views and its disparity targets.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use lfdata::lightfield::LightField;
use lfdata::truth::{EtaKind, SceneTruth, dominant, eta_of, front};
use lfformat::Mode;

use crate::config::{TrainConfig, UnimodalTarget};
use crate::mask::texture_mask;

/// Per-pixel disparity targets: `modes` pairs `(d_j, η_j)` per pixel, interleaved
/// (`(pixel * modes + j) * 2`), row-major, top row first. Unused slots are `(0, 0)` so that
/// `η · loss` is exactly zero there (a NaN disparity would poison the sum even with `η = 0`).
#[derive(Clone, Debug, PartialEq)]
pub struct Targets {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Slots per pixel.
    pub modes: usize,
    /// `width * height * modes * 2` values.
    pub pairs: Vec<f32>,
}

impl Targets {
    /// Targets of `truth`: the mode `unimodal` picks with `η = 1` when `modes == 1` (the
    /// thesis' unimodal truth), else the first `modes` modes front to back with their `η`.
    pub fn from_truth(truth: &SceneTruth, modes: usize, unimodal: Unimodal) -> Self {
        let mut pairs = Vec::with_capacity(truth.width() * truth.height() * modes * 2);
        for pixel in truth.modes.pixels() {
            let mut slots = vec![0.0f32; modes * 2];
            if modes == 1 {
                if let Some(d) = unimodal.pick(pixel).filter(|d| d.is_finite()) {
                    slots = vec![d, 1.0];
                }
            } else {
                let valid = pixel
                    .iter()
                    .filter(|m| eta_of(m, EtaKind::Over) > 0.0 && m.disparity.is_finite());
                for (slot, m) in slots.chunks_exact_mut(2).zip(valid) {
                    slot.copy_from_slice(&[m.disparity, eta_of(m, EtaKind::Over)]);
                }
            }
            pairs.extend_from_slice(&slots);
        }
        Self {
            width: truth.width(),
            height: truth.height(),
            modes,
            pairs,
        }
    }
}

/// How a unimodal target is chosen: [`UnimodalTarget`] with its visibility threshold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unimodal {
    pub target: UnimodalTarget,
    pub min_eta: f32,
}

impl Unimodal {
    /// The target of `cfg`.
    pub fn of(cfg: &TrainConfig) -> Self {
        Self {
            target: cfg.target,
            min_eta: cfg.target_min_eta,
        }
    }

    /// The chosen disparity of a pixel's modes (front to back), if it has any.
    pub fn pick(self, modes: &[Mode]) -> Option<f32> {
        match self.target {
            UnimodalTarget::Front => front(modes, EtaKind::Over),
            UnimodalTarget::Dominant => dominant(modes, EtaKind::Over),
            UnimodalTarget::Visible => modes
                .iter()
                .find(|m| eta_of(m, EtaKind::Over) >= self.min_eta && m.disparity.is_finite())
                .map(|m| m.disparity)
                .or_else(|| dominant(modes, EtaKind::Over)),
        }
    }
}

/// A scene ready for sampling.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Folder name (predictions are named after it).
    pub name: String,
    /// Scene folder.
    pub dir: PathBuf,
    /// Star views.
    pub lf: LightField,
    /// Disparity targets of the centre view.
    pub targets: Targets,
    /// 1 where the centre view is textured enough for a loss, 0 where flat (row-major);
    /// all 1 until [`Scene::with_texture_mask`].
    pub texture: Vec<f32>,
}

impl Scene {
    /// Loads views and ground truth (`modes.exr` if present, else `gt_disp_lowres.pfm`).
    pub fn load(dir: &Path, name: &str, modes: usize, unimodal: Unimodal) -> Result<Self> {
        let lf = LightField::load_star(dir)?;
        let truth = SceneTruth::load(dir)?;
        if (truth.width(), truth.height()) != (lf.width, lf.height) {
            bail!(
                "{}: ground truth is {}x{}, the views are {}x{}",
                dir.display(),
                truth.width(),
                truth.height(),
                lf.width,
                lf.height
            );
        }
        Ok(Self {
            name: name.to_string(),
            dir: dir.to_path_buf(),
            targets: Targets::from_truth(&truth, modes, unimodal),
            texture: vec![1.0; lf.width * lf.height],
            lf,
        })
    }

    /// The scene with its flat pixels masked ([`texture_mask`] of the centre view).
    pub fn with_texture_mask(self, window: usize, threshold: f32) -> Self {
        let (cu, cv) = self.lf.centre();
        let (w, h) = (self.lf.width, self.lf.height);
        let texture = texture_mask(self.lf.view(cu, cv), w, h, window, threshold);
        Self { texture, ..self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lfformat::pfm::FloatImage;
    use lfformat::{Mode, ModeMap};

    fn mode(disparity: f32, eta: f32) -> Mode {
        Mode {
            disparity,
            depth: 1.0,
            eta,
            eta_exact: eta,
        }
    }

    #[test]
    fn unimodal_targets_take_the_front_mode_and_multimodal_pad_with_zero() {
        let mut modes = ModeMap::new(2, 1);
        modes.push_pixel(&[mode(1.5, 0.4), mode(-1.0, 0.6)]);
        modes.push_pixel(&[]);
        let truth = SceneTruth {
            hci: FloatImage::new(2, 1, vec![1.5, f32::NAN]),
            modes,
        };
        let front = Unimodal {
            target: UnimodalTarget::Front,
            min_eta: 0.1,
        };
        let uni = Targets::from_truth(&truth, 1, front);
        assert_eq!(uni.pairs, vec![1.5, 1.0, 0.0, 0.0]);
        let multi = Targets::from_truth(&truth, 3, front);
        assert_eq!(
            multi.pairs,
            vec![1.5, 0.4, -1.0, 0.6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        );
    }

    #[test]
    fn the_visible_target_skips_slivers_and_falls_back_to_the_dominant_mode() {
        let pick = |target, modes: &[Mode]| {
            Unimodal {
                target,
                min_eta: 0.1,
            }
            .pick(modes)
        };
        // A 1e-4 sliver in front of a wall: "front" takes the sliver, "visible" the wall.
        let sliver = [mode(3.0, 1e-4), mode(0.5, 0.9999)];
        assert_eq!(pick(UnimodalTarget::Front, &sliver), Some(3.0));
        assert_eq!(pick(UnimodalTarget::Visible, &sliver), Some(0.5));
        // A visible foreground (η 0.3) stays the target although the back has more η.
        let veil = [mode(2.0, 0.3), mode(-1.0, 0.7)];
        assert_eq!(pick(UnimodalTarget::Visible, &veil), Some(2.0));
        assert_eq!(pick(UnimodalTarget::Dominant, &veil), Some(-1.0));
        // No mode reaches 0.1: the dominant one.
        let faint = [mode(1.0, 0.04), mode(0.0, 0.06)];
        assert_eq!(pick(UnimodalTarget::Visible, &faint), Some(0.0));
        assert_eq!(pick(UnimodalTarget::Visible, &[]), None);
    }
}

//! One EPI orientation of a light field: the grey views along one axis through the centre
//! view, the dictionary for their offsets, and the per-pixel Lasso coding of the EPI window
//! around a pixel.

use super::dictionary::Dictionary;
use super::lasso::{self, LassoSettings, Problem, Workspace};

/// The views along one axis (horizontal: the centre row, vertical: the centre column).
pub struct EpiStack {
    /// Along x (`true`) or y.
    pub horizontal: bool,
    /// Grey images, `width × height` row-major, in the order of the dictionary's offsets.
    pub planes: Vec<Vec<f32>>,
    /// Image columns.
    pub width: usize,
    /// Image rows.
    pub height: usize,
    /// Window radius.
    pub radius: usize,
    /// The atoms for these views and this stack's generators.
    pub dict: Dictionary,
}

/// Per-thread scratch of [`EpiStack::code`].
pub struct Scratch {
    patch: Vec<f64>,
    dty: Vec<f64>,
    lasso: Workspace,
}

impl EpiStack {
    /// The stack of `planes` along one axis (in the order of the offsets `dict` was made
    /// for), coding windows of radius `radius` against `dict` (see [`Dictionary::new`]).
    pub fn new(
        horizontal: bool,
        planes: Vec<Vec<f32>>,
        (width, height): (usize, usize),
        radius: usize,
        dict: Dictionary,
    ) -> Self {
        Self {
            horizontal,
            planes,
            width,
            height,
            radius,
            dict,
        }
    }

    /// Empty scratch sized for this stack.
    pub fn scratch(&self) -> Scratch {
        Scratch {
            patch: vec![0.0; self.dict.len],
            dty: vec![0.0; self.dict.count()],
            lasso: Workspace::default(),
        }
    }

    /// The EPI window around pixel `(x, y)`, view after view, positions clamped to the image
    /// (the border pixel repeats, as in the thesis' EPI shift).
    fn patch(&self, x: usize, y: usize, out: &mut [f64]) {
        let (len, along) = if self.horizontal {
            (self.width, x)
        } else {
            (self.height, y)
        };
        let span = 2 * self.radius + 1;
        for (plane, row) in self.planes.iter().zip(out.chunks_exact_mut(span)) {
            for (j, o) in row.iter_mut().enumerate() {
                let t = (along + j).saturating_sub(self.radius).min(len - 1);
                let i = if self.horizontal {
                    y * self.width + t
                } else {
                    t * self.width + x
                };
                *o = f64::from(plane[i]);
            }
        }
    }

    /// Codes the window around `(x, y)` by the Lasso, starting from and overwriting `w` (a
    /// neighbour's solution is a good start). Returns whether the solver converged.
    pub fn code(
        &self,
        (x, y): (usize, usize),
        settings: &LassoSettings,
        w: &mut [f64],
        s: &mut Scratch,
    ) -> bool {
        self.patch(x, y, &mut s.patch);
        // The intercept: atoms have zero mean, so the signal's mean is fitted by it alone.
        let mean = s.patch.iter().sum::<f64>() / s.patch.len() as f64;
        s.patch.iter_mut().for_each(|v| *v -= mean);
        self.dict.correlate(&s.patch, &mut s.dty);
        let problem = Problem {
            dty: &s.dty,
            yty: s.patch.iter().map(|v| v * v).sum(),
            len: s.patch.len(),
        };
        lasso::solve(&self.dict.gram, &problem, settings, w, &mut s.lasso)
    }

    /// Adds `|w|` per disparity bin to `weights`.
    pub fn accumulate(&self, w: &[f64], weights: &mut [f64]) {
        for (total, bin) in weights.iter_mut().zip(w.chunks_exact(self.dict.generators)) {
            *total += bin.iter().map(|c| c.abs()).sum::<f64>();
        }
    }
}

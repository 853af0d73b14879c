//! The SLFC dictionary (Johannsen et al., CVPR 2016): EPI patches ("atoms") made by lifting
//! one-dimensional generators to every disparity hypothesis, so that each atom carries
//! exactly one disparity.
//!
//! A generator `g` is a 1-D intensity profile along a view row. Lifted to disparity `d`, it
//! becomes the EPI patch `a[s][j] = g(j + s·d)` over the views `s` (offsets from the centre
//! view, in grid steps) and the window columns `j = −r ..= r`: a fronto-parallel surface at
//! disparity `d` shows the centre view's profile at `x + s·d` in view `s`. The generators are
//! longer than the window (the paper crops the shifted generator to the atom): they span
//! `|t| ≤ R = r + ⌈max|s| · max|d|⌉`, every position any view of the window reaches.
//!
//! The paper takes the generators from dictionary learning or PCA of centre-view patches and
//! reports 1-D generators as the best choice. Here they are the DCT-II basis of that support,
//! `cos(πk(t + L/2)/L)` for `k = 1 ..= L − 1` (`L = 2R + 1`): the basis PCA of natural image
//! rows approaches (their autocorrelation is close to stationary), complete on the support,
//! so a surface's EPI window is exactly a combination of the atoms of its own disparity
//! (a truncated or window-sized basis is not, and the Lasso then spreads the surface over
//! neighbouring disparities). The generators are evaluated analytically at the sub-pixel
//! positions `j + s·d`, so lifting needs no resampling and no training data. The constant
//! generator (`k = 0`) is left out: a flat profile looks the same at every disparity.
//!
//! Each atom has its mean removed (the Lasso fits an intercept: scikit-learn's default) and is
//! scaled to unit root mean square, so its coefficient is an amplitude in intensity units and
//! the authors' `α = 0.01` is one percent of the intensity range.

use super::lasso::Gram;

/// Atoms of one EPI orientation, bin after bin, every generator within a bin.
pub struct Dictionary {
    /// Entries per atom: views × window width, view after view.
    pub len: usize,
    /// Generators per disparity bin.
    pub generators: usize,
    /// All atoms, atom after atom: atom `k · generators + g` lifts generator `g` to bin `k`.
    pub atoms: Vec<f64>,
    /// `DᵀD`.
    pub gram: Gram,
}

impl Dictionary {
    /// The dictionary for views at `offsets` (grid steps from the centre view along the EPI's
    /// axis), windows of radius `radius` and one disparity per bin in `disparities`.
    pub fn new(offsets: &[f32], radius: usize, disparities: &[f64]) -> Self {
        let width = 2 * radius + 1;
        let len = offsets.len() * width;
        let reach = offsets
            .iter()
            .fold(0.0f64, |m, &s| m.max(f64::from(s).abs()))
            * disparities.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let support = (2 * (radius + reach.ceil() as usize) + 1) as f64;
        let generators = support as usize - 1;
        let mut atoms = Vec::with_capacity(disparities.len() * generators * len);
        for &d in disparities {
            for g in 0..generators {
                let omega = std::f64::consts::PI * (g + 1) as f64 / support;
                let start = atoms.len();
                for &s in offsets {
                    for j in 0..width {
                        let t = j as f64 - radius as f64 + f64::from(s) * d;
                        atoms.push((omega * (t + support / 2.0)).cos());
                    }
                }
                normalise(&mut atoms[start..]);
            }
        }
        let count = disparities.len() * generators;
        let gram = Gram::of(&atoms, count, len);
        Self {
            len,
            generators,
            atoms,
            gram,
        }
    }

    /// Number of atoms.
    pub fn count(&self) -> usize {
        self.gram.atoms
    }

    /// `out = Dᵀy`.
    pub fn correlate(&self, y: &[f64], out: &mut [f64]) {
        for (o, atom) in out.iter_mut().zip(self.atoms.chunks_exact(self.len)) {
            *o = atom.iter().zip(y).map(|(a, b)| a * b).sum();
        }
    }
}

/// Removes the mean of `v` and scales it to unit root mean square (a flat `v` stays zero).
pub fn normalise(v: &mut [f64]) {
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    v.iter_mut().for_each(|x| *x -= mean);
    let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    if rms > 1e-9 {
        v.iter_mut().for_each(|x| *x /= rms);
    } else {
        v.iter_mut().for_each(|x| *x = 0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atoms_are_centred_unit_rms_and_shift_with_their_disparity() {
        let offsets = [-1.0f32, 0.0, 1.0];
        let dict = Dictionary::new(&offsets, 2, &[0.0, 1.0]);
        // Support radius 2 + ⌈1 · 1⌉ = 3: 7 samples, 6 generators.
        assert_eq!((dict.len, dict.generators, dict.count()), (15, 6, 12));
        for atom in dict.atoms.chunks_exact(dict.len) {
            let mean: f64 = atom.iter().sum::<f64>() / 15.0;
            let ms: f64 = atom.iter().map(|x| x * x).sum::<f64>() / 15.0;
            assert!(mean.abs() < 1e-12 && (ms - 1.0).abs() < 1e-12);
        }
        // At d = 0 every view repeats the centre row; at d = 1, view s is the centre row
        // moved left by s pixels (a[s][j] = g(j + s)).
        let at = |k: usize, g: usize, s: usize, j: usize| {
            dict.atoms[(k * dict.generators + g) * dict.len + s * 5 + j]
        };
        for g in 0..6 {
            for j in 0..5 {
                assert!((at(0, g, 0, j) - at(0, g, 1, j)).abs() < 1e-12);
            }
            for j in 0..4 {
                assert!((at(1, g, 1, j + 1) - at(1, g, 2, j)).abs() < 1e-12);
            }
        }
        // The Gram diagonal is each atom's squared norm: its length.
        assert!((dict.gram.values[0] - 15.0).abs() < 1e-9);
    }
}

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
//! The paper lifts parts of the light field itself: 1-D generators learned from centre-view
//! profiles (by dictionary learning or PCA), which it reports as the best of its choices.
//! Here they are the principal components of the centre view's profiles of length
//! `L = 2R + 1` along the stack's axis ([`Generators::of_view`]), as many as hold a given
//! share of their variance. Each is stored as its coordinates in the DCT-II basis of the
//! support, `cos(πk(t + L/2)/L)` for `k = 1 ..= L − 1`, which is orthogonal at the integer
//! positions and gives the generator between them as a smooth interpolant, so lifting to a
//! sub-pixel position `j + s·d` needs no resampling. The view's own components matter: with
//! the whole DCT basis (complete, but far from sparse for a given texture) the Lasso codes a
//! texture frequency that falls between two basis frequencies as a nearby basis frequency at
//! a proportionally wrong disparity (at |d| > 2 only 2–40 of 64 pixels of an analytic plane
//! within one bin), where the components code a surface with few atoms of its own
//! disparity and put every pixel within one bin (design/tried.md). The
//! constant profile is left out: it looks the same at every disparity.
//!
//! Each atom has its mean removed (the Lasso fits an intercept: scikit-learn's default) and is
//! scaled to unit root mean square, so its coefficient is an amplitude in intensity units and
//! the authors' `α = 0.01` is one percent of the intensity range.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

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
    /// axis), windows of radius `radius`, one disparity per bin in `disparities` and the
    /// `generators` (whose support must be [`support`]`(offsets, radius, disparities)`).
    pub fn new(
        offsets: &[f32],
        radius: usize,
        disparities: &[f64],
        generators: &Generators,
    ) -> Self {
        let width = 2 * radius + 1;
        let len = offsets.len() * width;
        let count = disparities.len() * generators.mixes.len();
        let mut atoms = Vec::with_capacity(count * len);
        let mut cosines = vec![0.0; len * generators.basis()];
        for &d in disparities {
            let positions = offsets.iter().flat_map(|&s| {
                (0..width).map(move |j| j as f64 - radius as f64 + f64::from(s) * d)
            });
            for (t, row) in positions.zip(cosines.chunks_exact_mut(generators.basis())) {
                generators.cosines(t, row);
            }
            for mix in &generators.mixes {
                let start = atoms.len();
                atoms.extend(
                    cosines
                        .chunks_exact(generators.basis())
                        .map(|row| row.iter().zip(mix).map(|(c, m)| c * m).sum::<f64>()),
                );
                normalise(&mut atoms[start..]);
            }
        }
        let gram = Gram::of(&atoms, count, len);
        Self {
            len,
            generators: generators.mixes.len(),
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

/// The generators' support `L = 2R + 1`, `R = r + ⌈max|s| · max|d|⌉`: every position a view
/// of a window of radius `radius` reaches at any of the `disparities`.
pub fn support(offsets: &[f32], radius: usize, disparities: &[f64]) -> usize {
    let reach = offsets
        .iter()
        .fold(0.0f64, |m, &s| m.max(f64::from(s).abs()))
        * disparities.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    2 * (radius + reach.ceil() as usize) + 1
}

/// The 1-D generators of one stack, each as its coordinates in the DCT-II basis of the
/// support (module doc).
pub struct Generators {
    /// Support length `L`.
    pub support: usize,
    /// One coordinate vector (`L − 1` values, `k = 1 ..= L − 1`) per generator.
    pub mixes: Vec<Vec<f64>>,
}

impl Generators {
    /// The principal components of `plane`'s profiles of length `support` along the stack's
    /// axis (rows if `horizontal`), one centred on every pixel whose profile lies inside the
    /// image (on every pixel, clamped at the border as the EPI windows are, when the image
    /// is shorter than the support), their means removed: the fewest components that hold
    /// `energy` of the profiles' variance, largest first, at least one.
    pub fn of_view(
        plane: &[f32],
        (width, height): (usize, usize),
        horizontal: bool,
        support: usize,
        energy: f64,
    ) -> Self {
        let basis = support - 1;
        let dct = coordinates(support);
        let mut cov = DMatrix::<f64>::zeros(basis, basis);
        let (along, across) = if horizontal {
            (width, height)
        } else {
            (height, width)
        };
        let half = support / 2;
        let mut profile = DVector::<f64>::zeros(support);
        let mut coords = DVector::<f64>::zeros(basis);
        // Profiles that reach past the border repeat its pixel, a shape no surface has: they
        // are left out unless the image is shorter than the support.
        let centres = if along >= support {
            half..along - half
        } else {
            0..along
        };
        for a in 0..across {
            for c in centres.clone() {
                for (i, p) in profile.iter_mut().enumerate() {
                    let t = (c + i).saturating_sub(half).min(along - 1);
                    *p = f64::from(
                        plane[if horizontal {
                            a * width + t
                        } else {
                            t * width + a
                        }],
                    );
                }
                coords.gemv(1.0, &dct, &profile, 0.0);
                cov.syger(1.0, &coords, &coords, 1.0);
            }
        }
        cov.fill_upper_triangle_with_lower_triangle();
        let eigen = SymmetricEigen::new(cov);
        let mut order: Vec<usize> = (0..basis).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
        let total: f64 = eigen.eigenvalues.iter().map(|v| v.max(0.0)).sum();
        let mut kept = 0.0;
        let mut mixes = Vec::new();
        for i in order {
            if !mixes.is_empty() && kept >= energy * total {
                break;
            }
            kept += eigen.eigenvalues[i].max(0.0);
            mixes.push(eigen.eigenvectors.column(i).iter().copied().collect());
        }
        Self { support, mixes }
    }

    /// Number of DCT basis functions, `L − 1`.
    fn basis(&self) -> usize {
        self.support - 1
    }

    /// The basis functions at position `t` (`|t| ≤ R`), into `out`.
    fn cosines(&self, t: f64, out: &mut [f64]) {
        basis_at(self.support, t, out);
    }
}

/// The DCT-II basis functions `cos(πk(t + L/2)/L)`, `k = 1 ..= L − 1`, of a support of
/// length `L = support` at position `t` (`|t| ≤ R`), into `out`.
fn basis_at(support: usize, t: f64, out: &mut [f64]) {
    let l = support as f64;
    for (k, o) in out.iter_mut().enumerate() {
        *o = (std::f64::consts::PI * (k + 1) as f64 / l * (t + l / 2.0)).cos();
    }
}

/// The matrix that takes a profile sampled at the support's integer positions `t = n − R`
/// to its coordinates: the basis functions there, scaled to be orthonormal (`√(2/L)`).
fn coordinates(support: usize) -> DMatrix<f64> {
    let (basis, half) = (support - 1, (support / 2) as f64);
    let scale = (2.0 / support as f64).sqrt();
    let mut column = vec![0.0; basis];
    let mut m = DMatrix::zeros(basis, support);
    for n in 0..support {
        basis_at(support, n as f64 - half, &mut column);
        for (k, c) in column.iter().enumerate() {
            m[(k, n)] = scale * c;
        }
    }
    m
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

    /// A `size²` grey view whose rows are `f(x, y)`.
    fn view(size: usize, f: impl Fn(f64, f64) -> f64) -> Vec<f32> {
        (0..size * size)
            .map(|i| f((i % size) as f64, (i / size) as f64) as f32)
            .collect()
    }

    #[test]
    fn atoms_are_centred_unit_rms_and_shift_with_their_disparity() {
        let offsets = [-1.0f32, 0.0, 1.0];
        // Support radius 2 + ⌈1 · 1⌉ = 3: 7 samples, 6 DCT functions.
        let support = support(&offsets, 2, &[0.0, 1.0]);
        assert_eq!(support, 7);
        let plane = view(16, |x, y| {
            ((x * 1.3 + y * y).sin() + (x * 0.4 - y).cos()) * 0.2
        });
        let generators = Generators::of_view(&plane, (16, 16), true, support, 1.0);
        let g = generators.mixes.len();
        assert!((1..=6).contains(&g), "{g} generators");
        let dict = Dictionary::new(&offsets, 2, &[0.0, 1.0], &generators);
        assert_eq!((dict.len, dict.generators, dict.count()), (15, g, 2 * g));
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
        for g in 0..g {
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

    /// Rows of one wave at a phase that changes from row to row are two profiles (its sine and
    /// cosine): PCA finds exactly two generators, and the DCT coordinates give the wave back
    /// between the integer positions, where the lifted atoms sample it.
    #[test]
    fn a_single_wave_gives_two_generators_that_interpolate_it() {
        let (size, support) = (48, 21);
        let wave = |x: f64, y: f64| 0.5 + 0.2 * (0.9 * x + 0.37 * y).sin();
        let plane = view(size, wave);
        let generators = Generators::of_view(&plane, (size, size), true, support, 0.99);
        assert_eq!(generators.mixes.len(), 2);
        // Fit the row y = 30 around x = 24 at half-pixel positions with the two generators.
        let half = (support / 2) as f64;
        let positions: Vec<f64> = (0..2 * support - 1)
            .map(|i| i as f64 / 2.0 - half)
            .collect();
        let mut row = vec![0.0; support - 1];
        let columns: Vec<Vec<f64>> = generators
            .mixes
            .iter()
            .map(|mix| {
                positions
                    .iter()
                    .map(|&t| {
                        generators.cosines(t, &mut row);
                        row.iter().zip(mix).map(|(c, m)| c * m).sum()
                    })
                    .collect()
            })
            .collect();
        let target: Vec<f64> = positions
            .iter()
            .map(|&t| wave(24.0 + t, 30.0) - 0.5)
            .collect();
        let a = DMatrix::from_fn(positions.len(), 2, |i, j| columns[j][i]);
        let b = DVector::from_vec(target.clone());
        let fit = a
            .clone()
            .svd(true, true)
            .solve(&b, 1e-12)
            .expect("least squares");
        let residual = (a * fit - &b).norm() / b.norm();
        // Away from the ends of the support the interpolant follows the wave closely.
        assert!(residual < 0.02, "relative residual {residual}");
    }
}

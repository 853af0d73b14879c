//! The Lasso `min_w 1/(2n)·‖y − D w‖² + α‖w‖₁` (scikit-learn's scaling, `n` = signal length)
//! by cyclic coordinate descent over the dictionary's Gram matrix `G = DᵀD`.
//!
//! Every pixel codes its own small signal against one fixed dictionary, so the solver never
//! touches `D`: it keeps the correlations `c = Dᵀ(y − D w)` and, when `w_j` changes by `δ`,
//! subtracts `δ·G[j]` from them. Zero coefficients whose correlation stays under the threshold
//! cost one comparison per sweep. After a full sweep it sweeps only the non-zero coordinates
//! until they settle, then sweeps everything again; it stops when the duality gap (below) is
//! at most `tol · ‖y‖²`, scikit-learn's stopping rule. A warm start (the neighbouring pixel's
//! solution) is allowed: any `w` is a valid starting point.
//!
//! Duality gap, in the `n`-scaled form `½‖r‖² + λ‖w‖₁` with `λ = nα` and `r = y − D w`: the
//! residual scaled into the dual feasible set, `θ = s·r` with `s = min(1, λ / ‖c‖∞)`, has dual
//! value `s·yᵀr − ½ s²‖r‖²`; the gap (primal minus dual) bounds the distance of the objective
//! to its optimum.

/// A dictionary's Gram matrix, `p × p` row-major (symmetric).
pub struct Gram {
    /// Number of atoms.
    pub atoms: usize,
    /// `G[i * atoms + j] = d_i · d_j`.
    pub values: Vec<f64>,
}

impl Gram {
    /// The Gram matrix of `atoms` atoms of length `len`, stored atom after atom in `dict`.
    pub fn of(dict: &[f64], atoms: usize, len: usize) -> Self {
        let mut values = vec![0.0; atoms * atoms];
        for i in 0..atoms {
            let a = &dict[i * len..(i + 1) * len];
            for j in i..atoms {
                let b = &dict[j * len..(j + 1) * len];
                let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
                values[i * atoms + j] = dot;
                values[j * atoms + i] = dot;
            }
        }
        Self { atoms, values }
    }

    fn row(&self, j: usize) -> &[f64] {
        &self.values[j * self.atoms..(j + 1) * self.atoms]
    }

    fn diagonal(&self, j: usize) -> f64 {
        self.values[j * self.atoms + j]
    }
}

/// Settings of the solver.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LassoSettings {
    /// The `α` of the objective.
    pub alpha: f64,
    /// Stop when the duality gap is at most `tol · ‖y‖²`.
    pub tol: f64,
    /// At most this many full sweeps.
    pub max_sweeps: usize,
}

/// The problem of one signal: `b = Dᵀy`, `‖y‖²` and the signal length `n`.
pub struct Problem<'a> {
    /// `Dᵀy`.
    pub dty: &'a [f64],
    /// `‖y‖²`.
    pub yty: f64,
    /// Length of `y`.
    pub len: usize,
}

/// Per-thread working memory: the correlations `c = Dᵀr`.
#[derive(Default)]
pub struct Workspace {
    corr: Vec<f64>,
}

/// Minimises the Lasso objective for `problem`, starting from and overwriting `w`. Returns
/// whether the duality gap fell under the tolerance within `max_sweeps` full sweeps.
pub fn solve(
    gram: &Gram,
    problem: &Problem,
    s: &LassoSettings,
    w: &mut [f64],
    ws: &mut Workspace,
) -> bool {
    let lambda = s.alpha * problem.len as f64;
    correlations(gram, problem.dty, w, &mut ws.corr);
    let target = s.tol * problem.yty;
    for _ in 0..s.max_sweeps {
        sweep(gram, lambda, w, &mut ws.corr, false);
        // Settle the active set before paying for another full sweep.
        for _ in 0..ACTIVE_SWEEPS {
            let change = sweep(gram, lambda, w, &mut ws.corr, true);
            if change <= ACTIVE_CHANGE {
                break;
            }
        }
        if duality_gap(problem, lambda, w, &ws.corr) <= target {
            return true;
        }
    }
    false
}

/// Active-set sweeps between two full sweeps, at most.
const ACTIVE_SWEEPS: usize = 50;
/// An active-set sweep whose largest coefficient change is under this ends the inner loop.
const ACTIVE_CHANGE: f64 = 1e-7;

/// `c = Dᵀy − G w`.
fn correlations(gram: &Gram, dty: &[f64], w: &[f64], corr: &mut Vec<f64>) {
    corr.clear();
    corr.extend_from_slice(dty);
    for (j, &wj) in w.iter().enumerate() {
        if wj != 0.0 {
            for (c, g) in corr.iter_mut().zip(gram.row(j)) {
                *c -= wj * g;
            }
        }
    }
}

/// One cyclic pass over every coordinate, or (`active_only`) over the non-zero ones. Returns
/// the largest coefficient change.
fn sweep(gram: &Gram, lambda: f64, w: &mut [f64], corr: &mut [f64], active_only: bool) -> f64 {
    let mut largest = 0.0f64;
    for j in 0..w.len() {
        let old = w[j];
        if active_only && old == 0.0 {
            continue;
        }
        let gjj = gram.diagonal(j);
        if gjj <= 0.0 {
            continue;
        }
        let z = corr[j] + gjj * old;
        let new = soft_threshold(z, lambda) / gjj;
        let delta = new - old;
        if delta != 0.0 {
            w[j] = new;
            for (c, g) in corr.iter_mut().zip(gram.row(j)) {
                *c -= delta * g;
            }
            largest = largest.max(delta.abs());
        }
    }
    largest
}

fn soft_threshold(z: f64, lambda: f64) -> f64 {
    z.signum() * (z.abs() - lambda).max(0.0)
}

/// The duality gap of `w` (module doc), from the maintained correlations `c = Dᵀr`:
/// `yᵀr = ‖y‖² − wᵀb` and `‖r‖² = ‖y‖² − wᵀb − wᵀc`, since `G w = b − c`.
fn duality_gap(problem: &Problem, lambda: f64, w: &[f64], corr: &[f64]) -> f64 {
    let (mut wtb, mut wtc, mut l1) = (0.0, 0.0, 0.0);
    for ((&wj, &bj), &cj) in w.iter().zip(problem.dty).zip(corr) {
        if wj != 0.0 {
            wtb += wj * bj;
            wtc += wj * cj;
            l1 += wj.abs();
        }
    }
    let ytr = problem.yty - wtb;
    let rtr = (ytr - wtc).max(0.0);
    let cmax = corr.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let s = if cmax > lambda { lambda / cmax } else { 1.0 };
    let primal = 0.5 * rtr + lambda * l1;
    let dual = s * ytr - 0.5 * s * s * rtr;
    primal - dual
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift generator, so the test needs no random crate.
    fn noise(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// KKT of the Lasso at its optimum, with `c = Dᵀ(y − D w) / n` computed from `D` itself
    /// (not the solver's Gram bookkeeping): `c_j = α·sign(w_j)` where `w_j ≠ 0`, `|c_j| ≤ α`
    /// where `w_j = 0`.
    #[test]
    fn solution_satisfies_the_kkt_conditions_on_a_random_problem() {
        let (len, atoms, alpha) = (30, 80, 0.01);
        let mut state = 0x9e37_79b9_7f4a_7c15;
        let dict: Vec<f64> = (0..len * atoms).map(|_| noise(&mut state)).collect();
        let y: Vec<f64> = (0..len).map(|_| noise(&mut state)).collect();
        let atom = |j: usize| &dict[j * len..(j + 1) * len];
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let dty: Vec<f64> = (0..atoms).map(|j| dot(atom(j), &y)).collect();
        let gram = Gram::of(&dict, atoms, len);
        let problem = Problem {
            dty: &dty,
            yty: dot(&y, &y),
            len,
        };
        let settings = LassoSettings {
            alpha,
            tol: 1e-12,
            max_sweeps: 10_000,
        };
        let mut w = vec![0.0; atoms];
        assert!(solve(
            &gram,
            &problem,
            &settings,
            &mut w,
            &mut Workspace::default()
        ));
        let mut r = y.clone();
        for (j, &wj) in w.iter().enumerate() {
            for (ri, a) in r.iter_mut().zip(atom(j)) {
                *ri -= wj * a;
            }
        }
        let active = w.iter().filter(|&&v| v != 0.0).count();
        assert!(active > 0 && active < atoms, "{active} active atoms");
        for (j, &wj) in w.iter().enumerate() {
            let c = dot(atom(j), &r) / len as f64;
            if wj != 0.0 {
                assert!(
                    (c - alpha * wj.signum()).abs() < 1e-6,
                    "atom {j}: c {c}, w {wj}"
                );
            } else {
                assert!(c.abs() <= alpha + 1e-6, "atom {j}: |c| {c} > α");
            }
        }
    }

    #[test]
    fn warm_start_reaches_the_same_solution_and_zero_signal_gives_zero() {
        let (len, atoms) = (12, 20);
        let mut state = 42;
        let dict: Vec<f64> = (0..len * atoms).map(|_| noise(&mut state)).collect();
        let gram = Gram::of(&dict, atoms, len);
        let dty: Vec<f64> = (0..atoms).map(|j| dict[j * len] * 3.0).collect();
        let problem = Problem {
            dty: &dty,
            yty: 9.0,
            len,
        };
        let settings = LassoSettings {
            alpha: 0.01,
            tol: 1e-14,
            max_sweeps: 100_000,
        };
        let mut ws = Workspace::default();
        let mut cold = vec![0.0; atoms];
        assert!(solve(&gram, &problem, &settings, &mut cold, &mut ws));
        let mut warm: Vec<f64> = (0..atoms).map(|j| j as f64 * 0.1).collect();
        assert!(solve(&gram, &problem, &settings, &mut warm, &mut ws));
        for (a, b) in cold.iter().zip(&warm) {
            assert!((a - b).abs() < 1e-5, "{cold:?} vs {warm:?}");
        }
        let zero = Problem {
            dty: &vec![0.0; atoms],
            yty: 0.0,
            len,
        };
        assert!(solve(&gram, &zero, &settings, &mut warm, &mut ws));
        assert!(warm.iter().all(|&v| v == 0.0), "{warm:?}");
    }
}

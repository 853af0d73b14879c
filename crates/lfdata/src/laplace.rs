//! The Laplace distribution `p(d) = exp(-|d - μ| / b) / 2b` of the thesis' UPR and ESE models
//! (eq. 5.5): its probability over an interval (eq. 5.22 in closed form) and its variance.

/// Probability that `Laplace(mu, b)` falls in `[lo, hi]`; `lo` may be `-∞`, `hi` `+∞`.
///
/// The CDF is `½·exp((x-μ)/b)` left of `μ` and `1 - ½·exp(-(x-μ)/b)` right of it. Intervals
/// entirely on one side use the difference of the two exponentials directly instead of
/// `F(hi) - F(lo)`, which would cancel to 0 in the far tails where the KLD still needs the
/// small masses. `b = 0` is a point mass at `μ` (counted in `[lo, hi)`); a NaN parameter or
/// a negative `b` has no mass anywhere.
pub fn mass(mu: f64, b: f64, lo: f64, hi: f64) -> f64 {
    if mu.is_nan() || b.is_nan() || b < 0.0 || hi <= lo {
        return 0.0;
    }
    if b == 0.0 {
        return if lo <= mu && mu < hi { 1.0 } else { 0.0 };
    }
    let right = |x: f64| (-(x - mu) / b).exp(); // 2·(1 - F(x)) for x ≥ μ
    let left = |x: f64| ((x - mu) / b).exp(); // 2·F(x) for x ≤ μ
    if lo >= mu {
        0.5 * (right(lo) - right(hi))
    } else if hi <= mu {
        0.5 * (left(hi) - left(lo))
    } else {
        1.0 - 0.5 * right(hi) - 0.5 * left(lo)
    }
}

/// Density `exp(-|x - μ| / b) / 2b` of `Laplace(mu, b)` at `x` (`b > 0`).
pub fn density(mu: f64, b: f64, x: f64) -> f64 {
    (-(x - mu).abs() / b).exp() / (2.0 * b)
}

/// Variance `2b²` of `Laplace(μ, b)`.
pub fn variance(b: f64) -> f64 {
    2.0 * b * b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn density_is_the_derivative_of_the_mass() {
        let (mu, b, h) = (0.3, 0.7, 1e-6);
        for x in [-2.0, 0.1, 0.3, 1.9] {
            let numeric = mass(mu, b, x - h, x + h) / (2.0 * h);
            assert!((density(mu, b, x) - numeric).abs() < 1e-6, "{x}");
        }
        assert_eq!(density(mu, b, mu), 1.0 / 1.4);
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn masses_match_hand_computed_values() {
        let e = std::f64::consts::E;
        // Laplace(0, 1): [0, 1] holds ½(1 - e⁻¹) = 0.316060…
        assert!(close(mass(0.0, 1.0, 0.0, 1.0), 0.5 * (1.0 - 1.0 / e)));
        assert!(close(mass(0.0, 1.0, 0.0, 1.0), 0.316_060_279_414_278_6));
        // Symmetric interval around μ: 1 - e⁻¹.
        assert!(close(mass(0.0, 1.0, -1.0, 1.0), 1.0 - 1.0 / e));
        // Left tail (-∞, -1]: ½e⁻¹ = 0.18393972…
        assert!(close(
            mass(0.0, 1.0, f64::NEG_INFINITY, -1.0),
            0.183_939_720_585_721_16
        ));
        // Shifted and narrower: Laplace(0, ½) on [1, 2] = ½(e⁻² - e⁻⁴) = 0.0585098…
        assert!(close(
            mass(0.0, 0.5, 1.0, 2.0),
            0.5 * (e.powi(-2) - e.powi(-4))
        ));
        assert!(close(mass(3.0, 0.5, 4.0, 5.0), mass(0.0, 0.5, 1.0, 2.0)));
    }

    #[test]
    fn whole_line_and_adjacent_intervals_add_up() {
        let (mu, b) = (0.3, 0.2);
        assert!(close(mass(mu, b, f64::NEG_INFINITY, f64::INFINITY), 1.0));
        let parts = mass(mu, b, f64::NEG_INFINITY, 0.0)
            + mass(mu, b, 0.0, 0.5)
            + mass(mu, b, 0.5, f64::INFINITY);
        assert!(close(parts, 1.0));
    }

    #[test]
    fn far_tails_keep_their_tiny_mass() {
        // F(hi) - F(lo) would give exactly 0 here; the closed form keeps ½(e⁻⁴⁰ - e⁻⁴¹).
        let m = mass(0.0, 0.1, 4.0, 4.1);
        let expected = 0.5 * ((-40.0f64).exp() - (-41.0f64).exp());
        assert!(m > 0.0 && ((m - expected) / expected).abs() < 1e-9);
    }

    #[test]
    fn degenerate_parameters() {
        assert_eq!(mass(0.5, 0.0, 0.0, 1.0), 1.0, "b = 0 is a point mass");
        assert_eq!(
            mass(1.0, 0.0, 0.0, 1.0),
            0.0,
            "point mass on the open upper edge"
        );
        assert_eq!(mass(f64::NAN, 1.0, 0.0, 1.0), 0.0);
        assert_eq!(mass(0.0, f64::NAN, 0.0, 1.0), 0.0);
        assert_eq!(mass(0.0, -1.0, 0.0, 1.0), 0.0);
        assert_eq!(variance(0.5), 0.5);
    }
}

//! Equal-width disparity bins: the discretisation shared by the KLD (thesis eq. 5.21–5.23),
//! discrete posteriors and the baseline's cost volume.
//!
//! The outer bins are open-ended: a value or probability mass below the range counts in the
//! first bin, above it in the last. Every distribution then keeps its total mass, so the KLD
//! compares like with like even for the rare mode outside the range, and truth, point
//! estimates and continuous posteriors all follow the same rule.

use serde::Serialize;

/// `count` bins of equal width over `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bins {
    /// Lower end of the first bin, pixels.
    pub min: f64,
    /// Upper end of the last bin, pixels.
    pub max: f64,
    /// Number of bins.
    pub count: usize,
}

impl Bins {
    /// The thesis' bins: 108 over `[-3.5, 3.5]` px, width ≈ 0.065 px, just below the 0.07 px
    /// BadPix threshold.
    pub const THESIS: Bins = Bins {
        min: -3.5,
        max: 3.5,
        count: 108,
    };

    /// Most bins [`Bins::covering`] makes: ±40 px at the thesis' width needs 1 235.
    pub const MAX_COVERING: usize = 100_000;

    /// Bins of the thesis' width (7/108 px, below BadPix's 0.07) over the union of `ranges`
    /// (each scene's `[disp_min, disp_max]`), or `count` bins over it: KLD and discrete
    /// posteriors for wide-baseline data (±40 px) whose modes the thesis' ±3.5 px would pile
    /// into the two open-ended outer bins.
    pub fn covering(
        ranges: impl IntoIterator<Item = (f64, f64)>,
        count: Option<usize>,
    ) -> Result<Self, String> {
        let (min, max) = ranges
            .into_iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            });
        if !(min.is_finite() && max.is_finite()) {
            return Err("no finite disparity range to cover".into());
        }
        let width = Self::THESIS.width();
        let count = count.unwrap_or_else(|| ((max - min) / width).ceil().max(1.0) as usize);
        if count > Self::MAX_COVERING {
            return Err(format!(
                "[{min}, {max}] needs {count} bins, over {}",
                Self::MAX_COVERING
            ));
        }
        Self::new(min, max, count)
    }

    /// Validated bins; the message says what is wrong.
    pub fn new(min: f64, max: f64, count: usize) -> Result<Self, String> {
        if !(min.is_finite() && max.is_finite() && min < max) {
            return Err(format!(
                "bin range [{min}, {max}] must be finite with min < max"
            ));
        }
        if count == 0 {
            return Err("the number of bins must be at least 1".into());
        }
        Ok(Self { min, max, count })
    }

    /// Width of one bin, `(max - min) / count`.
    pub fn width(&self) -> f64 {
        (self.max - self.min) / self.count as f64
    }

    /// Edge `i` (`0..=count`), computed the same way everywhere so that two identical grids
    /// produce bit-identical edges and re-binning between them is exact.
    pub fn edge(&self, i: usize) -> f64 {
        self.min + (self.max - self.min) * i as f64 / self.count as f64
    }

    /// Centre of bin `k`.
    pub fn centre(&self, k: usize) -> f64 {
        0.5 * (self.edge(k) + self.edge(k + 1))
    }

    /// All bin centres, in order.
    pub fn centres(&self) -> Vec<f64> {
        (0..self.count).map(|k| self.centre(k)).collect()
    }

    /// The bin holding disparity `d` (outer bins open-ended); `None` for NaN.
    pub fn index(&self, d: f64) -> Option<usize> {
        if d.is_nan() {
            return None;
        }
        let k = ((d - self.min) / self.width()).floor();
        Some(k.clamp(0.0, (self.count - 1) as f64) as usize)
    }

    /// Integration limits of bin `k`: its edges, with `-∞` and `+∞` for the outer ends.
    pub fn open_interval(&self, k: usize) -> (f64, f64) {
        let lo = if k == 0 {
            f64::NEG_INFINITY
        } else {
            self.edge(k)
        };
        let hi = if k + 1 == self.count {
            f64::INFINITY
        } else {
            self.edge(k + 1)
        };
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_bins_have_the_documented_width() {
        let b = Bins::THESIS;
        assert!((b.width() - 7.0 / 108.0).abs() < 1e-15);
        assert!(
            b.width() < 0.07,
            "bins must be narrower than the BadPix threshold"
        );
        assert_eq!(b.centres().len(), 108);
        assert!((b.centre(0) - (-3.5 + 7.0 / 216.0)).abs() < 1e-12);
    }

    #[test]
    fn index_clamps_out_of_range_values_and_rejects_nan() {
        let b = Bins::new(0.0, 4.0, 4).unwrap();
        assert_eq!(b.index(0.0), Some(0));
        assert_eq!(b.index(0.999), Some(0));
        assert_eq!(b.index(1.0), Some(1));
        assert_eq!(b.index(3.999), Some(3));
        assert_eq!(
            b.index(4.0),
            Some(3),
            "the upper end belongs to the last bin"
        );
        assert_eq!(b.index(-10.0), Some(0));
        assert_eq!(b.index(f64::INFINITY), Some(3));
        assert_eq!(b.index(f64::NAN), None);
    }

    #[test]
    fn open_intervals_cover_the_real_line() {
        let b = Bins::new(0.0, 4.0, 4).unwrap();
        assert_eq!(b.open_interval(0), (f64::NEG_INFINITY, 1.0));
        assert_eq!(b.open_interval(1), (1.0, 2.0));
        assert_eq!(b.open_interval(3), (3.0, f64::INFINITY));
        let one = Bins::new(0.0, 1.0, 1).unwrap();
        assert_eq!(one.open_interval(0), (f64::NEG_INFINITY, f64::INFINITY));
    }

    #[test]
    fn covering_bins_span_all_ranges_at_the_thesis_width() {
        let b = Bins::covering([(-39.7, 37.7), (-3.6, 3.4), (-40.1, 12.0)], None).unwrap();
        assert_eq!((b.min, b.max), (-40.1, 37.7));
        assert!(
            b.width() <= Bins::THESIS.width() && b.width() > 0.064,
            "{}",
            b.width()
        );
        assert_eq!(b.count, 1201);
        let fixed = Bins::covering([(-1.0, 1.0)], Some(4)).unwrap();
        assert_eq!((fixed.count, fixed.width()), (4, 0.5));
        assert!(Bins::covering([], None).is_err());
        assert!(Bins::covering([(0.0, 1e9)], None).is_err());
    }

    #[test]
    fn invalid_bins_are_rejected() {
        assert!(Bins::new(1.0, 1.0, 10).is_err());
        assert!(Bins::new(0.0, f64::NAN, 10).is_err());
        assert!(Bins::new(0.0, 1.0, 0).is_err());
    }
}

//! Pure metric functions: no I/O, plain slices in, numbers out, each unit-tested with
//! hand-computed values.
//!
//! [`hci`] holds the HCI toolkit's unimodal scores, [`region`] its region metrics on the
//! scenes' evaluation masks, [`kld`] the thesis' discrete KLD (eq. 5.21–5.23),
//! [`sparsification`] the uncertainty ranking curves and AuSE.

pub mod hci;
pub mod kld;
pub mod region;
pub mod sparsification;

/// The evaluated region: the image without a `border`-pixel frame (HCI: 15 px), because the
/// outer views see little of the image edge and no method can be judged there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Image columns.
    pub width: usize,
    /// Image rows.
    pub height: usize,
    /// Pixels left out at each side.
    pub border: usize,
}

impl Frame {
    /// Row-major indices of the pixels inside the frame (none when the border eats the image).
    pub fn indices(&self) -> impl Iterator<Item = usize> + '_ {
        let xs = self.border..self.width.saturating_sub(self.border);
        let ys = self.border..self.height.saturating_sub(self.border);
        ys.flat_map(move |y| xs.clone().map(move |x| y * self.width + x))
    }

    /// Whether row-major pixel `i` is inside the frame.
    pub fn contains(&self, i: usize) -> bool {
        let (x, y) = (i % self.width, i / self.width);
        (self.border..self.width.saturating_sub(self.border)).contains(&x)
            && (self.border..self.height.saturating_sub(self.border)).contains(&y)
    }

    /// Number of pixels inside the frame.
    pub fn len(&self) -> usize {
        self.width.saturating_sub(2 * self.border) * self.height.saturating_sub(2 * self.border)
    }

    /// Whether the frame holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Mean of the present values, `None` if there are none.
pub fn mean(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let (sum, n) = values
        .flatten()
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

#[cfg(test)]
mod tests {
    use super::Frame;

    #[test]
    fn frame_leaves_out_the_border() {
        let f = Frame {
            width: 4,
            height: 3,
            border: 1,
        };
        assert_eq!(f.indices().collect::<Vec<_>>(), vec![5, 6]);
        assert_eq!(f.len(), 2);
        assert!(f.contains(5) && f.contains(6) && !f.contains(4) && !f.contains(9));
        let gone = Frame { border: 2, ..f };
        assert!(gone.is_empty());
        assert_eq!(gone.indices().count(), 0);
    }
}

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

use std::ops::Range;

use crate::stacks::Region;

/// The evaluated region: the image without a `border`-pixel frame (HCI: 15 px), because the
/// outer views see little of the image edge and no method can be judged there; optionally
/// only a centred crop of it (the thesis scores SLFC and the models on 0.5 × 0.5 crops).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Image columns.
    pub width: usize,
    /// Image rows.
    pub height: usize,
    /// Pixels left out at each side.
    pub border: usize,
    /// The crop, when only part of the image is scored.
    pub crop: Option<Region>,
}

impl Frame {
    /// The `width × height` image without its `border`.
    pub fn new(width: usize, height: usize, border: usize) -> Self {
        Self {
            width,
            height,
            border,
            crop: None,
        }
    }

    /// Only the centred `fraction × fraction` part of the image ([`Region::centre`]); 1 keeps
    /// the whole frame.
    pub fn cropped(self, fraction: f64) -> Self {
        let crop = (fraction < 1.0).then(|| Region::centre(self.width, self.height, fraction));
        Self { crop, ..self }
    }

    /// The same region on an image `scale` times larger each way.
    pub fn scaled(self, scale: usize) -> Self {
        let crop = self.crop.map(|c| Region {
            x0: c.x0 * scale,
            y0: c.y0 * scale,
            width: c.width * scale,
            height: c.height * scale,
        });
        Self {
            width: self.width * scale,
            height: self.height * scale,
            border: self.border * scale,
            crop,
        }
    }

    /// The columns and rows inside the frame (empty when the border eats the image).
    fn spans(&self) -> (Range<usize>, Range<usize>) {
        let xs = self.border..self.width.saturating_sub(self.border);
        let ys = self.border..self.height.saturating_sub(self.border);
        match self.crop {
            None => (xs, ys),
            Some(c) => (
                xs.start.max(c.x0)..xs.end.min(c.x0 + c.width),
                ys.start.max(c.y0)..ys.end.min(c.y0 + c.height),
            ),
        }
    }

    /// Row-major indices of the pixels inside the frame.
    pub fn indices(&self) -> impl Iterator<Item = usize> + '_ {
        let (xs, ys) = self.spans();
        ys.flat_map(move |y| xs.clone().map(move |x| y * self.width + x))
    }

    /// Whether row-major pixel `i` is inside the frame.
    pub fn contains(&self, i: usize) -> bool {
        let (xs, ys) = self.spans();
        xs.contains(&(i % self.width)) && ys.contains(&(i / self.width))
    }

    /// Number of pixels inside the frame.
    pub fn len(&self) -> usize {
        let (xs, ys) = self.spans();
        xs.len() * ys.len()
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
        let f = Frame::new(4, 3, 1);
        assert_eq!(f.indices().collect::<Vec<_>>(), vec![5, 6]);
        assert_eq!(f.len(), 2);
        assert!(f.contains(5) && f.contains(6) && !f.contains(4) && !f.contains(9));
        let gone = Frame { border: 2, ..f };
        assert!(gone.is_empty());
        assert_eq!(gone.indices().count(), 0);
    }

    #[test]
    fn a_cropped_frame_keeps_the_centre_inside_the_border() {
        // 8×6 with a border of 2: columns 2..6, rows 2..4. The half crop: columns 2..6,
        // rows 1..4. Both: columns 2..6, rows 2..4.
        let f = Frame::new(8, 6, 2).cropped(0.5);
        let inside: Vec<usize> = f.indices().collect();
        assert_eq!(inside, vec![18, 19, 20, 21, 26, 27, 28, 29]);
        assert_eq!(f.len(), 8);
        assert!(f.contains(18) && !f.contains(17) && !f.contains(34));
        assert_eq!(Frame::new(8, 6, 2).cropped(1.0), Frame::new(8, 6, 2));
        let big = Frame::new(8, 6, 0).cropped(0.5).scaled(3);
        assert_eq!(big.len(), 4 * 3 * 9);
        assert!(big.contains(6 * 24 + 6) && !big.contains(6 * 24 + 5));
    }
}

//! The four view stacks through the centre view (EPINET's input, thesis appendix B.1) and the
//! EPI shift that refocuses them (thesis eq. 4.2 / 5.11).
//!
//! EPINET's order for 9×9 (docs/conventions.md): 0° = views 36..44 left→right, 90° = 76, 67, …, 4
//! bottom→top, 45° = 72, 64, …, 8 (bottom-left → top-right), −45° = 0, 10, …, 80. Along every
//! stack the view offset grows "forward" in the same sense, so that a quarter turn maps the 90°
//! stack onto a 0° stack and the 45° stack onto a −45° one (the network shares their weights).

use crate::lightfield::LightField;

/// One of the four stack directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// The centre row, left → right.
    Horizontal,
    /// The centre column, bottom → top.
    Vertical,
    /// The anti-diagonal, bottom-left → top-right.
    Diagonal45,
    /// The main diagonal, top-left → bottom-right.
    DiagonalMinus45,
}

impl Direction {
    /// All four, in the network's input order.
    pub const ALL: [Direction; 4] = [
        Direction::Horizontal,
        Direction::Vertical,
        Direction::Diagonal45,
        Direction::DiagonalMinus45,
    ];

    /// Grid positions `(u, v)` of the stack's views, in stack order, for an `n × n` grid.
    pub fn positions(self, n: usize) -> Vec<(usize, usize)> {
        let c = n / 2;
        (0..n)
            .map(|k| match self {
                Direction::Horizontal => (k, c),
                Direction::Vertical => (c, n - 1 - k),
                Direction::Diagonal45 => (k, n - 1 - k),
                Direction::DiagonalMinus45 => (k, k),
            })
            .collect()
    }

    /// HCI file indices `v * n + u` of the stack's views.
    pub fn view_indices(self, n: usize) -> Vec<usize> {
        self.positions(n).iter().map(|&(u, v)| v * n + u).collect()
    }
}

/// The rectangle of the light field a stack is read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// Left column.
    pub x0: usize,
    /// Top row.
    pub y0: usize,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

impl Region {
    /// The whole image of `lf`.
    pub fn whole(lf: &LightField) -> Self {
        Self {
            x0: 0,
            y0: 0,
            width: lf.width,
            height: lf.height,
        }
    }
}

/// The stack `dir` of `lf` over `region`, EPI-shifted by `shift` pixels, channel-major:
/// `n * 3` planes (view after view, R G B) of `region.width × region.height`.
///
/// The shift is `L^s(x, y, u, v) = L^0(x - du s, y - dv s, u, v)` with `(du, dv)` the view's
/// offset from the centre (thesis eq. 4.2, 5.11; the diagonal stacks get both shifts), read
/// with bilinear interpolation and edge pixels repeated outside the image. A point of
/// disparity `d` has disparity `d - s` in the shifted light field: it lies at `x - du d` in
/// view `du`, and `x' - du s = x - du d` gives `x' = x - du (d - s)`.
pub fn extract(lf: &LightField, dir: Direction, region: Region, shift: f32) -> Vec<f32> {
    let mut out = vec![0.0; lf.n * 3 * region.width * region.height];
    extract_into(lf, dir, region, shift, &mut out);
    out
}

/// [`extract`] into `out` (`n * 3` planes of the region), for callers that refill one buffer.
pub fn extract_into(lf: &LightField, dir: Direction, region: Region, shift: f32, out: &mut [f32]) {
    let c = lf.centre() as f32;
    let plane = region.width * region.height;
    for (k, (u, v)) in dir.positions(lf.n).into_iter().enumerate() {
        let view = lf.view(u, v);
        let (ox, oy) = (-(u as f32 - c) * shift, -(v as f32 - c) * shift);
        let planes = &mut out[k * 3 * plane..(k + 1) * 3 * plane];
        sample_shifted(view, lf.width, lf.height, region, (ox, oy), planes);
    }
}

/// Bilinear samples of the RGB image `rgb` at `(x + ox, y + oy)` for every pixel of `region`
/// into three planes of `out`; coordinates are clamped to the image.
fn sample_shifted(
    rgb: &[f32],
    w: usize,
    h: usize,
    region: Region,
    (ox, oy): (f32, f32),
    out: &mut [f32],
) {
    let plane = region.width * region.height;
    let (fx, fy) = (ox.floor(), oy.floor());
    let (ax, ay) = (ox - fx, oy - fy);
    let clamp = |v: isize, max: usize| v.clamp(0, max as isize - 1) as usize;
    for y in 0..region.height {
        let sy = (region.y0 + y) as isize + fy as isize;
        let (y0, y1) = (clamp(sy, h), clamp(sy + 1, h));
        for x in 0..region.width {
            let sx = (region.x0 + x) as isize + fx as isize;
            let (x0, x1) = (clamp(sx, w), clamp(sx + 1, w));
            for ch in 0..3 {
                let at = |xx: usize, yy: usize| rgb[(yy * w + xx) * 3 + ch];
                let top = at(x0, y0) * (1.0 - ax) + at(x1, y0) * ax;
                let bottom = at(x0, y1) * (1.0 - ax) + at(x1, y1) * ax;
                out[ch * plane + y * region.width + x] = top * (1.0 - ay) + bottom * ay;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epinet_order_for_9x9() {
        assert_eq!(
            Direction::Horizontal.view_indices(9),
            (36..=44).collect::<Vec<_>>()
        );
        assert_eq!(
            Direction::Vertical.view_indices(9),
            vec![76, 67, 58, 49, 40, 31, 22, 13, 4]
        );
        assert_eq!(
            Direction::Diagonal45.view_indices(9),
            vec![72, 64, 56, 48, 40, 32, 24, 16, 8]
        );
        assert_eq!(
            Direction::DiagonalMinus45.view_indices(9),
            vec![0, 10, 20, 30, 40, 50, 60, 70, 80]
        );
        assert_eq!(Direction::Vertical.view_indices(3), vec![7, 4, 1]);
    }

    /// The loader colours a crop's views once instead of every resampled stack
    /// (`sample::make_sample`): a photometric draw is affine per pixel and the resampling's
    /// weights sum to one, so both orders agree to rounding, also where sampling clamps.
    #[test]
    fn a_photometric_draw_commutes_with_the_epi_shift() {
        use crate::augment::{Photometric, grey_axis_rotation};
        let lf = LightField::from_fn(9, 20, 20, |u, v, x, y| {
            let s = ((x * 7 + y * 13 + u * 3 + v * 5) % 17) as f32 / 17.0;
            [s, 1.0 - s, 0.3 + 0.4 * s * s]
        });
        let draw = Photometric {
            matrix: grey_axis_rotation(1.1),
            gain: 1.4,
            stretch: 0.7,
            contrast: 1.2,
            brightness: -0.05,
        };
        let region = Region {
            x0: 1,
            y0: 2,
            width: 16,
            height: 15,
        };
        let plane = region.width * region.height;
        let mut coloured = lf.clone();
        for view in coloured.views.iter_mut().flatten() {
            draw.apply(view, 1, 0.45);
        }
        for dir in Direction::ALL {
            let mut after = extract(&lf, dir, region, 1.37);
            draw.apply(&mut after, plane, 0.45);
            let before = extract(&coloured, dir, region, 1.37);
            let worst = before
                .iter()
                .zip(&after)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f32::max);
            assert!(worst < 1e-5, "{dir:?}: {worst}");
        }
    }
}

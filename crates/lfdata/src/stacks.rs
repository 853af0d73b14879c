//! The four view stacks through the centre view (EPINET's input, thesis appendix B.1) and the
//! EPI shift that refocuses them (thesis eq. 4.2 / 5.11).
//!
//! EPINET's order for 9×9 (docs/reference/format.md): 0° = views 36..44 left→right, 90° = 76, 67, …, 4
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

    /// The centred `fraction × fraction` part of a `width × height` image (rounded to whole
    /// pixels, at least one).
    pub fn centre(width: usize, height: usize, fraction: f64) -> Self {
        let side = |n: usize| ((n as f64 * fraction).round() as usize).clamp(1, n);
        let (w, h) = (side(width), side(height));
        Self {
            x0: (width - w) / 2,
            y0: (height - h) / 2,
            width: w,
            height: h,
        }
    }
}

/// The stack `dir` of `lf` (a square `n × n` grid, as [`LightField::load_star`] reads) over
/// `region`, EPI-shifted by `shift` pixels, channel-major: `n * 3` planes (view after view,
/// R G B) of `region.width × region.height`.
///
/// The shift is `L^s(x, y, u, v) = L^0(x - du s, y - dv s, u, v)` with `(du, dv)` the view's
/// offset from the centre (thesis eq. 4.2, 5.11; the diagonal stacks get both shifts), read
/// with bilinear interpolation and edge pixels repeated outside the image. A point of
/// disparity `d` has disparity `d - s` in the shifted light field: it lies at `x - du d` in
/// view `du`, and `x' - du s = x - du d` gives `x' = x - du (d - s)`.
pub fn extract(lf: &LightField, dir: Direction, region: Region, shift: f32) -> Vec<f32> {
    let mut out = vec![0.0; lf.nx * 3 * region.width * region.height];
    extract_into(lf, dir, region, shift, &mut out);
    out
}

/// [`extract`] into `out` (`n * 3` planes of the region), for callers that refill one buffer.
pub fn extract_into(lf: &LightField, dir: Direction, region: Region, shift: f32, out: &mut [f32]) {
    let plane = region.width * region.height;
    for (k, at) in dir.positions(lf.nx).into_iter().enumerate() {
        shift_view(
            lf,
            at,
            region,
            shift,
            &mut out[k * 3 * plane..(k + 1) * 3 * plane],
        );
    }
}

/// View `(u, v)` of `lf` over `region`, EPI-shifted by `shift` pixels (see [`extract`]), as
/// three planes (R, G, B) of `region.width × region.height` into `out`.
pub fn shift_view(
    lf: &LightField,
    (u, v): (usize, usize),
    region: Region,
    shift: f32,
    out: &mut [f32],
) {
    let (cu, cv) = lf.centre();
    let offset = (
        -((u as f32 - cu as f32) * shift),
        -((v as f32 - cv as f32) * shift),
    );
    sample_shifted(lf.view(u, v), lf.width, lf.height, region, offset, out);
}

/// Bilinear samples of the RGB image `rgb` at `(x + ox, y + oy)` for every pixel of `region`
/// into three planes of `out`; coordinates are clamped to the image.
///
/// The loader's hottest loop (a cost volume resamples each view once per hypothesis), so the
/// columns whose two source pixels lie inside the image run without clamping or per-pixel
/// index arithmetic; both paths evaluate the same expression in the same order, so the
/// result does not depend on which one a pixel takes.
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
    let lerp = |a: f32, b: f32, c: f32, d: f32| {
        let top = a * (1.0 - ax) + b * ax;
        let bottom = c * (1.0 - ax) + d * ax;
        top * (1.0 - ay) + bottom * ay
    };
    let clamp = |v: isize, max: usize| v.clamp(0, max as isize - 1) as usize;
    let (red, rest) = out[..3 * plane].split_at_mut(plane);
    let (green, blue) = rest.split_at_mut(plane);
    // Source column of output column 0; columns lo..hi read sx and sx + 1 unclamped.
    let base = region.x0 as isize + fx as isize;
    let lo = (-base).clamp(0, region.width as isize) as usize;
    let hi = (w as isize - 1 - base).clamp(lo as isize, region.width as isize) as usize;
    for y in 0..region.height {
        let sy = (region.y0 + y) as isize + fy as isize;
        let row = |r: usize| &rgb[r * w * 3..(r + 1) * w * 3];
        let (r0, r1) = (row(clamp(sy, h)), row(clamp(sy + 1, h)));
        let at = y * region.width;
        let mut planes = [
            &mut red[at..at + region.width],
            &mut green[at..at + region.width],
            &mut blue[at..at + region.width],
        ];
        for x in (0..lo).chain(hi..region.width) {
            let sx = base + x as isize;
            let (x0, x1) = (clamp(sx, w) * 3, clamp(sx + 1, w) * 3);
            for (ch, p) in planes.iter_mut().enumerate() {
                p[x] = lerp(r0[x0 + ch], r0[x1 + ch], r1[x0 + ch], r1[x1 + ch]);
            }
        }
        if lo < hi {
            let s0 = (base + lo as isize) as usize * 3;
            let span = 3 * (hi - lo);
            let (t0, t1) = (&r0[s0..s0 + span + 3], &r1[s0..s0 + span + 3]);
            let [pr, pg, pb] = planes;
            let pixels = (pr[lo..hi].iter_mut())
                .zip(pg[lo..hi].iter_mut())
                .zip(pb[lo..hi].iter_mut())
                .zip(t0.chunks_exact(3).zip(t0[3..].chunks_exact(3)))
                .zip(t1.chunks_exact(3).zip(t1[3..].chunks_exact(3)));
            for ((((r, g), b), (a0, b0)), (a1, b1)) in pixels {
                *r = lerp(a0[0], b0[0], a1[0], b1[0]);
                *g = lerp(a0[1], b0[1], a1[1], b1[1]);
                *b = lerp(a0[2], b0[2], a1[2], b1[2]);
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

    #[test]
    fn a_shift_moves_by_whole_and_fractional_pixels_with_clamping() {
        // 4×1 grey ramp 0, 1, 2, 3 in all channels.
        let rgb: Vec<f32> = (0..4).flat_map(|v| [v as f32; 3]).collect();
        let region = Region {
            x0: 0,
            y0: 0,
            width: 4,
            height: 1,
        };
        let mut out = vec![0.0; 12];
        sample_shifted(&rgb, 4, 1, region, (1.0, 0.0), &mut out);
        assert_eq!(out[..4], [1.0, 2.0, 3.0, 3.0]);
        sample_shifted(&rgb, 4, 1, region, (-0.25, 0.0), &mut out);
        assert_eq!(out[..4], [0.0, 0.75, 1.75, 2.75]);
    }

    /// The interior fast path of `sample_shifted` gives bit for bit what clamping every
    /// pixel gives, for shifts that leave the image on either side and regions at its edges.
    #[test]
    fn the_unclamped_interior_is_bit_identical_to_clamping_everywhere() {
        let (w, h) = (23, 17);
        let rgb: Vec<f32> = (0..w * h * 3)
            .map(|i| ((i * 37) % 101) as f32 / 101.0)
            .collect();
        let reference = |region: Region, (ox, oy): (f32, f32)| {
            let clamp = |v: f32, max: usize| (v.max(0.0) as usize).min(max - 1);
            let mut out = vec![0.0; 3 * region.width * region.height];
            let (fx, fy) = (ox.floor(), oy.floor());
            let (ax, ay) = (ox - fx, oy - fy);
            for y in 0..region.height {
                for x in 0..region.width {
                    let sx = (region.x0 + x) as f32 + fx;
                    let sy = (region.y0 + y) as f32 + fy;
                    let (x0, x1) = (clamp(sx, w), clamp(sx + 1.0, w));
                    let (y0, y1) = (clamp(sy, h), clamp(sy + 1.0, h));
                    for ch in 0..3 {
                        let at = |xx: usize, yy: usize| rgb[(yy * w + xx) * 3 + ch];
                        let top = at(x0, y0) * (1.0 - ax) + at(x1, y0) * ax;
                        let bottom = at(x0, y1) * (1.0 - ax) + at(x1, y1) * ax;
                        out[(ch * region.height + y) * region.width + x] =
                            top * (1.0 - ay) + bottom * ay;
                    }
                }
            }
            out
        };
        let regions = [(0, 0, 23, 17), (3, 2, 12, 9), (15, 10, 8, 7), (0, 5, 5, 5)];
        let shifts = [0.0, 0.37, -2.6, 7.9, -30.2, 25.5];
        for (x0, y0, width, height) in regions {
            let region = Region {
                x0,
                y0,
                width,
                height,
            };
            for &sx in &shifts {
                for &sy in &[0.0, -1.25, 3.5] {
                    let mut out = vec![0.0; 3 * width * height];
                    sample_shifted(&rgb, w, h, region, (sx, sy), &mut out);
                    assert_eq!(out, reference(region, (sx, sy)), "{region:?} {sx} {sy}");
                }
            }
        }
    }
}

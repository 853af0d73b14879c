//! A light field in memory (the views a cost volume or a network reads), with the geometric
//! operations of the data pipeline: cropping, rotation by 90° and down-scaling.
//!
//! Views are addressed by grid column `u` and row `v` (row 0 on top, as HCI's file index
//! `v * nx + u`); pixels are RGB in `[0, 1]`, row-major, top row first. Only the views a
//! consumer asks for are loaded (a [`ViewSet`]): training reads the star (centre row, column and
//! both diagonals), which cuts memory by 2.5× on a 9×9 grid; the classical baseline the cross.

use std::path::Path;

use anyhow::{Result, bail};
use lfformat::views::{ViewSet, read_grid, read_view};

/// Some views of an `nx × ny` camera grid (both odd).
#[derive(Clone, Debug, PartialEq)]
pub struct LightField {
    /// Views per grid row (columns `u`).
    pub nx: usize,
    /// Views per grid column (rows `v`).
    pub ny: usize,
    /// Image columns.
    pub width: usize,
    /// Image rows.
    pub height: usize,
    /// `nx * ny` entries, index `v * nx + u`; `None` for a view that was not loaded.
    pub views: Vec<Option<Vec<f32>>>,
    /// The scene's disparity range `[disp_min, disp_max]` from `parameters.cfg` (EPI-Shift's
    /// inference shifts cover it); `None` for light fields built in memory.
    pub disparity_range: Option<[f32; 2]>,
}

impl LightField {
    /// Reads `parameters.cfg` and the views of `set` from the scene folder `dir`.
    pub fn load(dir: &Path, set: ViewSet) -> Result<Self> {
        Self::load_views(dir, |nx, ny| Ok(set.positions(nx, ny)))
    }

    /// Reads the star views of the scene folder `dir`, whose grid must be square: what the
    /// four stacks of a network need.
    pub fn load_star(dir: &Path) -> Result<Self> {
        Self::load_views(dir, |nx, ny| {
            if nx != ny {
                bail!(
                    "{}: a {nx}x{ny} camera grid; the four stacks need a square grid with an odd side",
                    dir.display()
                );
            }
            Ok(ViewSet::Star.positions(nx, ny))
        })
    }

    /// Reads the views at the grid positions `select(nx, ny)` returns.
    fn load_views(
        dir: &Path,
        select: impl FnOnce(usize, usize) -> Result<Vec<(usize, usize)>>,
    ) -> Result<Self> {
        let params = read_grid(dir)?;
        let (nx, ny) = (params.num_cams_x as usize, params.num_cams_y as usize);
        let mut views = vec![None; nx * ny];
        for (u, v) in select(nx, ny)? {
            views[v * nx + u] = Some(read_view(dir, &params, (u, v))?);
        }
        let range = [params.disp_min as f32, params.disp_max as f32];
        Ok(Self {
            nx,
            ny,
            width: params.image_resolution_x_px as usize,
            height: params.image_resolution_y_px as usize,
            views,
            disparity_range: (range.iter().all(|d| d.is_finite()) && range[0] <= range[1])
                .then_some(range),
        })
    }

    /// Builds the star views of a square `n × n` grid from a function of grid position and
    /// pixel (synthetic scenes in tests and examples).
    pub fn from_fn(
        n: usize,
        width: usize,
        height: usize,
        f: impl Fn(usize, usize, usize, usize) -> [f32; 3],
    ) -> Self {
        let mut views = vec![None; n * n];
        for (u, v) in ViewSet::Star.positions(n, n) {
            let mut rgb = Vec::with_capacity(width * height * 3);
            for y in 0..height {
                for x in 0..width {
                    rgb.extend_from_slice(&f(u, v, x, y));
                }
            }
            views[v * n + u] = Some(rgb);
        }
        Self {
            nx: n,
            ny: n,
            width,
            height,
            views,
            disparity_range: None,
        }
    }

    /// Grid position `(u, v)` of the centre view (`Cam040` of 9×9).
    pub fn centre(&self) -> (usize, usize) {
        (self.nx / 2, self.ny / 2)
    }

    /// The view at column `u`, row `v`.
    ///
    /// # Panics
    /// If the view was not loaded (a view-selection bug, not a data error).
    pub fn view(&self, u: usize, v: usize) -> &[f32] {
        self.views[v * self.nx + u]
            .as_deref()
            .unwrap_or_else(|| panic!("view ({u}, {v}) was not loaded"))
    }

    /// The loaded views with their grid positions `(u, v)`, in file order.
    pub fn loaded(&self) -> impl Iterator<Item = ((usize, usize), &[f32])> {
        let nx = self.nx;
        (self.views.iter().enumerate())
            .filter_map(move |(i, view)| Some(((i % nx, i / nx), view.as_deref()?)))
    }

    /// The `w × h` region at `(x0, y0)` (which may reach outside the image: edge pixels are
    /// repeated, the thesis' nearest-neighbour padding), taking every `step`-th pixel: a
    /// down-scaling by `step` that divides every disparity by it.
    pub fn crop(&self, (x0, y0): (isize, isize), (w, h): (usize, usize), step: usize) -> Self {
        let (sw, sh) = (self.width, self.height);
        let views = self
            .views
            .iter()
            .map(|view| {
                view.as_ref()
                    .map(|rgb| crop_plane(rgb, sw, sh, 3, (x0, y0), (w, h), step))
            })
            .collect();
        let k = step.max(1) as f32;
        Self {
            nx: self.nx,
            ny: self.ny,
            width: w,
            height: h,
            views,
            disparity_range: self.disparity_range.map(|[lo, hi]| [lo / k, hi / k]),
        }
    }

    /// The light field rotated by 90° (see [`rotate_plane`]): every image is rotated and the
    /// view grid is rotated the same way, so that disparities keep their values and signs.
    ///
    /// A point at centre-relative image position `p` and view offset `w` moves to `R p` and
    /// `R w` with the same linear map `R`; since a point of disparity `d` appears at `p - d w`
    /// in view `w`, it appears at `R p - d R w` after the rotation: same disparity.
    pub fn rotate90(&self) -> Self {
        let (nx, ny) = (self.nx, self.ny);
        let views = (0..nx * ny)
            .map(|i| {
                let (u, v) = (i % ny, i / ny);
                let (ou, ov) = rotate_source(u, v, nx, ny);
                self.views[ov * nx + ou]
                    .as_ref()
                    .map(|rgb| rotate_plane(rgb, self.width, self.height, 3))
            })
            .collect();
        Self {
            nx: ny,
            ny: nx,
            width: self.height,
            height: self.width,
            views,
            disparity_range: self.disparity_range,
        }
    }

    /// Rotated by `quarter_turns` × 90°.
    pub fn rotate(&self, quarter_turns: usize) -> Self {
        (0..quarter_turns % 4).fold(self.clone(), |lf, _| lf.rotate90())
    }

    /// Down-scaled by `k`: each output pixel the mean of a `k × k` block (the last partial
    /// row and column of blocks dropped), every disparity divided by `k`. A box average, not
    /// [`crop`](Self::crop)'s slicing: a rendered view's noise then falls with the scale too.
    pub fn downscale(&self, k: usize) -> Self {
        let k = k.max(1);
        let (w, h) = (self.width / k, self.height / k);
        let views = self
            .views
            .iter()
            .map(|view| {
                view.as_ref()
                    .map(|rgb| box_downscale(rgb, self.width, (w, h), k))
            })
            .collect();
        Self {
            nx: self.nx,
            ny: self.ny,
            width: w,
            height: h,
            views,
            disparity_range: self
                .disparity_range
                .map(|[lo, hi]| [lo / k as f32, hi / k as f32]),
        }
    }
}

/// The `w × h` image of `k × k` block means of an RGB image `stride` pixels wide.
fn box_downscale(rgb: &[f32], stride: usize, (w, h): (usize, usize), k: usize) -> Vec<f32> {
    let scale = 1.0 / (k * k) as f32;
    let mut out = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0f32; 3];
            for yy in y * k..(y + 1) * k {
                for xx in x * k..(x + 1) * k {
                    let i = (yy * stride + xx) * 3;
                    sum.iter_mut()
                        .zip(&rgb[i..i + 3])
                        .for_each(|(s, v)| *s += v);
                }
            }
            out.extend(sum.map(|s| s * scale));
        }
    }
    out
}

/// The source `(x, y)` of target pixel `(x', y')` of the 90° rotation of a `w × h` grid:
/// `(w - 1 - y', x')`. In centre-relative coordinates this is `R(a, b) = (b, -a)`: a
/// quarter turn counter-clockwise as displayed (x right, y down). Pixels and views share it.
pub fn rotate_source(xr: usize, yr: usize, w: usize, _h: usize) -> (usize, usize) {
    (w - 1 - yr, xr)
}

/// A `w × h` image with `channels` interleaved values per pixel rotated by 90° (the result is
/// `h × w`), see [`rotate_source`].
pub fn rotate_plane<T: Copy>(data: &[T], w: usize, h: usize, channels: usize) -> Vec<T> {
    let (wr, hr) = (h, w);
    let mut out = Vec::with_capacity(data.len());
    for yr in 0..hr {
        for xr in 0..wr {
            let (x, y) = rotate_source(xr, yr, w, h);
            let i = (y * w + x) * channels;
            out.extend_from_slice(&data[i..i + channels]);
        }
    }
    out
}

/// The `size` region at `origin` of a `w × h` image with `channels` values per pixel, every
/// `step`-th pixel (mmlf's down-scaling by slicing), coordinates clamped to the image.
pub fn crop_plane<T: Copy>(
    data: &[T],
    w: usize,
    h: usize,
    channels: usize,
    (x0, y0): (isize, isize),
    (cw, ch): (usize, usize),
    step: usize,
) -> Vec<T> {
    let mut out = Vec::with_capacity(cw * ch * channels);
    let step = step.max(1) as isize;
    for y in 0..ch as isize {
        let sy = (y0 + y * step).clamp(0, h as isize - 1) as usize;
        for x in 0..cw as isize {
            let sx = (x0 + x * step).clamp(0, w as isize - 1) as usize;
            let i = (sy * w + sx) * channels;
            out.extend_from_slice(&data[i..i + channels]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_of_a_plane_is_a_quarter_turn() {
        // 3 × 2 image:  0 1 2 / 3 4 5  → quarter turn counter-clockwise: 2 5 / 1 4 / 0 3
        let img: Vec<u8> = (0..6).collect();
        assert_eq!(rotate_plane(&img, 3, 2, 1), vec![2, 5, 1, 4, 0, 3]);
        let four = (0..4).fold(img.clone(), |a, i| {
            let (w, h) = if i % 2 == 0 { (3, 2) } else { (2, 3) };
            rotate_plane(&a, w, h, 1)
        });
        assert_eq!(four, img);
    }

    /// A 3 × 1 grid turns into a 1 × 3 one: the grid is turned as each image is (see
    /// [`rotate_source`]), and four turns give the light field back.
    #[test]
    fn rotation_turns_a_non_square_grid() {
        let lf = LightField {
            nx: 3,
            ny: 1,
            width: 2,
            height: 1,
            views: (0..3).map(|u| Some(vec![u as f32; 6])).collect(),
            disparity_range: None,
        };
        let turned = lf.rotate90();
        assert_eq!(
            (turned.nx, turned.ny, turned.width, turned.height),
            (1, 3, 1, 2)
        );
        for v in 0..3 {
            assert_eq!(turned.view(0, v)[0], (2 - v) as f32);
        }
        assert_eq!(lf.rotate(4), lf);
    }

    #[test]
    fn downscale_averages_blocks_and_divides_the_range() {
        // A 5 × 5 grid (view (1, 0) is off the star) of 5 × 3 views, red = x + 10 y:
        // 2 × 1 blocks of 2 × 2 (the last column and row dropped).
        let mut lf = LightField::from_fn(5, 5, 3, |_, _, x, y| [(x + 10 * y) as f32, 1.0, 0.0]);
        lf.disparity_range = Some([-8.0, 4.0]);
        let d = lf.downscale(2);
        assert_eq!((d.width, d.height), (2, 1));
        assert_eq!(d.disparity_range, Some([-4.0, 2.0]));
        // Block means: (0 + 1 + 10 + 11) / 4 = 5.5, (2 + 3 + 12 + 13) / 4 = 7.5.
        assert_eq!(d.view(2, 2), &[5.5, 1.0, 0.0, 7.5, 1.0, 0.0]);
        assert!(d.views[0].is_some() && d.views[1].is_none());
    }

    #[test]
    fn crop_repeats_edge_pixels() {
        let img: Vec<u8> = (0..4).collect(); // 2 × 2
        assert_eq!(crop_plane(&img, 2, 2, 1, (-1, 0), (3, 1), 1), vec![0, 0, 1]);
        // Every second pixel of a 4 × 4 image, clamped at the edge (4 → 3).
        let img: Vec<u8> = (0..16).collect();
        assert_eq!(
            crop_plane(&img, 4, 4, 1, (0, 0), (2, 2), 2),
            vec![0, 2, 8, 10]
        );
        assert_eq!(
            crop_plane(&img, 4, 4, 1, (2, 2), (2, 2), 2),
            vec![10, 11, 14, 15]
        );
    }
}

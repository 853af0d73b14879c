//! The views of a scene folder (`input_CamNNN.png`): the subsets of the view grid that
//! evaluation baselines and training read, the reader of one view as RGB in `[0, 1]`, and
//! the camera-model draw the views went through.

use std::io::BufReader;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::dataset::PARAMETERS_FILE;
use crate::{Error, HciParameters, Result};

/// One scene's capture by the camera model, in a camera's terms: what its views were exposed
/// and developed with (`stats.json`'s `camera`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaptureDraw {
    /// Sensor sensitivity.
    pub iso: f64,
    /// Exposure error, stops.
    pub exposure_ev: f64,
    /// White balance of the red and blue channels against green, stops.
    pub white_balance_ev: [f64; 2],
    /// Share of the centre's light the image corners lose to vignetting.
    pub vignetting: f64,
}

/// A subset of the view grid (the views a cost volume or a network reads).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ViewSet {
    /// The centre row and column (9 + 8 views of 9×9, the thesis' chapter 4 setup).
    Cross,
    /// The cross plus both diagonals (EPINET's four stacks).
    Star,
    /// Every view.
    Full,
}

impl std::str::FromStr for ViewSet {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "cross" => Ok(Self::Cross),
            "star" => Ok(Self::Star),
            "full" => Ok(Self::Full),
            _ => Err(format!("{s:?}: expected cross, star or full")),
        }
    }
}

impl ViewSet {
    /// Grid positions `(u, v)` of the views in a `nx × ny` grid, centre included.
    pub fn positions(self, nx: usize, ny: usize) -> Vec<(usize, usize)> {
        let (uc, vc) = ((nx / 2) as isize, (ny / 2) as isize);
        let keep = |du: isize, dv: isize| match self {
            ViewSet::Cross => du == 0 || dv == 0,
            ViewSet::Star => du == 0 || dv == 0 || du.abs() == dv.abs(),
            ViewSet::Full => true,
        };
        (0..ny)
            .flat_map(|v| (0..nx).map(move |u| (u, v)))
            .filter(|&(u, v)| keep(u as isize - uc, v as isize - vc))
            .collect()
    }
}

/// `parameters.cfg` of the scene folder `dir`, checked to describe a view grid with a centre
/// view (odd counts, as HCI's).
pub fn read_grid(dir: &Path) -> Result<HciParameters> {
    let params = HciParameters::read(&dir.join(PARAMETERS_FILE))?;
    let (nx, ny) = (params.num_cams_x, params.num_cams_y);
    if nx % 2 == 0 || ny % 2 == 0 {
        return Err(Error::format(
            dir,
            format!("the camera grid {nx}x{ny} has no centre view"),
        ));
    }
    Ok(params)
}

/// The view at grid column `u`, row `v` of the scene folder `dir` (with its `parameters.cfg`
/// as [`read_grid`] returns it) as RGB in `[0, 1]`.
pub fn read_view(dir: &Path, params: &HciParameters, (u, v): (usize, usize)) -> Result<Vec<f32>> {
    let index = v * params.num_cams_x as usize + u;
    read_rgb(
        &dir.join(format!("input_Cam{index:03}.png")),
        params.image_resolution_x_px as usize,
        params.image_resolution_y_px as usize,
    )
}

/// The centre view of the scene in `dir` as RGB in `[0, 1]`, with its width and height.
pub fn centre_view(dir: &Path) -> Result<(Vec<f32>, usize, usize)> {
    let params = read_grid(dir)?;
    let centre = (
        params.num_cams_x as usize / 2,
        params.num_cams_y as usize / 2,
    );
    let rgb = read_view(dir, &params, centre)?;
    let size = (params.image_resolution_x_px, params.image_resolution_y_px);
    Ok((rgb, size.0 as usize, size.1 as usize))
}

/// An 8-bit (or 16-bit) image as RGB in `[0, 1]`, checked against the expected size.
pub fn read_rgb(path: &Path, width: usize, height: usize) -> Result<Vec<f32>> {
    let file = BufReader::new(crate::read::open(path)?);
    let img = image::ImageReader::new(file)
        .with_guessed_format()
        .map_err(|e| Error::io(path, e))?
        .decode()
        .map_err(|e| Error::format(path, format!("cannot read image: {e}")))?
        .into_rgb32f();
    if (img.width() as usize, img.height() as usize) != (width, height) {
        return Err(Error::format(
            path,
            format!(
                "{}x{} pixels, parameters.cfg says {width}x{height}",
                img.width(),
                img.height()
            ),
        ));
    }
    Ok(img.into_raw())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_sets_of_a_9x9_grid() {
        assert_eq!("star".parse::<ViewSet>(), Ok(ViewSet::Star));
        assert!(
            "diagonal"
                .parse::<ViewSet>()
                .unwrap_err()
                .contains("cross, star or full")
        );
        let cross = ViewSet::Cross.positions(9, 9);
        assert_eq!(cross.len(), 17);
        assert!(cross.contains(&(4, 4)) && cross.contains(&(0, 4)) && cross.contains(&(4, 8)));
        let star = ViewSet::Star.positions(9, 9);
        assert_eq!(star.len(), 33);
        assert!(star.contains(&(0, 0)) && star.contains(&(8, 0)) && !star.contains(&(1, 0)));
        assert_eq!(ViewSet::Full.positions(9, 9).len(), 81);
        assert_eq!(ViewSet::Cross.positions(3, 1), vec![(0, 0), (1, 0), (2, 0)]);
    }
}

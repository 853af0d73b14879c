//! A scene's HCI evaluation masks (`mask_*_lowres.png`, `mask_*_highres.png`) with what the
//! region metrics need beside them: the camera of `parameters.cfg` and, for the
//! high-resolution masks, `gt_disp_highres.pfm`.
//!
//! A scene without masks has no region scores; one with masks but without a file they need,
//! or with a mask of another size than its ground truth, is an error naming the file.

use std::path::Path;

use anyhow::{Context, Result, bail};
use lfformat::HciParameters;
use lfformat::pfm::read_pfm;
use lfformat::region_masks::{MASK_STEMS, mask_file, read_mask_png};

use crate::metrics::region::{DepthCamera, HighRes, RegionMasks, RegionTruth};

/// The high-resolution disparity the toolkit reads beside the `*_highres.png` masks.
pub const HIGHRES_GT_FILE: &str = "gt_disp_highres.pfm";

/// The region truth of the scene folder `dir` whose low-resolution ground truth is
/// `width × height`; `None` when it has no mask.
pub fn load_region_truth(dir: &Path, width: usize, height: usize) -> Result<Option<RegionTruth>> {
    let masks = read_masks(dir, false, (width, height))?;
    let high = read_high_res(dir)?;
    if masks.is_empty() && high.is_none() {
        return Ok(None);
    }
    let cfg = dir.join("parameters.cfg");
    let p = HciParameters::read(&cfg).with_context(|| {
        format!(
            "{}: needed for the region metrics (its masks are there)",
            cfg.display()
        )
    })?;
    let camera = DepthCamera {
        focal_length_mm: p.focal_length_mm,
        sensor_size_mm: p.sensor_size_mm,
        baseline_mm: p.baseline_mm,
        focus_distance_m: p.focus_distance_m,
        max_side_px: p.image_resolution_x_px.max(p.image_resolution_y_px) as usize,
    };
    Ok(Some(RegionTruth {
        camera,
        masks,
        high,
    }))
}

/// The high-resolution ground truth and masks, when the scene has any such mask.
fn read_high_res(dir: &Path) -> Result<Option<HighRes>> {
    let any_mask = MASK_STEMS
        .iter()
        .any(|stem| is_there(&dir.join(mask_file(stem, true))));
    if !any_mask {
        return Ok(None);
    }
    let gt_path = dir.join(HIGHRES_GT_FILE);
    if !is_there(&gt_path) {
        bail!(
            "{}: missing, but the scene has high-resolution masks",
            gt_path.display()
        );
    }
    let gt = read_pfm(&gt_path)?;
    let masks = read_masks(dir, true, (gt.width, gt.height))?;
    Ok(Some(HighRes {
        width: gt.width,
        height: gt.height,
        gt: gt.data,
        masks,
    }))
}

/// The masks of one resolution that exist, each checked to be `size`.
fn read_masks(dir: &Path, high: bool, size: (usize, usize)) -> Result<RegionMasks> {
    let mut read = MASK_STEMS.iter().map(|stem| {
        let path = dir.join(mask_file(stem, high));
        if !is_there(&path) {
            return Ok(None);
        }
        let (w, h, mask) = read_mask_png(&path)?;
        if (w, h) != size {
            bail!(
                "{}: {w}x{h}, but its ground truth is {}x{}",
                path.display(),
                size.0,
                size.1
            );
        }
        Ok(Some(mask))
    });
    let mut next = || read.next().expect("one per stem");
    Ok(RegionMasks {
        discontinuities: next()?,
        planes: next()?,
        smooth_surfaces: next()?,
        fine: next()?,
        fine_surrounding: next()?,
    })
}

/// Whether something is at `path` (a broken link too, so reading it reports the problem).
fn is_there(path: &Path) -> bool {
    path.symlink_metadata().is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use lfformat::region_masks::write_mask_png;

    #[test]
    fn a_scene_without_masks_has_no_region_truth() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(load_region_truth(dir.path(), 4, 3).unwrap(), None);
    }

    #[test]
    fn a_mask_of_the_wrong_size_or_without_its_files_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let mask = dir.path().join("mask_planes_lowres.png");
        write_mask_png(&mask, 2, 2, &[true; 4]).unwrap();
        let e = format!("{:#}", load_region_truth(dir.path(), 4, 3).unwrap_err());
        assert!(
            e.contains("mask_planes_lowres.png") && e.contains("4x3"),
            "{e}"
        );
        std::fs::remove_file(&mask).unwrap();
        let high = dir.path().join("mask_fine_highres.png");
        write_mask_png(&high, 2, 2, &[true; 4]).unwrap();
        let e = format!("{:#}", load_region_truth(dir.path(), 4, 3).unwrap_err());
        assert!(e.contains(HIGHRES_GT_FILE), "{e}");
    }
}

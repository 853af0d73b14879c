//! The HCI evaluation masks of the centre view (`mask_*_lowres.png`, `mask_*_highres.png`),
//! computed from its HCI layer's depth, geometric normals and object ids
//! (docs/design/ground-truth.md, "The HCI evaluation masks").

use crate::camera::LightFieldCamera;
use anyhow::Result;
use lfformat::gt_maps::HciLayer;
use lfformat::hci_masks::{HciMasks, Pinhole, SurfaceMaps, hci_masks};
use lfformat::region_masks::{mask_file, write_mask_png};
use std::path::Path;

/// Writes the five masks of `layer`, the centre view's HCI layer at `scale` pixels per
/// low-resolution pixel (1: the `_lowres` masks, else the `_highres` ones).
pub fn write_hci_masks(
    dir: &Path,
    cam: &LightFieldCamera,
    layer: &HciLayer,
    scale: u32,
) -> Result<()> {
    for (stem, mask) in centre_masks(cam, layer, scale).named() {
        let path = dir.join(mask_file(stem, scale > 1));
        write_mask_png(&path, layer.width, layer.height, mask)?;
    }
    Ok(())
}

/// The five masks of the centre view's HCI layer at `scale` pixels per low-resolution pixel.
pub fn centre_masks(cam: &LightFieldCamera, layer: &HciLayer, scale: u32) -> HciMasks {
    let maps = SurfaceMaps {
        width: layer.width,
        height: layer.height,
        depth: &layer.depth,
        normal: &layer.normal,
        object: &layer.object,
    };
    // The centre camera's sensor is not shifted: its principal point is the image centre.
    let pinhole = Pinhole {
        focal_px: cam.f_px() * f64::from(scale),
        cx: layer.width as f64 / 2.0,
        cy: layer.height as f64 / 2.0,
        disparity_per_inverse_depth: cam.f_px() * cam.baseline_m,
        scale: scale as usize,
    };
    hci_masks(&maps, &pinhole)
}

//! Where a single-valued disparity can be trusted: the rule of `valid_mask.png`.
//!
//! Trainers that read one disparity per pixel (OACC-Net, DistgDisp) learn from it only where
//! the mask is set. A pixel is valid when one mode carries (nearly) all of it, the HCI depth
//! lies on that mode's surface, and no glass or semi-transparent surface was seen in front of
//! or on it; everything else — depth edges, thin structures, panes, curtains, refraction — is
//! left out.

use lfformat::Mode;

/// The least η of the one mode that makes a pixel single-valued.
pub const DOMINANT_ETA: f32 = 0.99;

/// How far (relative depth) the HCI depth and a translucent hit may lie from the dominant
/// mode and still count as on its surface.
pub const SAME_SURFACE: f32 = 0.02;

/// Whether a pixel with these `modes`, nearest translucent hit `translucent_z` (infinity:
/// none) and HCI depth `hci_depth` (NaN: none) is valid.
pub fn is_valid(modes: &[Mode], translucent_z: f32, hci_depth: f32) -> bool {
    let Some(m) = modes.iter().find(|m| m.eta >= DOMINANT_ETA) else {
        return false;
    };
    let tolerance = SAME_SURFACE * m.depth;
    (hci_depth - m.depth).abs() <= tolerance && translucent_z > m.depth + tolerance
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(depth: f32, eta: f32) -> Mode {
        Mode {
            disparity: 1.0 / depth,
            depth,
            eta,
            eta_exact: eta,
        }
    }

    #[test]
    fn one_opaque_surface_carrying_the_pixel_is_valid_and_nothing_else() {
        let wall = [mode(4.0, 1.0)];
        assert!(is_valid(&wall, f32::INFINITY, 4.0));
        assert!(is_valid(&[mode(4.0, 0.995)], f32::INFINITY, 4.01));
        // An edge: two modes, neither carries 0.99.
        assert!(!is_valid(
            &[mode(2.0, 0.6), mode(4.0, 0.4)],
            f32::INFINITY,
            2.0
        ));
        // A thin wire on the pixel-centre ray: the HCI depth is not the dominant surface's.
        assert!(!is_valid(
            &[mode(1.0, 0.005), mode(4.0, 0.995)],
            f32::INFINITY,
            1.0
        ));
        // Seen through glass (the pane's own mode is tiny) or on a translucent surface.
        assert!(!is_valid(&wall, 2.0, 4.0));
        assert!(!is_valid(&wall, 4.0, 4.0));
        // A translucent surface behind the wall does not matter; no surface at all does.
        assert!(is_valid(&wall, 6.0, 4.0));
        assert!(!is_valid(&[], f32::INFINITY, f32::NAN));
        assert!(!is_valid(&wall, f32::INFINITY, f32::NAN));
    }
}

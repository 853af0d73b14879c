//! The sRGB transfer function (IEC 61966-2-1) of the 8-bit views and textures: one definition
//! for the writer, the texture decoder and the robustness benchmark's corruptions.

/// An encoded value in [0, 1] → linear.
pub fn to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A linear value in [0, 1] → encoded.
pub fn from_linear(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The standard's values, and the two functions inverting each other over 8-bit codes.
    #[test]
    fn the_transfer_function_matches_the_standard() {
        assert!((from_linear(0.002) - 0.025_84).abs() < 1e-5);
        assert!((to_linear(0.5) - 0.214_04).abs() < 1e-5);
        for code in 0..=255u8 {
            let c = f32::from(code) / 255.0;
            assert!((from_linear(to_linear(c)) - c).abs() < 1e-5, "code {code}");
        }
    }
}

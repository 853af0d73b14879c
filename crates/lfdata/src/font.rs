//! The font of every chart the binaries draw: DejaVu Sans embedded in the binary, so charts
//! look the same on machines without fonts (licence: `assets/DejaVuSans-LICENSE.txt`).

use std::sync::OnceLock;

use anyhow::{Result, anyhow};
use plotters::style::FontStyle;

/// The family name the embedded font is registered under; charts name it in their text styles.
pub const FAMILY: &str = "sans-serif";

/// DejaVu Sans.
static DATA: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the embedded font with plotters, once per process (plotters draws no text
/// without one here).
pub fn register() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED
        .get_or_init(|| plotters::style::register_font(FAMILY, FontStyle::Normal, DATA).is_ok());
    ok.then_some(())
        .ok_or_else(|| anyhow!("the embedded font could not be loaded"))
}

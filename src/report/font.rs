//! The one chart font: DejaVu Sans, embedded in the binary and registered with plotters as
//! the `sans-serif` family. No system font library or font file is needed at run time, and
//! charts render identically everywhere. Font and licence: `assets/fonts/`.

use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

use crate::error::ReportError;

/// DejaVu Sans 2.37, unmodified (`assets/fonts/README.md`).
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Family name the font is registered under. `sans-serif` is plotters' default family and a
/// generic CSS family, so the SVG files name a font every viewer has.
pub const FAMILY: &str = "sans-serif";

/// Registers the embedded font once per process; later calls return the first outcome.
/// Other styles (bold, italic) fall back to this regular face.
pub fn ensure_registered() -> Result<(), ReportError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok());
    if ok { Ok(()) } else { Err(ReportError::Font { font: "assets/fonts/DejaVuSans.ttf".into() }) }
}

#[cfg(test)]
mod tests {
    #[test]
    fn embedded_font_registers() {
        super::ensure_registered().unwrap();
        super::ensure_registered().unwrap();
    }
}

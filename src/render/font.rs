//! Text for pictures: the machine has no system fonts, so the DejaVu Sans bytes embedded by
//! the `dejavu` crate are registered with plotters once, under the family name every
//! renderer asks for. Also fits captions into a pixel width.

use super::error::RenderError;
use plotters::style::{FontDesc, FontFamily, FontStyle, register_font};
use std::sync::OnceLock;

/// Font family name the renderers draw text with.
pub(crate) const FAMILY: &str = "sans-serif";

/// Registers DejaVu Sans (regular and bold) under [`FAMILY`]; cheap after the first call.
pub(crate) fn ensure_fonts() -> Result<(), RenderError> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        register_font(FAMILY, FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| "DejaVu Sans regular is not a valid font".to_string())?;
        register_font(FAMILY, FontStyle::Bold, dejavu::sans::bold())
            .map_err(|_| "DejaVu Sans bold is not a valid font".to_string())
    })
    .clone()
    .map_err(RenderError::Draw)
}

/// Width in pixels of `text` drawn at `size` pixels (fonts must be registered).
pub(crate) fn text_width(text: &str, size: f64) -> f64 {
    let font = FontDesc::new(FontFamily::Name(FAMILY), size, FontStyle::Normal);
    match font.box_size(text) {
        Ok((w, _)) => f64::from(w),
        // Only reachable before registration; the average DejaVu advance is ~0.6 em.
        Err(_) => text.chars().count() as f64 * size * 0.6,
    }
}

/// Shortens `text` with an ellipsis so it fits `max_px` pixels at `size` pixels.
pub(crate) fn fit_text(text: &str, size: f64, max_px: f64) -> String {
    if text_width(text, size) <= max_px {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    // Longest prefix that still fits with the ellipsis: binary search on its length.
    let (mut lo, mut hi) = (0usize, chars.len());
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        let candidate: String = chars[..mid].iter().chain(['…'].iter()).collect();
        if text_width(&candidate, size) <= max_px {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    chars[..lo].iter().chain(['…'].iter()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fonts_register_and_long_text_is_shortened() {
        ensure_fonts().unwrap();
        ensure_fonts().unwrap();
        assert_eq!(fit_text("walk", 10.0, 100.0), "walk");
        let long = "a person walks forward and then turns around to sit down";
        let short = fit_text(long, 10.0, 60.0);
        assert!(short.ends_with('…'));
        assert!(text_width(&short, 10.0) <= 60.0, "{short}");
        assert!(short.chars().count() > 3, "{short}");
    }
}

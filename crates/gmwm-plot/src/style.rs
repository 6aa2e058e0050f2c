//! The look shared by every figure: the colour-blind-safe palette, the embedded font, text
//! sizes and tick labels written as powers of ten.

use plotters::style::RGBColor;

/// Okabe & Ito's palette (Color Universal Design, 2008), distinguishable under every common
/// colour-vision deficiency: black, orange, sky blue, bluish green, blue, vermillion, reddish
/// purple, yellow (last: weak on white, used only for fills).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 158, 115),
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(204, 121, 167),
    RGBColor(240, 228, 66),
];

/// Grey of the empirical estimates' band and points.
pub const EMPIRICAL: RGBColor = RGBColor(80, 80, 80);

/// The family every text is set in: DejaVu Sans, embedded (the `dejavu` crate), registered
/// under this name so that PNG text never needs a system font; SVG viewers use their own
/// sans-serif.
pub const FONT: &str = "sans-serif";

/// Text sizes as plotters takes them (it sets text at 1/1.24 of the size: 22 gives 17.7 px),
/// legible at 100% in a 1000-pixel-wide figure.
pub const TITLE_SIZE: u32 = 22;
/// Axis descriptions (15.3 px).
pub const LABEL_SIZE: u32 = 19;
/// Tick labels and legend entries (13.7 px).
pub const TICK_SIZE: u32 = 17;

/// Registers the embedded font once per process (plotters keeps a global font table).
#[cfg(not(target_family = "wasm"))]
pub(crate) fn ensure_fonts() {
    use plotters::style::FontStyle;
    use std::sync::Once;
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // the bytes are a TrueType font shipped inside the dejavu crate: registration cannot
        // fail for them, and a failure would only leave text unrendered in PNGs
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// No font table on WebAssembly: SVG text is laid out by estimate and drawn by the browser.
#[cfg(target_family = "wasm")]
pub(crate) fn ensure_fonts() {}

/// A palette colour by index (wrapping).
pub(crate) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

fn superscript(k: i32) -> String {
    k.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

/// A tick label on a logarithmic axis: `10⁻³` for a power of ten, `2×10⁻³` between them.
pub fn pow10_label(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    let k = v.log10().floor() as i32;
    let mantissa = v / 10f64.powi(k);
    let m = mantissa.round();
    if (mantissa - 1.0).abs() < 1e-6 {
        format!("10{}", superscript(k))
    } else if (mantissa - m).abs() < 1e-6 {
        format!("{m}×10{}", superscript(k))
    } else {
        format!("{mantissa:.1}×10{}", superscript(k))
    }
}

/// A value in a label: four significant digits, scientific outside [1e-3, 1e4).
pub fn number(v: f64) -> String {
    if !v.is_finite() {
        return "—".to_string();
    }
    let a = v.abs();
    if a == 0.0 {
        "0".to_string()
    } else if (1e-3..1e4).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let mut k = a.log10().floor() as i32;
        let mut m = v / 10f64.powi(k);
        // a mantissa that rounds up to 10 moves to the next power: 9.9996e-4 is 1×10⁻³
        if format!("{:.3}", m.abs()).starts_with("10") {
            k += 1;
            m /= 10.0;
        }
        let ms = format!("{m:.3}");
        let ms = ms.trim_end_matches('0').trim_end_matches('.');
        format!("{ms}×10{}", superscript(k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow10_label_writes_powers_and_multiples() {
        assert_eq!(pow10_label(1e-3), "10⁻³");
        assert_eq!(pow10_label(1.0), "10⁰");
        assert_eq!(pow10_label(100.0), "10²");
        assert_eq!(pow10_label(2e-5), "2×10⁻⁵");
        assert_eq!(pow10_label(0.0), "");
    }

    #[test]
    fn number_keeps_four_significant_digits() {
        assert_eq!(number(0.012345), "0.01235");
        assert_eq!(number(12.5), "12.5");
        assert_eq!(number(3.2e-6), "3.2×10⁻⁶");
        assert_eq!(number(-4.0e5), "-4×10⁵");
        assert_eq!(number(9.9996e-4), "1×10⁻³");
    }
}

//! The wv figure (one place per figure: its builder and what only it draws).

use super::*;

/// Wavelet variances with their confidence bands, one panel per column (`Layout::Grid`, paper
/// Fig. 1a) or one per sensor type with the axes overlaid (Fig. 1b); a column's datasheet
/// lines dashed grey.
pub fn wv_figure(columns: &[Column<'_, WaveletVariance>], layout: Layout) -> Figure {
    let curves: Vec<Curve<'_>> = columns
        .iter()
        .map(|c| Curve {
            name: c.name,
            place: c.place(),
            unit: c.unit,
            tau_s: c.data.tau_s().to_vec(),
            value: c.data.wv().to_vec(),
            low: c.data.ci_low().to_vec(),
            high: c.data.ci_high().to_vec(),
            datasheet: datasheet_series(&c.datasheet, c.data.tau_s(), Quantity::Wv),
        })
        .collect();
    let what = match columns.first().map(|c| c.data.robust().is_some()) {
        Some(true) => "robust WV",
        _ => "WV",
    };
    variance_figure(&curves, layout, WV_SCALE, &wv_label, what)
}

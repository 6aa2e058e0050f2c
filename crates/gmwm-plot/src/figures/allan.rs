//! The allan figure (one place per figure: its builder and what only it draws).

use super::*;

/// Allan, modified Allan or Hadamard deviations with their bands (square roots of the
/// variance's interval), laid out as [`wv_figure`]; on the Allan deviation, a column's
/// datasheet lines dashed grey.
pub fn allan_figure(columns: &[Column<'_, AllanVariance>], layout: Layout) -> Figure {
    let curves: Vec<Curve<'_>> = columns
        .iter()
        .map(|c| Curve {
            name: c.name,
            place: c.place(),
            unit: c.unit,
            tau_s: c.data.tau_s().to_vec(),
            value: c.data.adev().to_vec(),
            low: c.data.ci_low().iter().map(|v| v.sqrt()).collect(),
            high: c.data.ci_high().iter().map(|v| v.sqrt()).collect(),
            // the IEEE slope laws are those of the Allan variance only
            datasheet: match c.data.kind() {
                AllanKind::Overlapping | AllanKind::NonOverlapping => {
                    datasheet_series(&c.datasheet, c.data.tau_s(), Quantity::Adev)
                }
                _ => Vec::new(),
            },
        })
        .collect();
    let (what, quantity) = match columns.first().map(|c| c.data.kind()) {
        Some(AllanKind::Modified) => ("modified Allan deviation", "modified Allan deviation"),
        Some(AllanKind::Hadamard | AllanKind::HadamardNonOverlapping) => {
            ("Hadamard deviation", "Hadamard deviation")
        }
        _ => ("Allan deviation", "Allan deviation σ(τ)"),
    };
    let label = move |unit: &str| format!("{quantity} [{}]", pretty(unit));
    variance_figure(&curves, layout, AV_SCALE, &label, what)
}

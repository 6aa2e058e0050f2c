//! The calibration report: one self-contained HTML page (no external asset, works offline,
//! prints well) that renders a [`CalibrationReport`] — the recording's summary, every figure,
//! the selection table, the estimates with intervals and the fit verdict, the IEEE read-off
//! beside the GMWM values, the navigation-filter files as exported and the classical-vs-robust
//! check. It computes nothing: the page's numbers are the report's, whose JSON (as
//! `gmwm calibrate --json` writes it) is embedded in the page.

use crate::figures::{
    compare_figure, covariate_figure, fit_figure, ieee_figure, psd_figure, recordings_figure,
    selection_figure, wv_figure, Column, Layout, WIC_ROWS,
};
use crate::style::number;
use crate::{Figure, PlotError};
use base64::Engine as _;
use gmwm::{
    AxisCalibration, CalibrationReport, DatasheetComparison, Estimate, EstimateStatus, RowStatus,
    Sensor, SignalKind,
};
use std::fmt::Write as _;

/// Everything the page shows besides the calibration itself.
#[derive(Debug, Clone, Default)]
pub struct ReportContext {
    /// The recording's file, as the user named it.
    pub file: String,
    /// What it was read from (text, binary records, a ROS container and topic).
    pub source: String,
    /// What the reader noticed (timestamps, columns left out), one line each.
    pub reader_notes: Vec<String>,
    /// The timestamp checks, as text (`None`: no time column).
    pub timing: Option<String>,
    /// The command that made the report.
    pub command: String,
    /// The navigation-filter files as exported: (stack, file name, content).
    pub exports: Vec<(String, String, String)>,
    /// The JSON document `--json` writes for this calibration, embedded (compact, `<` escaped
    /// as `\u003c`).
    pub json: String,
    /// The program and version that made the report.
    pub generator: String,
    /// N, B, K against a covariate (`gmwm calibrate --covariate`), when asked for.
    pub covariate: Option<gmwm::CovariateCalibration>,
    /// GMWM+ of every axis (`gmwm calibrate --augment`); empty when not asked for.
    pub augmented: Vec<gmwm::AxisAugmented>,
}

/// A sentence with its first letter upper-case.
fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    chars
        .next()
        .map(|c| c.to_uppercase().chain(chars).collect())
        .unwrap_or_default()
}

/// An HTML id for a column: letters, digits, `_` and `-` kept, anything else `-`.
fn slug(column: &str) -> String {
    column
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// HTML-escapes text.
fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A figure as an `<img>` with an SVG data URI, inside a `<figure>` with its caption.
fn figure_html(figure: &Figure, caption: &str) -> Result<String, PlotError> {
    let svg = figure.svg()?;
    let data = base64::engine::general_purpose::STANDARD.encode(svg.as_bytes());
    Ok(format!(
        "<figure><img src=\"data:image/svg+xml;base64,{data}\" width=\"{}\" height=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
        figure.size.0,
        figure.size.1,
        esc(caption),
        esc(caption)
    ))
}

/// An estimate with its interval, unit and, where they exist, its datasheet form.
fn estimate_cell(e: &Estimate) -> String {
    let value = match e.status {
        EstimateStatus::UpperBound => format!("≤ {}", number(e.value)),
        _ => number(e.value),
    };
    let interval = match (e.ci_low, e.ci_high, e.status) {
        (Some(lo), Some(hi), EstimateStatus::Estimated) => {
            format!(
                " <span class=\"ci\">[{}, {}]</span>",
                number(lo),
                number(hi)
            )
        }
        (_, _, EstimateStatus::Undetermined) => {
            " <span class=\"ci\">(not determined)</span>".to_string()
        }
        _ => String::new(),
    };
    let datasheet = e
        .forms
        .as_ref()
        .and_then(|f| f.datasheet.as_ref())
        .map(|q| {
            format!(
                "<br><span class=\"alt\">{} {}</span>",
                number(q.value),
                esc(&q.unit)
            )
        })
        .unwrap_or_default();
    format!("{value} {}{interval}{datasheet}", esc(&e.unit))
}

fn row(out: &mut String, cells: &[String]) {
    out.push_str("<tr>");
    for c in cells {
        let _ = write!(out, "<td>{c}</td>");
    }
    out.push_str("</tr>\n");
}

fn header(out: &mut String, cells: &[&str]) {
    out.push_str("<thead><tr>");
    for c in cells {
        let _ = write!(out, "<th>{}</th>", esc(c));
    }
    out.push_str("</tr></thead>\n");
}

/// The recording's summary.
fn summary(out: &mut String, report: &CalibrationReport, ctx: &ReportContext) {
    out.push_str("<section id=\"recording\"><h2>Recording</h2><table class=\"kv\">\n");
    let hours = report.duration_s / 3600.0;
    let duration = if hours >= 1.0 {
        format!("{} s ({:.2} h)", number(report.duration_s), hours)
    } else {
        format!("{} s", number(report.duration_s))
    };
    // a pooled calibration lists its recordings where one recording names its file
    let file = if report.recordings.is_empty() {
        ("file", esc(&ctx.file))
    } else {
        (
            "recordings",
            report
                .recordings
                .iter()
                .map(|r| {
                    format!(
                        "{}: {} samples ({} s)",
                        esc(&r.name),
                        r.samples,
                        number(r.duration_s)
                    )
                })
                .collect::<Vec<_>>()
                .join("<br>"),
        )
    };
    let kv = vec![
        file,
        ("read as", esc(&ctx.source)),
        ("name", esc(report.name.as_deref().unwrap_or("—"))),
        (
            if report.recordings.is_empty() {
                "samples per axis"
            } else {
                "samples per axis, all recordings"
            },
            report.samples.to_string(),
        ),
        ("sampling rate", format!("{} Hz", number(report.freq_hz))),
        ("length", duration),
        (
            "columns",
            report
                .axes
                .iter()
                .map(|a| {
                    format!(
                        "{} ({})",
                        esc(&a.column),
                        esc(a.data_unit.as_deref().unwrap_or("unit unknown"))
                    )
                })
                .collect::<Vec<_>>()
                .join(", "),
        ),
        (
            "timestamps",
            esc(ctx
                .timing
                .as_deref()
                .unwrap_or("no time column: rate from the sidecar or --freq")),
        ),
        ("full model", esc(&report.full_model)),
        (
            "confidence level",
            format!("{:.0}%", 100.0 * (1.0 - report.alpha)),
        ),
    ];
    for (k, v) in kv {
        let _ = writeln!(out, "<tr><th>{k}</th><td>{v}</td></tr>");
    }
    out.push_str("</table>\n");
    // the timestamp checks have their own row
    let notes: Vec<&String> = ctx
        .reader_notes
        .iter()
        .filter(|n| Some(n.as_str()) != ctx.timing.as_deref())
        .chain(&report.checks)
        .collect();
    if !notes.is_empty() {
        out.push_str("<ul class=\"notes\">");
        for n in notes {
            let _ = write!(out, "<li>{}</li>", esc(n));
        }
        out.push_str("</ul>\n");
    }
    out.push_str("</section>\n");
}

/// The overview table: one row per axis with the values a filter takes.
fn overview(out: &mut String, report: &CalibrationReport) {
    out.push_str("<section id=\"overview\"><h2>Summary</h2><table>\n");
    header(
        out,
        &[
            "axis",
            "selected model",
            "noise density N",
            "random walk K",
            "bias instability B",
            "fit",
            "contamination",
        ],
    );
    out.push_str("<tbody>\n");
    for a in &report.axes {
        let cell = |e: &Option<Estimate>| e.as_ref().map_or("—".to_string(), estimate_cell);
        row(
            out,
            &[
                format!(
                    "<a href=\"#axis-{}\">{}</a>",
                    slug(&a.column),
                    esc(&a.column)
                ),
                esc(&a.canonical_model),
                cell(&a.noise_density),
                cell(&a.random_walk),
                cell(&a.bias_instability),
                if a.verdict.explains_wv {
                    "explains the WV".into()
                } else {
                    "<b>misfit</b>".into()
                },
                match &a.contamination {
                    Some(c) if c.matters => "<b>matters</b>".into(),
                    Some(_) => "does not matter".into(),
                    None => "not checked".into(),
                },
            ],
        );
    }
    out.push_str("</tbody></table></section>\n");
}

fn status_text(status: RowStatus) -> &'static str {
    match status {
        RowStatus::Selected => "selected",
        RowStatus::Equivalent => "equivalent",
        RowStatus::Separable => "",
    }
}

/// Rows of the selection table shown: the best ten and every selected or equivalent one.
const TABLE_ROWS: usize = 10;

/// The Welch PSD of every axis that has one, beside the WVs, with the fitted white-noise
/// density's level where the calibration has one (an upper bound is no level).
fn psd_section(out: &mut String, report: &CalibrationReport) -> Result<(), PlotError> {
    let pairs: Vec<(&AxisCalibration, (gmwm::Psd, Option<f64>))> = report
        .axes
        .iter()
        .filter_map(|a| {
            let n = a
                .noise_density
                .as_ref()
                .filter(|e| e.status != EstimateStatus::UpperBound)
                .map(|e| e.value);
            Some((a, (a.psd.clone()?, n)))
        })
        .collect();
    if pairs.is_empty() {
        out.push_str("<p>No power spectral density (see each axis' notes).</p>\n");
        return Ok(());
    }
    let columns: Vec<Column<'_, _>> = pairs.iter().map(|(a, p)| column(a, p)).collect();
    let first = &pairs[0].1 .0;
    out.push_str(&figure_html(
        &psd_figure(&columns, Layout::Grid),
        &format!(
            "Power spectral density of every axis as the one-sided √PSD (Welch: Hann window, 50% overlap, {} segments of {} samples, resolution {} Hz; means of {} log-spaced frequency bins). Humps above the flat white-noise floor are vibration or other periodic errors, the fall before f/2 = {} Hz the sensor's own filter. The dashed line is the fitted white-noise density N at its one-sided level √2·N.",
            first.segments(),
            first.segment_length(),
            number(first.resolution_hz()),
            gmwm::BINNED_POINTS,
            number(report.freq_hz / 2.0)
        ),
    )?);
    Ok(())
}

/// The axis' column of a figure.
fn one<'a, T>(a: &'a AxisCalibration, data: &'a T) -> [Column<'a, T>; 1] {
    [column(a, data)]
}

/// The axis' column, placed by the sensor and axis the engine recognised.
fn column<'a, T>(a: &'a AxisCalibration, data: &'a T) -> Column<'a, T> {
    let lines = a.datasheet.as_ref().map(|d| d.lines()).unwrap_or_default();
    let c = Column::new(&a.column, &a.unit, data).with_datasheet(lines);
    match a.kind {
        Some(SignalKind::Gyroscope) => c.with_sensor(Sensor::Gyroscope, &a.axis),
        Some(SignalKind::Accelerometer) => c.with_sensor(Sensor::Accelerometer, &a.axis),
        None => c,
    }
}

/// The axis against its datasheet: each value as given and in SI, the measured one in the
/// datasheet's unit with its interval, the ratio and the verdict (the engine's comparison).
fn datasheet_table(out: &mut String, d: &DatasheetComparison) {
    out.push_str("<h3>Against the datasheet</h3><table>\n");
    header(
        out,
        &[
            "term",
            "datasheet",
            "datasheet (SI)",
            "measured (datasheet unit) [interval]",
            "measured / datasheet",
            "verdict",
        ],
    );
    out.push_str("<tbody>\n");
    for t in d.terms() {
        let unit = esc(&t.unit);
        let measured = match (t.measured_si, t.ci_low_si, t.ci_high_si) {
            (None, ..) => "not measured".to_string(),
            (Some(m), ..) if t.upper_bound => {
                format!("≤ {} {unit} (upper bound)", number(t.in_datasheet_unit(m)))
            }
            (Some(m), Some(lo), Some(hi)) => format!(
                "{} [{}, {}] {unit}",
                number(t.in_datasheet_unit(m)),
                number(t.in_datasheet_unit(lo)),
                number(t.in_datasheet_unit(hi))
            ),
            (Some(m), ..) => format!("{} {unit} (no interval)", number(t.in_datasheet_unit(m))),
        };
        let ratio = match t.ratio {
            Some(r) if t.upper_bound => format!("≤ {}", number(r)),
            Some(r) => number(r),
            None => "—".to_string(),
        };
        row(
            out,
            &[
                t.key.to_string(),
                format!("{} {unit}", t.value),
                format!("{} {}", number(t.value_si), esc(&t.unit_si)),
                measured,
                ratio,
                esc(t.verdict_text()),
            ],
        );
    }
    out.push_str(
        "</tbody></table>\n<p class=\"small\">The measured values are those of the \
        Estimates table, whose source column says where each comes from (a term of the GMWM fit; \
        B from a flicker term, else the Allan deviation's floor / 0.664); \
        the figures draw the datasheet's lines dashed grey.</p>\n",
    );
}

/// `+1.2%`, or a dash.
fn percent(x: f64) -> String {
    if x.is_finite() {
        format!("{:+.1}%", 100.0 * x)
    } else {
        "–".into()
    }
}

/// The self-audit of an axis: how far to trust each number, and GMWM against the IEEE read-off.
fn audit_section(out: &mut String, column: &str, au: &gmwm::Audit) {
    let _ = writeln!(
        out,
        "<h3 id=\"audit-{}\">Self-audit: how far to trust these numbers</h3>\n<p>The identified model <code>{}</code> was simulated {} times at this recording's length and rate and each simulation recalibrated from scratch. The same canonical model (<b>{}</b>) was selected in {:.0}% of them{}. For each number: the calibration's median error against the simulated value, its spread, how often its 95% interval held the value, and the same for the IEEE 952 slope read-off on the same recordings.</p>",
        esc(column),
        esc(&au.model),
        au.replicates,
        esc(&au.canonical_model),
        100.0 * au.same_model,
        if au.failed > 0 { format!(" ({} calibrations failed)", au.failed) } else { String::new() }
    );
    out.push_str("<table>\n");
    header(
        out,
        &[
            "",
            "simulated value",
            "GMWM bias",
            "GMWM spread",
            "interval coverage",
            "IEEE bias",
            "IEEE spread",
            "more accurate",
        ],
    );
    out.push_str("<tbody>\n");
    for q in &au.quantities {
        let coverage = match q.gmwm.coverage {
            Some(c) => format!("{:.0}% ({} intervals)", 100.0 * c, q.gmwm.intervals),
            None => "no intervals".into(),
        };
        // root mean square error relative to the value: bias and spread together
        let rmse = |s: &gmwm::AuditStats| (s.bias * s.bias + s.spread * s.spread).sqrt();
        let (ib, is, better) = match &q.ieee {
            Some(i) => (
                percent(i.bias),
                percent(i.spread).trim_start_matches('+').to_string(),
                if rmse(&q.gmwm) <= rmse(i) {
                    "GMWM"
                } else {
                    "IEEE"
                }
                .to_string(),
            ),
            None => ("–".into(), "–".into(), "GMWM (no read-off)".into()),
        };
        let _ = write!(out, "<tr>");
        for c in [
            q.name.clone(),
            format!("{} {}", number(q.target), esc(&q.unit)),
            percent(q.gmwm.bias),
            percent(q.gmwm.spread).trim_start_matches('+').to_string(),
            coverage,
            ib,
            is,
            better,
        ] {
            let _ = write!(out, "<td>{c}</td>");
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table>\n");
    if au.models.len() > 1 {
        let list: Vec<String> = au
            .models
            .iter()
            .map(|(m, n)| format!("{} ({n})", esc(m)))
            .collect();
        let _ = writeln!(
            out,
            "<p class=\"small\">Models selected: {}.</p>",
            list.join(", ")
        );
    }
}

fn axis_section(out: &mut String, a: &AxisCalibration, alpha: f64) -> Result<(), PlotError> {
    let id = esc(&a.column);
    let _ = writeln!(
        out,
        "<section class=\"axis\" id=\"axis-{id}\"><h2>{id}</h2>"
    );
    let selected = a.selection.selected().without_values().to_string();
    let reason = a.selection.reason();
    // the refinement guided by the WV's shape may have changed the selection's model
    let how = if selected == a.model {
        esc(&capitalised(&reason))
    } else {
        format!(
            "The WIC selected {} ({}); the notes below say how the calibration refined it.",
            // as the selection's figure and table name it
            esc(&a.selection.selected_canonical().model.to_string()),
            esc(reason.trim_end_matches('.'))
        )
    };
    let _ = writeln!(
        out,
        "<p>Model <b>{}</b> (canonical model {}; estimates from the identified fit of {}). {how}</p>",
        esc(&a.model),
        esc(&a.canonical_model),
        esc(&a.identified_model),
    );
    let unit = a.unit.as_str();

    // model selection
    out.push_str(&figure_html(
        &selection_figure(&one(a, &a.selection), WIC_ROWS),
        &format!("{}: the empirical WV and the selected model's implied WV; the WIC of the best canonical models (objective + optimism, the selected one marked ▶).", a.column),
    )?);
    out.push_str("<h3>Model selection (WIC)</h3><table>\n");
    header(
        out,
        &[
            "canonical model",
            "candidates",
            "objective",
            "optimism",
            "WIC",
            "ΔWIC ± se",
            "status",
        ],
    );
    out.push_str("<tbody>\n");
    for (i, r) in a.selection.rows().iter().enumerate() {
        if i >= TABLE_ROWS && r.status == RowStatus::Separable {
            continue;
        }
        let class = if r.status == RowStatus::Selected {
            " class=\"selected\""
        } else {
            ""
        };
        let _ = write!(out, "<tr{class}>");
        for c in [
            esc(&r.score.canonical_model.to_string()),
            r.members.len().to_string(),
            number(r.score.objective),
            number(r.score.optimism),
            number(r.score.wic),
            format!("{} ± {}", number(r.delta_wic), number(r.delta_wic_se)),
            status_text(r.status).to_string(),
        ] {
            let _ = write!(out, "<td>{c}</td>");
        }
        out.push_str("</tr>\n");
    }
    let _ = writeln!(out, "</tbody></table><p class=\"small\">{} canonical models from {} candidates; rows beyond the best {TABLE_ROWS} that are neither selected nor equivalent are left out (they are in the JSON).</p>", a.selection.rows().len(), a.selection.candidates().len());

    // estimates
    out.push_str("<h3>Estimates</h3><table>\n");
    header(out, &["quantity", "value (SI) [interval]", "source"]);
    out.push_str("<tbody>\n");
    let named: Vec<(&str, Option<&Estimate>)> = vec![
        ("noise density N", a.noise_density.as_ref()),
        ("random walk K", a.random_walk.as_ref()),
        ("bias instability B", a.bias_instability.as_ref()),
        ("quantization Q", a.quantization.as_ref()),
        ("rate ramp R", a.rate_ramp.as_ref()),
        (
            "Gauss–Markov correlation time",
            a.gauss_markov_bias.as_ref().map(|g| &g.correlation_time),
        ),
        (
            "Gauss–Markov σ",
            a.gauss_markov_bias.as_ref().map(|g| &g.sigma),
        ),
        (
            "Gauss–Markov driving density",
            a.gauss_markov_bias.as_ref().map(|g| &g.driving_density),
        ),
    ];
    for (name, e) in named {
        if let Some(e) = e {
            row(out, &[name.to_string(), estimate_cell(e), esc(&e.source)]);
        }
    }
    out.push_str("</tbody></table>\n<table>\n");
    header(
        out,
        &[
            "parameter of the identified fit",
            "estimate",
            "se",
            &format!("{:.0}% interval", 100.0 * (1.0 - alpha)),
        ],
    );
    out.push_str("<tbody>\n");
    for p in a.inference.parameters() {
        let opt = |v: Option<f64>| v.map_or("—".to_string(), number);
        let interval = match (p.ci_low, p.ci_high) {
            (Some(lo), Some(hi)) => format!("[{}, {}]", number(lo), number(hi)),
            _ => "—".to_string(),
        };
        row(
            out,
            &[esc(&p.name), number(p.estimate), opt(p.se), interval],
        );
    }
    out.push_str("</tbody></table>\n");
    let _ = writeln!(
        out,
        "<p class=\"verdict {}\"><b>Goodness of fit:</b> {}</p>",
        if a.verdict.explains_wv { "ok" } else { "bad" },
        esc(&a.verdict.summary)
    );
    out.push_str(&figure_html(
        &fit_figure(&one(a, &a.fit)),
        &format!(
            "{}: the identified fit {}, its implied WV and each process's (values in {unit}).",
            a.column,
            a.fit.model().without_values()
        ),
    )?);

    // IEEE beside GMWM
    out.push_str("<h3>IEEE 952 read-off beside the GMWM values</h3><table>\n");
    header(out, &["term", "IEEE 952 (Allan deviation)", "GMWM"]);
    out.push_str("<tbody>\n");
    let ieee = &a.ieee;
    for (term, r, gmwm) in [
        ("N", &ieee.n, a.noise_density.as_ref()),
        ("B", &ieee.b, a.bias_instability.as_ref()),
        ("K", &ieee.k, a.random_walk.as_ref()),
        ("Q", &ieee.q, a.quantization.as_ref()),
        ("R", &ieee.r, a.rate_ramp.as_ref()),
    ] {
        let read = match (r.value, r.ci_low, r.ci_high) {
            (Some(v), Some(lo), Some(hi)) => format!(
                "{} [{}, {}] at {} s",
                number(v),
                number(lo),
                number(hi),
                number(r.at_tau_s)
            ),
            (Some(v), _, _) => format!("{} at {} s", number(v), number(r.at_tau_s)),
            (None, _, _) => format!("— {}", esc(r.note.as_deref().unwrap_or(""))),
        };
        let g = match (term, gmwm) {
            ("B", _) => "read from the Allan deviation only; the model's Gauss–Markov terms are under Estimates".to_string(),
            (_, Some(e)) => estimate_cell(e),
            (_, None) => "not in the model".to_string(),
        };
        row(out, &[term.to_string(), read, g]);
    }
    out.push_str("</tbody></table>\n");
    if let Some(d) = &a.datasheet {
        datasheet_table(out, d);
    }
    let pair = (a.allan.clone(), a.ieee.clone());
    out.push_str(&figure_html(
        &ieee_figure(&one(a, &pair)),
        &format!(
            "{}: Allan deviation with the IEEE 952 slope lines (cluster time m/f, half the WV \
             scale of the same information, docs/methods.md §14.1).",
            a.column
        ),
    )?);

    // contamination
    out.push_str("<h3>Classical against robust WV</h3>\n");
    match &a.contamination {
        Some(c) => {
            let _ = writeln!(
                out,
                "<p class=\"verdict {}\">{}</p>",
                if c.matters { "bad" } else { "ok" },
                esc(&c.summary)
            );
            let pair = (c.classical.clone(), c.robust.clone());
            out.push_str(&figure_html(
                &compare_figure(&one(a, &pair)),
                &format!(
                    "{}: classical and robust (efficiency {}) WV with their intervals.",
                    a.column,
                    c.robust.robust().map_or(0.6, |r| r.eff())
                ),
            )?);
        }
        None => out.push_str("<p>Not compared (see the notes).</p>\n"),
    }
    if let Some(au) = &a.audit {
        audit_section(out, &a.column, au);
    }
    if !a.notes.is_empty() {
        out.push_str("<h3>Notes</h3><ul class=\"notes\">");
        for n in &a.notes {
            let _ = write!(out, "<li>{}</li>", esc(n));
        }
        out.push_str("</ul>\n");
    }
    out.push_str("</section>\n");
    Ok(())
}

const CSS: &str = "
body{font-family:'DejaVu Sans',Verdana,Arial,sans-serif;margin:24px auto;max-width:1560px;padding:0 16px;color:#111;line-height:1.45}
h1{font-size:26px;margin-bottom:4px}h2{font-size:21px;border-bottom:2px solid #0072b2;padding-bottom:3px;margin-top:36px}
h3{font-size:17px;margin-top:22px}table{border-collapse:collapse;margin:8px 0 14px;font-size:14px}
td,th{border:1px solid #ccc;padding:4px 8px;text-align:left;vertical-align:top}thead th{background:#eef4f8}
table.kv th{background:#f6f6f6;font-weight:600;white-space:nowrap}tr.selected td{background:#e6f2ea;font-weight:600}
.ci{color:#444}.alt{color:#555;font-size:13px}.small{font-size:13px;color:#444}
.verdict{padding:6px 10px;border-left:4px solid #999;background:#f7f7f7}.verdict.ok{border-color:#009e73}.verdict.bad{border-color:#d55e00}
figure{margin:12px 0 20px}figure img{max-width:100%;height:auto;border:1px solid #e3e3e3}figcaption{font-size:13px;color:#333;margin-top:4px}
pre{background:#f6f6f6;border:1px solid #ddd;padding:8px;font-size:12.5px;overflow-x:auto;white-space:pre-wrap}
ul.notes{font-size:14px}nav a{margin-right:10px}.meta{color:#555;font-size:13px}
@media print{body{max-width:none;margin:0}section.axis{break-before:page}figure,table,pre,.verdict{break-inside:avoid}h2,h3{break-after:avoid}nav{display:none}a{color:inherit;text-decoration:none}}
";

/// The section on N, B, K against a covariate: the figure, then per axis the chosen form and
/// the no-dependence test.
fn covariate_section(out: &mut String, c: &gmwm::CovariateCalibration) -> Result<(), PlotError> {
    let unit = c
        .unit
        .as_deref()
        .map(|u| format!(" {u}"))
        .unwrap_or_default();
    let _ = write!(
        out,
        "<section id=\"covariate\"><h2>Against {}</h2>\n<p>The recording was cut into {} windows at {} levels from {} to {}{unit}; each axis' identified model was fitted with its variances depending on {} (log-affine, the form chosen by WIC) — docs/methods.md §5.14. Bands are {:.0}% pointwise.</p>\n",
        esc(&c.covariate),
        c.windows,
        esc(&c.covariate),
        crate::style::number(c.range[0]),
        crate::style::number(c.range[1]),
        esc(&c.covariate),
        100.0 * (1.0 - c.alpha)
    );
    out.push_str(&figure_html(
        &covariate_figure(c),
        &format!(
            "N, B, K of every axis against {}: lines are the estimates, shaded the pointwise bands; dashed where the chosen form keeps the quantity constant.",
            esc(&c.covariate)
        ),
    )?);
    out.push_str(
        "<table><tr><th>axis</th><th>model</th><th>no dependence (Wald)</th><th>notes</th></tr>\n",
    );
    for a in &c.axes {
        let test = a
            .inference
            .as_ref()
            .and_then(|i| i.no_dependence.as_ref())
            .map_or_else(
                || "—".to_string(),
                |t| {
                    format!(
                        "W = {:.1}, df = {}, p = {:.3e}",
                        t.statistic, t.df, t.p_value
                    )
                },
            );
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            esc(&a.column),
            esc(&a.fit.model().without_values().to_string()),
            esc(&test),
            esc(&a.notes.join("; "))
        );
    }
    out.push_str("</table></section>\n");
    Ok(())
}

/// The GMWM+ section (`gmwm calibrate --augment`): per axis the physical quantities of GMWM
/// and GMWM+ with GMWM+'s interval, and the J-test of the stacked moments.
fn augmented_section(out: &mut String, axes: &[gmwm::AxisAugmented]) {
    let augment = axes
        .iter()
        .find_map(|a| a.fit.as_ref())
        .map_or_else(String::new, |f| f.augment().to_string());
    let _ = write!(
        out,
        "<section id=\"augmented\"><h2>GMWM+ (augment {})</h2>\n<p>Each axis' identified model refitted to its wavelet variance stacked with moments of the samples' first differences, weighted by their joint bootstrap covariance (docs/methods.md §5.15). The filter files keep the calibration's (GMWM) values; a J-test that rejects says the model does not reproduce the differences' first autocovariances (the sensor's own filter shapes them).</p>\n<table><tr><th>axis</th><th>quantity</th><th>GMWM</th><th>GMWM+</th><th>interval</th><th>unit</th></tr>\n",
        esc(&augment)
    );
    let num = |v: f64| esc(&crate::style::number(v));
    for a in axes {
        let Some(fit) = &a.fit else {
            let _ = writeln!(
                out,
                "<tr><td>{}</td><td colspan=\"5\">{}</td></tr>",
                esc(&a.column),
                esc(a.note.as_deref().unwrap_or("not run"))
            );
            continue;
        };
        for q in &a.physical {
            let ci = match (q.ci_low, q.ci_high) {
                (Some(lo), Some(hi)) if lo > 0.0 && hi.is_finite() => {
                    format!("[{}, {}]", num(lo), num(hi))
                }
                (Some(_), Some(_)) => "not determined".to_string(),
                _ => "—".to_string(),
            };
            let _ = writeln!(
                out,
                "<tr><td>{}</td><td>{}[{}].{}</td><td>{}</td><td>{}</td><td>{ci}</td><td>{}</td></tr>",
                esc(&a.column),
                esc(&q.process),
                q.index,
                esc(q.name),
                num(q.gmwm),
                num(q.value),
                esc(&q.unit)
            );
        }
        let j = fit.j_test();
        let p = match j.p_value {
            Some(p) if p < 1e-16 => "p &lt; 1e-16".to_string(),
            Some(p) => format!("p = {p:.3}"),
            None => "no degrees of freedom".to_string(),
        };
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td colspan=\"5\">J-test of the stacked moments: Q = {:.1} on {} degrees of freedom, {p}</td></tr>",
            esc(&a.column),
            j.statistic,
            j.df
        );
    }
    out.push_str("</table></section>\n");
}

/// Renders the page.
///
/// # Errors
/// [`PlotError`] if a figure cannot be drawn.
pub fn render(report: &CalibrationReport, ctx: &ReportContext) -> Result<String, PlotError> {
    let title = format!(
        "Calibration of {}",
        report.name.as_deref().unwrap_or(ctx.file.as_str())
    );
    let mut out = String::with_capacity(1 << 20);
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>{}</title><style>{CSS}</style></head><body>\n<h1>{}</h1>\n<p class=\"meta\">{} · made by <code>{}</code></p>\n<nav>",
        esc(&title),
        esc(&title),
        esc(&ctx.generator),
        esc(&ctx.command)
    );
    for a in &report.axes {
        let _ = write!(
            out,
            "<a href=\"#axis-{}\">{}</a>",
            slug(&a.column),
            esc(&a.column)
        );
    }
    out.push_str("<a href=\"#filters\">filter files</a></nav>\n");
    summary(&mut out, report, ctx);
    overview(&mut out, report);
    let wvs: Vec<Column<'_, gmwm::WaveletVariance>> =
        report.axes.iter().map(|a| column(a, &a.wv)).collect();
    out.push_str("<section id=\"wv\"><h2>Wavelet variances</h2>\n");
    out.push_str(&figure_html(
        &wv_figure(&wvs, Layout::Grid),
        &format!(
            "Wavelet variance of every axis with its {:.0}% interval (Haar MODWT; scale τ = 2^j samples / f).",
            100.0 * (1.0 - report.alpha)
        ),
    )?);
    psd_section(&mut out, report)?;
    out.push_str("</section>\n");
    if !report.recordings.is_empty() {
        let pairs: Vec<(gmwm::WaveletVariance, Vec<gmwm::WaveletVariance>)> = report
            .axes
            .iter()
            .map(|a| (a.wv.clone(), a.recording_wvs.clone()))
            .collect();
        let columns: Vec<Column<'_, _>> = report
            .axes
            .iter()
            .zip(&pairs)
            .map(|(a, p)| column(a, p))
            .collect();
        // the recordings by file name: their folders are in the table above
        let labels: Vec<String> = report
            .recordings
            .iter()
            .map(|r| {
                std::path::Path::new(&r.name)
                    .file_name()
                    .map_or(r.name.clone(), |f| f.to_string_lossy().into_owned())
            })
            .collect();
        out.push_str("<section id=\"recordings\"><h2>Recordings</h2>\n");
        out.push_str(&figure_html(
            &recordings_figure(&columns, &labels),
            &format!(
                "Each recording's wavelet variance and the pooled one that was calibrated (grey, with its {:.0}% interval). The notes of each axis compare every recording with the others, scale by scale.",
                100.0 * (1.0 - report.alpha)
            ),
        )?);
        out.push_str("</section>\n");
    }
    if let Some(c) = &ctx.covariate {
        covariate_section(&mut out, c)?;
    }
    if !ctx.augmented.is_empty() {
        augmented_section(&mut out, &ctx.augmented);
    }
    for a in &report.axes {
        axis_section(&mut out, a, report.alpha)?;
    }
    out.push_str("<section id=\"filters\"><h2>Navigation-filter parameters</h2>\n");
    if ctx.exports.is_empty() {
        out.push_str(
            "<p>No filter file was exported (use --kalibr FILE or --export STACK FILE).</p>\n",
        );
    }
    for (stack, name, content) in &ctx.exports {
        let _ = writeln!(
            out,
            "<h3>{} <span class=\"small\">({})</span></h3><pre>{}</pre>",
            esc(stack),
            esc(name),
            esc(content)
        );
    }
    out.push_str("</section>\n");
    // the machine-readable calibration: the document --json writes (compact), with `<` written
    // as \u003c so that no text inside can close the script element
    let _ = write!(
        out,
        "<script type=\"application/json\" id=\"calibration-json\">{}</script>\n</body></html>\n",
        ctx.json.replace('<', "\\u003c")
    );
    Ok(out)
}

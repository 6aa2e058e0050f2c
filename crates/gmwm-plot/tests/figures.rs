//! Every figure renders for real recordings (ADIS16405, the contaminated cont_imu1, a
//! precomputed WV) and for edge cases (one level, a component below the plot, an undefined
//! robust level): the SVG parses and holds the expected series and legend entries, the PNG
//! decodes to the stated size. With `GMWM_FIGURES_DIR` set, the figures are also written there
//! for a person to look at.

use gmwm::{
    allan_variance, ieee_readoff, read_table, read_wv_json, welch_psd, AllanOptions, Gmwm,
    ReadOptions, RobustOptions, WaveletVariance, Wic, WvOptions, BINNED_POINTS,
};
use gmwm_plot::{
    allan_figure, compare_figure, fit_figure, ieee_figure, psd_figure, selection_figure, wv_figure,
    Column, Figure, Layout, PanelKind,
};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(name)
}

/// Columns of a recording (`limit` samples each) and its rate.
fn recording(name: &str, limit: usize) -> (Vec<(String, Vec<f64>)>, f64) {
    let table = read_table(&data(name), &ReadOptions::default()).unwrap();
    let freq = table.facts.freq_hz.unwrap();
    let cols = table
        .columns
        .into_iter()
        .map(|c| {
            let n = c.values.len().min(limit);
            (c.name, c.values[..n].to_vec())
        })
        .collect();
    (cols, freq)
}

fn wv(x: &[f64], freq: f64, robust: bool) -> WaveletVariance {
    let opts = WvOptions {
        robust: robust.then(RobustOptions::default),
        ..WvOptions::default()
    };
    gmwm::wavelet_variance(x, freq, &opts).unwrap()
}

/// Element counts of an SVG document.
struct Svg {
    polygons: usize,
    polylines: usize,
    circles: usize,
    texts: Vec<String>,
}

/// Parses the SVG (failing the test if it is not well-formed XML with an `svg` root) and counts
/// its elements.
fn parse(svg: &str) -> Svg {
    let doc = roxmltree::Document::parse(svg).expect("the SVG parses as XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    let count = |tag: &str| doc.descendants().filter(|n| n.has_tag_name(tag)).count();
    Svg {
        polygons: count("polygon"),
        polylines: count("polyline"),
        circles: count("circle"),
        texts: doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| n.text().unwrap_or_default().trim().to_string())
            .collect(),
    }
}

/// Renders both formats, checks the PNG's size, saves them when asked; returns the SVG counts.
/// `wv` with level `j` (0-based) undefined, as a saved wavelet variance with `null` there
/// reads back (the engine's WV file reader).
fn with_undefined_level(wv: &WaveletVariance, j: usize) -> WaveletVariance {
    let mut series = serde_json::to_value(wv).unwrap();
    for key in ["wv", "ci_low", "ci_high"] {
        series[key][j] = serde_json::Value::Null;
    }
    series["name"] = "gyro_x".into();
    let doc = serde_json::json!({ "freq_hz": wv.freq_hz(), "series": [series] });
    let path = std::env::temp_dir().join(format!(
        "gmwm_plot_undefined_level_{}_{j}.json",
        std::process::id()
    ));
    std::fs::write(&path, doc.to_string()).unwrap();
    let read = read_wv_json(&path, None);
    std::fs::remove_file(&path).ok();
    read.unwrap().remove(0).1
}

fn render(figure: &Figure, name: &str) -> Svg {
    let svg = figure.svg().unwrap();
    let png = figure.png().unwrap();
    let decoder = png::Decoder::new(std::io::Cursor::new(&png));
    let reader = decoder.read_info().expect("the PNG decodes");
    let info = reader.info();
    assert_eq!((info.width, info.height), figure.size, "{name}: PNG size");
    if let Some(dir) = std::env::var_os("GMWM_FIGURES_DIR") {
        let dir = PathBuf::from(dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(format!("{name}.svg")), &svg).unwrap();
        std::fs::write(dir.join(format!("{name}.png")), &png).unwrap();
    }
    for label in figure.legend() {
        let shown = label.clone();
        let svg_doc = parse(&svg);
        assert!(
            svg_doc.texts.iter().any(|t| t.starts_with(&shown)),
            "{name}: legend entry {label:?} not drawn"
        );
    }
    parse(&svg)
}

#[test]
fn figures_wv_grid_and_overlay_of_the_adis_imu() {
    let (cols, freq) = recording("adis_16405_imu1.csv.gz", usize::MAX);
    let wvs: Vec<(String, WaveletVariance)> = cols
        .iter()
        .map(|(n, x)| (n.clone(), wv(x, freq, false)))
        .collect();
    let columns: Vec<Column<'_, WaveletVariance>> = wvs
        .iter()
        .map(|(n, w)| Column::new(n, if n.starts_with("gyro") { "deg/s" } else { "g" }, w))
        .collect();
    let levels = wvs[0].1.levels();
    let grid = wv_figure(&columns, Layout::Grid);
    assert_eq!(
        grid.grid,
        (2, 3),
        "gyroscope and accelerometer rows, X Y Z columns"
    );
    let svg = render(&grid, "wv_grid_adis");
    assert_eq!(svg.polygons, 6, "one band per axis");
    assert_eq!(svg.circles, 6 * levels, "one point per scale and axis");
    assert!(svg.texts.iter().any(|t| t.contains("gyro_y")));
    assert!(
        svg.texts.iter().any(|t| t == "10⁻²"),
        "tick labels as powers of ten"
    );

    let overlay = wv_figure(&columns, Layout::Overlay);
    assert_eq!(overlay.grid, (2, 1));
    assert_eq!(
        overlay.legend(),
        vec!["axis X", "axis Y", "axis Z", "axis X", "axis Y", "axis Z"]
    );
    let svg = render(&overlay, "wv_overlay_adis");
    assert_eq!(svg.polygons, 6);
    assert!(
        svg.texts.iter().any(|t| t == gmwm_plot::WV_SCALE),
        "the WV scale is named (docs/methods.md §14.1)"
    );
}

#[test]
fn figures_allan_deviation_of_a_precomputed_wv_and_the_recording() {
    // the precomputed WV of the R package is read as it is
    let series = read_wv_json(&data("precomputed/adis_wv.json"), None).unwrap();
    let columns: Vec<Column<'_, WaveletVariance>> =
        series.iter().map(|(n, w)| Column::new(n, "u", w)).collect();
    let figure = wv_figure(&columns, Layout::Grid);
    let svg = render(&figure, "wv_grid_precomputed");
    assert_eq!(svg.polygons, series.len());

    let (cols, freq) = recording("adis_16405_imu1.csv.gz", 1 << 18);
    let av = allan_variance(&cols[0].1, freq, &AllanOptions::default()).unwrap();
    let figure = allan_figure(&[Column::new(&cols[0].0, "deg/s", &av)], Layout::Grid);
    let svg = render(&figure, "avar_adis_gyro_x");
    assert_eq!(svg.circles, av.tau_s().len());
    assert!(svg.texts.iter().any(|t| t.contains("Allan deviation")));
    assert!(
        svg.texts.iter().any(|t| t.contains("cluster time")),
        "the AV scale is named (docs/methods.md §14.1)"
    );
}

#[test]
fn figures_classical_against_robust_shows_the_contamination() {
    let (cols, freq) = recording("cont_imu1.csv.gz", usize::MAX);
    let x = &cols[0].1;
    let pair = (wv(x, freq, false), wv(x, freq, true));
    let figure = compare_figure(&[Column::new("gyro_x", "u", &pair)]);
    assert_eq!(figure.legend().len(), 4);
    let svg = render(&figure, "compare_cont_imu1");
    assert_eq!(svg.polygons, 2, "one band each");
    assert_eq!(
        svg.circles,
        2 * pair.0.levels() + 2,
        "a point per scale and estimator, and two legend markers"
    );
}

#[test]
fn figures_compare_with_an_undefined_robust_level_splits_its_band() {
    let (cols, freq) = recording("cont_imu1.csv.gz", 1 << 16);
    let x = &cols[0].1;
    let (classical, robust) = (wv(x, freq, false), wv(x, freq, true));
    let robust = with_undefined_level(&robust, 4);
    assert!(robust.wv()[4].is_nan() && robust.ci_low()[4].is_nan());
    let levels = classical.levels();
    let pair = (classical, robust);
    let svg = render(
        &compare_figure(&[Column::new("gyro_x", "u", &pair)]),
        "compare_undefined_level",
    );
    assert_eq!(
        svg.polygons, 3,
        "the robust band in two pieces around the undefined level"
    );
    assert_eq!(
        svg.circles,
        2 * levels - 1 + 2,
        "no point for the undefined level (two legend markers)"
    );
}

#[test]
fn figures_fit_decomposition_names_every_process_with_its_value() {
    let (cols, freq) = recording("adis_16405_imu1.csv.gz", usize::MAX);
    let x = &cols[0].1;
    let fit = Gmwm::new("2*AR1()+WN()+RW()".parse().unwrap())
        .with_seed(1)
        .fit(x, freq, &WvOptions::default())
        .unwrap();
    let figure = fit_figure(&[Column::new("gyro_x", "deg/s", &fit)]);
    let legend = figure.legend();
    // band, empirical, model, and one line per component
    assert_eq!(legend.len(), 3 + 4, "{legend:?}");
    // the fast AR1 (T = 5.5 ms, below the sampling interval) takes the white noise, whose
    // term collapses to nothing: it reads as negligible, never as N = 4.7×10⁻³⁹
    assert!(
        legend
            .iter()
            .any(|l| l == "WN: negligible (below the plot)"),
        "{legend:?}"
    );
    assert!(
        !legend.iter().any(|l| l.starts_with("WN: N = ")),
        "{legend:?}"
    );
    assert!(
        legend.iter().any(|l| l.starts_with("RW: K = ")),
        "{legend:?}"
    );
    assert!(
        legend
            .iter()
            .any(|l| l.starts_with("AR1: T = ") && l.contains(" s, σ = ")),
        "{legend:?}"
    );
    let svg = render(&figure, "fit_adis_gyro_x");
    assert_eq!(svg.polygons, 1);
    assert!(
        svg.polylines >= 5,
        "model and four components: {}",
        svg.polylines
    );
}

#[test]
fn figures_fit_with_a_component_below_the_plot_says_so() {
    let (cols, freq) = recording("adis_16405_imu1.csv.gz", 1 << 16);
    let fit = Gmwm::new("AR1()+WN()".parse().unwrap())
        .with_seed(1)
        .fit(&cols[0].1, freq, &WvOptions::default())
        .unwrap();
    let mut figure = fit_figure(&[Column::new("gyro_x", "deg/s", &fit)]);
    // the AR1 component's line, moved twelve decades down
    let PanelKind::LogLog(series) = &mut figure.panels[0].kind else {
        panic!("the fit panel is a log-log panel")
    };
    let ar1 = series
        .iter_mut()
        .find(|s| s.label.as_deref().is_some_and(|l| l.starts_with("AR1: ")))
        .expect("an AR1 component line");
    ar1.y.iter_mut().for_each(|v| *v *= 1e-12);
    let svg = render(&figure, "fit_component_below");
    // a term that collapsed below the plot reads as negligible, not as its tiny values
    assert!(
        svg.texts
            .iter()
            .any(|t| t == "AR1: negligible (below the plot)"),
        "{:?}",
        svg.texts
    );
    assert!(
        !svg.texts.iter().any(|t| t.starts_with("AR1: T = ")),
        "{:?}",
        svg.texts
    );
}

#[test]
fn figures_one_level_still_has_axes_and_its_interval() {
    let x: Vec<f64> = (0..64).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
    let opts = WvOptions {
        levels: Some(1),
        ..WvOptions::default()
    };
    let w = gmwm::wavelet_variance(&x, 10.0, &opts).unwrap();
    assert_eq!(w.levels(), 1);
    let figure = wv_figure(&[Column::new("x", "V", &w)], Layout::Grid);
    let svg = render(&figure, "wv_one_level");
    assert_eq!(svg.circles, 1);
    assert_eq!(svg.polygons, 0, "a one-level band is an interval bar");
    assert!(
        svg.texts
            .iter()
            .any(|t| t.contains('×') || t.starts_with("10")),
        "ticks exist"
    );
}

#[test]
fn figures_selection_and_ieee_on_the_adis_gyroscope() {
    let (cols, freq) = recording("adis_16405_imu1.csv.gz", 1 << 18);
    let x = &cols[0].1;
    let selection = Wic::nested("2*AR1()+WN()+RW()".parse().unwrap())
        .unwrap()
        .with_bootstrap(10)
        .with_draws(2000)
        .select(x, freq)
        .unwrap();
    let figure = selection_figure(
        &[Column::new("gyro_x", "deg/s", &selection)],
        gmwm_plot::WIC_ROWS,
    );
    assert_eq!(figure.grid, (1, 2));
    let svg = render(&figure, "select_adis_gyro_x");
    let shown = selection.rows().len().min(gmwm_plot::WIC_ROWS);
    // two segments per shown row, the bar legend's two swatches, the fit legend's band swatch
    // and the white background
    assert!(
        svg.texts.iter().any(|t| t.starts_with("▶ ")),
        "the selected row is marked"
    );
    assert_eq!(count_rects(&figure), 2 * shown + 2 + 1 + 1);
    assert_eq!(svg.polygons, 1, "the fit panel's band");

    let av = allan_variance(x, freq, &AllanOptions::default()).unwrap();
    let readoff = ieee_readoff(&av).unwrap();
    let pair = (av, readoff);
    let figure = ieee_figure(&[Column::new("gyro_x", "deg/s", &pair)]);
    let legend = figure.legend();
    assert!(legend.iter().any(|l| l.starts_with("N = ")), "{legend:?}");
    assert!(legend.iter().any(|l| l.starts_with("B = ")), "{legend:?}");
    render(&figure, "ieee_adis_gyro_x");
    // each read-off point lies on its own slope line: sigma = N / sqrt(tau) through (1 s, N),
    // the flat line at 0.664 B through the minimum, sigma = K sqrt(tau / 3) through (3 s, K)
    let gmwm_plot::PanelKind::LogLog(series) = &figure.panels[0].kind else {
        panic!("a log-log panel")
    };
    let readoff = &pair.1;
    for (symbol, value, at, line) in [
        (
            "N",
            readoff.n.value,
            1.0,
            &(|v: f64, t: f64| v / t.sqrt()) as &dyn Fn(f64, f64) -> f64,
        ),
        ("B", readoff.b.value, readoff.b.at_tau_s, &|v: f64, _| {
            v * 0.664
        }),
        ("K", readoff.k.value, 3.0, &|v: f64, t: f64| {
            v * (t / 3.0).sqrt()
        }),
    ] {
        let Some(v) = value else { continue };
        let k = series
            .iter()
            .position(|s| {
                s.label
                    .as_deref()
                    .is_some_and(|l| l.starts_with(&format!("{symbol} = ")))
            })
            .unwrap_or_else(|| panic!("{symbol} has a legend entry"));
        let (point, slope) = (&series[k], &series[k - 1]);
        assert_eq!(
            (point.x[0], point.y[0]),
            (at, line(v, at)),
            "{symbol} read-off point"
        );
        for (x, y) in slope.x.iter().zip(&slope.y) {
            assert!(
                (y / line(v, *x) - 1.0).abs() < 1e-12,
                "{symbol} line at {x}"
            );
        }
    }
}

/// Rectangles of the SVG (bars are `rect` elements).
fn count_rects(figure: &Figure) -> usize {
    let svg = figure.svg().unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    doc.descendants().filter(|n| n.has_tag_name("rect")).count()
}

#[test]
fn figures_refuse_a_bad_name_or_size_in_one_line() {
    let x: Vec<f64> = (0..256).map(|i| (i % 7) as f64).collect();
    let w = gmwm::wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
    let figure = wv_figure(&[Column::new("x", "u", &w)], Layout::Grid);
    let e = figure
        .save(std::path::Path::new("/tmp/figure.jpg"))
        .unwrap_err();
    assert!(e.to_string().contains(".svg or .png"), "{e}");
    let e = figure.clone().with_size((100, 50)).svg().unwrap_err();
    assert!(e.to_string().contains("100x50"), "{e}");
    assert!(!e.to_string().contains('\n'), "one line: {e}");
}

#[test]
fn figures_ieee_lines_of_white_noise_and_random_walk_go_through_their_read_offs() {
    // N = 1e-3 rad/s/√Hz and K = 1e-4 rad/s²/√Hz at 100 Hz (sigma2 = N² f, gamma2 = K² / f):
    // both regions are read, and each point lies on its line (docs/methods.md §14.3). Seed 1: a
    // series whose RW region is read (in 2 of 20 seeds the top octaves go to the rate ramp and
    // the read-off gives no K; the engine's ieee tests cover that case)
    let model: gmwm::Model = "WN(sigma2=1e-4)+RW(gamma2=1e-10)".parse().unwrap();
    let x = gmwm::simulate_model(&model, 1 << 20, 100.0, 1).unwrap();
    let av = allan_variance(&x, 100.0, &AllanOptions::default()).unwrap();
    let readoff = ieee_readoff(&av).unwrap();
    let (n, k) = (
        readoff.n.value.unwrap(),
        readoff.k.value.unwrap_or_else(|| panic!("{:?}", readoff.k)),
    );
    assert!((n / 1e-3 - 1.0).abs() < 0.05, "N {n}");
    assert!((k / 1e-4 - 1.0).abs() < 0.5, "K {k}");
    let pair = (av, readoff);
    let figure = ieee_figure(&[Column::new("gyro_x", "rad/s", &pair)]);
    let legend = figure.legend();
    assert!(
        legend
            .iter()
            .any(|l| l.starts_with("N = ") && l.contains("rad/s/√Hz")),
        "{legend:?}"
    );
    assert!(
        legend
            .iter()
            .any(|l| l.starts_with("K = ") && l.contains("rad/s²/√Hz")),
        "{legend:?}"
    );
    let gmwm_plot::PanelKind::LogLog(series) = &figure.panels[0].kind else {
        panic!("a log-log panel")
    };
    let on_line = |symbol: &str, v: f64, sigma: &dyn Fn(f64) -> f64| {
        let i = series
            .iter()
            .position(|s| {
                s.label
                    .as_deref()
                    .is_some_and(|l| l.starts_with(&format!("{symbol} = ")))
            })
            .unwrap();
        let (point, line) = (&series[i], &series[i - 1]);
        assert!(
            (point.y[0] / sigma(point.x[0]) - 1.0).abs() < 1e-12,
            "{symbol} point"
        );
        for (x, y) in line.x.iter().zip(&line.y) {
            assert!((y / sigma(*x) - 1.0).abs() < 1e-12, "{symbol} line at {x}");
        }
        assert!(v > 0.0);
    };
    on_line("N", n, &|t| n / t.sqrt());
    on_line("K", k, &|t| k * (t / 3.0).sqrt());
    render(&figure, "ieee_wn_rw");
}

#[test]
fn figures_without_columns_are_an_empty_figure_not_an_error() {
    let figure = wv_figure(&[], Layout::Grid);
    assert!(figure.svg().is_ok());
    let figure = wv_figure(&[], Layout::Overlay);
    assert!(figure.svg().is_ok());
}

#[test]
fn figures_psd_of_the_adis_imu_with_the_white_noise_level() {
    let (cols, freq) = recording("adis_16405_imu1.csv.gz", 1 << 18);
    let pairs: Vec<(String, _)> = cols
        .iter()
        .map(|(name, x)| {
            let psd = welch_psd(x, freq).unwrap().binned(BINNED_POINTS);
            // a white-noise density for the reference line: the floor's, N = sqrt(level / 2)
            let n = (psd.density()[psd.density().len() / 2] / 2.0).sqrt();
            (name.clone(), (psd, Some(n)))
        })
        .collect();
    let units = ["deg/s", "deg/s", "deg/s", "g", "g", "g"];
    let columns: Vec<Column<'_, _>> = pairs
        .iter()
        .zip(units)
        .map(|((name, p), u)| Column::new(name, u, p))
        .collect();
    let grid = psd_figure(&columns, Layout::Grid);
    assert_eq!(grid.grid, (2, 3));
    let svg = render(&grid, "psd_adis_grid");
    assert!(
        svg.polylines >= 6 * 2,
        "a curve and a line per panel: {}",
        svg.polylines
    );
    assert!(
        svg.texts.iter().any(|t| t == "√PSD, one-sided [deg/s/√Hz]"),
        "{:?}",
        svg.texts
    );
    // the density in the title, its √2·N line in the legend
    assert!(
        svg.texts
            .iter()
            .any(|t| t.starts_with("accel_x: N = ") && t.ends_with(" g/√Hz")),
        "{:?}",
        svg.texts
    );
    assert!(svg.texts.iter().any(|t| t == "√2·N"), "{:?}", svg.texts);
    let overlay = psd_figure(&columns, Layout::Overlay);
    assert_eq!(overlay.grid, (2, 1));
    let svg = render(&overlay, "psd_adis_overlay");
    assert!(
        svg.texts
            .iter()
            .any(|t| t.starts_with("Z: √2·N, N = ") && t.ends_with(" deg/s/√Hz")),
        "{:?}",
        svg.texts
    );
    // without a white-noise density: the curve alone, no legend
    let bare: Vec<(String, _)> = pairs
        .iter()
        .map(|(n, (p, _))| (n.clone(), (p.clone(), None)))
        .collect();
    let columns: Vec<Column<'_, _>> = bare
        .iter()
        .map(|(name, p)| Column::new(name, "deg/s", p))
        .collect();
    assert!(psd_figure(&columns[..1], Layout::Grid).legend().is_empty());
}

//! `gmwm plot` and `gmwm report` end to end: every figure command on the real recordings, the
//! report's numbers against `--json`, and the report opened in headless Chromium
//! (`tests/browser/check_report.py`, Debian `chromium` + the pip package `playwright`, both
//! installed by `.ci/run`), which fails on console errors, broken images, external requests or
//! missing figures. Set `GMWM_SKIP_BROWSER=1` to skip only the browser run on a machine without
//! Chromium; it never passes silently otherwise.

mod common;

use common::{assert_usage_error, gmwm};
use std::path::{Path, PathBuf};
use std::process::Command;

fn data(name: &str) -> PathBuf {
    std::env::var_os("GMWM_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
        .join(name)
}

const CHECKER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/browser/check_report.py");
const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/browser/fixtures");

/// Runs `gmwm plot ...`, asserts success and returns the figure's bytes.
fn plot(args: &[&str], out: &Path) -> Vec<u8> {
    let result = gmwm()
        .arg("plot")
        .args(args)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&result.stderr)
    );
    let stdout = String::from_utf8_lossy(&result.stdout);
    assert!(stdout.starts_with("wrote "), "{stdout}");
    std::fs::read(out).unwrap()
}

fn png_size(bytes: &[u8]) -> (u32, u32) {
    // IHDR: width and height, big-endian, at bytes 16..24 after the 8-byte signature
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "a PNG file");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

#[test]
fn plot_every_figure_on_the_real_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let adis = data("adis_16405_imu1.csv.gz");
    let adis = adis.to_str().unwrap();
    let cont = data("cont_imu1.csv.gz");
    let cont = cont.to_str().unwrap();

    let svg = String::from_utf8(plot(&["wv", adis], &dir.path().join("wv.svg"))).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("gyro_z") && svg.contains("accel_x"));
    assert!(svg.contains("(deg/s)²"), "the sidecar's unit on the axis");

    let png = plot(
        &["wv", adis, "--overlay", "--width", "900", "--height", "700"],
        &dir.path().join("wv.png"),
    );
    assert_eq!(png_size(&png), (900, 700));

    let svg = String::from_utf8(plot(
        &["avar", adis, "--columns", "gyro_x"],
        &dir.path().join("av.svg"),
    ))
    .unwrap();
    assert!(svg.contains("Allan deviation") && svg.contains("cluster time"));

    let svg = String::from_utf8(plot(&["compare", cont], &dir.path().join("cmp.svg"))).unwrap();
    assert!(svg.contains("classical WV"));
    assert!(svg.contains("robust WV (efficiency 0.6)"));

    let svg = String::from_utf8(plot(
        &[
            "fit",
            adis,
            "--columns",
            "gyro_x",
            "--model",
            "AR1()+WN()+RW()",
            "--G",
            "2000",
        ],
        &dir.path().join("fit.svg"),
    ))
    .unwrap();
    // the fit's WN collapses to 1e-30 (the AR1 of 5.5 ms takes the white noise): the legend
    // says so instead of printing N = 1.0×10⁻¹⁶
    assert!(
        svg.contains("WN: negligible (below the plot)") && svg.contains("RW: K = "),
        "legend with values, a collapsed term as negligible"
    );
    assert!(!svg.contains("WN: N = "), "no value of a collapsed term");

    let png = plot(
        &[
            "select",
            adis,
            "--columns",
            "gyro_x",
            "--model",
            "AR1()+WN()+RW()",
            "--bootstrap",
            "10",
            "--G",
            "2000",
        ],
        &dir.path().join("select.png"),
    );
    assert_eq!(png_size(&png), (1500, 560));

    let svg = String::from_utf8(plot(
        &["ieee", adis, "--columns", "gyro_x"],
        &dir.path().join("ieee.svg"),
    ))
    .unwrap();
    assert!(svg.contains("N = ") && svg.contains("slope −1/2"));

    // a saved WV (precomputed by the R package) is drawn as it is
    let pre = data("precomputed/adis_wv.json");
    let svg = String::from_utf8(plot(
        &["wv", pre.to_str().unwrap()],
        &dir.path().join("pre.svg"),
    ))
    .unwrap();
    assert!(svg.contains("gyro_x"));
}

#[test]
fn plot_refuses_bad_flags_in_one_line() {
    let adis = data("adis_16405_imu1.csv.gz");
    assert_usage_error(
        gmwm()
            .args(["plot", "wv"])
            .arg(&adis)
            .args(["-o", "/tmp/fig.jpg"]),
        &["--output", ".svg or .png"],
    );
    assert_usage_error(
        gmwm()
            .args(["plot", "wv"])
            .arg(&adis)
            .args(["--json", "-o", "/tmp/fig.svg"]),
        &["--json"],
    );
    assert_usage_error(
        gmwm()
            .args(["plot", "ieee"])
            .arg(&adis)
            .args(["--kind", "modified", "-o", "/tmp/fig.svg"]),
        &["overlapping Allan variance"],
    );
    assert_usage_error(
        gmwm().args(["plot", "fit"]).arg(&adis).args([
            "--model",
            "WN()",
            "--inference",
            "-o",
            "/tmp/fig.svg",
        ]),
        &["--inference"],
    );
    assert_usage_error(
        gmwm().args(["plot", "fit"]).arg(&adis).args([
            "--model",
            "WN()",
            "--overlay",
            "-o",
            "/tmp/fig.svg",
        ]),
        &["--overlay"],
    );
    assert_usage_error(
        gmwm()
            .args(["plot", "wv"])
            .arg(&adis)
            .args(["--width", "30000", "-o", "/tmp/fig.svg"]),
        &["--width"],
    );
    let out = gmwm().args(["plot", "wv"]).arg(&adis).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "-o is required");
}

/// The JSON embedded in the page.
fn embedded_json(html: &str) -> serde_json::Value {
    let start = html
        .find("id=\"calibration-json\">")
        .expect("embedded JSON")
        + "id=\"calibration-json\">".len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end].replace("\\u003c", "<")).unwrap()
}

#[test]
fn report_numbers_are_the_json_and_chromium_finds_no_fault() {
    let dir = tempfile::tempdir().unwrap();
    let html_path = dir.path().join("report.html");
    let json_path = dir.path().join("calib.json");
    let out = gmwm()
        .arg("report")
        .arg(data("adis_16405_imu1.csv.gz"))
        .arg("-o")
        .arg(&html_path)
        .arg("--json")
        .arg(&json_path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    // four an axis, the WVs' and the PSDs'
    assert!(stdout.contains("(HTML report, 26 figures)"), "{stdout}");
    let html = std::fs::read_to_string(&html_path).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    assert_eq!(
        embedded_json(&html),
        json,
        "the page carries the --json document"
    );
    // every headline number of every axis appears in the page as --json gives it
    let axes = json["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 6);
    for axis in axes {
        let column = axis["column"].as_str().unwrap();
        assert!(
            html.contains(&format!("id=\"axis-{column}\"")),
            "{column} has its section"
        );
        for key in ["noise_density", "random_walk", "bias_instability"] {
            let value = axis[key]["value"].as_f64().unwrap();
            let shown = gmwm_plot::style::number(value);
            assert!(
                html.contains(&shown),
                "{column} {key}: {shown} not in the page"
            );
        }
        let wic = axis["selection"]["rows"][0]["wic"].as_f64().unwrap();
        assert!(
            html.contains(&gmwm_plot::style::number(wic)),
            "{column}: WIC {wic}"
        );
        let summary = axis["contamination"]["summary"].as_str().unwrap();
        assert!(html.contains(summary), "{column}: contamination sentence");
    }
    // self-contained: no external reference anywhere
    for needle in ["src=\"http", "href=\"http", "url(http", "@import"] {
        assert!(!html.contains(needle), "external reference {needle}");
    }
    assert!(
        html.contains("Power spectral density of every axis"),
        "the PSD figure beside the WVs"
    );
    browser_check(&html_path, &dir.path().join("report.png"), 26);
}

/// Runs the browser checker; with `GMWM_SKIP_BROWSER=1` the check is skipped, saying so.
fn browser_check(html: &Path, screenshot: &Path, min_figures: usize) {
    if std::env::var_os("GMWM_SKIP_BROWSER").is_some() {
        eprintln!("GMWM_SKIP_BROWSER set: the report is not opened in Chromium");
        return;
    }
    let out = checker(html, screenshot, min_figures);
    assert!(
        out.status.success(),
        "check_report failed (install Debian chromium and `python3 -m pip install playwright`, or set GMWM_SKIP_BROWSER=1):\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let png = std::fs::read(screenshot).unwrap();
    let (w, h) = png_size(&png);
    assert_eq!(w, 1280);
    assert!(h > 5000, "the whole page: {h} px");
    if let Some(keep) = std::env::var_os("GMWM_KEEP_SCREENSHOT") {
        std::fs::copy(screenshot, keep).unwrap();
    }
}

fn checker(html: &Path, screenshot: &Path, min_figures: usize) -> std::process::Output {
    Command::new("python3")
        .arg(CHECKER)
        .arg(html)
        .arg(screenshot)
        .args(["--min-figures", &min_figures.to_string(), "--timeout", "90"])
        .output()
        .expect("python3 runs")
}

#[test]
fn report_browser_checker_catches_each_fault() {
    if std::env::var_os("GMWM_SKIP_BROWSER").is_some() {
        eprintln!("GMWM_SKIP_BROWSER set: the checker is not exercised");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("shot.png");
    let good = checker(&Path::new(FIXTURES).join("good.html"), &shot, 2);
    assert!(
        good.status.success(),
        "{}",
        String::from_utf8_lossy(&good.stderr)
    );
    for (page, expected) in [
        ("console_error.html", "console error"),
        ("page_error.html", "page error"),
        ("broken_image.html", "broken image"),
        ("external.html", "external request"),
        ("missing_figures.html", "too few figures"),
        ("sibling.html", "external request"),
    ] {
        let out = checker(&Path::new(FIXTURES).join(page), &shot, 1);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{page}: {stderr}");
        assert!(stderr.contains(expected), "{page}: {stderr}");
    }
}

#[test]
fn calibrate_report_flag_writes_the_same_page() {
    let dir = tempfile::tempdir().unwrap();
    // a gyroscope at 100 Hz in rad/s: a time column gives the rate, the header the unit
    let model: gmwm::Model = "WN(sigma2=1e-4)+RW(gamma2=1e-10)".parse().unwrap();
    let x = gmwm::simulate_model(&model, 1 << 14, 100.0, 3).unwrap();
    let mut text = String::from("time,gyro_x [rad/s]\n");
    for (i, v) in x.iter().enumerate() {
        text.push_str(&format!("{},{v}\n", i as f64 / 100.0));
    }
    let csv = dir.path().join("sim.csv");
    std::fs::write(&csv, text).unwrap();
    let flags = [
        "--model",
        "AR1()+WN()+RW()",
        "--bootstrap",
        "10",
        "--G",
        "1000",
    ];
    let via_calibrate = dir.path().join("calibrate.html");
    let out = gmwm()
        .arg("calibrate")
        .arg(&csv)
        .args(flags)
        .arg("--report")
        .arg(&via_calibrate)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("gyro_x") && stdout.contains("HTML report"),
        "summary and the page: {stdout}"
    );
    let via_report = dir.path().join("report.html");
    let out = gmwm()
        .arg("report")
        .arg(&csv)
        .args(flags)
        .arg("-o")
        .arg(&via_report)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // the same page but for the command line it names
    let without_command = |p: &Path| {
        let page = std::fs::read_to_string(p).unwrap();
        page.lines()
            .filter(|l| !l.contains("made by"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let page = without_command(&via_calibrate);
    assert!(page.starts_with("<!DOCTYPE html>") && page.contains("<figure>"));
    assert_eq!(page, without_command(&via_report));
    // the file named twice is refused
    assert_usage_error(
        gmwm()
            .arg("report")
            .arg(&csv)
            .args(["-o", "a.html", "--report", "b.html"]),
        &["once"],
    );
}

#[test]
fn report_with_the_robust_estimator_compares_with_the_classical_wv() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("r.html");
    let json = dir.path().join("c.json");
    let out = gmwm()
        .arg("report")
        .arg(data("cont_imu1.csv.gz"))
        .args([
            "--robust",
            "--bootstrap",
            "10",
            "--model",
            "2*AR1()+WN()+RW()",
            "-o",
        ])
        .arg(&html)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let axis = &doc["axes"][0];
    let c = &axis["contamination"];
    assert_eq!(c["fit_uses"], "robust");
    assert_eq!(
        c["robust"]["wv"], axis["wv"]["wv"],
        "the fit's WV is the robust one"
    );
    assert_ne!(
        c["classical"]["wv"], axis["wv"]["wv"],
        "the classical WV is the other one"
    );
    assert_eq!(c["matters"], true);
    let summary = c["summary"].as_str().unwrap();
    assert!(summary.contains("the robust fit used here"), "{summary}");
    assert!(std::fs::read_to_string(&html).unwrap().contains(summary));
}

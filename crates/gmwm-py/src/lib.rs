//! `gmwm._native`: the engine's verbs for Python. Conversions only: numpy arrays in (borrowed
//! when contiguous float64, copied otherwise, and counted), the engine's JSON documents out
//! (`gmwm::document`, the CLI's `--json`), engine errors as `gmwm.GmwmError`; the GIL is released
//! while the engine works. The Python package (`python/gmwm`) wraps these in typed results.

use gmwm::{
    allan_variance, infer_with_progress, read_table, wavelet_variance, Adjustment, AllanKind,
    AllanOptions, AvConvention, AxisPolicy, Calibration, CalibrationOptions, CalibrationSource,
    ColumnSelector, CovarianceMethod, Gmwm, HeaderMode, Imu, InferenceOptions, InputFormat, Model,
    Named, OptimismConvention, OptimismMethod, Progress, ReadOptions, Recording, RecordingOptions,
    RobustConvention, RobustOptions, SelectionRule, SensorInfo, TimeUnit, Transform, WaveletFilter,
    Weighting, Wic, WvOptions,
};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::borrow::Cow;
use std::path::PathBuf;
use std::str::FromStr;
use std::sync::atomic::{AtomicUsize, Ordering};

create_exception!(
    gmwm._native,
    GmwmError,
    PyValueError,
    "An input or computation the engine refuses; the message names what is wrong."
);

/// Columns copied because they were not contiguous float64 (a test hook for zero-copy).
static COPIES: AtomicUsize = AtomicUsize::new(0);

fn err(e: impl std::fmt::Display) -> PyErr {
    GmwmError::new_err(e.to_string())
}

/// One line from an engine error and its causes, as the CLI prints it.
fn engine(e: impl std::error::Error) -> PyErr {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let t = s.to_string();
        if !text.contains(&t) {
            text.push_str(": ");
            text.push_str(&t);
        }
        source = s.source();
    }
    GmwmError::new_err(text)
}

/// Borrowed 1-D float64 arrays (see [`columns`]).
type Borrowed<'py> = Vec<PyReadonlyArray1<'py, f64>>;

/// Borrows each 1-D float64 array; a non-contiguous one is copied (and counted).
fn columns_of<'a>(arrays: &'a Borrowed<'_>) -> Vec<Cow<'a, [f64]>> {
    arrays
        .iter()
        .map(|a| match a.as_slice() {
            Ok(s) => Cow::Borrowed(s),
            Err(_) => {
                COPIES.fetch_add(1, Ordering::Relaxed);
                Cow::Owned(a.as_array().iter().copied().collect())
            }
        })
        .collect()
}

/// `f` on every column in parallel (the engine's [`gmwm::per_column`], as the CLI),
/// each result named by its column; the first failure as one line naming the column.
fn per_column<T: Send, E: std::fmt::Display + Send>(
    names: &[String],
    cols: &[Cow<'_, [f64]>],
    f: impl Fn(&[f64]) -> Result<T, E> + Sync + Send,
) -> Result<Vec<(String, T)>, String> {
    let slices: Vec<&[f64]> = cols.iter().map(|c| c.as_ref()).collect();
    names
        .iter()
        .zip(gmwm::per_column(&slices, f))
        .map(|(n, r)| {
            r.map(|t| (n.clone(), t))
                .map_err(|e| format!("column {n}: {e}"))
        })
        .collect()
}

fn check_columns(arrays: &Borrowed<'_>, names: &[String]) -> PyResult<()> {
    if arrays.len() != names.len() {
        return Err(err(format!(
            "{} column(s) but {} name(s)",
            arrays.len(),
            names.len()
        )));
    }
    if arrays.is_empty() {
        return Err(err("no column to analyse"));
    }
    Ok(())
}

/// The engine value a keyword names, read by the engine's `FromStr`; an unknown name is refused
/// with the valid ones (`invalid rule "best": "navigation", "parsimonious" or "wic-minimum"`).
fn choice<T: Named + FromStr>(keyword: &str, text: &str) -> PyResult<T> {
    text.parse::<T>().map_err(|_| {
        let names: Vec<String> = T::names().iter().map(|n| format!("{n:?}")).collect();
        let listed = match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => names.join(", "),
        };
        err(format!("invalid {keyword} {text:?}: {listed}"))
    })
}

fn check_freq(freq: f64) -> PyResult<()> {
    if freq.is_finite() && freq > 0.0 {
        Ok(())
    } else {
        Err(err(format!(
            "invalid freq {freq}: must be a positive number of hertz"
        )))
    }
}

/// The WV options of the keywords (the flags of `gmwm wv`).
#[allow(clippy::too_many_arguments)]
fn wv_options(
    robust: bool,
    eff: f64,
    robust_convention: &str,
    filter: &str,
    transform: &str,
    levels: Option<usize>,
    alpha: f64,
) -> PyResult<WvOptions> {
    let convention: RobustConvention = choice("robust_convention", robust_convention)?;
    let robust = if robust {
        Some(RobustOptions::new(eff, convention).map_err(engine)?)
    } else {
        None
    };
    if let Some(why) = gmwm::significance_level_problem(alpha) {
        return Err(err(format!("invalid alpha {alpha}: {why}")));
    }
    if levels == Some(0) {
        return Err(err("invalid levels 0: at least one level"));
    }
    Ok(WvOptions {
        transform: choice::<Transform>("transform", transform)?,
        filter: filter.parse::<WaveletFilter>().map_err(engine)?,
        levels,
        alpha,
        robust,
    })
}

fn json(value: &serde_json::Value) -> String {
    value.to_string()
}

/// Wavelet variance of each column (docs/methods.md §1, §2): the `gmwm wv --json` document.
#[pyfunction]
#[pyo3(signature = (arrays, names, freq, robust=false, eff=0.6, robust_convention="exact", filter="haar", transform="modwt", levels=None, alpha=0.05))]
#[allow(clippy::too_many_arguments)]
fn wv(
    py: Python<'_>,
    arrays: Borrowed<'_>,
    names: Vec<String>,
    freq: f64,
    robust: bool,
    eff: f64,
    robust_convention: &str,
    filter: &str,
    transform: &str,
    levels: Option<usize>,
    alpha: f64,
) -> PyResult<String> {
    check_columns(&arrays, &names)?;
    check_freq(freq)?;
    let opts = wv_options(
        robust,
        eff,
        robust_convention,
        filter,
        transform,
        levels,
        alpha,
    )?;
    let cols = columns_of(&arrays);
    let items = py
        .detach(|| per_column(&names, &cols, |x| wavelet_variance(x, freq, &opts)))
        .map_err(err)?;
    Ok(json(&gmwm::document::series(&items)))
}

/// Allan, modified Allan or Hadamard variance of each column (docs/methods.md §3): the
/// `gmwm avar --json` document.
#[pyfunction]
#[pyo3(signature = (arrays, names, freq, kind="overlapping", convention="textbook", alpha=0.05))]
fn avar(
    py: Python<'_>,
    arrays: Borrowed<'_>,
    names: Vec<String>,
    freq: f64,
    kind: &str,
    convention: &str,
    alpha: f64,
) -> PyResult<String> {
    check_columns(&arrays, &names)?;
    check_freq(freq)?;
    if let Some(why) = gmwm::significance_level_problem(alpha) {
        return Err(err(format!("invalid alpha {alpha}: {why}")));
    }
    let opts = AllanOptions {
        kind: choice::<AllanKind>("kind", kind)?,
        convention: choice::<AvConvention>("convention", convention)?,
        alpha,
    };
    let cols = columns_of(&arrays);
    let items = py
        .detach(|| per_column(&names, &cols, |x| allan_variance(x, freq, &opts)))
        .map_err(err)?;
    Ok(json(&gmwm::document::series(&items)))
}

/// The implied WV of a fully specified model and of each process (docs/methods.md §4): the
/// `gmwm implied --json` document.
#[pyfunction]
#[pyo3(signature = (model, levels, freq=1.0))]
fn implied(model: &str, levels: usize, freq: f64) -> PyResult<String> {
    check_freq(freq)?;
    let model: Model = model.parse().map_err(engine)?;
    let implied = model.implied_wv(levels, freq).map_err(engine)?;
    serde_json::to_string(&implied).map_err(err)
}

/// A simulated series and its named components.
type Simulated<'py> = (
    Bound<'py, PyArray1<f64>>,
    Vec<(String, Bound<'py, PyArray1<f64>>)>,
);

/// A seeded simulation of a fully specified model (docs/methods.md §10): the sum and, with
/// `components`, each process.
#[pyfunction]
#[pyo3(signature = (model, n, freq=1.0, seed=0, components=false))]
fn simulate<'py>(
    py: Python<'py>,
    model: &str,
    n: usize,
    freq: f64,
    seed: u64,
    components: bool,
) -> PyResult<Simulated<'py>> {
    check_freq(freq)?;
    if n == 0 {
        return Err(err("invalid n 0: simulate at least one sample"));
    }
    let model: Model = model.parse().map_err(engine)?;
    let k = model.components().len();
    let result = py.detach(|| -> Result<(Vec<f64>, Vec<Vec<f64>>), gmwm::Error> {
        let mut sim = gmwm::Simulator::for_model(&model, freq, seed)?;
        if !components {
            let mut x = vec![0.0; n];
            sim.fill(&mut x);
            return Ok((x, Vec::new()));
        }
        let mut parts = vec![vec![0.0; n]; k];
        sim.fill_components(&mut parts)?;
        let x = (0..n).map(|i| parts.iter().map(|p| p[i]).sum()).collect();
        Ok((x, parts))
    });
    let (x, parts) = result.map_err(engine)?;
    let names: Vec<String> = model.components().iter().map(|c| c.to_string()).collect();
    Ok((
        PyArray1::from_vec(py, x),
        names
            .into_iter()
            .zip(parts)
            .map(|(name, p)| (name, PyArray1::from_vec(py, p)))
            .collect(),
    ))
}

/// A Python callable told `(done, total)`, in increasing `done` (the engine's threads finish
/// out of order; a stale count is not passed on); errors inside it are ignored (progress must
/// never stop a computation).
struct PyProgress {
    callback: Option<Py<PyAny>>,
    total: AtomicUsize,
    /// The last count passed on; held while calling so that calls arrive in order (lock
    /// order: this mutex, then the GIL).
    reported: std::sync::Mutex<usize>,
}

impl Progress for PyProgress {
    fn start(&self, total: usize) {
        self.total.store(total, Ordering::Relaxed);
        self.advance(0);
    }

    fn advance(&self, done: usize) {
        if let Some(cb) = &self.callback {
            let mut last = match self.reported.lock() {
                Ok(guard) => guard,
                Err(poisoned) => poisoned.into_inner(),
            };
            if done > 0 && *last >= done {
                return;
            }
            *last = done;
            let total = self.total.load(Ordering::Relaxed);
            Python::attach(|py| {
                let _ = cb.call1(py, (done, total));
            });
        }
    }
}

/// GMWM fit of a model on each column (docs/methods.md §5, §7 with `inference`): the
/// `gmwm fit --json` document.
#[pyfunction]
#[pyo3(signature = (arrays, names, freq, model, weights="fast", draws=None, seed=1337, inference=false, bootstrap=None, covariance="auto", robust=false, eff=0.6, robust_convention="exact", levels=None, alpha=0.05, progress=None, augment=None))]
#[allow(clippy::too_many_arguments)]
fn fit(
    py: Python<'_>,
    arrays: Borrowed<'_>,
    names: Vec<String>,
    freq: f64,
    model: &str,
    weights: &str,
    draws: Option<usize>,
    seed: u64,
    inference: bool,
    bootstrap: Option<usize>,
    covariance: &str,
    robust: bool,
    eff: f64,
    robust_convention: &str,
    levels: Option<usize>,
    alpha: f64,
    progress: Option<Py<PyAny>>,
    augment: Option<&str>,
) -> PyResult<String> {
    check_columns(&arrays, &names)?;
    check_freq(freq)?;
    let wv_opts = wv_options(
        robust,
        eff,
        robust_convention,
        "haar",
        "modwt",
        levels,
        alpha,
    )?;
    // GMWM+ (docs/methods.md §5.15), as `gmwm fit --augment` with the same seed and level
    let augment = augment
        .map(|a| {
            a.parse::<gmwm::Augment>()
                .map(|augment| gmwm::AugmentOptions {
                    seed,
                    alpha,
                    ..gmwm::AugmentOptions::new(augment)
                })
        })
        .transpose()
        .map_err(|e| err(format!("invalid augment: {e}")))?;
    let model: Model = model.parse().map_err(engine)?;
    let mut gmwm = Gmwm::new(model)
        .with_seed(seed)
        .with_weighting(choice::<Weighting>("weights", weights)?);
    if let Some(g) = draws {
        if g == 0 {
            return Err(err("invalid draws 0: at least one starting-value draw"));
        }
        gmwm = gmwm.with_draws(g);
    }
    if bootstrap.is_some_and(|b| b < 2) {
        return Err(err("invalid bootstrap: at least 2 replicates"));
    }
    let v_method = choice::<CovarianceMethod>("covariance", covariance)?;
    let cols = columns_of(&arrays);
    let reporter = PyProgress {
        callback: progress,
        total: AtomicUsize::new(0),
        reported: std::sync::Mutex::new(0),
    };
    let out = py.detach(|| -> Result<String, String> {
        let fits: Vec<_> = per_column(&names, &cols, |x| gmwm.fit(x, freq, &wv_opts))?
            .into_iter()
            .map(|(_, f)| f)
            .collect();
        let canonicals = fits
            .iter()
            .zip(&names)
            .map(|(f, n)| f.canonical().map_err(|e| format!("column {n}: {e}")))
            .collect::<Result<Vec<_>, _>>()?;
        let mut inferences = Vec::new();
        if inference {
            let opts = InferenceOptions {
                alpha,
                bootstrap,
                v_method,
                ..InferenceOptions::default()
            };
            for ((f, n), x) in fits.iter().zip(&names).zip(&cols) {
                let wv = f.empirical().ok_or("the fit carries no WV")?;
                let this_wv = wv.options();
                let i = infer_with_progress(&gmwm, f, x.len(), &this_wv, &opts, &|d| {
                    reporter.advance(d)
                })
                .map_err(|e| format!("column {n}: {e}"))?;
                inferences.push(i);
            }
        }
        let mut augmented = Vec::new();
        if let Some(opts) = &augment {
            for ((f, n), x) in fits.iter().zip(&names).zip(&cols) {
                let a =
                    gmwm::augment_fit(&gmwm, f, x, opts).map_err(|e| format!("column {n}: {e}"))?;
                augmented.push(a);
            }
        }
        let items: Vec<gmwm::document::FitItem<'_>> = names
            .iter()
            .zip(&fits)
            .zip(&canonicals)
            .enumerate()
            .map(|(k, ((column, fit), canonical))| gmwm::document::FitItem {
                column,
                fit,
                canonical,
                inference: inferences.get(k),
                augmented: augmented.get(k),
            })
            .collect();
        Ok(json(&gmwm::document::fits(&items)))
    });
    out.map_err(err)
}

/// WIC model selection on each column (docs/methods.md §8): the `gmwm select --json` document.
#[pyfunction]
#[pyo3(signature = (arrays, names, freq, model=None, candidates=None, bootstrap=50, covariance="auto", optimism="asymptotic", convention="corrected", rule="navigation", draws=None, seed=1337, robust=false, eff=0.6, robust_convention="exact", levels=None, alpha=0.05, progress=None))]
#[allow(clippy::too_many_arguments)]
fn select(
    py: Python<'_>,
    arrays: Borrowed<'_>,
    names: Vec<String>,
    freq: f64,
    model: Option<&str>,
    candidates: Option<Vec<String>>,
    bootstrap: usize,
    covariance: &str,
    optimism: &str,
    convention: &str,
    rule: &str,
    draws: Option<usize>,
    seed: u64,
    robust: bool,
    eff: f64,
    robust_convention: &str,
    levels: Option<usize>,
    alpha: f64,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    check_columns(&arrays, &names)?;
    check_freq(freq)?;
    if bootstrap < 2 {
        return Err(err(format!(
            "invalid bootstrap {bootstrap}: at least 2 (a covariance needs two replicates)"
        )));
    }
    let wv_opts = wv_options(
        robust,
        eff,
        robust_convention,
        "haar",
        "modwt",
        levels,
        alpha,
    )?;
    let mut wic = match (candidates, model) {
        (Some(mut list), m) => {
            list.extend(m.map(str::to_string));
            Wic::parse_list(&list).map_err(engine)?
        }
        (None, Some(m)) => Wic::nested(m.parse::<Model>().map_err(engine)?).map_err(engine)?,
        (None, None) => return Err(err("give model (a full model) or candidates (a list)")),
    };
    wic = wic
        .with_bootstrap(bootstrap)
        .with_covariance(choice::<CovarianceMethod>("covariance", covariance)?)
        .with_seed(seed)
        .with_wv_options(wv_opts)
        .with_optimism(choice::<OptimismMethod>("optimism", optimism)?)
        .with_convention(choice::<OptimismConvention>("convention", convention)?)
        .with_rule(choice::<SelectionRule>("rule", rule)?);
    if let Some(g) = draws {
        if g == 0 {
            return Err(err("invalid draws 0: at least one starting-value draw"));
        }
        wic = wic.with_draws(g);
    }
    let cols = columns_of(&arrays);
    let reporter = PyProgress {
        callback: progress,
        total: AtomicUsize::new(0),
        reported: std::sync::Mutex::new(0),
    };
    let done = AtomicUsize::new(0);
    let ticks = Ticks {
        inner: &reporter,
        done: &done,
    };
    reporter.start(names.len() * wic.candidates().len());
    let results = py
        .detach(|| per_column(&names, &cols, |x| wic.select_with_progress(x, freq, &ticks)))
        .map_err(err)?;
    Ok(json(&gmwm::document::selections(&results)))
}

/// Counts the engine's per-candidate ticks across columns into one running total.
struct Ticks<'a> {
    inner: &'a PyProgress,
    done: &'a AtomicUsize,
}

impl Progress for Ticks<'_> {
    fn start(&self, _total: usize) {}
    fn advance(&self, _done: usize) {
        let d = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        self.inner.advance(d);
    }
}

/// The read options of the keywords (the input flags of the CLI).
#[allow(clippy::too_many_arguments)]
fn read_options(
    columns: Option<Vec<String>>,
    freq: Option<f64>,
    format: &str,
    ncols: Option<usize>,
    header: &str,
    (time_column, time_unit, time_policy): (Option<String>, Option<&str>, &str),
) -> PyResult<ReadOptions> {
    if let Some(f) = freq {
        check_freq(f)?;
    }
    let selector = |t: &str| match t.trim().parse::<usize>() {
        Ok(i) => ColumnSelector::Index(i),
        Err(_) => ColumnSelector::Name(t.trim().to_string()),
    };
    Ok(ReadOptions {
        format: choice::<InputFormat>("format", format)?,
        header: choice::<HeaderMode>("header", header)?,
        time_column: time_column.as_deref().map(selector),
        time_unit: time_unit
            .map(|u| choice::<TimeUnit>("time_unit", u))
            .transpose()?,
        columns: columns
            .unwrap_or_default()
            .iter()
            .map(|c| selector(c))
            .collect(),
        ncols,
        freq_hz: freq,
        time_policy: choice::<gmwm::TimePolicy>("time_policy", time_policy)?,
    })
}

/// Reads a recording as the CLI does (text, raw binary, binary IMU records, ROS): returns
/// `(names, arrays, freq, units, notes)`; the arrays are handed to numpy without a copy.
#[pyfunction]
#[pyo3(signature = (path, columns=None, freq=None, format="auto", ncols=None, header="auto", time_column=None, time_unit=None, time_policy="strict", topic=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn read<'py>(
    py: Python<'py>,
    path: PathBuf,
    columns: Option<Vec<String>>,
    freq: Option<f64>,
    format: &str,
    ncols: Option<usize>,
    header: &str,
    time_column: Option<String>,
    time_unit: Option<&str>,
    time_policy: &str,
    topic: Option<String>,
) -> PyResult<(
    Vec<String>,
    Vec<Bound<'py, PyArray1<f64>>>,
    Option<f64>,
    Vec<Option<String>>,
    Vec<String>,
)> {
    let opts = read_options(
        columns,
        freq,
        format,
        ncols,
        header,
        (time_column, time_unit, time_policy),
    )?;
    let probe = gmwm::Probe::of(&path, &opts);
    let read = py.detach(|| -> Result<_, gmwm::Error> {
        if probe.is_ros() {
            let rec = Recording::open_probed(
                &probe,
                &RecordingOptions {
                    read: opts,
                    topic: topic.clone(),
                },
            )?;
            let freq = rec.imu.freq_hz();
            let units: Vec<Option<String>> =
                rec.imu.axes().iter().map(|a| a.info.unit.clone()).collect();
            let cols = rec.imu.into_axes().into_iter().map(|a| a.column).collect();
            return Ok((cols, Some(freq), units, rec.notes));
        }
        if let Some(t) = &topic {
            return Err(gmwm::ParamError::new(
                "topic",
                t,
                format!(
                    "a topic of a ROS recording; {} is not one (ROS1 bag, MCAP, rosbag2 sqlite3)",
                    path.display()
                ),
            )
            .into());
        }
        let table = read_table(&path, &opts)?;
        let units = SensorInfo::of_table(&table)
            .into_iter()
            .map(|i| i.unit)
            .collect();
        let mut notes = Vec::new();
        if let Some(t) = &table.facts.timing {
            notes.push(t.to_string());
        }
        notes.extend(gmwm::left_out_note(&table.facts.skipped));
        notes.push(table.facts.samples.to_string());
        notes.extend(table.facts.warnings.iter().map(ToString::to_string));
        Ok((table.columns, table.facts.freq_hz, units, notes))
    });
    let (cols, freq, units, notes) = read.map_err(engine)?;
    let names = cols.iter().map(|c| c.name.clone()).collect();
    let arrays = cols
        .into_iter()
        .map(|c| PyArray1::from_vec(py, c.values))
        .collect();
    Ok((names, arrays, freq, units, notes))
}

/// The calibration of an IMU (the pipeline of `gmwm calibrate`), returning the
/// `gmwm calibrate --json` document: of the recording at `path` (read as the CLI reads it), of
/// `arrays` named `names` with `units` at `freq`, or of the recordings at `paths` calibrated as
/// one sensor (`gmwm calibrate --pool`).
#[pyfunction]
#[pyo3(signature = (path=None, arrays=None, paths=None, names=None, units=None, freq=None, columns=None, format="auto", ncols=None, header="auto", time_column=None, time_unit=None, time_policy="strict", topic=None, gyro_unit=None, accel_unit=None, model=None, rule="navigation", bootstrap=50, covariance="auto", draws=None, seed=1337, eff=0.6, robust_convention="exact", robust=false, alpha=0.05, axis_policy="worst", inflate=None, conservative=false, horizon=None, rostopic=None, tolerance=0.1, force_units=false, datasheet=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn calibrate(
    py: Python<'_>,
    path: Option<PathBuf>,
    arrays: Option<Borrowed<'_>>,
    paths: Option<Vec<PathBuf>>,
    names: Option<Vec<String>>,
    units: Option<Vec<Option<String>>>,
    freq: Option<f64>,
    columns: Option<Vec<String>>,
    format: &str,
    ncols: Option<usize>,
    header: &str,
    time_column: Option<String>,
    time_unit: Option<&str>,
    time_policy: &str,
    topic: Option<String>,
    gyro_unit: Option<&str>,
    accel_unit: Option<&str>,
    model: Option<&str>,
    rule: &str,
    bootstrap: usize,
    covariance: &str,
    draws: Option<usize>,
    seed: u64,
    eff: f64,
    robust_convention: &str,
    robust: bool,
    alpha: f64,
    axis_policy: &str,
    inflate: Option<f64>,
    conservative: bool,
    horizon: Option<f64>,
    rostopic: Option<String>,
    tolerance: f64,
    force_units: bool,
    datasheet: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    if !(tolerance > 0.0 && tolerance <= 1.0) {
        return Err(err(format!(
            "invalid tolerance {tolerance}: a fraction in (0, 1], e.g. 0.1 for 10%"
        )));
    }
    if bootstrap < 2 {
        return Err(err(format!(
            "invalid bootstrap {bootstrap}: at least 2 (a covariance needs two replicates)"
        )));
    }
    let unit = |u: Option<&str>, what: &str| -> PyResult<Option<gmwm::SignalUnit>> {
        u.map(|t| {
            t.parse().map_err(|_| {
                err(format!(
                    "invalid {what} {t:?}: rad/s, deg/s, deg/h (gyroscope) or m/s^2, g, mg (accelerometer)"
                ))
            })
        })
        .transpose()
    };
    let convention: RobustConvention = choice("robust_convention", robust_convention)?;
    let wv = wv_options(robust, eff, robust_convention, "haar", "modwt", None, alpha)?;
    let options = CalibrationOptions {
        full_model: model
            .unwrap_or(gmwm::DEFAULT_FULL_MODEL)
            .parse()
            .map_err(engine)?,
        wv,
        covariance: choice::<CovarianceMethod>("covariance", covariance)?,
        bootstrap,
        draws,
        seed,
        rule: choice::<SelectionRule>("rule", rule)?,
        gyro_unit: unit(gyro_unit, "gyro_unit")?,
        accel_unit: unit(accel_unit, "accel_unit")?,
        robust_check: Some(RobustOptions::new(eff, convention).map_err(engine)?),
        tolerance,
        force_units,
        datasheet: datasheet
            .map(|t| {
                t.parse::<gmwm::Datasheet>()
                    .map_err(|e| err(format!("invalid datasheet {t:?}: {e}")))
            })
            .transpose()?,
        horizon_s: horizon,
        ..CalibrationOptions::default()
    };
    let policy: AxisPolicy = choice("axis_policy", axis_policy)?;
    let adjustment = match (inflate, conservative, horizon) {
        (Some(_), true, _) | (Some(_), _, Some(_)) | (_, true, Some(_)) => {
            return Err(err("give one of inflate, conservative and horizon"))
        }
        (_, _, Some(t)) => Adjustment::horizon(t).map_err(engine)?,
        (Some(k), ..) => Adjustment::inflate(k).map_err(engine)?,
        (None, true, None) => Adjustment::Conservative,
        (None, false, None) => Adjustment::Estimate,
    };
    let reporter = PyProgress {
        callback: progress,
        total: AtomicUsize::new(0),
        reported: std::sync::Mutex::new(0),
    };
    // several recordings of one sensor: each read as the CLI reads it, pooled
    if let Some(paths) = paths {
        if path.is_some() || arrays.is_some() {
            return Err(err(
                "give paths alone (a pooled calibration), or a path, or arrays",
            ));
        }
        let read = read_options(
            columns,
            freq,
            format,
            ncols,
            header,
            (time_column, time_unit, time_policy),
        )?;
        let opts = RecordingOptions { read, topic };
        let recordings = py
            .detach(|| {
                paths
                    .iter()
                    .map(|p| Recording::open(p, &opts))
                    .collect::<Result<Vec<_>, _>>()
            })
            .map_err(engine)?;
        let labels: Vec<String> = recordings
            .iter()
            .map(|r| r.path.display().to_string())
            .collect();
        let notes: Vec<String> = labels
            .iter()
            .zip(&recordings)
            .flat_map(|(l, r)| r.notes.iter().map(move |n| format!("{l}: {n}")))
            .collect();
        let rostopic = rostopic.or_else(|| recordings.first().and_then(|r| r.topic.clone()));
        let file = recordings
            .first()
            .map(|r| r.path.clone())
            .unwrap_or_default();
        let pooled = CalibrationSource::Pooled(
            labels
                .iter()
                .cloned()
                .zip(recordings)
                .map(|(l, r)| (l, r.imu))
                .collect(),
        );
        let doc = py.detach(|| -> Result<String, gmwm::CalibError> {
            let report = Calibration::new(options).run_source(&pooled, &reporter)?;
            let sets = report.nav_sets(policy, adjustment, rostopic.as_deref());
            Ok(json(&gmwm::document::calibration(
                &file, &notes, None, &report, &sets,
            )))
        });
        return doc.map_err(engine);
    }
    // a wavelet variance saved by `gmwm wv --json` (or precomputed): calibrated from it, as
    // `gmwm calibrate FILE.json` does
    if let Some(wv_path) = path
        .as_ref()
        .filter(|p| arrays.is_none() && format == "auto" && gmwm::is_wv_json(p))
    {
        let read = read_options(
            columns,
            freq,
            format,
            ncols,
            header,
            (time_column, time_unit, time_policy),
        )?;
        let series = gmwm::read_wv_json(wv_path, read.freq_hz)
            .and_then(|all| gmwm::select_series(wv_path, all, &read.columns))
            .map_err(engine)?;
        let (rows, note) = gmwm::wv_account(&series);
        let doc = py.detach(|| -> Result<String, gmwm::CalibError> {
            let name = wv_path
                .file_name()
                .map(|f| f.to_string_lossy().into_owned());
            let source = CalibrationSource::SavedWv { name, series };
            let report = Calibration::new(options).run_source(&source, &reporter)?;
            let sets = report.nav_sets(policy, adjustment, rostopic.as_deref());
            Ok(json(&gmwm::document::calibration(
                wv_path,
                &[note],
                Some(&rows),
                &report,
                &sets,
            )))
        });
        return doc.map_err(engine);
    }
    // the recording: a file read as the CLI reads it, or the given columns
    let (imu, file, notes, topic_read, rows) = match (path, arrays) {
        (Some(path), None) => {
            let read = read_options(
                columns,
                freq,
                format,
                ncols,
                header,
                (time_column, time_unit, time_policy),
            )?;
            let opts = RecordingOptions { read, topic };
            let rec = py
                .detach(|| Recording::open(&path, &opts))
                .map_err(engine)?;
            (rec.imu, rec.path, rec.notes, rec.topic, Some(rec.samples))
        }
        (None, Some(arrays)) => {
            let names = names.ok_or_else(|| err("arrays need names"))?;
            check_columns(&arrays, &names)?;
            let freq = freq.ok_or_else(|| err("arrays need freq (Hz)"))?;
            check_freq(freq)?;
            let units = units.unwrap_or_else(|| vec![None; names.len()]);
            if units.len() != names.len() {
                return Err(err("one unit (or None) per column"));
            }
            let infos = names
                .iter()
                .zip(&units)
                .map(|(n, u)| {
                    let (sensor, axis) =
                        SensorInfo::infer(n).unwrap_or((gmwm::Sensor::Other, n.clone()));
                    SensorInfo {
                        sensor,
                        axis,
                        unit: u.clone(),
                    }
                })
                .collect();
            // the IMU owns its columns: one copy of each
            let owned = names
                .iter()
                .zip(columns_of(&arrays))
                .map(|(n, x)| gmwm::Column {
                    name: n.clone(),
                    values: x.into_owned(),
                })
                .collect();
            let imu = Imu::new(owned, infos, freq).map_err(engine)?;
            (imu, PathBuf::from("<array>"), Vec::new(), None, None)
        }
        _ => return Err(err("give a path or arrays, not both")),
    };
    let rostopic = rostopic.or(topic_read);
    let doc = py.detach(|| -> Result<String, gmwm::CalibError> {
        let report = Calibration::new(options).run_with_progress(&imu, &reporter)?;
        let sets = report.nav_sets(policy, adjustment, rostopic.as_deref());
        Ok(json(&gmwm::document::calibration(
            &file,
            &notes,
            rows.as_ref(),
            &report,
            &sets,
        )))
    });
    doc.map_err(engine)
}

/// How many columns were copied because they were not contiguous float64 (zero-copy check).
#[pyfunction]
fn copies() -> usize {
    COPIES.load(Ordering::Relaxed)
}

/// The engine's version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("GmwmError", m.py().get_type::<GmwmError>())?;
    m.add_function(wrap_pyfunction!(wv, m)?)?;
    m.add_function(wrap_pyfunction!(avar, m)?)?;
    m.add_function(wrap_pyfunction!(implied, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(select, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(copies, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}

//! Flags become a validated configuration once: one typed configuration per subcommand, built
//! from its clap arguments ([`crate::args`]) by `main` before any file is read or any work
//! starts. Every check that needs the flags alone happens here, with the one-line message the
//! CLI prints; the commands take the configuration, never the raw arguments. Checks that need
//! the data (a column exists, levels against the series length, what FILE turns out to be) stay
//! with the data, in the commands and `input.rs`; what a saved wavelet variance cannot honour is
//! decided here from the flags ([`SavedWvCheck`]) and raised there once FILE is known to be one.

pub use crate::args::Against;
use crate::args::{
    AvarArgs, BatchArgs, CalibrateArgs, CalibrateCommand, Command, DemoArgs, FigureArgs, FitArgs,
    ImpliedArgs, InputArgs, MonitorArgs, OutputArgs, PlotArgs, PlotCommand, ReportArgs,
    SameModelArgs, SelectArgs, SharedArgs, SimulateArgs, TopicsArgs, WvArgs, WvCommand,
    WvEstimatorArgs,
};
use crate::error::UsageError;
use crate::input::InputConfig;
use crate::recordings::{is_glob, is_rosbag2_folder};
use crate::render::Style;
use anyhow::{Context, Result};
use gmwm::{
    Adjustment, AllanKind, AllanOptions, AugmentOptions, AvConvention, AxisPolicy,
    CalibrationOptions, ColumnSelector, Datasheet, ExportFormat, Gmwm, InferenceOptions, Model,
    MonitorOptions, ReadOptions, RobustOptions, SameModelOptions, SharedOptions, SignalUnit,
    Transform, WaveletFilter, Weighting, Wic, WvOptions, DEFAULT_FULL_MODEL,
};
use gmwm_plot::{ImageFormat, Layout};
use std::path::{Path, PathBuf};

/// The configuration of one run: the subcommand's, validated.
#[derive(Debug)]
pub enum Config {
    /// `gmwm demo`.
    Demo(DemoConfig),
    /// `gmwm wv`.
    Wv(WvConfig),
    /// `gmwm avar`.
    Avar(AvarConfig),
    /// `gmwm simulate`.
    Simulate(SimulateConfig),
    /// `gmwm implied`.
    Implied(ImpliedConfig),
    /// `gmwm plan`.
    Plan(PlanConfig),
    /// `gmwm fit`.
    Fit(FitConfig),
    /// `gmwm select`.
    Select(SelectConfig),
    /// `gmwm calibrate`.
    Calibrate(CalibrateConfig),
    /// `gmwm topics`.
    Topics(TopicsConfig),
    /// `gmwm plot`.
    Plot(PlotConfig),
    /// `gmwm report`.
    Report(ReportConfig),
    /// `gmwm calibrate` or `gmwm wv` over many recordings.
    Batch(BatchConfig),
    /// `gmwm shared`.
    Shared(SharedConfig),
    /// `gmwm monitor`.
    Monitor(MonitorConfig),
    /// `gmwm same-model`.
    SameModel(SameModelConfig),
    /// `gmwm fit FILE... --pool`.
    PooledFit(PooledFitConfig),
    /// `gmwm fit FILE... --covariate COL` or `--covariate-values LIST`.
    CovariateFit(CovariateFitConfig),
    /// `gmwm fit FILE --covariate COL --dynamic`.
    DynamicFit(DynamicFitConfig),
    /// `gmwm select FILE... --pool`.
    PooledSelect(PooledSelectConfig),
}

impl TryFrom<&Command> for Config {
    type Error = anyhow::Error;

    fn try_from(command: &Command) -> Result<Self> {
        Ok(match command {
            Command::Demo(a) => Self::Demo(a.try_into()?),
            Command::Wv(a) => wv_or_batch(a)?,
            Command::Avar(a) => Self::Avar(a.try_into()?),
            Command::Simulate(a) => Self::Simulate(a.try_into()?),
            Command::Implied(a) => Self::Implied(a.try_into()?),
            Command::Plan(a) => Self::Plan(a.try_into()?),
            Command::Calibrate(a) => calibrate_or_batch(a)?,
            Command::Topics(a) => Self::Topics(a.into()),
            Command::Plot(a) => Self::Plot(a.try_into()?),
            Command::Report(a) => Self::Report(a.try_into()?),
            Command::SameModel(a) => Self::SameModel(a.try_into()?),
            Command::Fit(a) if a.pool => Self::PooledFit(a.try_into()?),
            Command::Fit(a) if a.dynamic => Self::DynamicFit(a.try_into()?),
            Command::Fit(a) if a.covariate.is_some() || !a.covariate_values.is_empty() => {
                Self::CovariateFit(a.try_into()?)
            }
            Command::Fit(a) if !a.depends.is_empty() || !a.at.is_empty() => anyhow::bail!(
                "--{} describes a covariate fit: give the covariate with --covariate COL or \
                 --covariate-values LIST",
                if a.depends.is_empty() {
                    "at"
                } else {
                    "depends"
                }
            ),
            Command::Select(a) if a.pool => Self::PooledSelect(a.try_into()?),
            Command::Fit(a) => Self::Fit(a.try_into()?),
            Command::Select(a) => Self::Select(a.try_into()?),
            Command::Shared(a) => Self::Shared(a.try_into()?),
            Command::Monitor(a) => Self::Monitor(a.try_into()?),
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Shared parts

/// `--columns` entries: all digits → a 1-based index, anything else a name.
fn selector(text: &str) -> ColumnSelector {
    match text.trim().parse::<usize>() {
        Ok(i) => ColumnSelector::Index(i),
        Err(_) => ColumnSelector::Name(text.trim().to_string()),
    }
}

impl TryFrom<&InputArgs> for InputConfig {
    type Error = anyhow::Error;

    /// Checks the input flags (also for arguments not parsed by clap, whose value parsers
    /// refuse these values first) and turns them into engine read options.
    fn try_from(a: &InputArgs) -> Result<Self> {
        if let Some(f) = a.freq {
            anyhow::ensure!(
                f.is_finite() && f > 0.0,
                "invalid --freq {f}: must be a positive number of hertz"
            );
        }
        if let Some(k) = a.ncols {
            anyhow::ensure!(
                k >= 1,
                "invalid --ncols 0: a binary file has at least one column"
            );
        }
        let read = ReadOptions {
            format: a.format,
            header: a.header,
            time_column: a.time_column.as_deref().map(selector),
            time_unit: a.time_unit,
            columns: a.columns.iter().map(|c| selector(c)).collect(),
            ncols: a.ncols,
            freq_hz: a.freq,
            time_policy: a.time_policy,
        };
        Ok(Self {
            file: a.file.clone(),
            read,
            topic: a.topic.clone(),
            stream_from: a.stream_from.unwrap_or(gmwm::STREAM_FROM),
            gaps: a.gaps,
            probe: Default::default(),
        })
    }
}

/// The output style of `--json` / `--csv` (a table otherwise): the output configuration of the
/// analysis commands.
pub type OutputConfig = Style;

impl From<&OutputArgs> for OutputConfig {
    fn from(o: &OutputArgs) -> Self {
        if o.json {
            Style::Json
        } else if o.csv {
            Style::Csv
        } else {
            Style::Table
        }
    }
}

/// What a saved wavelet variance (FILE written by `gmwm wv --json`, used as it is) cannot
/// honour among the flags: decided from the flags alone, raised by [`SavedWvCheck::check`] once
/// FILE turns out to be one.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct SavedWvCheck {
    /// The first refusal, without the file name.
    refusal: Option<String>,
}

impl SavedWvCheck {
    /// This check, or else `next` when this one refuses nothing.
    fn or_else(self, next: impl FnOnce() -> Option<String>) -> Self {
        match self.refusal {
            Some(_) => self,
            None => Self { refusal: next() },
        }
    }

    /// Refuses the flags for `file`, a saved wavelet variance, if they ask what it cannot give.
    pub fn check(&self, file: &Path) -> Result<()> {
        match &self.refusal {
            Some(r) => Err(anyhow::anyhow!("{}: {r}", file.display())),
            None => Ok(()),
        }
    }
}

/// The engine's estimator options of the wavelet-variance flags (`--robust`, `--eff`,
/// `--robust-convention`, `--filter`, `--transform`, `--levels`, `--alpha`).
fn wv_options(a: &WvEstimatorArgs) -> Result<WvOptions> {
    let robust = if a.robust {
        Some(robust_at_eff(a)?)
    } else {
        None
    };
    gmwm::check_alpha(a.alpha)?;
    Ok(WvOptions {
        transform: a.transform,
        filter: a.filter.parse::<WaveletFilter>()?,
        levels: a.levels,
        alpha: a.alpha,
        robust,
    })
}

/// The robust estimator at `--eff` and `--robust-convention`, whether or not `--robust` is
/// given (the contamination check of calibrate, the robust series of plot compare).
fn robust_at_eff(a: &WvEstimatorArgs) -> Result<RobustOptions> {
    Ok(RobustOptions::new(a.eff, a.robust_convention)?)
}

/// Refuses a non-Haar `--filter` for the estimation commands (fit, select, calibrate): every
/// model's implied WV is the Haar one (docs/methods.md §1.8, §4); the engine refuses it too.
fn check_haar(a: &WvEstimatorArgs, opts: &WvOptions) -> Result<()> {
    if opts.filter != WaveletFilter::Haar {
        return Err(UsageError(format!(
            "invalid --filter {}: every model's implied wavelet variance is the Haar one \
             (docs/methods.md §1.8, §4), so fits and selections use --filter haar (the default); \
             other filters are for gmwm wv",
            a.filter
        ))
        .into());
    }
    Ok(())
}

/// Estimator flags that need the series when FILE is a saved wavelet variance: it is used as
/// it is (robust if it says so).
fn estimator_saved_wv_check(a: &WvEstimatorArgs) -> SavedWvCheck {
    SavedWvCheck::default()
        .or_else(|| {
            a.robust.then(|| {
                "--robust needs the series; a wavelet-variance file is used as it is (robust if \
                 it says so)"
                    .to_string()
            })
        })
        .or_else(|| {
            (a.filter != "haar" || a.transform != Transform::Modwt).then(|| {
                "--filter/--transform apply to a recording; a wavelet-variance file is used as \
                 it is"
                    .to_string()
            })
        })
}

// ---------------------------------------------------------------------------------------------
// Per subcommand

/// `gmwm demo`: the simulation and the (Haar MODWT) estimator.
#[derive(Debug, Clone, PartialEq)]
pub struct DemoConfig {
    /// `--n`: samples to simulate.
    pub n: usize,
    /// `--seed`: seed of the simulation.
    pub seed: u64,
    /// The estimator of the empirical WV (Haar MODWT: the implied WV exists for it only).
    pub wv: WvOptions,
    /// Table, JSON or CSV.
    pub output: OutputConfig,
}

impl TryFrom<&DemoArgs> for DemoConfig {
    type Error = anyhow::Error;

    fn try_from(a: &DemoArgs) -> Result<Self> {
        let wv = wv_options(&a.estimator)?;
        anyhow::ensure!(
            wv.filter == WaveletFilter::Haar && wv.transform == Transform::Modwt,
            "gmwm demo compares with the implied WV of docs/methods.md §4, which exists for the \
             Haar MODWT only; drop --filter/--transform"
        );
        Ok(Self {
            n: a.n,
            seed: a.seed,
            wv,
            output: (&a.output).into(),
        })
    }
}

/// `gmwm wv`: the input, the estimator, the output.
#[derive(Debug, Clone, PartialEq)]
pub struct WvConfig {
    /// What to read.
    pub input: InputConfig,
    /// The estimator.
    pub wv: WvOptions,
    /// Estimator flags a saved wavelet variance cannot honour.
    pub saved_wv: SavedWvCheck,
    /// Table, JSON or CSV.
    pub output: OutputConfig,
}

impl TryFrom<&WvArgs> for WvConfig {
    type Error = anyhow::Error;

    fn try_from(a: &WvArgs) -> Result<Self> {
        let wv = wv_options(&a.estimator)?;
        Ok(Self {
            input: (&a.input).try_into()?,
            wv,
            saved_wv: estimator_saved_wv_check(&a.estimator),
            output: (&a.output).into(),
        })
    }
}

/// `gmwm avar`: the input, the Allan-type variance, the output.
#[derive(Debug, Clone, PartialEq)]
pub struct AvarConfig {
    /// What to read.
    pub input: InputConfig,
    /// Kind, convention and interval level.
    pub allan: AllanOptions,
    /// A kind or convention other than the overlapping textbook one, which a saved wavelet
    /// variance cannot give.
    pub saved_wv: SavedWvCheck,
    /// Table, JSON or CSV.
    pub output: OutputConfig,
}

impl TryFrom<&AvarArgs> for AvarConfig {
    type Error = anyhow::Error;

    fn try_from(a: &AvarArgs) -> Result<Self> {
        gmwm::check_alpha(a.alpha)?;
        let allan = AllanOptions {
            kind: a.kind,
            alpha: a.alpha,
            convention: a.convention,
        };
        // docs/methods.md §3.4, AV(m) = 2 WV(2m), holds for the overlapping textbook estimator only
        let saved_wv = SavedWvCheck::default().or_else(|| {
            (allan.kind != AllanKind::Overlapping || allan.convention != AvConvention::Textbook)
                .then(|| {
                    format!(
                        "--kind {} --convention {} needs the raw recording; a saved wavelet \
                         variance gives only the overlapping textbook Allan variance \
                         (AV(m) = 2 WV(2m), docs/methods.md §3.4)",
                        allan.kind,
                        allan.convention.name()
                    )
                })
        });
        Ok(Self {
            input: (&a.input).try_into()?,
            allan,
            saved_wv,
            output: (&a.output).into(),
        })
    }
}

/// `gmwm simulate`: the fully specified model, the length, rate and seed, where to write.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateConfig {
    /// The model to simulate.
    pub model: Model,
    /// `--n`: samples.
    pub n: usize,
    /// `--freq`: sampling rate in Hz.
    pub freq_hz: f64,
    /// `--seed`.
    pub seed: u64,
    /// `-o`: the file, in the format of its name (`None`: CSV on stdout).
    pub output: Option<PathBuf>,
    /// `--components`: each component as its own column too.
    pub components: bool,
    /// `--yes`: write an output above the size limits.
    pub yes: bool,
}

impl TryFrom<&SimulateArgs> for SimulateConfig {
    type Error = anyhow::Error;

    fn try_from(a: &SimulateArgs) -> Result<Self> {
        let model: Model = a.model.parse()?;
        anyhow::ensure!(a.n >= 1, "invalid --n 0: simulate at least one sample");
        anyhow::ensure!(
            a.freq.is_finite() && a.freq > 0.0,
            "invalid --freq {}: must be a positive number of hertz",
            a.freq
        );
        Ok(Self {
            model,
            n: a.n,
            freq_hz: a.freq,
            seed: a.seed,
            output: a.output.clone(),
            components: a.components,
            yes: a.yes,
        })
    }
}

/// `gmwm implied`: the fully specified model, its levels and rate.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpliedConfig {
    /// The model.
    pub model: Model,
    /// `--levels`: J.
    pub levels: usize,
    /// `--freq`: sampling rate in Hz.
    pub freq_hz: f64,
    /// `--json` instead of a table.
    pub json: bool,
}

impl TryFrom<&ImpliedArgs> for ImpliedConfig {
    type Error = anyhow::Error;

    fn try_from(a: &ImpliedArgs) -> Result<Self> {
        Ok(Self {
            model: a.model.parse()?,
            levels: a.levels,
            freq_hz: a.freq,
            json: a.json,
        })
    }
}

/// `gmwm fit`: the input, the estimator (model, weighting, search) with its WV settings, the
/// inference, the output.
#[derive(Debug, Clone, PartialEq)]
pub struct FitConfig {
    /// What to read.
    pub input: InputConfig,
    /// The GMWM estimator: model, weighting, seed, draws.
    pub gmwm: Gmwm,
    /// The wavelet variance it fits (Haar).
    pub wv: WvOptions,
    /// `--inference` (and `--bootstrap B`): docs/methods.md §7 on each fit; `None` without.
    pub inference: Option<InferenceOptions>,
    /// `--augment`: GMWM+ beside each fit (docs/methods.md §5.15); `None` without.
    pub augment: Option<AugmentOptions>,
    /// Flags a saved wavelet variance cannot honour (`--robust`, `--filter`/`--transform`,
    /// `--weights diag`).
    pub saved_wv: SavedWvCheck,
    /// Table, JSON or CSV.
    pub output: OutputConfig,
}

impl TryFrom<&FitArgs> for FitConfig {
    type Error = anyhow::Error;

    fn try_from(a: &FitArgs) -> Result<Self> {
        let model: Model = a.model.parse()?;
        let wv = wv_options(&a.estimator)?;
        check_haar(&a.estimator, &wv)?;
        let mut gmwm = Gmwm::new(model).with_weighting(a.weights).with_seed(a.seed);
        if let Some(g) = a.draws {
            anyhow::ensure!(g >= 1, "invalid --G 0: at least one starting-value draw");
            gmwm = gmwm.with_draws(g);
        }
        let input = (&a.input).try_into()?;
        let inference = if a.inference {
            if let Some(b) = a.bootstrap {
                anyhow::ensure!(b >= 2, "invalid --bootstrap {b}: at least 2 replicates");
            }
            Some(InferenceOptions {
                alpha: a.estimator.alpha,
                bootstrap: a.bootstrap,
                v_method: a.covariance,
                ..InferenceOptions::default()
            })
        } else {
            None
        };
        let saved_wv = estimator_saved_wv_check(&a.estimator).or_else(|| {
            (a.weights == Weighting::Diag).then(|| {
                "--weights diag needs the series; use fast or bootstrap with a wavelet-variance \
                 file"
                    .to_string()
            })
        });
        let augment = a.augment.map(|augment| AugmentOptions {
            seed: a.seed,
            alpha: a.estimator.alpha,
            ..AugmentOptions::new(augment)
        });
        Ok(Self {
            input,
            gmwm,
            wv,
            inference,
            augment,
            saved_wv,
            output: (&a.output).into(),
        })
    }
}

/// `gmwm select`: the input, the WIC selection (candidates, optimism, rule, bootstrap, search,
/// WV settings), the rows shown, the output.
#[derive(Debug, Clone, PartialEq)]
pub struct SelectConfig {
    /// What to read.
    pub input: InputConfig,
    /// The selection.
    pub wic: Wic,
    /// The wavelet variance it selects on (Haar; also inside `wic`).
    pub wv: WvOptions,
    /// Estimator flags a saved wavelet variance cannot honour.
    pub saved_wv: SavedWvCheck,
    /// `--top`: rows of the table per column (0: all).
    pub top: usize,
    /// Table, JSON or CSV.
    pub output: OutputConfig,
}

impl TryFrom<&SelectArgs> for SelectConfig {
    type Error = anyhow::Error;

    fn try_from(a: &SelectArgs) -> Result<Self> {
        let wic = match &a.candidates {
            Some(list) => {
                let mut texts: Vec<String> = list
                    .split(';')
                    .map(str::trim)
                    .filter(|t| !t.is_empty())
                    .map(String::from)
                    .collect();
                if let Some(m) = &a.model {
                    texts.push(m.clone());
                }
                anyhow::ensure!(
                    !texts.is_empty(),
                    "invalid --candidates {list:?}: give models separated by ';', e.g. \"AR1()+WN();2*AR1()+WN()\""
                );
                Wic::parse_list(&texts)?
            }
            None => {
                let text = a
                    .model
                    .as_deref()
                    .ok_or_else(|| anyhow::anyhow!("give --model or --candidates"))?;
                let model: Model = text.parse()?;
                Wic::nested(model)?
            }
        };
        let wv = wv_options(&a.estimator)?;
        check_haar(&a.estimator, &wv)?;
        let mut wic = wic
            .with_bootstrap(a.bootstrap)
            .with_covariance(a.covariance)
            .with_seed(a.seed)
            .with_optimism(a.optimism)
            .with_convention(a.convention)
            .with_rule(a.rule)
            .with_wv_options(wv);
        if let Some(g) = a.draws {
            wic = wic.with_draws(g);
        }
        Ok(Self {
            input: (&a.input).try_into()?,
            wic,
            wv,
            saved_wv: estimator_saved_wv_check(&a.estimator),
            top: a.top,
            output: (&a.output).into(),
        })
    }
}

/// `gmwm calibrate`: the recording, the engine's calibration options, and what to write.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrateConfig {
    /// The recording.
    pub input: InputConfig,
    /// The calibration: full model, WV settings, bootstrap, search, rule, units, robust check.
    pub options: CalibrationOptions,
    /// The navigation-filter files to write, (stack, path), `--kalibr` first then each
    /// `--export` in order.
    pub exports: Vec<(ExportFormat, PathBuf)>,
    /// `--inflate K`, `--conservative` or `--horizon T` (the estimates otherwise).
    pub adjustment: Adjustment,
    /// `--axis-policy`.
    pub policy: AxisPolicy,
    /// `--json FILE` (`-` for standard output).
    pub json: Option<PathBuf>,
    /// `--rostopic` written to the Kalibr/OpenVINS files.
    pub rostopic: Option<String>,
    /// `--report FILE`: the HTML report too.
    pub report: Option<PathBuf>,
    /// `--pool`: every FILE argument as given (files, folders, globs), calibrated as one
    /// sensor; empty for one recording.
    pub pool: Vec<PathBuf>,
    /// `--audit R`: replicates of the self-audit per axis (0: none).
    pub audit: usize,
    /// `--covariate COL` and its options: N, B, K against a covariate.
    pub covariate: Option<CovariateCalibrationConfig>,
    /// `--augment`: GMWM+ of every axis' identified model (docs/methods.md §5.15).
    pub augment: Option<AugmentOptions>,
}

/// Which N, B, K a calibration against a covariate exports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CovariateExport {
    /// The estimates of the whole recording.
    Whole,
    /// `--at X`.
    At(f64),
    /// `--over LO:HI`: each at its largest over the range.
    Over(f64, f64),
}

/// `gmwm calibrate --covariate COL [--windows K] [--at X | --over LO:HI]`.
#[derive(Debug, Clone, PartialEq)]
pub struct CovariateCalibrationConfig {
    /// The covariate: a column, or a ROS recording's topic or IMU magnitude.
    pub column: String,
    /// Windows the recording is cut into.
    pub windows: usize,
    /// What is exported.
    pub export: CovariateExport,
}

impl CovariateCalibrationConfig {
    fn of(a: &CalibrateArgs) -> Result<Option<Self>> {
        let Some(column) = &a.covariate else {
            return Ok(None);
        };
        let windows = a.windows.unwrap_or(DEFAULT_WINDOWS);
        anyhow::ensure!(
            windows <= MAX_WINDOWS,
            UsageError(format!(
                "invalid --windows {windows}: at most {MAX_WINDOWS}; each window loses the \
                 recording's longest scales"
            ))
        );
        let export = match (a.at, &a.over) {
            (Some(x), _) if !x.is_finite() => {
                return Err(UsageError(format!("invalid --at {x}: not a finite number")).into())
            }
            (Some(x), _) => CovariateExport::At(x),
            (None, Some(range)) => {
                let bad = || {
                    UsageError(format!(
                        "invalid --over {range}: expected LO:HI with finite LO <= HI, e.g. 0:40"
                    ))
                };
                let (lo, hi) = range.split_once(':').ok_or_else(bad)?;
                let lo: f64 = lo.trim().parse().map_err(|_| bad())?;
                let hi: f64 = hi.trim().parse().map_err(|_| bad())?;
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return Err(bad().into());
                }
                CovariateExport::Over(lo, hi)
            }
            (None, None) => CovariateExport::Whole,
        };
        Ok(Some(Self {
            column: column.clone(),
            windows,
            export,
        }))
    }
}

/// The files of `--kalibr` and `--export STACK FILE`, Kalibr first.
fn exports(a: &CalibrateArgs) -> Result<Vec<(ExportFormat, PathBuf)>> {
    let mut out = Vec::new();
    if let Some(p) = &a.kalibr {
        out.push((ExportFormat::KALIBR, p.clone()));
    }
    for pair in a.export.chunks(2) {
        let [stack, file] = pair else {
            return Err(UsageError("--export takes two values: STACK FILE".into()).into());
        };
        let format: ExportFormat = stack.parse().map_err(|_| {
            UsageError(format!(
                "invalid --export {stack}: one of {}",
                ExportFormat::names()
            ))
        })?;
        out.push((format, PathBuf::from(file)));
    }
    Ok(out)
}

impl TryFrom<&CalibrateArgs> for CalibrateConfig {
    type Error = anyhow::Error;

    fn try_from(a: &CalibrateArgs) -> Result<Self> {
        let wv = wv_options(&a.estimator)?;
        check_haar(&a.estimator, &wv)?;
        let full_model = a.model.as_deref().unwrap_or(DEFAULT_FULL_MODEL).parse()?;
        let input: InputConfig = (&a.input).try_into()?;
        let options = CalibrationOptions {
            stream_from: input.stream_from,
            full_model,
            wv,
            covariance: a.covariance,
            bootstrap: a.bootstrap,
            draws: a.draws,
            seed: a.seed,
            rule: a.rule,
            gyro_unit: a.units.gyro_unit,
            accel_unit: a.units.accel_unit,
            // the contamination check compares with the robust WV at --eff
            robust_check: Some(robust_at_eff(&a.estimator)?),
            tolerance: a.tolerance,
            force_units: a.force_units,
            datasheet: a.datasheet.datasheet.clone(),
            horizon_s: a.horizon,
            gaps: input.gaps,
        };
        let exports = exports(a)?;
        let adjustment = match (a.inflate, a.conservative, a.horizon) {
            (_, _, Some(t)) => Adjustment::horizon(t)?,
            (Some(k), ..) => Adjustment::inflate(k)?,
            (None, true, None) => Adjustment::Conservative,
            (None, false, None) => Adjustment::Estimate,
        };
        Ok(Self {
            input,
            options,
            exports,
            adjustment,
            policy: a.axis_policy,
            json: a.json.clone(),
            rostopic: a.rostopic.clone(),
            report: a.report.clone(),
            pool: Vec::new(),
            covariate: CovariateCalibrationConfig::of(a)?,
            augment: a.augment.map(|augment| AugmentOptions {
                seed: a.seed,
                alpha: a.estimator.alpha,
                ..AugmentOptions::new(augment)
            }),
            audit: a.audit.unwrap_or(if a.report.is_some() {
                DEFAULT_REPORT_AUDIT
            } else {
                0
            }),
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Batch mode

/// `gmwm calibrate` or `gmwm wv` over many recordings: the inputs as given (files, folders,
/// globs; expanded by [`crate::cmd::batch`]), where the outputs go, and the job run on each.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchConfig {
    /// FILE arguments as given.
    pub inputs: Vec<PathBuf>,
    /// `--out-dir`: where each recording's outputs go (beside it when `None`).
    pub out_dir: Option<PathBuf>,
    /// `--force`: redo recordings whose outputs are up to date.
    pub force: bool,
    /// The job run on each recording.
    pub job: BatchJob,
}

/// The job of a batch, configured once; each recording runs it with its own FILE.
#[derive(Debug, Clone, PartialEq)]
pub enum BatchJob {
    /// `gmwm calibrate`: `json` is where the batch summary goes as JSON (`--json`, `-` for
    /// standard output); the export and report files of `config` are suffixes of each
    /// recording's stem (checked to be bare file names); `config.json` is unused.
    Calibrate {
        /// The calibration and its file suffixes (boxed: the variants differ in size).
        config: Box<CalibrateConfig>,
        /// `--json FILE|-`: the summary as JSON.
        json: Option<PathBuf>,
    },
    /// `gmwm wv`: `json` prints the batch summary as JSON (`--json`).
    Wv {
        /// The estimator (boxed: the variants differ in size).
        config: Box<WvConfig>,
        /// `--json`: the summary as JSON.
        json: bool,
    },
}

/// Batch mode: more than one FILE, a folder that is not a rosbag2 recording, a glob, or a
/// batch flag (`--out-dir`, `--force`); one plain FILE runs as it always has.
fn is_batch(file: &Path, b: &BatchArgs) -> bool {
    !b.more.is_empty()
        || b.out_dir.is_some()
        || b.force
        || is_glob(file)
        || (file.is_dir() && !is_rosbag2_folder(file))
}

/// The FILE arguments of a batch, in order.
fn batch_inputs(first: &Path, b: &BatchArgs) -> Vec<PathBuf> {
    std::iter::once(first.to_path_buf())
        .chain(b.more.iter().cloned())
        .collect()
}

/// In batch mode a file flag names a suffix of every recording's stem: a file name, no folder.
fn check_suffix(flag: &str, path: &Path) -> Result<()> {
    let mut parts = path.components();
    let bare = matches!(
        (parts.next(), parts.next()),
        (Some(std::path::Component::Normal(_)), None)
    );
    if bare {
        return Ok(());
    }
    Err(UsageError(format!(
        "invalid {flag} {}: in batch mode it names a suffix of each recording's files \
         (imu.yaml writes <stem>.imu.yaml in --out-dir or beside the recording); give a file \
         name without a folder",
        path.display()
    ))
    .into())
}

fn calibrate_or_batch(a: &CalibrateCommand) -> Result<Config> {
    let (args, batch) = (&a.args, &a.batch);
    if a.pool {
        if batch.out_dir.is_some() || batch.force {
            return Err(UsageError(
                "--pool writes one calibration of all the recordings: --out-dir and --force \
                 are for batch mode (one calibration each)"
                    .into(),
            )
            .into());
        }
        let mut config: CalibrateConfig = args.try_into()?;
        config.pool = batch_inputs(&args.input.file, batch);
        return Ok(Config::Calibrate(config));
    }
    if !is_batch(&args.input.file, batch) {
        return Ok(Config::Calibrate(args.try_into()?));
    }
    if let Some(k) = &args.kalibr {
        check_suffix("--kalibr", k)?;
    }
    for pair in args.export.chunks(2) {
        if let [stack, file] = pair {
            check_suffix(&format!("--export {stack}"), Path::new(file))?;
        }
    }
    if let Some(r) = &args.report {
        check_suffix("--report", r)?;
    }
    let mut config: CalibrateConfig = args.try_into()?;
    let json = config.json.take();
    Ok(Config::Batch(BatchConfig {
        inputs: batch_inputs(&args.input.file, batch),
        out_dir: batch.out_dir.clone(),
        force: batch.force,
        job: BatchJob::Calibrate {
            config: Box::new(config),
            json,
        },
    }))
}

fn wv_or_batch(a: &WvCommand) -> Result<Config> {
    let (args, batch) = (&a.args, &a.batch);
    if !is_batch(&args.input.file, batch) {
        return Ok(Config::Wv(args.try_into()?));
    }
    if args.output.csv {
        return Err(UsageError(
            "--csv is for one recording: in batch mode gmwm wv writes each recording's \
             wavelet variance as JSON (<stem>.wv.json), and --json prints the summary as JSON"
                .into(),
        )
        .into());
    }
    let config: WvConfig = args.try_into()?;
    Ok(Config::Batch(BatchConfig {
        inputs: batch_inputs(&args.input.file, batch),
        out_dir: batch.out_dir.clone(),
        force: batch.force,
        job: BatchJob::Wv {
            json: config.output == Style::Json,
            config: Box::new(config),
        },
    }))
}

/// Replicates of the self-audit in a report when `--audit` is not given: enough to show a
/// bias or a coverage gap of the size the real recordings have, at about 5 s per axis.
const DEFAULT_REPORT_AUDIT: usize = 8;

/// `gmwm report`: the calibration, as `gmwm calibrate`, and the HTML file it is written to.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportConfig {
    /// The calibration.
    pub calibrate: CalibrateConfig,
    /// The HTML file: `-o`, else `--report`, else the recording's name with `.report.html`.
    pub output: PathBuf,
}

/// The default report file: the recording's name without its data extensions, with
/// `.report.html`, in the current folder (`imu.csv.gz` gives `imu.report.html`).
fn default_report(file: &Path) -> PathBuf {
    let name = file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "gmwm".to_string());
    let mut stem = name.as_str();
    for ext in [
        ".gz", ".csv", ".tsv", ".txt", ".bag", ".mcap", ".db3", ".bin", ".f64", ".f32",
    ] {
        stem = stem.strip_suffix(ext).unwrap_or(stem);
    }
    let stem = stem.trim_end_matches('/');
    PathBuf::from(format!(
        "{}.report.html",
        if stem.is_empty() { "gmwm" } else { stem }
    ))
}

impl TryFrom<&ReportArgs> for ReportConfig {
    type Error = anyhow::Error;

    fn try_from(a: &ReportArgs) -> Result<Self> {
        if let (Some(o), Some(r)) = (&a.output, &a.calibrate.report) {
            return Err(UsageError(format!(
                "give the report's file once: -o {} or --report {}",
                o.display(),
                r.display()
            ))
            .into());
        }
        let file = &a.calibrate.input.file;
        if a.output.is_none() && a.calibrate.report.is_none() && file.as_os_str() == "-" {
            return Err(UsageError(format!(
                "{}: the report is named after the recording, and standard input has no name; \
                 give -o FILE",
                crate::spool::STDIN
            ))
            .into());
        }
        let output = a
            .output
            .clone()
            .or_else(|| a.calibrate.report.clone())
            .unwrap_or_else(|| default_report(file));
        let mut calibrate: CalibrateConfig = (&a.calibrate).try_into()?;
        // a report carries the self-audit unless --audit says otherwise (as calibrate --report)
        calibrate.audit = a.calibrate.audit.unwrap_or(DEFAULT_REPORT_AUDIT);
        Ok(Self { calibrate, output })
    }
}

/// `gmwm topics`: the ROS recording and the output.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicsConfig {
    /// The recording.
    pub file: PathBuf,
    /// `--json` instead of a list.
    pub json: bool,
}

impl From<&TopicsArgs> for TopicsConfig {
    fn from(a: &TopicsArgs) -> Self {
        Self {
            file: a.file.clone(),
            json: a.json,
        }
    }
}

/// `gmwm plot`: the figure file and what it draws.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotConfig {
    /// File, layout and size.
    pub figure: FigureConfig,
    /// `--gyro-unit`, `--accel-unit`: the units of the samples, over the recording's.
    pub gyro_unit: Option<SignalUnit>,
    /// `--accel-unit`.
    pub accel_unit: Option<SignalUnit>,
    /// `--datasheet`: lines drawn on the axes of each value's sensor.
    pub datasheet: Option<Datasheet>,
    /// The figure and the configuration of the command whose results it draws.
    pub kind: PlotKind,
}

/// The figure of `gmwm plot` with the configuration of its data.
#[derive(Debug, Clone, PartialEq)]
pub enum PlotKind {
    /// `plot wv`: as `gmwm wv`.
    Wv(WvConfig),
    /// `plot avar`: as `gmwm avar`.
    Avar(AvarConfig),
    /// `plot compare`: classical against robust wavelet variance.
    Compare(CompareConfig),
    /// `plot fit`: as `gmwm fit` (without inference).
    Fit(FitConfig),
    /// `plot select`: as `gmwm select`.
    Select(SelectConfig),
    /// `plot ieee`: the overlapping Allan variance, as `gmwm avar`.
    Ieee(AvarConfig),
    /// `plot psd`: the Welch PSD of each column.
    Psd(PsdConfig),
}

/// `gmwm plot psd`: one recording's samples (not a saved wavelet variance).
#[derive(Debug, Clone, PartialEq)]
pub struct PsdConfig {
    /// What to read.
    pub input: InputConfig,
}

/// `gmwm plot compare`: one recording, two estimators.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareConfig {
    /// What to read (the samples; not a saved wavelet variance).
    pub input: InputConfig,
    /// The classical estimator (the flags without `--robust`).
    pub classical: WvOptions,
    /// The robust estimator at `--eff` and `--robust-convention`.
    pub robust: WvOptions,
}

/// Where a figure goes and how it is laid out.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureConfig {
    /// `-o`: the .svg or .png file.
    pub output: PathBuf,
    /// Grid of panels, or the axes overlaid (`--overlay`).
    pub layout: Layout,
    /// `--width` in pixels (default: by the figure's panels).
    pub width: Option<u32>,
    /// `--height` in pixels (default: by the figure's panels).
    pub height: Option<u32>,
}

/// `--json`/`--csv` belong to the tables; a figure refuses them instead of ignoring them.
fn no_table_output(output: &OutputArgs) -> Result<()> {
    if output.json || output.csv {
        return Err(UsageError(
            "gmwm plot draws a figure: --json and --csv belong to gmwm wv|avar|fit|select".into(),
        )
        .into());
    }
    Ok(())
}

/// Flags the figure cannot honour.
fn figure_config(command: &PlotCommand) -> Result<FigureConfig> {
    let (output, figure) = match command {
        PlotCommand::Wv { args, figure, .. } | PlotCommand::Compare { args, figure, .. } => {
            (&args.output, figure)
        }
        PlotCommand::Avar {
            args,
            figure,
            datasheet,
            ..
        } => {
            if datasheet.datasheet.is_some()
                && !matches!(
                    args.kind,
                    AllanKind::Overlapping | AllanKind::NonOverlapping
                )
            {
                return Err(UsageError(format!(
                    "--datasheet draws the Allan-deviation lines of N, B, K (IEEE Std 952 slope \
                     laws), which do not hold for --kind {}: drop --kind or --datasheet",
                    args.kind
                ))
                .into());
            }
            (&args.output, figure)
        }
        PlotCommand::Ieee { args, figure, .. } => {
            if args.kind != AllanKind::Overlapping {
                return Err(UsageError(
                    "gmwm plot ieee reads the overlapping Allan variance (IEEE Std 952): drop --kind"
                        .into(),
                )
                .into());
            }
            (&args.output, figure)
        }
        PlotCommand::Fit { args, figure, .. } => {
            if args.inference {
                return Err(UsageError(
                    "gmwm plot fit draws the fit: --inference belongs to gmwm fit".into(),
                )
                .into());
            }
            (&args.output, figure)
        }
        PlotCommand::Select { args, figure, .. } => (&args.output, figure),
        // no table flags to refuse
        PlotCommand::Psd { figure, .. } => return figure.try_into(),
    };
    if let PlotCommand::Wv {
        args, datasheet, ..
    } = command
    {
        if datasheet.datasheet.is_some() && args.estimator.filter != "haar" {
            return Err(UsageError(format!(
                "--datasheet draws the lines of N, B, K in the Haar wavelet variance \
                 (docs/methods.md §3.4): not with --filter {}",
                args.estimator.filter
            ))
            .into());
        }
    }
    no_table_output(output)?;
    let layered = matches!(command, PlotCommand::Wv { .. } | PlotCommand::Avar { .. });
    if figure.overlay && !layered {
        return Err(UsageError(
            "--overlay lays out the axes of gmwm plot wv and avar; this figure has one panel per column"
                .into(),
        )
        .into());
    }
    figure.try_into()
}

impl TryFrom<&FigureArgs> for FigureConfig {
    type Error = anyhow::Error;

    fn try_from(figure: &FigureArgs) -> Result<Self> {
        let too_large = |v: Option<usize>| v.is_some_and(|v| v > gmwm_plot::MAX_SIDE as usize);
        if too_large(figure.width) || too_large(figure.height) {
            return Err(UsageError(format!(
                "invalid --width/--height: at most {} px a side",
                gmwm_plot::MAX_SIDE
            ))
            .into());
        }
        if let (Some(w), Some(h)) = (figure.width, figure.height) {
            if (w as u64) * (h as u64) > gmwm_plot::MAX_PIXELS {
                return Err(UsageError(format!(
                    "invalid --width {w} --height {h}: at most {} megapixels",
                    gmwm_plot::MAX_PIXELS / 1_000_000
                ))
                .into());
            }
        }
        // a file name the renderer can write
        ImageFormat::of(&figure.output).map_err(|e| UsageError(format!("invalid --output {e}")))?;
        let side = |v: Option<usize>| v.map(|v| u32::try_from(v).unwrap_or(u32::MAX));
        Ok(Self {
            output: figure.output.clone(),
            layout: if figure.overlay {
                Layout::Overlay
            } else {
                Layout::Grid
            },
            width: side(figure.width),
            height: side(figure.height),
        })
    }
}

impl TryFrom<&PlotArgs> for PlotConfig {
    type Error = anyhow::Error;

    fn try_from(a: &PlotArgs) -> Result<Self> {
        let figure = figure_config(&a.figure)?;
        let kind = match &a.figure {
            PlotCommand::Wv { args, .. } => PlotKind::Wv(args.try_into()?),
            PlotCommand::Avar { args, .. } => PlotKind::Avar(args.try_into()?),
            PlotCommand::Compare { args, .. } => {
                let classical = WvOptions {
                    robust: None,
                    ..wv_options(&args.estimator)?
                };
                let robust = WvOptions {
                    robust: Some(robust_at_eff(&args.estimator)?),
                    ..classical
                };
                PlotKind::Compare(CompareConfig {
                    input: (&args.input).try_into()?,
                    classical,
                    robust,
                })
            }
            PlotCommand::Fit { args, .. } => {
                anyhow::ensure!(
                    !args.pool,
                    "--pool: gmwm plot fit draws one recording's fit; use gmwm fit --pool --json"
                );
                PlotKind::Fit(args.try_into()?)
            }
            PlotCommand::Select { args, .. } => {
                anyhow::ensure!(
                    !args.pool,
                    "--pool: gmwm plot select draws one recording's selection; use gmwm select --pool"
                );
                PlotKind::Select(args.try_into()?)
            }
            PlotCommand::Ieee { args, .. } => PlotKind::Ieee(args.try_into()?),
            PlotCommand::Psd { args, .. } => PlotKind::Psd(PsdConfig {
                input: (&args.input).try_into()?,
            }),
        };
        let (units, datasheet) = match &a.figure {
            PlotCommand::Wv {
                units, datasheet, ..
            }
            | PlotCommand::Avar {
                units, datasheet, ..
            }
            | PlotCommand::Fit {
                units, datasheet, ..
            }
            | PlotCommand::Ieee {
                units, datasheet, ..
            }
            | PlotCommand::Compare {
                units, datasheet, ..
            }
            | PlotCommand::Select {
                units, datasheet, ..
            } => (units, datasheet.datasheet.clone()),
            PlotCommand::Psd { units, .. } => (units, None),
        };
        Ok(Self {
            figure,
            kind,
            gyro_unit: units.gyro_unit,
            accel_unit: units.accel_unit,
            datasheet,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Several recordings (one model for all, or are they one model?)

/// `gmwm fit FILE... --pool`: the fit's configuration (its `input` names the first recording
/// and how every recording is read) and every recording.
#[derive(Debug, Clone, PartialEq)]
pub struct PooledFitConfig {
    /// The fit, as `gmwm fit` (`--inference` and `--bootstrap` included).
    pub fit: FitConfig,
    /// `--seed`: of the search and the inference.
    pub seed: u64,
    /// FILE and the more FILEs, in order.
    pub files: Vec<PathBuf>,
}

impl TryFrom<&FitArgs> for PooledFitConfig {
    type Error = anyhow::Error;

    fn try_from(a: &FitArgs) -> Result<Self> {
        let fit = FitConfig::try_from(a)?;
        let files = std::iter::once(fit.input.file.clone())
            .chain(a.more.iter().cloned())
            .collect();
        Ok(Self {
            fit,
            seed: a.seed,
            files,
        })
    }
}

/// Where a covariate fit's levels come from.
#[derive(Debug, Clone, PartialEq)]
pub enum CovariateSource {
    /// `--covariate COL`: the mean of column COL of each FILE.
    Column(String),
    /// `--covariate-values LIST`: one level per FILE.
    Values(Vec<f64>),
}

/// `gmwm fit FILE... --covariate COL | --covariate-values LIST`: the parameters as functions of
/// a covariate (docs/methods.md §5.13).
#[derive(Debug, Clone, PartialEq)]
pub struct CovariateFitConfig {
    /// The fit's reading, estimator and output, as `gmwm fit`.
    pub fit: FitConfig,
    /// `--seed`: of the searches and of the inference.
    pub seed: u64,
    /// FILE and the more FILEs, in order.
    pub files: Vec<PathBuf>,
    /// The covariate's levels.
    pub covariate: CovariateSource,
    /// `--depends`, resolved per parameter.
    pub dependence: Vec<gmwm::Dependence>,
    /// `--at`: levels at which the parameters are reported (empty: each FILE's).
    pub at: Vec<f64>,
    /// `--windows K` of one FILE ([`DEFAULT_WINDOWS`] when not given); `None` with several.
    pub windows: Option<usize>,
}

/// `gmwm fit FILE --covariate COL --dynamic [--windows K]`: the non-stationary AR1 of the
/// paper's §IV-B (docs/methods.md §5.16) on each sensor column.
#[derive(Debug, Clone)]
pub struct DynamicFitConfig {
    /// The reading and output, as `gmwm fit`.
    pub fit: FitConfig,
    /// `--covariate COL`.
    pub covariate: String,
    /// The estimator's settings (windows, white noise).
    pub options: gmwm::NsAr1Options,
}

impl TryFrom<&FitArgs> for DynamicFitConfig {
    type Error = anyhow::Error;

    fn try_from(a: &FitArgs) -> Result<Self> {
        let fit = FitConfig::try_from(a)?;
        let Some(covariate) = a.covariate.clone() else {
            return Err(UsageError(
                "--dynamic needs the dynamics: give them with --covariate COL (a column, or a \
                 ROS recording's topic or angular_rate / specific_force)"
                    .into(),
            )
            .into());
        };
        anyhow::ensure!(
            a.more.is_empty(),
            "--dynamic fits one recording along its covariate; {} more FILEs were given",
            a.more.len()
        );
        let canonical = fit.gmwm.model().without_values().to_string();
        let white_noise = match canonical.as_str() {
            "AR1()" | "GM()" => false,
            "AR1()+WN()" | "GM()+WN()" | "WN()+AR1()" | "WN()+GM()" => true,
            other => {
                return Err(UsageError(format!(
                    "invalid --model {other} with --dynamic: the non-stationary model is AR1() or \
                     AR1()+WN() (docs/methods.md §5.16)"
                ))
                .into())
            }
        };
        let windows = a.windows.unwrap_or(DEFAULT_WINDOWS);
        anyhow::ensure!(
            windows <= MAX_WINDOWS,
            "invalid --windows {windows}: at most {MAX_WINDOWS}"
        );
        Ok(Self {
            fit,
            covariate,
            options: gmwm::NsAr1Options {
                windows,
                white_noise,
                ..gmwm::NsAr1Options::default()
            },
        })
    }
}

/// Windows one drifting recording is cut into without `--windows`: enough levels for an
/// affine or quadratic dependence with a few to spare, each window 1/8 of the recording.
pub const DEFAULT_WINDOWS: usize = 8;
/// Most windows `--windows` cuts one recording into.
pub const MAX_WINDOWS: usize = 64;

impl TryFrom<&FitArgs> for CovariateFitConfig {
    type Error = anyhow::Error;

    fn try_from(a: &FitArgs) -> Result<Self> {
        let fit = FitConfig::try_from(a)?;
        anyhow::ensure!(
            a.bootstrap.is_none(),
            "invalid --bootstrap with a covariate: a covariate fit's intervals are the sandwich's \
             (docs/methods.md §5.13)"
        );
        let files: Vec<PathBuf> = std::iter::once(fit.input.file.clone())
            .chain(a.more.iter().cloned())
            .collect();
        let windows = match (files.len(), &a.covariate, a.windows) {
            (1, Some(_), Some(k)) if k > MAX_WINDOWS => anyhow::bail!(
                "invalid --windows {k}: at most {MAX_WINDOWS}; each window loses the recording's \
                 longest scales, and a polynomial of degree 2 needs only a few levels"
            ),
            (1, Some(_), k) => Some(k.unwrap_or(DEFAULT_WINDOWS)),
            (1, None, _) => anyhow::bail!(
                "a covariate fit of one FILE cuts it into windows at their mean levels of \
                 --covariate COL; --covariate-values needs a FILE per level"
            ),
            (n, _, Some(k)) => anyhow::bail!(
                "invalid --windows {k}: it cuts one FILE into windows, and {n} FILEs were given"
            ),
            _ => None,
        };
        let covariate = match &a.covariate {
            Some(col) => CovariateSource::Column(col.clone()),
            None => {
                let v = &a.covariate_values;
                anyhow::ensure!(
                    v.len() == files.len(),
                    "invalid --covariate-values: {} value(s) for {} FILEs; give one level per FILE, \
                     in order",
                    v.len(),
                    files.len()
                );
                if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                    anyhow::bail!("invalid --covariate-values: {x} is not a finite number");
                }
                CovariateSource::Values(v.clone())
            }
        };
        if let Some(x) = a.at.iter().find(|x| !x.is_finite()) {
            anyhow::bail!("invalid --at: {x} is not a finite number");
        }
        let dependence = gmwm::dependences(fit.gmwm.model(), &a.depends)
            .map_err(|e| anyhow::anyhow!("invalid --depends {}: {}", e.value, e.expected))?;
        Ok(Self {
            fit,
            seed: a.seed,
            files,
            covariate,
            dependence,
            at: a.at.clone(),
            windows,
        })
    }
}

/// `gmwm select FILE... --pool`: the sub-models of `--model` ranked by the pooled WIC.
#[derive(Debug, Clone, PartialEq)]
pub struct PooledSelectConfig {
    /// The selection's flags, as `gmwm select` (`input`, `wv`, `top`, `output` are used).
    pub select: SelectConfig,
    /// The full model's estimator (values dropped), seed and draws.
    pub gmwm: Gmwm,
    /// `--seed`: of the searches.
    pub seed: u64,
    /// FILE and the more FILEs, in order.
    pub files: Vec<PathBuf>,
}

impl TryFrom<&SelectArgs> for PooledSelectConfig {
    type Error = anyhow::Error;

    fn try_from(a: &SelectArgs) -> Result<Self> {
        let select = SelectConfig::try_from(a)?;
        let Some(text) = &a.model else {
            return Err(UsageError(
                "--pool selects among the sub-models of --model; --candidates is not supported \
                 with --pool"
                    .into(),
            )
            .into());
        };
        let model: Model = text.parse()?;
        let mut gmwm = Gmwm::new(model.without_values()).with_seed(a.seed);
        if let Some(g) = a.draws {
            gmwm = gmwm.with_draws(g.max(1));
        }
        let files = std::iter::once(select.input.file.clone())
            .chain(a.more.iter().cloned())
            .collect();
        Ok(Self {
            select,
            gmwm,
            seed: a.seed,
            files,
        })
    }
}

/// `gmwm same-model FILE...`: the recordings, how each is read, the model and the test.
#[derive(Debug, Clone, PartialEq)]
pub struct SameModelConfig {
    /// The recordings (at least two).
    pub files: Vec<PathBuf>,
    /// How every recording is read (`--columns`, `--freq`; `file` is the first).
    pub input: InputConfig,
    /// The model's estimator, seed and draws.
    pub gmwm: Gmwm,
    /// `--levels`: the WV of every recording (Haar MODWT).
    pub wv: WvOptions,
    /// `--bootstrap`, `--seed`.
    pub test: SameModelOptions,
    /// `--plot FILE`.
    pub plot: Option<PathBuf>,
    /// `--json` instead of a table.
    pub json: bool,
}

impl TryFrom<&SameModelArgs> for SameModelConfig {
    type Error = anyhow::Error;

    fn try_from(a: &SameModelArgs) -> Result<Self> {
        if a.files.len() < 2 {
            anyhow::bail!(
                "{}: the same-model test needs at least two recordings (FILEs); got one",
                a.files[0].display()
            );
        }
        if let Some(b) = a.bootstrap {
            if b < 1 {
                return Err(
                    UsageError(format!("invalid --bootstrap {b}: at least 1 replicate")).into(),
                );
            }
        }
        if let Some(f) = a.freq {
            if !(f.is_finite() && f > 0.0) {
                return Err(UsageError(format!(
                    "invalid --freq {f}: must be a positive number of hertz"
                ))
                .into());
            }
        }
        let model: Model = a.model.parse()?;
        let mut gmwm = Gmwm::new(model).with_seed(a.seed);
        if let Some(g) = a.draws {
            gmwm = gmwm.with_draws(g.max(1));
        }
        let input = InputConfig {
            file: a.files[0].clone(),
            read: ReadOptions {
                columns: a.columns.iter().map(|c| selector(c)).collect(),
                freq_hz: a.freq,
                ..ReadOptions::default()
            },
            topic: None,
            stream_from: gmwm::STREAM_FROM,
            gaps: gmwm::GapPolicy::default(),
            probe: Default::default(),
        };
        Ok(Self {
            files: a.files.clone(),
            input,
            gmwm,
            wv: WvOptions {
                levels: a.levels,
                ..WvOptions::default()
            },
            test: SameModelOptions {
                bootstrap: a.bootstrap,
                seed: a.seed,
            },
            plot: a.plot.clone(),
            json: a.json,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Several axes of one recording

/// Validated `gmwm shared`.
#[derive(Debug, Clone)]
pub struct SharedConfig {
    /// The recording.
    pub input: InputConfig,
    /// `--shared`.
    pub shared: Model,
    /// `--model`.
    pub specific: Model,
    /// Estimator settings.
    pub options: SharedOptions,
    /// `--plot`.
    pub plot: Option<std::path::PathBuf>,
    /// Table, JSON or CSV.
    pub output: OutputConfig,
}

impl TryFrom<&SharedArgs> for SharedConfig {
    type Error = anyhow::Error;

    fn try_from(a: &SharedArgs) -> Result<Self> {
        let model = |flag: &str, text: &str| -> Result<Model> {
            text.parse::<Model>()
                .with_context(|| format!("invalid {flag} {text:?}"))
        };
        if let Some(why) = gmwm::significance_level_problem(a.alpha) {
            anyhow::bail!("invalid --alpha {}: {why}", a.alpha);
        }
        anyhow::ensure!(a.draws >= 1, "invalid --G 0: at least one draw");
        if a.levels == Some(0) {
            anyhow::bail!("invalid --levels 0: at least one level");
        }
        Ok(Self {
            input: InputConfig::try_from(&a.input)?,
            shared: model("--shared", &a.shared)?,
            specific: model("--model", &a.model)?,
            options: SharedOptions {
                levels: a.levels,
                alpha: a.alpha,
                seed: a.seed,
                draws: a.draws,
                ..SharedOptions::default()
            },
            plot: a.plot.clone(),
            output: OutputConfig::from(&a.output),
        })
    }
}

/// A length given as samples or as a duration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Span {
    /// Samples.
    Samples(usize),
    /// Seconds.
    Seconds(f64),
}

impl Span {
    fn parse(flag: &str, text: &str) -> Result<Self> {
        let t = text.trim();
        if let Ok(n) = t.parse::<usize>() {
            anyhow::ensure!(n >= 1, "invalid {flag} {text}: at least 1 sample");
            return Ok(Span::Samples(n));
        }
        let (num, unit) = t
            .find(|c: char| c.is_ascii_alphabetic())
            .map(|i| t.split_at(i))
            .unwrap_or((t, ""));
        let factor = match unit {
            "s" => 1.0,
            "min" => 60.0,
            "h" => 3600.0,
            _ => anyhow::bail!(
                "invalid {flag} {text}: give samples (65536) or a duration in s, min or h (600s)"
            ),
        };
        let v: f64 = num
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite() && *v > 0.0)
            .with_context(|| format!("invalid {flag} {text}: not a positive duration"))?;
        Ok(Span::Seconds(v * factor))
    }

    /// The samples at `freq_hz`.
    pub fn samples(self, freq_hz: f64) -> usize {
        match self {
            Span::Samples(n) => n,
            Span::Seconds(s) => (s * freq_hz).round() as usize,
        }
    }
}

/// Validated `gmwm monitor`.
#[derive(Debug, Clone)]
pub struct MonitorConfig {
    /// The recording.
    pub input: InputConfig,
    /// `--model-from`.
    pub calibration: PathBuf,
    /// `--window`.
    pub window: Span,
    /// `--step`.
    pub step: Option<Span>,
    /// Engine settings (window and step filled in once the rate is known).
    pub options: MonitorOptions,
    /// `--against`.
    pub against: Against,
    /// Table or JSON.
    pub output: OutputConfig,
}

impl TryFrom<&MonitorArgs> for MonitorConfig {
    type Error = anyhow::Error;

    fn try_from(a: &MonitorArgs) -> Result<Self> {
        if let Some(why) = gmwm::significance_level_problem(a.alpha) {
            anyhow::bail!("invalid --alpha {}: {why}", a.alpha);
        }
        let robust = gmwm::RobustOptions::new(a.eff, gmwm::RobustConvention::Exact)
            .map_err(|e| anyhow::anyhow!("invalid --eff {}: {e}", a.eff))?;
        if a.levels == Some(0) {
            anyhow::bail!("invalid --levels 0: at least one level");
        }
        Ok(Self {
            input: InputConfig::try_from(&a.input)?,
            calibration: a.model_from.clone(),
            window: Span::parse("--window", &a.window)?,
            step: a
                .step
                .as_deref()
                .map(|s| Span::parse("--step", s))
                .transpose()?,
            options: MonitorOptions {
                alpha: a.alpha,
                robust,
                levels: a.levels,
                ..MonitorOptions::default()
            },
            against: a.against,
            output: OutputConfig::from(&a.output),
        })
    }
}

// ---------------------------------------------------------------------------------------------
// gmwm plan

/// One model to plan for, named.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanSubject {
    /// The axis or sensor it stands for.
    pub name: String,
    /// The unit of its values (`u` when unknown).
    pub unit: String,
    /// The model, every value given.
    pub model: Model,
    /// Its rate, Hz.
    pub freq_hz: f64,
    /// Where it comes from, in words.
    pub from: String,
}

/// `gmwm plan`, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanConfig {
    /// The models.
    pub subjects: Vec<PlanSubject>,
    /// `--lengths`, s.
    pub lengths_s: Vec<f64>,
    /// `--target`: (quantity, relative half-width).
    pub targets: Vec<(String, f64)>,
    /// `--alpha`.
    pub alpha: f64,
    /// `--json`.
    pub json: bool,
    /// FILE, when given.
    pub file: Option<PathBuf>,
    /// `--plot FILE`.
    pub plot: Option<PathBuf>,
}

/// `30min`, `2h`, `1d`, `600` (s) in seconds.
fn length(text: &str) -> Result<f64> {
    let t = text.trim();
    let split = t.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let factor = match unit.trim() {
        "" | "s" => 1.0,
        "min" | "m" => 60.0,
        "h" => 3600.0,
        "d" => 86400.0,
        _ => f64::NAN,
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && factor.is_finite() => Ok(v * factor),
        _ => Err(UsageError(format!(
            "invalid --lengths item {t:?}: a length with s, min, h or d, e.g. 30min, 3h, 1d"
        ))
        .into()),
    }
}

/// `K=20%` or `K=0.2`.
fn target(text: &str) -> Result<(String, f64)> {
    let bad = || {
        UsageError(format!(
            "invalid --target item {text:?}: QUANTITY=PERCENT, e.g. K=20% (N, B, K, T1, ...)"
        ))
    };
    let (name, value) = text.split_once('=').ok_or_else(bad)?;
    let value = value.trim();
    let v = match value.strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().map(|x| x / 100.0),
        None => value.parse::<f64>(),
    }
    .map_err(|_| bad())?;
    if !(v.is_finite() && v > 0.0) {
        return Err(bad().into());
    }
    Ok((name.trim().to_string(), v))
}

/// Each axis of a calibration document: its identified model with its values.
fn subjects_of_calibration(path: &Path, columns: Option<&str>) -> Result<Vec<PlanSubject>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let doc: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let axes = doc["axes"].as_array().ok_or_else(|| {
        UsageError(format!(
            "{}: not a calibration (no axes[]; write one with gmwm calibrate --json)",
            path.display()
        ))
    })?;
    let wanted: Option<Vec<&str>> = columns.map(|c| c.split(',').map(str::trim).collect());
    let mut out = Vec::new();
    for (i, a) in axes.iter().enumerate() {
        let column = a["column"].as_str().unwrap_or("?").to_string();
        if wanted
            .as_ref()
            .is_some_and(|w| !w.contains(&column.as_str()))
        {
            continue;
        }
        let field = |what: &str| {
            UsageError(format!(
                "{}: axes[{i}] ({column}) has no {what}",
                path.display()
            ))
        };
        let text = a["fit"]["model"]
            .as_str()
            .ok_or_else(|| field("fit.model"))?;
        let freq_hz = a["fit"]["freq_hz"]
            .as_f64()
            .ok_or_else(|| field("fit.freq_hz"))?;
        let model: Model = text
            .parse()
            .with_context(|| format!("{}: axes[{i}] ({column}) fit.model", path.display()))?;
        out.push(PlanSubject {
            name: column,
            unit: a["unit"].as_str().unwrap_or("u").to_string(),
            model,
            freq_hz,
            from: format!("identified model of {}", path.display()),
        });
    }
    if out.is_empty() {
        return Err(UsageError(format!(
            "{}: no axis {}",
            path.display(),
            columns.unwrap_or("")
        ))
        .into());
    }
    Ok(out)
}

impl TryFrom<&crate::args::PlanArgs> for PlanConfig {
    type Error = anyhow::Error;

    fn try_from(a: &crate::args::PlanArgs) -> Result<Self> {
        let need_freq = || {
            a.freq.ok_or_else(|| {
                UsageError("--freq HZ: the sampling rate the model or datasheet is at".into())
            })
        };
        let subjects = match (&a.file, &a.model, &a.datasheet) {
            (Some(f), ..) => subjects_of_calibration(f, a.columns.as_deref())?,
            (None, Some(m), _) => vec![PlanSubject {
                name: "model".into(),
                unit: "u".into(),
                model: m.parse()?,
                freq_hz: need_freq()?,
                from: "--model".into(),
            }],
            (None, None, Some(d)) => {
                let f = need_freq()?;
                [gmwm::SignalKind::Gyroscope, gmwm::SignalKind::Accelerometer]
                    .into_iter()
                    .filter_map(|kind| {
                        d.model_for(kind, f).map(|(model, from)| PlanSubject {
                            name: match kind {
                                gmwm::SignalKind::Gyroscope => "gyro".into(),
                                gmwm::SignalKind::Accelerometer => "accel".into(),
                            },
                            unit: match kind {
                                gmwm::SignalKind::Gyroscope => "rad/s".into(),
                                gmwm::SignalKind::Accelerometer => "m/s^2".into(),
                            },
                            model,
                            freq_hz: f,
                            from,
                        })
                    })
                    .collect()
            }
            (None, None, None) => {
                return Err(UsageError(
                    "give a calibration FILE, --model or --datasheet (see gmwm plan --help)".into(),
                )
                .into())
            }
        };
        let lengths_s = match &a.lengths {
            Some(l) => l.split(',').map(length).collect::<Result<Vec<_>>>()?,
            None => gmwm::PLAN_LENGTHS_S.to_vec(),
        };
        let targets = match &a.target {
            Some(t) => t.split(',').map(target).collect::<Result<Vec<_>>>()?,
            None => Vec::new(),
        };
        Ok(Self {
            subjects,
            lengths_s,
            targets,
            alpha: a.alpha,
            json: a.json,
            file: a.file.clone(),
            plot: a.plot.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::Cli;
    use clap::Parser;
    use gmwm::RobustConvention;
    use gmwm::{HeaderMode, ImuRecordType, InputFormat, TimeUnit};
    use gmwm::{OptimismConvention, OptimismMethod, SelectionRule};

    /// The arguments clap parses from `gmwm ARGV`.
    fn parse(argv: &[&str]) -> Command {
        Cli::try_parse_from(std::iter::once("gmwm").chain(argv.iter().copied()))
            .unwrap_or_else(|e| panic!("clap refuses {argv:?}: {e}"))
            .command
    }

    fn config(argv: &[&str]) -> Config {
        Config::try_from(&parse(argv)).unwrap_or_else(|e| panic!("{argv:?}: {e:#}"))
    }

    /// The error of `gmwm ARGV`'s configuration and whether it is a usage error (exit code 2).
    fn refusal(argv: &[&str]) -> (String, bool) {
        let e = Config::try_from(&parse(argv)).expect_err("refused");
        (format!("{e:#}"), e.downcast_ref::<UsageError>().is_some())
    }

    const HAAR_ONLY: &str = "invalid --filter la8: every model's implied wavelet variance is \
        the Haar one (docs/methods.md §1.8, §4), so fits and selections use --filter haar (the \
        default); other filters are for gmwm wv";

    #[test]
    fn estimation_commands_refuse_a_non_haar_filter_as_a_usage_error() {
        for argv in [
            &["fit", "x.csv", "--model", "WN()", "--filter", "la8"][..],
            &["select", "x.csv", "--model", "WN()", "--filter", "la8"],
            &["calibrate", "x.csv", "--filter", "la8"],
            &["report", "x.csv", "--filter", "la8"],
            &[
                "plot", "fit", "x.csv", "--model", "WN()", "--filter", "la8", "-o", "f.svg",
            ],
        ] {
            assert_eq!(refusal(argv), (HAAR_ONLY.to_string(), true), "{argv:?}");
        }
        // gmwm wv takes any filter; an unknown one is the engine's error (exit code 1)
        assert!(matches!(
            config(&["wv", "x.csv", "--filter", "la8"]),
            Config::Wv(c) if c.wv.filter == WaveletFilter::La8
        ));
        let (msg, usage) = refusal(&["wv", "x.csv", "--filter", "nope"]);
        assert!(msg.contains("nope") && !usage, "{msg}");
        let (msg, usage) = refusal(&["demo", "--transform", "dwt"]);
        assert!(msg.starts_with("gmwm demo compares with the implied WV") && !usage);
    }

    #[test]
    fn wv_flags_give_the_engine_options() {
        let Config::Wv(c) = config(&["wv", "x.csv"]) else {
            panic!()
        };
        assert_eq!(c.wv, WvOptions::default());
        assert_eq!(c.input.read, ReadOptions::default());
        assert_eq!(c.input.file, PathBuf::from("x.csv"));
        assert_eq!(c.output, Style::Table);
        assert_eq!(c.saved_wv, SavedWvCheck::default());
        let Config::Wv(c) = config(&[
            "wv",
            "x.bin",
            "--robust",
            "--eff",
            "0.8",
            "--robust-convention",
            "package",
            "--transform",
            "dwt",
            "--filter",
            "d4",
            "--levels",
            "5",
            "--alpha",
            "0.1",
            "--columns",
            "gyro_x,3",
            "--freq",
            "200",
            "--format",
            "f32",
            "--ncols",
            "6",
            "--header",
            "no",
            "--time-column",
            "1",
            "--time-unit",
            "ms",
            "--topic",
            "/imu0",
            "--csv",
        ]) else {
            panic!()
        };
        assert_eq!(
            c.wv,
            WvOptions {
                transform: Transform::Dwt,
                filter: WaveletFilter::D4,
                levels: Some(5),
                alpha: 0.1,
                robust: Some(RobustOptions::new(0.8, RobustConvention::Package).unwrap()),
            }
        );
        assert_eq!(
            c.input.read,
            ReadOptions {
                format: InputFormat::F32,
                header: HeaderMode::Absent,
                time_column: Some(ColumnSelector::Index(1)),
                time_unit: Some(TimeUnit::Milliseconds),
                columns: vec![
                    ColumnSelector::Name("gyro_x".into()),
                    ColumnSelector::Index(3)
                ],
                ncols: Some(6),
                freq_hz: Some(200.0),
                time_policy: gmwm::TimePolicy::Strict,
            }
        );
        assert_eq!(c.input.topic.as_deref(), Some("/imu0"));
        assert_eq!(c.output, Style::Csv);
        let refused = c.saved_wv.check(Path::new("wv.json")).unwrap_err();
        assert_eq!(
            refused.to_string(),
            "wv.json: --robust needs the series; a wavelet-variance file is used as it is \
             (robust if it says so)"
        );
    }

    #[test]
    fn input_checks_hold_without_clap() {
        let mut args = InputArgs {
            file: "x.csv".into(),
            columns: Vec::new(),
            freq: Some(-5.0),
            format: InputFormat::Auto,
            ncols: None,
            header: HeaderMode::Auto,
            time_column: None,
            time_unit: None,
            time_policy: gmwm::TimePolicy::Strict,
            gaps: gmwm::GapPolicy::Aware,
            topic: None,
            stream_from: None,
        };
        assert_eq!(
            InputConfig::try_from(&args).unwrap_err().to_string(),
            "invalid --freq -5: must be a positive number of hertz"
        );
        args.freq = None;
        args.ncols = Some(0);
        assert_eq!(
            InputConfig::try_from(&args).unwrap_err().to_string(),
            "invalid --ncols 0: a binary file has at least one column"
        );
        args.format = InputFormat::ImuRecord(ImuRecordType::Ln200Ig);
        args.ncols = None;
        assert_eq!(
            InputConfig::try_from(&args).unwrap().read.format,
            InputFormat::ImuRecord(ImuRecordType::Ln200Ig)
        );
    }

    #[test]
    fn saved_wv_refusals_are_decided_from_the_flags() {
        let file = Path::new("wv.json");
        let check = |argv: &[&str]| match config(argv) {
            Config::Wv(c) => c.saved_wv.check(file),
            Config::Fit(c) => c.saved_wv.check(file),
            Config::Select(c) => c.saved_wv.check(file),
            Config::Avar(c) => c.saved_wv.check(file),
            _ => unreachable!(),
        };
        let refused = |argv: &[&str]| check(argv).unwrap_err().to_string();
        let filter = "wv.json: --filter/--transform apply to a recording; a wavelet-variance \
                      file is used as it is";
        assert_eq!(refused(&["wv", "x", "--filter", "d4"]), filter);
        assert_eq!(
            refused(&["select", "x", "--model", "WN()", "--transform", "dwt"]),
            filter
        );
        assert_eq!(
            refused(&["fit", "x", "--model", "WN()", "--weights", "diag"]),
            "wv.json: --weights diag needs the series; use fast or bootstrap with a \
             wavelet-variance file"
        );
        // the estimator's refusal comes first
        assert!(refused(&[
            "fit",
            "x",
            "--model",
            "WN()",
            "--weights",
            "diag",
            "--robust"
        ])
        .contains("--robust needs the series"));
        assert_eq!(
            refused(&["avar", "x", "--kind", "modified"]),
            "wv.json: --kind modified --convention textbook needs the raw recording; a saved \
             wavelet variance gives only the overlapping textbook Allan variance \
             (AV(m) = 2 WV(2m), docs/methods.md §3.4)"
        );
        assert!(refused(&["avar", "x", "--convention", "package"]).contains("--kind overlapping"));
        for ok in [
            &["wv", "x", "--levels", "4", "--alpha", "0.1"][..],
            &["fit", "x", "--model", "WN()", "--weights", "bootstrap"],
            &["select", "x", "--model", "WN()", "--filter", "haar"],
            &["avar", "x", "--json"],
        ] {
            assert!(check(ok).is_ok(), "{ok:?}");
        }
    }

    #[test]
    fn fit_flags_give_the_estimator_and_the_inference() {
        let Config::Fit(c) = config(&[
            "fit",
            "x.csv",
            "--model",
            "AR1()+WN()",
            "--weights",
            "bootstrap",
            "--G",
            "500",
            "--seed",
            "7",
            "--alpha",
            "0.1",
            "--inference",
            "--bootstrap",
            "20",
            "--json",
        ]) else {
            panic!()
        };
        let model: Model = "AR1()+WN()".parse().unwrap();
        assert_eq!(
            c.gmwm,
            Gmwm::new(model)
                .with_weighting(Weighting::Bootstrap)
                .with_seed(7)
                .with_draws(500)
        );
        assert_eq!(c.wv.alpha, 0.1);
        assert_eq!(
            c.inference,
            Some(InferenceOptions {
                alpha: 0.1,
                bootstrap: Some(20),
                ..InferenceOptions::default()
            })
        );
        assert_eq!(c.output, Style::Json);
        let Config::Fit(c) = config(&["fit", "x.csv", "--model", "WN()"]) else {
            panic!()
        };
        assert_eq!(c.inference, None);
        assert_eq!(c.gmwm.weighting(), Weighting::Fast);
        let (msg, usage) = refusal(&["fit", "x.csv", "--model", "AR1("]);
        assert!(msg.contains("AR1(") && !usage, "{msg}");
    }

    #[test]
    fn fit_counts_are_checked_without_clap() {
        let Command::Fit(mut args) = parse(&["fit", "x.csv", "--model", "WN()", "--inference"])
        else {
            panic!()
        };
        args.draws = Some(0);
        assert_eq!(
            FitConfig::try_from(&args).unwrap_err().to_string(),
            "invalid --G 0: at least one starting-value draw"
        );
        args.draws = None;
        args.bootstrap = Some(1);
        assert_eq!(
            FitConfig::try_from(&args).unwrap_err().to_string(),
            "invalid --bootstrap 1: at least 2 replicates"
        );
    }

    #[test]
    fn select_flags_give_the_wic() {
        let Config::Select(c) = config(&[
            "select",
            "x.csv",
            "--model",
            "2*AR1()+WN()",
            "--bootstrap",
            "30",
            "--optimism",
            "bootstrap",
            "--convention",
            "package",
            "--rule",
            "parsimonious",
            "--G",
            "100",
            "--seed",
            "3",
            "--top",
            "0",
        ]) else {
            panic!()
        };
        let full: Model = "2*AR1()+WN()".parse().unwrap();
        let expected = Wic::nested(full)
            .unwrap()
            .with_bootstrap(30)
            .with_seed(3)
            .with_optimism(OptimismMethod::Bootstrap)
            .with_convention(OptimismConvention::Package)
            .with_rule(SelectionRule::Parsimonious)
            .with_wv_options(WvOptions::default())
            .with_draws(100);
        assert_eq!(c.wic, expected);
        assert_eq!(c.top, 0);
        let Config::Select(c) = config(&["select", "x.csv", "--candidates", "AR1()+WN();WN()"])
        else {
            panic!()
        };
        assert_eq!(c.wic.candidates().len(), 2);
        let (msg, usage) = refusal(&["select", "x.csv", "--candidates", " ; "]);
        assert_eq!(
            msg,
            "invalid --candidates \" ; \": give models separated by ';', e.g. \
             \"AR1()+WN();2*AR1()+WN()\""
        );
        assert!(!usage);
    }

    #[test]
    fn calibrate_flags_give_the_calibration_and_the_files() {
        let Config::Calibrate(c) = config(&[
            "calibrate",
            "imu.csv",
            "--gyro-unit",
            "deg/s",
            "--kalibr",
            "k.yaml",
            "--export",
            "px4",
            "p.sdf",
            "--export",
            "openvins",
            "o.yaml",
            "--inflate",
            "2",
            "--axis-policy",
            "per-axis",
            "--rule",
            "wic-minimum",
            "--eff",
            "0.7",
            "--json",
            "-",
        ]) else {
            panic!()
        };
        assert_eq!(
            c.options,
            CalibrationOptions {
                rule: SelectionRule::WicMinimum,
                gyro_unit: Some("deg/s".parse().unwrap()),
                robust_check: Some(RobustOptions::new(0.7, RobustConvention::Exact).unwrap()),
                ..CalibrationOptions::default()
            }
        );
        assert_eq!(
            c.exports,
            [
                (ExportFormat::KALIBR, PathBuf::from("k.yaml")),
                (ExportFormat::PX4, PathBuf::from("p.sdf")),
                (ExportFormat::OPENVINS, PathBuf::from("o.yaml")),
            ]
        );
        assert_eq!(c.adjustment, Adjustment::Inflate(2.0));
        assert_eq!(c.policy, AxisPolicy::PerAxis);
        assert_eq!(c.json.as_deref(), Some(Path::new("-")));
        let Config::Calibrate(c) = config(&["calibrate", "imu.csv", "--conservative"]) else {
            panic!()
        };
        assert_eq!(c.adjustment, Adjustment::Conservative);
        assert_eq!(c.policy, AxisPolicy::Worst);
        assert_eq!(
            refusal(&["calibrate", "imu.csv", "--export", "rovio", "x.yaml"]),
            (
                "invalid --export rovio: one of kalibr, openvins, vins, orbslam3, px4".into(),
                true
            )
        );
    }

    #[test]
    fn several_files_a_folder_or_a_batch_flag_give_a_batch() {
        let batch = |argv: &[&str]| match config(argv) {
            Config::Batch(b) => b,
            c => panic!("{argv:?}: {c:?}"),
        };
        let b = batch(&[
            "calibrate",
            "a.csv",
            "b.csv",
            "--json",
            "-",
            "--report",
            "r.html",
        ]);
        assert_eq!(b.inputs, [PathBuf::from("a.csv"), PathBuf::from("b.csv")]);
        assert!(!b.force && b.out_dir.is_none());
        let BatchJob::Calibrate { config: c, json } = b.job else {
            panic!()
        };
        assert_eq!(json.as_deref(), Some(Path::new("-")));
        assert_eq!(c.json, None);
        assert_eq!(c.report.as_deref(), Some(Path::new("r.html")));
        let dir = std::env::temp_dir();
        let b = batch(&["wv", dir.to_str().unwrap(), "--json"]);
        assert!(matches!(b.job, BatchJob::Wv { json: true, .. }));
        let b = batch(&["wv", "a.csv", "--out-dir", "out", "--force"]);
        assert_eq!((b.out_dir, b.force), (Some(PathBuf::from("out")), true));
        assert!(matches!(
            batch(&["wv", "no-such-dir/*.csv"]).job,
            BatchJob::Wv { json: false, .. }
        ));
        // one plain file is the single-recording command
        assert!(matches!(config(&["wv", "a.csv"]), Config::Wv(_)));
        assert!(matches!(
            config(&["calibrate", "a.csv", "--json", "-"]),
            Config::Calibrate(_)
        ));
        for (argv, needle) in [
            (
                &["calibrate", "a.csv", "b.csv", "--kalibr", "k/imu.yaml"][..],
                "invalid --kalibr k/imu.yaml: in batch mode",
            ),
            (
                &["calibrate", "a.csv", "b.csv", "--export", "px4", "/x.sdf"],
                "invalid --export px4 /x.sdf: in batch mode",
            ),
            (
                &["calibrate", "a.csv", "--force", "--report", "../r.html"],
                "invalid --report ../r.html: in batch mode",
            ),
            (
                &["wv", "a.csv", "b.csv", "--csv"],
                "--csv is for one recording",
            ),
        ] {
            let (msg, usage) = refusal(argv);
            assert!(msg.starts_with(needle) && usage, "{argv:?}: {msg}");
        }
    }

    #[test]
    fn report_names_its_file_once() {
        assert_eq!(
            refusal(&["report", "imu.csv", "-o", "a.html", "--report", "b.html"]),
            (
                "give the report's file once: -o a.html or --report b.html".into(),
                true
            )
        );
        for (argv, file) in [
            (&["report", "data/imu.csv.gz"][..], "imu.report.html"),
            (&["report", "run.bag", "--report", "r.html"], "r.html"),
            (&["report", "rosbag2_x/", "-o", "o.html"], "o.html"),
            (&["report", "rosbag2_x/"], "rosbag2_x.report.html"),
        ] {
            let Config::Report(c) = config(argv) else {
                panic!()
            };
            assert_eq!(c.output, PathBuf::from(file), "{argv:?}");
        }
    }

    #[test]
    fn plot_refuses_what_a_figure_cannot_honour() {
        for (argv, msg) in [
            (
                &["plot", "wv", "x.csv", "-o", "f.jpg"][..],
                "invalid --output ",
            ),
            (
                &["plot", "avar", "x.csv", "--csv", "-o", "f.svg"],
                "gmwm plot draws a figure: --json and --csv belong to gmwm wv|avar|fit|select",
            ),
            (
                &["plot", "ieee", "x.csv", "--kind", "modified", "-o", "f.svg"],
                "gmwm plot ieee reads the overlapping Allan variance (IEEE Std 952): drop --kind",
            ),
            (
                &[
                    "plot",
                    "fit",
                    "x.csv",
                    "--model",
                    "WN()",
                    "--inference",
                    "-o",
                    "f.svg",
                ],
                "gmwm plot fit draws the fit: --inference belongs to gmwm fit",
            ),
            (
                &[
                    "plot",
                    "select",
                    "x.csv",
                    "--model",
                    "WN()",
                    "--overlay",
                    "-o",
                    "f.svg",
                ],
                "--overlay lays out the axes of gmwm plot wv and avar; this figure has one \
                 panel per column",
            ),
            (
                &["plot", "wv", "x.csv", "--width", "30000", "-o", "f.svg"],
                "invalid --width/--height: at most 20000 px a side",
            ),
            (
                &[
                    "plot", "wv", "x.csv", "--width", "10000", "--height", "10000", "-o", "f.svg",
                ],
                "invalid --width 10000 --height 10000: at most 40 megapixels",
            ),
        ] {
            let (text, usage) = refusal(argv);
            assert!(text.starts_with(msg) && usage, "{argv:?}: {text}");
        }
        // the figure's checks come before the data flags'
        assert!(refusal(&[
            "plot",
            "fit",
            "x",
            "--model",
            "AR1(",
            "--inference",
            "-o",
            "f.svg"
        ])
        .0
        .contains("--inference"));
    }

    #[test]
    fn plot_flags_give_the_figure_and_its_data() {
        let Config::Plot(c) = config(&[
            "plot",
            "wv",
            "x.csv",
            "--overlay",
            "--width",
            "800",
            "-o",
            "f.PNG",
        ]) else {
            panic!()
        };
        assert_eq!(
            c.figure,
            FigureConfig {
                output: "f.PNG".into(),
                layout: Layout::Overlay,
                width: Some(800),
                height: None,
            }
        );
        assert!(matches!(c.kind, PlotKind::Wv(_)));
        let Config::Plot(c) = config(&[
            "plot", "compare", "x.csv", "--eff", "0.7", "--robust", "-o", "f.svg",
        ]) else {
            panic!()
        };
        assert_eq!(c.figure.layout, Layout::Grid);
        let PlotKind::Compare(k) = c.kind else {
            panic!()
        };
        assert_eq!(k.classical, WvOptions::default());
        assert_eq!(
            k.robust,
            WvOptions {
                robust: Some(RobustOptions::new(0.7, RobustConvention::Exact).unwrap()),
                ..WvOptions::default()
            }
        );
    }

    #[test]
    fn model_commands_parse_their_model() {
        let Config::Simulate(c) = config(&[
            "simulate",
            "--model",
            "WN(sigma2=1)",
            "--n",
            "10",
            "--freq",
            "100",
            "--components",
        ]) else {
            panic!()
        };
        assert_eq!(c.model, "WN(sigma2=1)".parse::<Model>().unwrap());
        assert_eq!((c.n, c.freq_hz, c.seed, c.components), (10, 100.0, 0, true));
        let Config::Implied(c) = config(&["implied", "--model", "WN(sigma2=2)", "--levels", "4"])
        else {
            panic!()
        };
        assert_eq!((c.levels, c.freq_hz, c.json), (4, 1.0, false));
        let (msg, usage) = refusal(&["implied", "--model", "XX()", "--levels", "4"]);
        assert!(msg.contains("XX") && !usage, "{msg}");
        let Command::Simulate(mut args) =
            parse(&["simulate", "--model", "WN(sigma2=1)", "--n", "1"])
        else {
            panic!()
        };
        args.n = 0;
        assert_eq!(
            SimulateConfig::try_from(&args).unwrap_err().to_string(),
            "invalid --n 0: simulate at least one sample"
        );
    }

    #[test]
    fn several_recordings_are_one_configuration() {
        let Config::PooledFit(c) = config(&[
            "fit", "a.csv", "b.csv", "--pool", "--model", "WN()", "--seed", "4",
        ]) else {
            panic!()
        };
        assert_eq!(c.files, [PathBuf::from("a.csv"), PathBuf::from("b.csv")]);
        assert_eq!(
            (c.seed, c.fit.input.file.as_path()),
            (4, Path::new("a.csv"))
        );
        let Config::PooledSelect(c) = config(&[
            "select",
            "a.csv",
            "b.csv",
            "--pool",
            "--model",
            "AR1(phi=0.5, sigma2=1)",
            "--G",
            "5",
        ]) else {
            panic!()
        };
        assert_eq!(c.gmwm.model(), &"AR1()".parse::<Model>().unwrap());
        assert_eq!(c.files.len(), 2);
        let (msg, usage) = refusal(&[
            "select",
            "a.csv",
            "b.csv",
            "--pool",
            "--candidates",
            "WN();RW()",
        ]);
        assert!(
            msg.starts_with("--pool selects among the sub-models") && usage,
            "{msg}"
        );
        let Config::SameModel(c) = config(&[
            "same-model",
            "a.csv",
            "b.csv",
            "--model",
            "WN()",
            "--columns",
            "gyro_x,2",
            "--freq",
            "100",
            "--levels",
            "5",
            "--bootstrap",
            "20",
        ]) else {
            panic!()
        };
        assert_eq!(c.input.file, PathBuf::from("a.csv"));
        assert_eq!(
            c.input.read,
            ReadOptions {
                columns: vec![
                    ColumnSelector::Name("gyro_x".into()),
                    ColumnSelector::Index(2)
                ],
                freq_hz: Some(100.0),
                ..ReadOptions::default()
            }
        );
        assert_eq!((c.wv.levels, c.test.bootstrap), (Some(5), Some(20)));
        for (argv, text, usage) in [
            (
                &["same-model", "a.csv", "--model", "WN()"][..],
                "a.csv: the same-model test needs at least two recordings (FILEs); got one",
                false,
            ),
            (
                &[
                    "same-model",
                    "a.csv",
                    "b.csv",
                    "--model",
                    "WN()",
                    "--bootstrap",
                    "0",
                ],
                "invalid --bootstrap 0: at least 1 replicate",
                true,
            ),
            (
                &[
                    "same-model",
                    "a.csv",
                    "b.csv",
                    "--model",
                    "WN()",
                    "--freq",
                    "0",
                ],
                "invalid --freq 0: must be a positive number of hertz",
                true,
            ),
        ] {
            assert_eq!(refusal(argv), (text.to_string(), usage), "{argv:?}");
        }
    }

    #[test]
    fn output_flags_give_the_style() {
        let style = |argv: &[&str]| match config(argv) {
            Config::Avar(c) => c.output,
            _ => unreachable!(),
        };
        assert_eq!(style(&["avar", "x"]), Style::Table);
        assert_eq!(style(&["avar", "x", "--json"]), Style::Json);
        assert_eq!(style(&["avar", "x", "--csv"]), Style::Csv);
    }
}

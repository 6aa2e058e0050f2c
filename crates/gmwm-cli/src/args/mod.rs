//! Raw command-line arguments: the clap definition only (derive structs, value enums, and the
//! value parsers that refuse a value outside its domain with a usage error). `config.rs` turns
//! them into one validated configuration per subcommand, in `main`, before any file is read.

mod several;
mod values;

pub use several::{Against, MonitorArgs, SameModelArgs, SharedArgs};

use clap::{Args, Parser, Subcommand};
use gmwm::{
    AllanKind, AvConvention, AxisPolicy, CovarianceMethod, GapPolicy, HeaderMode, InputFormat,
    OptimismConvention, OptimismMethod, RobustConvention, SelectionRule, TimePolicy, TimeUnit,
    Transform, Weighting,
};
use std::path::PathBuf;
use values::{
    alpha, at_least_1, at_least_2, augment, choice, datasheet, efficiency, horizon_seconds,
    inflation, positive_hz, seed, signal_unit, tolerance, whole, window_count,
};

const EXAMPLES: &str = "\
Examples:
  gmwm demo                                   simulate the built-in sensor and show its WV
  gmwm wv imu.csv.gz                          wavelet variance of every column
  gmwm wv imu.csv.gz --columns gyro_x,3 --robust --eff 0.6 --json
  gmwm avar imu.csv.gz --kind modified --csv
  gmwm wv log.bin --format f64 --ncols 6 --columns 1 --freq 400
  gmwm wv ln200.bin --format ln200 --columns gyro_x
  gmwm wv euroc_imu0.csv                      time column and units from the EuRoC header
  gmwm select imu.csv.gz --model \"3*AR1()+WN()+RW()+QN()+DR()\"
  gmwm calibrate imu.csv.gz --gyro-unit deg/s --accel-unit g --kalibr imu.yaml
  gmwm fit run1.csv run2.csv run3.csv --pool --model \"2*AR1()+RW()\"   one model, three recordings
  gmwm same-model run*.csv --model \"2*AR1()+RW()\" --columns gyro_x   do they share one model?
  gmwm shared imu.csv.gz --shared \"GM()\" --model \"WN()+RW()\" --columns gyro_x,gyro_y,gyro_z
  gmwm monitor day.csv.gz --model-from cal/day.calibration.json    flag windows off the model";

/// Stochastic error calibration of inertial sensors with the Generalized Method of Wavelet
/// Moments: wavelet, Allan and Hadamard variances of IMU recordings.
#[derive(Debug, Parser)]
#[command(name = "gmwm", version, about, after_long_help = EXAMPLES)]
pub struct Cli {
    /// No progress bars or notes on standard error (warnings and errors still show).
    ///
    /// Notes say what the reader found (time column, columns left out, samples) and which files
    /// were written; standard output is the same with or without --quiet. Without it, progress
    /// bars show on a terminal, except with TERM=dumb; NO_COLOR or TERM=dumb turn colour off.
    #[arg(short, long, global = true, display_order = 10_000)]
    pub quiet: bool,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate the built-in sensor (known truth) and print its wavelet variance.
    #[command(
        allow_negative_numbers = true,
        after_long_help = "Examples:\n  gmwm demo\n  gmwm demo --n 100000 --seed 7 --json"
    )]
    Demo(DemoArgs),
    /// Wavelet variance (classical or robust) with confidence intervals, per column.
    #[command(
        allow_negative_numbers = true,
        after_long_help = WV_EXAMPLES
    )]
    Wv(WvCommand),
    /// Allan, modified Allan or Hadamard variance with confidence intervals, per column.
    #[command(
        allow_negative_numbers = true,
        after_long_help = "Examples:\n  gmwm avar imu.csv.gz\n  gmwm avar imu.csv.gz --kind non-overlapping --columns accel_z\n  gmwm avar imu.csv.gz --kind hadamard --json"
    )]
    Avar(AvarArgs),
    /// Simulate a fully specified error model (seeded; CSV on stdout or to a file).
    #[command(
        allow_negative_numbers = true,
        after_long_help = "Examples:\n  gmwm simulate --model \"AR1(phi=0.99, sigma2=0.01)+WN(sigma2=1)\" --n 100000 --seed 1 -o sim.csv.gz\n  gmwm simulate --model \"GM(beta=0.25, sigma2_gm=7e-9)+WN(sigma2=7e-7)\" --freq 250 --n 1000 --components"
    )]
    Simulate(SimulateArgs),
    /// Implied (theoretical) wavelet variance of a fully specified model and of each process.
    #[command(
        allow_negative_numbers = true,
        after_long_help = "Examples:\n  gmwm implied --model \"3*AR1(phi=0.9, sigma2=1)+WN(sigma2=2)\" --levels 10\n  gmwm implied --model \"GM(beta=0.25, sigma2_gm=7.08e-9)+RW(gamma2=3.9e-14)\" --levels 20 --freq 250 --json"
    )]
    Implied(ImpliedArgs),
    /// How long to record: the predicted interval half-widths of N, B, K and each correlation
    /// time for recordings from minutes to days, from a model, a datasheet or a calibration,
    /// and the length a target needs (docs/methods.md §18).
    #[command(allow_negative_numbers = true, after_long_help = PLAN_EXAMPLES)]
    Plan(PlanArgs),
    /// Estimate a latent error model by GMWM on each selected column (docs/methods.md §5), from a
    /// recording or from a wavelet variance saved by `gmwm wv --json`.
    #[command(
        allow_negative_numbers = true,
        after_long_help = "FILE may also be the JSON of `gmwm wv --json` (or any JSON with series[].{name, n, tau, wv, ci_low, ci_high} and a top-level freq_hz or --freq): the WV is fitted without recomputing it.\n\nExamples:\n  gmwm fit imu.csv.gz --model \"3*GM()+WN()+QN()+RW()\" --columns gyro_x\n  gmwm fit imu.csv.gz --model \"AR1(phi=0.99, sigma2=1e-6)+WN(sigma2=1e-4)\" --json\n  gmwm fit sim.csv.gz --model \"AR1()+WN()+RW()\" --robust --eff 0.6 --G 20000 --seed 7\n  gmwm wv imu.csv.gz --json > wv.json && gmwm fit wv.json --model \"2*GM()+WN()+RW()\"\n  gmwm fit imu.csv.gz --model \"GM()+WN()+RW()\" --weights bootstrap\n  gmwm fit imu.csv.gz --columns gyro_x --model \"2*GM()+WN()+RW()\" --inference --json\n  gmwm fit sim.csv --model \"AR1()+WN()\" --inference --bootstrap 200\n  gmwm fit imu.csv.gz --columns gyro_x --model \"GM()+WN()+RW()\" --augment acf:3   GMWM+ beside GMWM\n  gmwm fit a.csv b.csv c.csv --pool --model \"AR1()+WN()+RW()\" --inference   one model for all three\n  gmwm fit t5.csv t15.csv t25.csv t35.csv --covariate-values 5,15,25,35 --model \"GM()+WN()\"   parameters as functions of temperature\n  gmwm fit a.csv b.csv c.csv --covariate temperature --model \"GM()+WN()\" --depends variances=quadratic --at 0,40 --json\n  gmwm fit ramp.csv --covariate temperature --windows 12 --model \"GM()+WN()+RW()\"   one recording whose temperature drifts\n  gmwm fit run.mcap --covariate temperature --windows 8 --model \"WN()+RW()\"   a ROS bag with a sensor_msgs/Temperature topic\n  gmwm fit drive.mcap --covariate angular_rate --dynamic --model \"AR1()+WN()\"   rho_t following the dynamics (paper IV-B)"
    )]
    Fit(FitArgs),
    /// Select a model by the Wavelet Information Criterion on each selected column (docs/methods.md
    /// §8).
    #[command(allow_negative_numbers = true, after_long_help = SELECT_EXAMPLES)]
    Select(SelectArgs),
    /// Calibrate an IMU recording: per axis the WV, the model selected by WIC, its fit with
    /// intervals, the noise density, bias instability and random walk in SI and datasheet
    /// units, the IEEE 952 read-off, and navigation-filter files (Kalibr, OpenVINS, ...).
    #[command(allow_negative_numbers = true, after_long_help = CALIBRATE_EXAMPLES)]
    Calibrate(CalibrateCommand),
    /// Draw a figure (SVG or PNG, by the file name): wavelet or Allan variances, classical
    /// against robust, a fit with its decomposition, a model selection, the IEEE read-off.
    #[command(after_long_help = PLOT_EXAMPLES)]
    Plot(PlotArgs),
    /// Calibrate a recording (as `gmwm calibrate`) and write one self-contained HTML report:
    /// the recording, every figure, the selection, the estimates, the IEEE read-off, the
    /// filter files, the contamination check.
    #[command(allow_negative_numbers = true, after_long_help = REPORT_EXAMPLES)]
    Report(ReportArgs),
    /// List the topics of a ROS recording (ROS1 bag, MCAP, rosbag2 sqlite3) and mark the
    /// sensor_msgs/Imu topics.
    #[command(after_long_help = TOPICS_EXAMPLES)]
    Topics(TopicsArgs),
    /// Test whether several recordings (or axes, or sensors) are generated by the same model
    /// (docs/methods.md §7.7): statistic, chi-square and bootstrap p-values, per-scale
    /// contributions.
    #[command(after_long_help = several::SAME_MODEL_EXAMPLES)]
    SameModel(SameModelArgs),
    /// Fit a latent process shared by several axes (x_i = V + U_i, paper §IV-A) from their
    /// wavelet variances and cross-covariances, with intervals and a test of "no shared
    /// process" (docs/methods.md §15).
    #[command(allow_negative_numbers = true, after_long_help = several::SHARED_EXAMPLES)]
    Shared(SharedArgs),
    /// Flag the windows of a long recording whose robust wavelet variance leaves the band of a
    /// calibrated model (paper §IV-C, docs/methods.md §16), with their times.
    #[command(allow_negative_numbers = true, after_long_help = several::MONITOR_EXAMPLES)]
    Monitor(MonitorArgs),
}

const CALIBRATE_EXAMPLES: &str = "\
Record the IMU at rest, warmed up, for at least a few hours: the longest scale the WV sees is
about a quarter of the recording, and the bias instability and random walk live there.

Many recordings (batch mode: several FILEs, a folder, a quoted glob, or --out-dir/--force):
each is calibrated, in parallel, into <stem>.calibration.json (the document of --json FILE;
<stem> is the file name without its data extensions) in --out-dir or beside it; --kalibr,
--export and --report then name suffixes: --kalibr imu.yaml writes <stem>.imu.yaml, --report
report.html writes <stem>.report.html. A recording whose outputs are all newer than it (and
its sidecar) is skipped as up to date, --force redoes it; outputs are written atomically.
One table at the end (--json - for JSON); exit code 1 if any recording failed.

Examples:
  gmwm calibrate imu.csv.gz --gyro-unit deg/s --accel-unit g
  gmwm calibrate imu.csv.gz --kalibr imu.yaml --json calib.json
  gmwm calibrate imu.csv.gz --datasheet \"N=2 deg/sqrt(h), B=25.2 deg/h, N=0.2 m/s/sqrt(h), B=0.2 mg\"
      each axis against its datasheet: ratio measured/datasheet, inside/above/below
  gmwm calibrate flight.bag --topic /imu0 --kalibr imu.yaml --conservative
  gmwm calibrate run.mcap --export openvins kalibr_imu_chain.yaml --export px4 imu.sdf
  gmwm calibrate log.bin --format ln200 --axis-policy per-axis --kalibr imu.yaml
  gmwm calibrate imu.csv.gz --model \"2*AR1()+WN()+RW()\" --inflate 2 --export vins vins.yaml
  gmwm calibrate imu.csv.gz --horizon 600 --kalibr imu.yaml
      a white noise + random walk that bounds the sensor's model over a 10-minute mission
  gmwm calibrate imu.csv.gz --audit 50 --json calib.json
      how far to trust each number: 50 simulated recordings of the model, each recalibrated
  gmwm calibrate runs/ --out-dir calib/ --kalibr imu.yaml      every recording in runs/
  gmwm calibrate 'runs/*.csv.gz' a.bag --json summary.json      a glob (quoted) and a file
  gmwm calibrate imu1.csv.gz imu2.csv.gz imu3.csv.gz --pool --kalibr imu.yaml
      one calibration of three recordings of one sensor (their pooled wavelet variance)
  gmwm calibrate warmup.mcap --covariate temperature --at 5 --kalibr imu.yaml
      N, B, K against the bag's sensor_msgs/Temperature topic; the filter file at 5 degC
  gmwm calibrate ramp.csv --covariate temperature --over 0:40 --report r.html
      the worst case over 0..40 degC of a recording whose temperature column drifts";

const WV_EXAMPLES: &str = "\
Many recordings (batch mode: several FILEs, a folder, a quoted glob, or --out-dir/--force):
each one's wavelet variance is written, in parallel, to <stem>.wv.json (the document of
--json; <stem> is the file name without its data extensions) in --out-dir or beside it; a
recording whose output is newer than it (and its sidecar) is skipped as up to date, --force
redoes it. One table at the end (--json for JSON); exit code 1 if any recording failed.

Examples:
  gmwm wv imu.csv.gz
  gmwm wv imu.csv.gz --columns gyro_x --robust --eff 0.6
  gmwm wv imu.csv.gz --transform dwt --filter la8 --levels 6 --csv
  gmwm wv log.f64 --format f64 --ncols 3 --freq 200 --json
  gmwm wv runs/ --out-dir wv/                   every recording in runs/
  gmwm wv 'runs/*.csv.gz' --robust --json       a quoted glob; the summary as JSON";

/// `gmwm calibrate`: the calibration's flags and the batch flags.
#[derive(Debug, Args)]
pub struct CalibrateCommand {
    /// The calibration.
    #[command(flatten)]
    pub args: CalibrateArgs,
    /// More recordings.
    #[command(flatten)]
    pub batch: BatchArgs,
    /// One calibration of all the recordings given (files, folders, globs): one model for the
    /// sensor, fitted to their pooled wavelet variances (docs/methods.md §5.12), instead of
    /// one calibration each.
    #[arg(long)]
    pub pool: bool,
}

/// `gmwm wv`: the wavelet-variance flags and the batch flags.
#[derive(Debug, Args)]
pub struct WvCommand {
    /// The wavelet variance.
    #[command(flatten)]
    pub args: WvArgs,
    /// More recordings.
    #[command(flatten)]
    pub batch: BatchArgs,
}

/// What makes `gmwm calibrate` and `gmwm wv` run over many recordings.
const BATCH_HELP: &str = "\
More recordings: batch mode. Each FILE may be a recording, a folder (every recording directly
inside it, by name: .csv .tsv .txt (also .gz), .bag .mcap .db3, .f64 .f32 (.f64le .f32le),
.bin .dat .raw with a JSON sidecar or --format, and rosbag2 folders; sidecars and gmwm's
outputs are skipped) or a quoted glob expanded by gmwm ('runs/*.csv.gz', the same choice
among its matches). A folder holding metadata.yaml is one rosbag2 recording.";

/// Batch mode: several recordings, folders or globs.
#[derive(Debug, Args)]
pub struct BatchArgs {
    /// More recordings, folders of recordings or quoted globs (batch mode).
    #[arg(value_name = "FILE", long_help = BATCH_HELP)]
    pub more: Vec<PathBuf>,
    /// Batch mode: write each recording's outputs to DIR (created if missing)
    /// [default: beside each recording].
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Batch mode: redo recordings whose outputs are up to date.
    #[arg(long)]
    pub force: bool,
}

/// `gmwm calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// Units of the samples.
    #[command(flatten)]
    pub units: UnitArgs,
    /// The sensor's datasheet.
    #[command(flatten)]
    pub datasheet: DatasheetArgs,
    /// Full model: every sub-model is a candidate of the WIC selection
    /// [default: 3*AR1()+WN()+QN()+RW()+DR()].
    #[arg(long, value_name = "MODEL")]
    pub model: Option<String>,
    /// How the selected model is chosen among the canonical models within one standard error
    /// of the WIC minimum.
    #[arg(long, value_parser = choice::<SelectionRule>(), default_value_t = SelectionRule::Navigation)]
    pub rule: SelectionRule,
    /// Wavelet-variance settings.
    #[command(flatten)]
    pub estimator: WvEstimatorArgs,
    /// Bootstrap replicates of a simulated WV covariance V (see --covariance).
    #[arg(long, value_name = "B", default_value_t = 50, value_parser = at_least_2)]
    pub bootstrap: usize,
    /// How V, the covariance of the WV behind the WIC and every interval, is obtained: exact
    /// from the model (no simulation, any length) when it has only WN, QN, RW, DR, AR1/GM,
    /// MA1 or ARMA11 terms, else simulated (auto); always exact; or simulated as the R package.
    #[arg(long, value_parser = choice::<CovarianceMethod>(), default_value_t = CovarianceMethod::Auto)]
    pub covariance: CovarianceMethod,
    /// Number of starting-value draws of every fit [default: 20000 for N <= 1e4, else 100000,
    /// with early stop].
    #[arg(long = "G", value_name = "N", value_parser = at_least_1)]
    pub draws: Option<usize>,
    /// Seed of every search and simulation.
    #[arg(long, value_name = "S", default_value_t = 1337, value_parser = seed)]
    pub seed: u64,
    /// Write everything as JSON to FILE ('-' for standard output, replacing the summary).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write a Kalibr imu.yaml (noise densities and random walks, continuous-time SI).
    #[arg(long, value_name = "FILE")]
    pub kalibr: Option<PathBuf>,
    /// Write a navigation stack's file (the stacks of `ExportFormat::ALL`); repeatable.
    #[arg(
        long,
        num_args = 2,
        value_names = ["STACK", "FILE"],
        action = clap::ArgAction::Append,
        help = export_help()
    )]
    pub export: Vec<String>,
    /// Which axis speaks for a sensor triad in the exported files.
    #[arg(long, value_parser = choice::<AxisPolicy>(), default_value_t = AxisPolicy::Worst)]
    pub axis_policy: AxisPolicy,
    /// Multiply the exported noise densities and random walks by K (stated in the file; cruder
    /// than --horizon, which computes the factors from the model).
    #[arg(long, value_name = "K", value_parser = inflation, conflicts_with = "conservative")]
    pub inflate: Option<f64>,
    /// Export the upper ends of the intervals instead of the estimates (stated in the file;
    /// cruder than --horizon: it covers the estimation error, not the terms a white noise and a
    /// random walk leave out).
    #[arg(long)]
    pub conservative: bool,
    /// Mission length T in seconds (a flight, a drive): export per axis the white noise and
    /// random walk with the least inflation whose Allan variance (1/f to T) and integrated-error
    /// variance (angle or velocity, up to T) are at least the fitted model's; the table and
    /// JSON give the pair and its inflation over the estimates.
    #[arg(long, value_name = "T", value_parser = horizon_seconds, conflicts_with_all = ["conservative", "inflate"])]
    pub horizon: Option<f64>,
    /// Self-audit: simulate each axis' identified model R times at the recording's length and
    /// rate, calibrate every replicate, and report per exported number its bias, spread and
    /// interval coverage, the IEEE read-off's beside it, and how often the same model is
    /// selected [default: 0; 8 with --report].
    #[arg(long, value_name = "R")]
    pub audit: Option<usize>,
    /// The verdict's tolerance: a scale is explained when the model's WV is inside the band or
    /// within this fraction of the empirical WV (0.1 = 10%).
    #[arg(long, value_name = "FRACTION", default_value_t = gmwm::DEFAULT_TOLERANCE, value_parser = tolerance)]
    pub tolerance: f64,
    /// Apply --gyro-unit/--accel-unit to a ROS recording too (sensor_msgs/Imu is SI by
    /// definition, so they are refused there without this).
    #[arg(long)]
    pub force_units: bool,
    /// rostopic written to Kalibr/OpenVINS files [default: the ROS topic read, else /imu0].
    #[arg(long, value_name = "TOPIC")]
    pub rostopic: Option<String>,
    /// Also write the HTML report (as `gmwm report`) to FILE.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Calibrate against a covariate (docs/methods.md §5.14): each axis' identified model is
    /// fitted over windows of the recording with its variances depending on COL, and N, B, K
    /// are reported as curves against it. COL is a column (e.g. temperature), or of a ROS
    /// recording a topic (sensor_msgs/Temperature, ...; `temperature` finds the only one)
    /// interpolated to the IMU messages, or angular_rate / specific_force.
    #[arg(long, value_name = "COL")]
    pub covariate: Option<String>,
    /// GMWM+ (docs/methods.md §5.15) of each axis' identified model: the WV stacked with
    /// extra moments of the samples' first differences, `mean` (a DR term's slope), `acf:K`
    /// (their autocovariances at lags 1..K) or both; reported beside the calibration's
    /// estimates with intervals and a J-test (the exports stay the calibration's).
    #[arg(long, value_name = "LIST", value_parser = augment)]
    pub augment: Option<gmwm::Augment>,
    /// With --covariate: cut the recording into K windows of equal length, each at its mean
    /// level [default: 8, at most 64].
    #[arg(long, value_name = "K", value_parser = window_count, requires = "covariate")]
    pub windows: Option<usize>,
    /// With --covariate: export (and report as the axes' N, B, K) the values at covariate
    /// value X, e.g. --at 5 for 5 degC [default: the estimates of the whole recording].
    #[arg(
        long,
        value_name = "X",
        requires = "covariate",
        conflicts_with = "over",
        allow_hyphen_values = true
    )]
    pub at: Option<f64>,
    /// With --covariate: export the worst case over covariate values LO:HI, each of N, B, K
    /// at its largest (e.g. --over 0:40 for a filter that must hold from 0 to 40 degC).
    #[arg(
        long,
        value_name = "LO:HI",
        requires = "covariate",
        allow_hyphen_values = true
    )]
    pub over: Option<String>,
}

/// `--gyro-unit`, `--accel-unit`: the unit of the samples, as `gmwm calibrate` and
/// `gmwm plot` take it.
#[derive(Debug, Clone, Copy, Args)]
pub struct UnitArgs {
    /// Unit of the gyroscope samples: rad/s, deg/s or deg/h [default: the sidecar's, SI for
    /// ROS and binary IMU records].
    #[arg(long, value_name = "UNIT", value_parser = signal_unit)]
    pub gyro_unit: Option<gmwm::SignalUnit>,
    /// Unit of the accelerometer samples: m/s^2, g or mg [default: the sidecar's, SI for ROS
    /// and binary IMU records].
    #[arg(long, value_name = "UNIT", value_parser = signal_unit)]
    pub accel_unit: Option<gmwm::SignalUnit>,
}

/// What `--datasheet` takes, for `--help`.
const DATASHEET_HELP: &str = "\
The sensor's datasheet values, compared with the measured ones (calibrate, report) or drawn as
dashed grey lines (plot avar, ieee, wv, fit, compare, select): KEY=VALUE UNIT items separated by commas.
Keys: N white-noise density (angle / velocity random walk), B bias instability, K rate /
acceleration random walk. The unit says the sensor: an angle is a gyroscope, a length or g an
accelerometer, and its dimension must be the key's:
  gyroscope      N deg/sqrt(h), deg/h/sqrt(Hz), deg/s/sqrt(Hz), rad/s/sqrt(Hz)
                 B deg/h, deg/s, rad/s          K deg/h/sqrt(h), rad/s^2/sqrt(Hz)
  accelerometer  N m/s/sqrt(h), ug/sqrt(Hz), m/s^2/sqrt(Hz)
                 B mg, ug, m/s^2                K m/s/h/sqrt(h), m/s^3/sqrt(Hz)
(° and √ are accepted for deg and sqrt). B is IEEE Std 952's bias instability, the Allan
deviation's minimum / 0.664: a datasheet quoting the minimum itself as in-run bias stability
compares as B = value / 0.664. Both sensors may be given in one flag; an optional
gyro: or accel: prefix is checked against the unit. Each line is drawn on the axes of its sensor
in the figure's unit, which needs the unit of the samples (sidecar or --gyro-unit/--accel-unit).
Example (ADIS16405):
  --datasheet \"N=2 deg/sqrt(h), B=25.2 deg/h, N=0.2 m/s/sqrt(h), B=0.2 mg\"";

/// `--datasheet`.
#[derive(Debug, Clone, Args)]
pub struct DatasheetArgs {
    /// The sensor's datasheet, e.g. "N=2 deg/sqrt(h), B=25 deg/h, accel:B=0.2 mg" (keys N, B,
    /// K; the unit says the sensor).
    #[arg(long, value_name = "SPEC", value_parser = datasheet, long_help = DATASHEET_HELP)]
    pub datasheet: Option<gmwm::Datasheet>,
}

const REPORT_EXAMPLES: &str = "\
The page is one file: figures are embedded, nothing is fetched, it prints one axis per page.
Its numbers are those of `gmwm calibrate --json`, which the page also carries verbatim.

Examples:
  gmwm report imu.csv.gz                       writes imu.report.html
  gmwm report imu.csv.gz -o acceptance.html --gyro-unit deg/s --accel-unit g
  gmwm report flight.bag --topic /imu0 --kalibr imu.yaml -o report.html
  gmwm calibrate imu.csv.gz --report report.html --json calib.json";

/// `gmwm report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The calibration's flags, as `gmwm calibrate`.
    #[command(flatten)]
    pub calibrate: CalibrateArgs,
    /// The HTML file to write [default: the recording's name with .report.html, in the current
    /// folder].
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
}

const PLOT_EXAMPLES: &str = "\
FIGURE is written as SVG or PNG by its extension. Each figure takes the data and model flags of
the matching command (gmwm wv, avar, fit, select); scales are in seconds, the WV's (2^j / f) or
the Allan cluster time (m / f), as each axis says.

Examples:
  gmwm plot wv imu.csv.gz -o wv.svg                    grid: gyroscope / accelerometer x axes
  gmwm plot wv imu.csv.gz --overlay -o wv.png          one panel per sensor, axes overlaid
  gmwm plot avar imu.csv.gz --columns gyro_x -o adev.png
  gmwm plot compare cont.csv.gz --eff 0.6 -o robust.svg   classical against robust WV
  gmwm plot fit imu.csv.gz --columns gyro_x --model \"2*AR1()+WN()+RW()\" -o fit.svg
  gmwm plot select imu.csv.gz --columns gyro_x --model \"2*AR1()+WN()+RW()+QN()\" -o select.png
  gmwm plot ieee imu.csv.gz --columns gyro_x -o ieee.svg
  gmwm plot psd imu.csv.gz --columns gyro_x,gyro_y -o psd.png   √PSD (Welch): vibration, filter
  gmwm plot ieee imu.csv.gz --gyro-unit deg/s --datasheet \"N=2 deg/sqrt(h), B=25 deg/h\" -o ieee.png
      the datasheet's N line, B floor and K line (dashed grey) on the gyroscope axes";

/// `gmwm plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// The figure.
    #[command(subcommand)]
    pub figure: PlotCommand,
}

/// The figures of `gmwm plot`.
#[derive(Debug, Subcommand)]
pub enum PlotCommand {
    /// Wavelet variances with their intervals (paper Fig. 1).
    #[command(allow_negative_numbers = true)]
    Wv {
        /// Data and estimator flags, as `gmwm wv`.
        #[command(flatten)]
        args: WvArgs,
        /// Units of the samples, as `gmwm calibrate`.
        #[command(flatten)]
        units: UnitArgs,
        /// Datasheet lines.
        #[command(flatten)]
        datasheet: DatasheetArgs,
        /// Figure file and layout.
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// Allan, modified Allan or Hadamard deviations with their intervals.
    #[command(allow_negative_numbers = true)]
    Avar {
        /// Data and estimator flags, as `gmwm avar`.
        #[command(flatten)]
        args: AvarArgs,
        /// Units of the samples, as `gmwm calibrate`.
        #[command(flatten)]
        units: UnitArgs,
        /// Datasheet lines.
        #[command(flatten)]
        datasheet: DatasheetArgs,
        /// Figure file and layout.
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// Classical against robust wavelet variance of each column (paper Fig. 2); --eff sets
    /// the robust estimator's efficiency.
    #[command(allow_negative_numbers = true)]
    Compare {
        /// Data and estimator flags, as `gmwm wv` (--robust is implied for the second series).
        #[command(flatten)]
        args: WvArgs,
        /// Units of the samples, as `gmwm calibrate`.
        #[command(flatten)]
        units: UnitArgs,
        /// Datasheet lines.
        #[command(flatten)]
        datasheet: DatasheetArgs,
        /// Figure file.
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// A fit: empirical WV, the model's implied WV and each process's (paper Fig. 3).
    #[command(allow_negative_numbers = true)]
    Fit {
        /// Data and model flags, as `gmwm fit`.
        #[command(flatten)]
        args: FitArgs,
        /// Units of the samples, as `gmwm calibrate`.
        #[command(flatten)]
        units: UnitArgs,
        /// Datasheet lines.
        #[command(flatten)]
        datasheet: DatasheetArgs,
        /// Figure file.
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// A model selection: the selected model against the WV and the candidates' WIC (Fig. 4).
    #[command(allow_negative_numbers = true)]
    Select {
        /// Data and model flags, as `gmwm select`.
        #[command(flatten)]
        args: SelectArgs,
        /// Units of the samples, as `gmwm calibrate`.
        #[command(flatten)]
        units: UnitArgs,
        /// Datasheet lines.
        #[command(flatten)]
        datasheet: DatasheetArgs,
        /// Figure file.
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// The IEEE Std 952 read-off on the Allan deviation: N, B, K with their slope lines.
    #[command(allow_negative_numbers = true)]
    Ieee {
        /// Data flags, as `gmwm avar` (overlapping Allan variance).
        #[command(flatten)]
        args: AvarArgs,
        /// Units of the samples, as `gmwm calibrate`.
        #[command(flatten)]
        units: UnitArgs,
        /// Datasheet lines.
        #[command(flatten)]
        datasheet: DatasheetArgs,
        /// Figure file.
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// The power spectral density (Welch: Hann, 50% overlap, segments of a power of two up to
    /// 2^16 samples, at least 8 a recording where it is long enough), drawn as the one-sided
    /// √PSD in unit/√Hz on log-frequency bins: vibration humps and the sensor's filter
    /// roll-off, which the WV smears over an octave. White noise of density N reads √2·N.
    #[command(allow_negative_numbers = true)]
    Psd {
        /// Data flags.
        #[command(flatten)]
        args: PsdArgs,
        /// Units of the samples, as `gmwm calibrate`.
        #[command(flatten)]
        units: UnitArgs,
        /// Figure file and layout.
        #[command(flatten)]
        figure: FigureArgs,
    },
}

/// `gmwm plot psd`: the recording to read.
#[derive(Debug, Args)]
pub struct PsdArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
}

/// Where a figure goes and how it is laid out.
#[derive(Debug, Args)]
pub struct FigureArgs {
    /// The figure file: .svg or .png.
    #[arg(short = 'o', long = "output", value_name = "FIGURE", required = true)]
    pub output: PathBuf,
    /// One panel per sensor type with the axes overlaid (paper Fig. 1b) instead of a grid of
    /// panels (wv, avar, psd).
    #[arg(long)]
    pub overlay: bool,
    /// Width in pixels [default: by the figure's panels].
    #[arg(long, value_name = "PX", value_parser = at_least_1)]
    pub width: Option<usize>,
    /// Height in pixels [default: by the figure's panels].
    #[arg(long, value_name = "PX", value_parser = at_least_1)]
    pub height: Option<usize>,
}

const SELECT_EXAMPLES: &str = "\
Each candidate's fit is read as its canonical model (an AR1 below the sampling interval is white
noise, one rising over every observed scale a random walk, two the WV cannot separate are one, a
drift the WV cannot tell from a random walk is the random walk); candidates with the same
canonical model are one row of the table. The selected row is the WIC minimum or, within one
standard error of it, the one --rule prefers.

Examples:
  gmwm select imu.csv.gz --model \"3*AR1()+WN()+RW()+QN()+DR()\"
      every sub-model of the full model (63 candidates), on every column
  gmwm select imu.csv.gz --columns gyro_x --model \"3*AR1()+WN()+RW()+QN()\" --json
  gmwm select imu.csv.gz --columns gyro_x --model \"2*AR1()+WN()+RW()+QN()+DR()\" --top 0 --csv
      every row of the table, as CSV
  gmwm select sim.csv.gz --candidates \"AR1()+WN()+RW();2*AR1()+WN()+RW();3*AR1()+WN()+QN()+RW()\"
      a list of candidates; their common denominator is added and plays the full model
  gmwm select imu.csv.gz --model \"2*GM()+WN()+RW()\" --robust --eff 0.6 --G 20000 --seed 7
  gmwm select imu.csv.gz --model \"2*AR1()+WN()+RW()\" --rule parsimonious
  gmwm select a.csv b.csv c.csv --pool --model \"2*AR1()+WN()+RW()\"
      the sub-models ranked by the WIC of the pooled fit (one model for all recordings)";

/// `gmwm select`.
#[derive(Debug, Args)]
pub struct SelectArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// Full model: every non-empty sub-model of it is a candidate (docs/methods.md §8.4); values in
    /// it are ignored. With --candidates it is one more candidate of the list.
    #[arg(long, value_name = "MODEL", required_unless_present = "candidates")]
    pub model: Option<String>,
    /// Candidate models separated by ';' instead of the sub-models of --model; their common
    /// denominator is added if absent and plays the full model (docs/methods.md §8.5).
    #[arg(long, value_name = "M1;M2;...")]
    pub candidates: Option<String>,
    /// Bootstrap replicates B: of the covariance V of the WV when it is simulated from the
    /// full model's estimate (see --covariance), and per candidate with --optimism bootstrap.
    #[arg(long, value_name = "B", default_value_t = 50, value_parser = at_least_2)]
    pub bootstrap: usize,
    /// How V, the covariance of the WV behind the WIC and every interval, is obtained: exact
    /// from the model (no simulation, any length) when it has only WN, QN, RW, DR, AR1/GM,
    /// MA1 or ARMA11 terms, else simulated (auto); always exact; or simulated as the R package.
    #[arg(long, value_parser = choice::<CovarianceMethod>(), default_value_t = CovarianceMethod::Auto)]
    pub covariance: CovarianceMethod,
    /// Optimism estimator (docs/methods.md §8.2, §8.3).
    #[arg(long, value_parser = choice::<OptimismMethod>(), default_value_t = OptimismMethod::Asymptotic)]
    pub optimism: OptimismMethod,
    /// Asymptotic optimism formula: the corrected derivative and trace order, or the R
    /// package's (docs/methods.md §13.15).
    #[arg(long, value_parser = choice::<OptimismConvention>(), default_value_t = OptimismConvention::Corrected)]
    pub convention: OptimismConvention,
    /// How the selected model is chosen among the canonical models whose WIC is within one
    /// standard error of the minimum.
    #[arg(long, value_parser = choice::<SelectionRule>(), default_value_t = SelectionRule::Navigation)]
    pub rule: SelectionRule,
    /// Wavelet-variance settings of the estimate.
    #[command(flatten)]
    pub estimator: WvEstimatorArgs,
    /// Number of starting-value draws of every fit [default: 20000 for N <= 1e4, else 100000,
    /// with early stop].
    #[arg(long = "G", value_name = "N", value_parser = at_least_1)]
    pub draws: Option<usize>,
    /// Seed of the starting-value searches and of the bootstrap.
    #[arg(long, value_name = "S", default_value_t = 1337, value_parser = seed)]
    pub seed: u64,
    /// Rows of the table per column (0: all); the selected and equivalent rows are always
    /// shown. JSON and CSV hold every row.
    #[arg(long, value_name = "K", default_value_t = 10, value_parser = whole)]
    pub top: usize,
    /// Select one model for all FILEs on the pooled criterion (recordings of one sensor at
    /// one rate, docs/methods.md §5.11): `gmwm select a.csv b.csv --pool --model M`.
    #[arg(long)]
    pub pool: bool,
    /// More recordings, with --pool, --covariate or --covariate-values.
    #[arg(value_name = "FILE", requires = "several")]
    pub more: Vec<PathBuf>,
    /// Fit the parameters as functions of a covariate over all FILEs (docs/methods.md §5.13):
    /// each FILE's level is the mean of its column COL (e.g. temperature); COL is not fitted.
    /// Of a ROS recording, COL is a topic (sensor_msgs/Temperature or FluidPressure,
    /// std_msgs/Float64 or Float32; `temperature` finds the only Temperature topic)
    /// interpolated to the IMU messages in log time, or angular_rate / specific_force (the
    /// magnitudes of the IMU messages' angular_velocity / linear_acceleration).
    #[arg(long, value_name = "COL", conflicts_with_all = ["pool", "covariate_values"])]
    pub covariate: Option<String>,
    /// The covariate's level of each FILE, in order (e.g. 5,15,25,35 for recordings at those
    /// temperatures), instead of --covariate.
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        conflicts_with = "pool",
        allow_hyphen_values = true
    )]
    pub covariate_values: Vec<f64>,
    /// With a covariate: how each parameter depends on it, NAME=constant|affine|quadratic
    /// (comma-separated, later entries win; NAME a label such as WN[0].sigma2, `variances` or
    /// `all`), on the parameter's log/logit scale [default: variances affine, the rest constant].
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub depends: Vec<String>,
    /// With --covariate and one FILE whose covariate drifts (a temperature ramp): cut it into K
    /// windows of equal length, each at its mean level [default: 8].
    #[arg(long, value_name = "K", value_parser = window_count)]
    pub windows: Option<usize>,
    /// With a covariate: report the parameters and their pointwise bands at these levels
    /// [default: each FILE's; with --windows the lowest, middle and highest level].
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub at: Vec<f64>,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `gmwm fit`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("several").args(["pool", "covariate", "covariate_values"]).multiple(true)))]
pub struct FitArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// Model to estimate: guess mode ("3*GM()+WN()") or with starting values
    /// ("AR1(phi=0.99, sigma2=1e-6)+WN(sigma2=1e-4)").
    #[arg(long, value_name = "MODEL")]
    pub model: String,
    /// Wavelet-variance settings of the estimate.
    #[command(flatten)]
    pub estimator: WvEstimatorArgs,
    /// Weighting matrix Omega (docs/methods.md §5.2): CI-width ("fast", the IMU default), the
    /// Percival asymptotic diagonal, or a parametric bootstrap of the WV variances at the
    /// first fit (100 replicates of the series length, then a refit).
    #[arg(long, value_parser = choice::<Weighting>(), default_value_t = Weighting::Fast)]
    pub weights: Weighting,
    /// Number of starting-value draws [default: 20000 for N <= 1e4, else 100000, with early stop].
    #[arg(long = "G", value_name = "N", value_parser = at_least_1)]
    pub draws: Option<usize>,
    /// Seed of the starting-value search.
    #[arg(long, value_name = "S", default_value_t = 1337, value_parser = seed)]
    pub seed: u64,
    /// Add inference (docs/methods.md §7): standard errors, 1 - alpha intervals and the J-test
    /// goodness of fit, from the sandwich with the WV covariance V (see --covariance).
    #[arg(long)]
    pub inference: bool,
    /// With --inference: how V is obtained: exact from the fitted model when it has only WN,
    /// QN, RW, DR, AR1/GM, MA1 or ARMA11 terms, else simulated (auto); always exact; or
    /// simulated from it, 100 replicates, as the R package.
    #[arg(long, value_parser = choice::<CovarianceMethod>(), default_value_t = CovarianceMethod::Auto, requires = "inference")]
    pub covariance: CovarianceMethod,
    /// With --inference: parametric-bootstrap inference with B replicates instead of the
    /// sandwich (bootstrap SE/CI and the bootstrap goodness-of-fit p-value).
    #[arg(long, value_name = "B", requires = "inference", value_parser = at_least_2)]
    pub bootstrap: Option<usize>,
    /// GMWM+ (docs/methods.md §5.15): also fit the model to the WV stacked with extra moments
    /// of the series' first differences, `mean` (the slope of a DR term), `acf:K` (their
    /// autocovariances at lags 1..K) or both (`mean,acf:3`), weighted by their joint covariance
    /// from 200 bootstrap series at the GMWM fit; shown beside the GMWM estimates with
    /// intervals and a J-test.
    #[arg(long, value_name = "LIST", value_parser = augment, conflicts_with_all = ["pool", "covariate", "covariate_values"])]
    pub augment: Option<gmwm::Augment>,
    /// Fit one model to all FILEs (recordings of one sensor at one rate, docs/methods.md
    /// §5.11): `gmwm fit a.csv b.csv c.csv --pool --model M`.
    #[arg(long)]
    pub pool: bool,
    /// More recordings, with --pool, --covariate or --covariate-values.
    #[arg(value_name = "FILE", requires = "several")]
    pub more: Vec<PathBuf>,
    /// Fit the parameters as functions of a covariate over all FILEs (docs/methods.md §5.13):
    /// each FILE's level is the mean of its column COL (e.g. temperature); COL is not fitted.
    /// Of a ROS recording, COL is a topic (sensor_msgs/Temperature or FluidPressure,
    /// std_msgs/Float64 or Float32; `temperature` finds the only Temperature topic)
    /// interpolated to the IMU messages in log time, or angular_rate / specific_force (the
    /// magnitudes of the IMU messages' angular_velocity / linear_acceleration).
    #[arg(long, value_name = "COL", conflicts_with_all = ["pool", "covariate_values"])]
    pub covariate: Option<String>,
    /// The covariate's level of each FILE, in order (e.g. 5,15,25,35 for recordings at those
    /// temperatures), instead of --covariate.
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        conflicts_with = "pool",
        allow_hyphen_values = true
    )]
    pub covariate_values: Vec<f64>,
    /// With a covariate: how each parameter depends on it, NAME=constant|affine|quadratic
    /// (comma-separated, later entries win; NAME a label such as WN[0].sigma2, `variances` or
    /// `all`), on the parameter's log/logit scale [default: variances affine, the rest constant].
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub depends: Vec<String>,
    /// With --covariate: the paper's non-stationary AR1 (§IV-B, docs/methods.md §5.16),
    /// rho_t = tanh(beta0 + beta1 z_{t-1}) and log sigma2_t affine in z_{t-1}, sample by
    /// sample along the covariate z (e.g. angular_rate), fitted over --windows K windows with
    /// the exact implied WV given z; --model AR1() or AR1()+WN().
    #[arg(long, conflicts_with_all = ["pool", "covariate_values", "depends", "at", "augment"])]
    pub dynamic: bool,
    /// With --covariate and one FILE whose covariate drifts (a temperature ramp): cut it into K
    /// windows of equal length, each at its mean level [default: 8].
    #[arg(long, value_name = "K", value_parser = window_count)]
    pub windows: Option<usize>,
    /// With a covariate: report the parameters and their pointwise bands at these levels
    /// [default: each FILE's; with --windows the lowest, middle and highest level].
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub at: Vec<f64>,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `gmwm simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Fully specified model, e.g. "AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)".
    #[arg(long, value_name = "MODEL")]
    pub model: String,
    /// Number of samples.
    #[arg(long, value_name = "N", value_parser = at_least_1)]
    pub n: usize,
    /// Sampling rate in Hz (converts GM parameters; written to the sidecar).
    #[arg(long, value_name = "HZ", default_value_t = 1.0, value_parser = positive_hz)]
    pub freq: f64,
    /// Seed of the simulation (same seed, same bits).
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = seed)]
    pub seed: u64,
    /// Output file, written in the format of its name: .csv/.txt (CSV), .tsv, either with .gz
    /// (gzip), .f64/.f64le/.f64.bin or .f32/... (raw little-endian, columns interleaved), with a
    /// JSON sidecar FILE.json (rate, format, columns) that lets every command read it back
    /// without flags [default: CSV on stdout].
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Option<std::path::PathBuf>,
    /// Also write each component as its own column (x is their sum).
    #[arg(long)]
    pub components: bool,
    /// Write an output of more than 10^9 samples, or larger than the free space of the output
    /// file's file system (refused without it, stating the size).
    #[arg(long)]
    pub yes: bool,
}

const PLAN_EXAMPLES: &str = "\
The prediction is the asymptotic covariance of the GMWM estimates at each length, with the exact
covariance of the wavelet variance (a flicker term through Gauss-Markov stand-ins; B of a model
without flicker is the IEEE read-off of the Allan minimum). It holds for the model given; the
self-audit says what selecting a model adds.

Examples:
  gmwm plan calib.json                               each calibrated axis (gmwm calibrate --json)
  gmwm plan calib.json --columns gyro_x --target \"K=20%,B=10%\"
  gmwm plan --datasheet \"N=0.15 deg/sqrt(h), B=2 deg/h, K=0.5 deg/h/sqrt(h)\" --freq 200
  gmwm plan --model \"GM(beta=0.01, sigma2_gm=1e-9)+WN(sigma2=1e-6)+RW(gamma2=1e-14)\" --freq 100 --lengths 30min,2h,1d --json
  gmwm plan calib.json --target K=20% --plot plan.png      the figure: precision against length";

/// `gmwm plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// A calibration (`gmwm calibrate --json`): each axis' identified model.
    #[arg(value_name = "FILE", conflicts_with_all = ["model", "datasheet"])]
    pub file: Option<PathBuf>,
    /// The axes of FILE (names, comma-separated) [default: all].
    #[arg(long, value_name = "NAMES", requires = "file")]
    pub columns: Option<String>,
    /// A fully specified model (with --freq).
    #[arg(long, value_name = "MODEL", conflicts_with = "datasheet")]
    pub model: Option<String>,
    /// A datasheet, as calibrate takes it (with --freq): N as white noise, B as flicker, K as
    /// a random walk.
    #[arg(long, value_name = "VALUES", value_parser = datasheet)]
    pub datasheet: Option<gmwm::Datasheet>,
    /// Sampling rate in Hz (for --model and --datasheet).
    #[arg(long, value_name = "HZ", value_parser = positive_hz)]
    pub freq: Option<f64>,
    /// Recording lengths: numbers with s, min, h or d [default: 10min,30min,1h,3h,6h,12h,1d,2d,7d].
    #[arg(long, value_name = "LIST")]
    pub lengths: Option<String>,
    /// Targets: QUANTITY=PERCENT items (N, B, K, T1, ...), e.g. \"K=20%,B=10%\".
    #[arg(long, value_name = "LIST")]
    pub target: Option<String>,
    /// Significance level of the intervals.
    #[arg(long, default_value_t = 0.05, value_parser = alpha)]
    pub alpha: f64,
    /// Also draw the precision against the length to FILE (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `gmwm implied`.
#[derive(Debug, Args)]
pub struct ImpliedArgs {
    /// Fully specified model.
    #[arg(long, value_name = "MODEL")]
    pub model: String,
    /// Number of levels J (scales 2^1 .. 2^J samples).
    #[arg(long, value_name = "J", value_parser = at_least_1)]
    pub levels: usize,
    /// Sampling rate in Hz (converts GM parameters; labels tau_s).
    #[arg(long, value_name = "HZ", default_value_t = 1.0, value_parser = positive_hz)]
    pub freq: f64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// How FILE is read (long help of every command that reads a recording).
const INPUT_HELP: &str = "\
Data file: CSV/TSV (optionally .gz), raw little-endian binary, binary IMU records
(--format imar|ln200|ln200ig|ixsea|navchip-int|navchip-flt), a ROS recording (ROS1 .bag, ROS2
.mcap or .db3, or the rosbag2 folder holding one; its sensor_msgs/Imu topic, --topic if it has
several, becomes gyro_x ... accel_z in rad/s and m/s^2 at the rate of its header stamps) or a
wavelet variance saved by `gmwm wv --json` (calibrate and report take it too, and then say what
needs the samples: the spectrum, the gravity and contamination checks).

FILE is read by its name, its JSON sidecar and its content: .f64/.f32 (also .f64le, .f64.bin)
are raw little-endian binary; a sidecar FILE.json (or NAME.json beside NAME.csv.gz) gives the
rate, and for raw binary the format, --ncols and the column names; gzip is recognised by its
first bytes; binary data without --format is refused instead of being read as text; a JSON
document is a wavelet variance saved by `gmwm wv --json`.

FILE - reads standard input (text, gzip, a saved wavelet variance, or raw binary with --format
f64|f32; messages call it <stdin>; no sidecar can come with it, so --freq is needed unless a
time column gives the rate); a pipe such as <(zcat run.csv.gz) is read the same way. Raw floats
that no sensor gives (f64 read as f32, ...) are warned about.

Time column: --time-column, else the first column named time, timestamp, t, stamp, %time
(rostopic echo -p, ns), #timestamp [ns] (EuRoC/TUM-VI), timestamp_ns, time_s, time [s],
field.header.stamp (ns), ... (case-insensitive; a header stamp is preferred). It is not
analysed. Its unit: --time-unit, else the name ([ns], _ms, (us), [s], ...), else inferred:
Unix-epoch-sized stamps (~1.7e9 s, 1.7e12 ms, 1.7e15 us, 1.7e18 ns), fractional stamps with a
step <= 1 are seconds, else the unit giving a rate of 10 Hz to 10 kHz. The rate is 1 / the
nominal step (the mean of the steps within 1.5 median steps): gaps (steps over 1.5 nominal
steps), repeated and reordered stamps are reported as warnings, and stamps must increase. A
--freq that differs from the time column by more than 1% is used, with a warning.

Columns: --columns, else every column but the time columns; when some columns are gyroscope
or accelerometer axes (gyro_x, acc_x, gx, ax, wx, w_RS_S_x, angular_velocity.x,
linear_acceleration.x, ...), only those, and the others are listed in a note.";

/// Where the data come from and how to read them.
#[derive(Debug, Args)]
pub struct InputArgs {
    /// Data file: CSV/TSV (optionally .gz), raw little-endian binary (.f64, .f32 or
    /// --format f64|f32), binary IMU records (--format imar|ln200|...), a ROS recording (.bag,
    /// .mcap, .db3, rosbag2 folder), or a wavelet variance saved by `gmwm wv --json`; - for
    /// standard input (see --help for how FILE is read).
    #[arg(value_name = "FILE", long_help = INPUT_HELP)]
    pub file: PathBuf,
    /// Columns to analyse, comma-separated names or 1-based indices (also the series of a
    /// wavelet-variance JSON) [default: the sensor axes, else all but the time columns].
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub columns: Vec<String>,
    /// Sampling rate in Hz [default: from a time column or the JSON sidecar beside FILE].
    #[arg(long, value_name = "HZ", value_parser = positive_hz)]
    pub freq: Option<f64>,
    /// Input format (auto: from the name, the sidecar and the content).
    #[arg(long, value_parser = choice::<InputFormat>(), default_value_t = InputFormat::Auto)]
    pub format: InputFormat,
    /// Number of interleaved columns of a raw binary file [default: the sidecar's, else 1].
    #[arg(long, value_name = "K", value_parser = at_least_1)]
    pub ncols: Option<usize>,
    /// Whether the first row of a text file is a header.
    #[arg(long, value_parser = choice::<HeaderMode>(), default_value_t = HeaderMode::Auto)]
    pub header: HeaderMode,
    /// Column holding time stamps (name or 1-based index); excluded from analysis
    /// [default: a column named like time, timestamp, t, %time, #timestamp [ns], ...].
    #[arg(long, value_name = "COL")]
    pub time_column: Option<String>,
    /// Unit of the time column [default: stated by its name, else inferred from the values].
    #[arg(long, value_parser = choice::<TimeUnit>(), value_name = "UNIT")]
    pub time_unit: Option<TimeUnit>,
    /// What a text file's row whose time stamp is not after the previous one does.
    #[arg(long, value_parser = choice::<TimePolicy>(), default_value_t = TimePolicy::Strict, value_name = "POLICY")]
    pub time_policy: TimePolicy,
    /// How gaps in the time stamps (packet loss) enter the wavelet and Allan variances:
    /// `aware` uses the observed samples on their time grid (docs/methods.md §1.11),
    /// `contiguous` analyses the samples as one series.
    #[arg(long, value_parser = choice::<GapPolicy>(), default_value_t = GapPolicy::Aware, value_name = "POLICY")]
    pub gaps: GapPolicy,
    /// The sensor_msgs/Imu topic of a ROS recording (ROS1 .bag, MCAP, rosbag2 .db3 or folder)
    /// [default: its only IMU topic; `gmwm topics FILE` lists them].
    #[arg(long, value_name = "TOPIC")]
    pub topic: Option<String>,
    /// `gmwm wv` and `gmwm calibrate`: read a text or binary IMU record recording of at least
    /// ROWS rows streamed (one pass, memory bounded whatever its length) instead of loading
    /// it; a text file counts one row for every 8 bytes, its rows being known only once read
    /// [default: 16777216 = 2^24].
    #[arg(long, value_name = "ROWS", value_parser = clap::value_parser!(u64).range(1..))]
    pub stream_from: Option<u64>,
}

/// Output format shared by the analysis commands.
#[derive(Debug, Args)]
pub struct OutputArgs {
    /// Print JSON (machine-readable, full precision) instead of a table.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV instead of a table (one line per record: per series and scale for variances,
    /// per parameter for fits, per table row for selections).
    #[arg(long)]
    pub csv: bool,
}

/// Wavelet-variance estimator settings.
#[derive(Debug, Args)]
pub struct WvEstimatorArgs {
    /// Use the robust (Tukey biweight) wavelet variance.
    #[arg(long)]
    pub robust: bool,
    /// Gaussian efficiency of the robust estimator, in (0, 0.99].
    #[arg(long, value_name = "E", default_value_t = 0.6, value_parser = efficiency)]
    pub eff: f64,
    /// Robust tuning constant and solver: the correct formula, or the R package's.
    #[arg(long, value_parser = choice::<RobustConvention>(), default_value_t = RobustConvention::Exact)]
    pub robust_convention: RobustConvention,
    /// Wavelet filter (docs/methods.md §1.8): haar, d4, d6, d8, d16, fk4, fk8, fk14, fk22, bl14,
    /// bl20, la8, la16, la20, mb4, mb8, mb16, mb24.
    #[arg(long, value_name = "NAME", default_value = "haar")]
    pub filter: String,
    /// Wavelet transform.
    #[arg(long, value_parser = choice::<Transform>(), default_value_t = Transform::Modwt)]
    pub transform: Transform,
    /// Number of levels J [default: floor(log2 N), one fewer if the last would keep < 2 coefficients].
    #[arg(long, value_name = "J", value_parser = at_least_1)]
    pub levels: Option<usize>,
    /// Significance level A: the intervals cover 1 - A (0.05 gives 95% intervals; a value
    /// above 0.5, such as 0.95, is refused as a likely confidence level).
    #[arg(long, value_name = "A", default_value_t = 0.05, value_parser = alpha)]
    pub alpha: f64,
}

/// `gmwm demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Number of samples to simulate [default: 2^22, about 4.7 hours at 250 Hz, as the paper's 3.1e6].
    #[arg(long, value_name = "N", default_value_t = 1 << 22, value_parser = at_least_1)]
    pub n: usize,
    /// Seed of the simulation.
    #[arg(long, value_name = "S", default_value_t = 2018, value_parser = seed)]
    pub seed: u64,
    /// Estimator settings.
    #[command(flatten)]
    pub estimator: WvEstimatorArgs,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `gmwm wv`.
#[derive(Debug, Args)]
pub struct WvArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// Estimator settings.
    #[command(flatten)]
    pub estimator: WvEstimatorArgs,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `gmwm avar`.
#[derive(Debug, Args)]
pub struct AvarArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// Which variance.
    #[arg(long, value_parser = choice::<AllanKind>(), default_value_t = AllanKind::Overlapping)]
    pub kind: AllanKind,
    /// Textbook estimators, or the R package's (with its off-by-one terms, docs/methods.md
    /// §13.8–13.10).
    #[arg(long, value_parser = choice::<AvConvention>(), default_value_t = AvConvention::Textbook)]
    pub convention: AvConvention,
    /// Significance level A: the intervals cover 1 - A (0.05 gives 95% intervals; a value
    /// above 0.5, such as 0.95, is refused as a likely confidence level).
    #[arg(long, value_name = "A", default_value_t = 0.05, value_parser = alpha)]
    pub alpha: f64,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

const TOPICS_EXAMPLES: &str = "\
FILE is a ROS1 bag (format 2.0), an MCAP file, a rosbag2 sqlite3 .db3 file or a rosbag2 folder
(metadata.yaml + .mcap/.db3 files); the format is recognised by its first bytes. IMU topics
(sensor_msgs/Imu) are marked; \"(default)\" marks the one read when no topic is named: the only
IMU topic holding messages.

Examples:
  gmwm topics run.bag
  gmwm topics rosbag2_2024_05_01-10_00_00/
  gmwm topics run.mcap --json";

/// `gmwm topics`.
#[derive(Debug, Args)]
pub struct TopicsArgs {
    /// ROS recording: .bag, .mcap or .db3 file, or rosbag2 folder.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// JSON on stdout: {"file", "container", "topics": [{topic, message_type, messages,
    /// is_imu}]}.
    #[arg(long)]
    pub json: bool,
}

/// The help of `--export`: the stacks' names from the engine's one list, Kalibr (which
/// `--kalibr` also writes) last.
fn export_help() -> String {
    use gmwm::ExportFormat;
    let others: Vec<&str> = ExportFormat::ALL
        .iter()
        .filter(|f| **f != ExportFormat::KALIBR)
        .map(|f| f.name())
        .collect();
    format!(
        "Write a navigation stack's file: {} (or {}); repeatable",
        others.join(", "),
        ExportFormat::KALIBR.name()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}

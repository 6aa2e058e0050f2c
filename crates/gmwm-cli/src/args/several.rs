//! The flags of the commands over several recordings or axes: `gmwm same-model`, `gmwm shared`,
//! `gmwm monitor`.

use super::{InputArgs, OutputArgs};
use clap::Args;
use std::path::PathBuf;

/// Examples of `gmwm same-model --help`.
pub(super) const SAME_MODEL_EXAMPLES: &str = "\
The recordings must share one sampling rate (within 1%), the units their sidecars state and
the columns tested. The statistic T compares the pooled fit (one model for all) with the
separate fits (one per recording), both with efficient weights; p_value is its chi-square
tail with df = (K - 1) p, p_value_bootstrap the rank of T among B replicates simulated from
the pooled fit (every recording at its own length). per_scale shows where they differ: the
contributions sum to T; wv_max_abs_z is the largest model-free difference of two recordings'
WVs at that scale over its standard error (flagged above the normal quantile).

Examples:
  gmwm same-model a.csv b.csv c.csv --model \"AR1()+WN()+RW()\"
  gmwm same-model imu1.csv.gz imu2.csv.gz --model \"2*GM()+WN()+RW()\" --columns gyro_x,accel_x --bootstrap 200 --json
  gmwm fit a.csv b.csv c.csv --pool --model \"AR1()+WN()+RW()\" --inference      the pooled fit";

/// `gmwm same-model`.
#[derive(Debug, Args)]
pub struct SameModelArgs {
    /// Recordings (at least two), read as by `gmwm fit`.
    #[arg(value_name = "FILE", required = true, num_args = 1..)]
    pub files: Vec<PathBuf>,
    /// The model of every recording (guess mode, or with starting values).
    #[arg(long, value_name = "MODEL")]
    pub model: String,
    /// Columns to test, comma-separated names or 1-based indices [default: the sensor axes].
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub columns: Vec<String>,
    /// Sampling rate in Hz of every file [default: from a time column or the JSON sidecar].
    #[arg(long, value_name = "HZ")]
    pub freq: Option<f64>,
    /// Parametric-bootstrap replicates B of the p-value (none: the chi-square p-value only).
    #[arg(long, value_name = "B")]
    pub bootstrap: Option<usize>,
    /// Number of wavelet-variance levels J of every recording [default: per recording].
    #[arg(long, value_name = "J")]
    pub levels: Option<usize>,
    /// Number of starting-value draws of the separate fits.
    #[arg(long = "G", value_name = "N")]
    pub draws: Option<usize>,
    /// Seed of the searches and of the bootstrap.
    #[arg(long, value_name = "S", default_value_t = 1337)]
    pub seed: u64,
    /// Also draw every recording's WV with the pooled model's implied WV, one panel per
    /// column, to FILE (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `gmwm shared --help` examples.
pub(super) const SHARED_EXAMPLES: &str = "The shared model is one text (--shared), the axis-specific model another (--model) that \
every axis gets with its own parameters; the columns must be of one sensor and unit.\n\n\
Examples:\n  gmwm shared imu.csv.gz --shared \"GM()\" --model \"WN()+RW()\" --columns gyro_x,gyro_y,gyro_z\n  \
gmwm shared imu.csv.gz --shared \"GM()\" --model \"WN()+RW()\" --columns gyro_x,gyro_y,gyro_z --json\n  \
gmwm shared imu.csv.gz --shared \"GM()\" --model \"WN()+RW()\" --columns gyro_x,gyro_y,gyro_z --plot shared.png\n  \
gmwm shared imu.csv.gz --shared \"AR1()\" --model \"WN()+QN()+RW()\" --columns accel_x,accel_y --levels 14";

/// `gmwm shared` flags.
#[derive(Debug, Args)]
pub struct SharedArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// The shared process V (model text, values ignored), e.g. "GM()".
    #[arg(long = "shared", value_name = "MODEL")]
    pub shared: String,
    /// Each axis's own processes U_i (model text, values ignored), e.g. "WN()+RW()".
    #[arg(long = "model", value_name = "MODEL")]
    pub model: String,
    /// Wavelet levels [default: docs/methods.md §1.6].
    #[arg(long, value_name = "J")]
    pub levels: Option<usize>,
    /// Significance level of the intervals, in (0, 0.5].
    #[arg(long, default_value_t = 0.05)]
    pub alpha: f64,
    /// Seed of the starting-value searches.
    #[arg(long, default_value_t = 1337)]
    pub seed: u64,
    /// Draws of each starting-value search.
    #[arg(long = "G", value_name = "G", default_value_t = 2000)]
    pub draws: usize,
    /// Also draw the axes' WVs, their cross-covariances and the shared process's implied WV
    /// with its band to FILE (.svg or .png).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<std::path::PathBuf>,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `gmwm monitor --help` examples.
pub(super) const MONITOR_EXAMPLES: &str = "Each window's robust WV (docs/methods.md §2) is compared with the band the calibrated \
model predicts for a window of that length (chi-square with the model's equivalent degrees of \
freedom, Bonferroni over the levels); a window outside at some level is flagged. About --alpha \
of the windows of a recording that follows the model are flagged by chance. Where the \
calibration's verdict says the model misfits its WV, the windows are compared with that \
empirical WV and its uncertainty instead (--against auto, the default; docs/methods/multi-axis.md \
§16.6): a misfit of a few percent would otherwise flag nearly every long window.\n\n\
Examples:\n  gmwm calibrate imu.csv.gz --out-dir cal && gmwm monitor imu.csv.gz --model-from cal/imu.calibration.json\n  \
gmwm monitor long.csv.gz --model-from cal/imu.calibration.json --columns gyro_x --window 600s --step 60s\n  \
gmwm monitor long.csv.gz --model-from cal/imu.calibration.json --window 65536 --json";

/// `gmwm monitor` flags.
#[derive(Debug, Args)]
pub struct MonitorArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// The calibration JSON (`gmwm calibrate FILE --out-dir DIR` writes DIR/NAME.calibration.json):
    /// per axis the model and its estimates.
    #[arg(long = "model-from", value_name = "CALIB_JSON")]
    pub model_from: PathBuf,
    /// Window length: samples (65536) or a duration with a unit (600s, 10min, 2h).
    #[arg(long, default_value = "65536")]
    pub window: String,
    /// Step between windows: samples or a duration [default: half a window].
    #[arg(long)]
    pub step: Option<String>,
    /// Probability that a window of a recording following the model is flagged, in (0, 0.5].
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Efficiency of the robust WV, in (0, 0.99].
    #[arg(long, default_value_t = 0.6)]
    pub eff: f64,
    /// Largest level tested [default: every level with M_j / 2^j >= 8].
    #[arg(long, value_name = "J")]
    pub levels: Option<usize>,
    /// What each window is compared with: the calibrated model's WV (model), the calibration's
    /// empirical WV with its uncertainty (wv), or the model where the calibration's verdict says it
    /// explains the WV and the empirical WV where it misfits (auto; docs/methods/multi-axis.md
    /// §16.6).
    #[arg(long, value_enum, default_value_t = Against::Auto)]
    pub against: Against,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `--against`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Against {
    /// The model where it explains the calibration's WV, else that WV.
    Auto,
    /// The calibrated model's implied WV.
    Model,
    /// The calibration's empirical WV.
    Wv,
}

//! `gmwm shared`: a latent process shared by several axes of one recording (paper §IV-A,
//! docs/methods.md §15): `x_i = V + U_i`, fitted from the axes' wavelet variances and
//! cross-covariances, with intervals and the test of "no shared process".

use crate::args::{InputArgs, OutputArgs};
use crate::config::OutputConfig;
use crate::input::load;
use crate::input::InputConfig;
use crate::render::Style;
use anyhow::{Context, Result};
use clap::Args;
use gmwm::model::Model;
use gmwm::shared::{fit_shared, SharedFit, SharedOptions};
use std::io::Write;

/// `gmwm shared --help` examples.
pub const EXAMPLES: &str = "The shared model is one text (--shared), the axis-specific model another (--model) that \
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
        if let Some(why) = gmwm::variance::ci::significance_level_problem(a.alpha) {
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

/// Runs the subcommand.
pub fn run(config: &SharedConfig, out: &mut impl Write) -> Result<()> {
    let (fit, unit) = compute(config)?;
    if let Some(path) = &config.plot {
        let unit = crate::render::figure_unit(unit.as_deref());
        crate::render::save_figure(&gmwm_plot::shared_figure(&fit, &unit), path)?;
        eprintln!("gmwm: wrote {}", path.display());
    }
    render(&fit, config.output, out)
}

/// Reads the columns, checks they are one sensor in one unit, fits; the fit and that unit.
pub fn compute(config: &SharedConfig) -> Result<(SharedFit, Option<String>)> {
    let file = config.input.file.display().to_string();
    let loaded = load(&config.input)?;
    let table = &loaded.table;
    anyhow::ensure!(
        table.columns.len() >= 2,
        "{file}: a shared process needs at least 2 columns, got {} ({}); give --columns, e.g. \
         --columns gyro_x,gyro_y,gyro_z",
        table.columns.len(),
        table
            .columns
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let infos = gmwm::imu::SensorInfo::of_table(table);
    if let Some((i, info)) = infos
        .iter()
        .enumerate()
        .find(|(_, s)| s.sensor != infos[0].sensor || s.unit != infos[0].unit)
    {
        let what = |s: &gmwm::imu::SensorInfo| {
            format!(
                "{} in {}",
                s.sensor.tag(),
                s.unit.as_deref().unwrap_or("an unknown unit")
            )
        };
        anyhow::bail!(
            "{file}: --columns: {} is {} but {} is {}: a shared process needs axes of one sensor \
             and unit",
            table.columns[i].name,
            what(info),
            table.columns[0].name,
            what(&infos[0])
        );
    }
    let axes: Vec<(&str, &[f64])> = table
        .columns
        .iter()
        .map(|c| (c.name.as_str(), c.values.as_slice()))
        .collect();
    let fit = fit_shared(
        &axes,
        loaded.freq_hz,
        &config.shared,
        &config.specific,
        &config.options,
    )
    .map_err(|e| short_context(e, &file, &config.shared, &config.specific))?;
    Ok((fit, infos[0].unit.clone()))
}

/// The engine's error with the file and, for a recording too short for the model, the fix.
fn short_context(e: gmwm::Error, file: &str, shared: &Model, specific: &Model) -> anyhow::Error {
    if let gmwm::Error::Fit(gmwm::FitError::TooFewLevels { params, levels }) = &e {
        return anyhow::anyhow!(
            "{file}: too short for --shared {shared} --model {specific}: {params} parameters \
             but {levels} wavelet levels; give a longer recording or a smaller model"
        );
    }
    anyhow::Error::new(e).context(file.to_string())
}

/// Table, JSON or CSV.
pub fn render(fit: &SharedFit, style: Style, out: &mut impl Write) -> Result<()> {
    match style {
        Style::Json => {
            serde_json::to_writer_pretty(&mut *out, fit)?;
            writeln!(out)?;
        }
        Style::Csv => {
            writeln!(out, "block,parameter,estimate,se,ci_low,ci_high")?;
            let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:e}"));
            for p in &fit.parameters {
                writeln!(
                    out,
                    "{},{},{:e},{},{},{}",
                    p.block,
                    p.name,
                    p.estimate,
                    opt(p.se),
                    opt(p.ci_low),
                    opt(p.ci_high)
                )?;
            }
        }
        _ => writeln!(out, "{fit}")?,
    }
    Ok(())
}

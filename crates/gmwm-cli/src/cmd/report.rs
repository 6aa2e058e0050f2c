//! `gmwm report`: `gmwm calibrate` with the HTML report as its output.

use crate::args::ReportArgs;
use anyhow::Result;
use std::io::Write;
use std::path::PathBuf;

/// The default report file: the recording's name without its data extensions, with
/// `.report.html`, in the current folder (`imu.csv.gz` gives `imu.report.html`).
fn default_output(file: &std::path::Path) -> PathBuf {
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

/// Runs the subcommand.
pub fn run(args: &ReportArgs, out: &mut impl Write) -> Result<()> {
    if let (Some(o), Some(r)) = (&args.output, &args.calibrate.report) {
        return Err(crate::UsageError(format!(
            "give the report's file once: -o {} or --report {}",
            o.display(),
            r.display()
        ))
        .into());
    }
    let path = args
        .output
        .clone()
        .or_else(|| args.calibrate.report.clone())
        .unwrap_or_else(|| default_output(&args.calibrate.input.file));
    crate::cmd::calibrate::execute(&args.calibrate, Some(&path), false, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_output_drops_the_data_extensions() {
        assert_eq!(
            default_output("data/imu.csv.gz".as_ref()),
            PathBuf::from("imu.report.html")
        );
        assert_eq!(
            default_output("run.bag".as_ref()),
            PathBuf::from("run.report.html")
        );
        assert_eq!(
            default_output("rosbag2_x/".as_ref()),
            PathBuf::from("rosbag2_x.report.html")
        );
    }
}

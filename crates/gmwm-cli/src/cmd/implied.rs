//! `gmwm implied`: the implied wavelet variance of a fully specified model.

use crate::args::ImpliedArgs;
use anyhow::Result;
use gmwm::model::Model;
use std::io::Write;

/// Runs the subcommand.
pub fn run(args: &ImpliedArgs, out: &mut impl Write) -> Result<()> {
    let model: Model = args.model.parse()?;
    let implied = model.implied_wv(args.levels, args.freq)?;
    if args.json {
        serde_json::to_writer_pretty(&mut *out, &implied)?;
        writeln!(out)?;
    } else {
        write!(out, "{implied}")?;
    }
    Ok(())
}

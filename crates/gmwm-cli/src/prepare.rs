//! Input preparation, before any work: what each command reads ([`Inputs`], declared by the
//! command) is checked, a stream (`-` or a pipe) copied to a temporary file ([`crate::spool`]),
//! and raw floats no sensor gives warned about, in one place for every command.

use crate::error::UsageError;
use crate::input::InputConfig;
use crate::recordings::is_rosbag2_folder;
use crate::spool::{self, Spool};
use anyhow::Result;
use gmwm::InputFormat;
use std::path::{Path, PathBuf};

/// What a command reads, as its preparation needs to know it.
#[derive(Debug)]
pub enum Inputs<'a> {
    /// No file: the command simulates or computes from its flags (demo, simulate, implied).
    None,
    /// One recording or saved wavelet variance: `--topic` is refused for a file that is no ROS
    /// recording and a folder that is none, a stream is copied (its copy replaces FILE), and
    /// raw floats that no sensor gives are warned about.
    Recording(&'a mut InputConfig),
    /// A ROS recording listed as it is (topics): a stream is copied, nothing else.
    RosFile(&'a mut PathBuf),
    /// Files, folders or globs the command expands and reads one by one (batch mode,
    /// `calibrate --pool`): none may be a stream; `refusal` says why, after its name.
    Files {
        /// The FILE arguments.
        paths: &'a [PathBuf],
        /// The usage error's text after `NAME: `.
        refusal: &'static str,
    },
    /// Recordings that the pooled commands (`same-model`, `fit`/`select --pool`) read one after
    /// the other, each refusing a stream as it comes to it
    /// ([`crate::cmd::same_model`]'s pool reader): nothing to prepare before.
    Pool,
}

/// Prepares what a command reads (see [`Inputs`]); the guard removes a stream's copy when
/// dropped, at the end of the run.
///
/// # Errors
/// A usage error for a stream where files are read, or a `--topic` for a file that is no ROS
/// recording; an error for a folder that is no recording, or a stream that cannot be copied.
pub fn prepare(inputs: Inputs<'_>) -> Result<Option<Spool>> {
    match inputs {
        Inputs::None | Inputs::Pool => Ok(None),
        Inputs::Files { paths, refusal } => match paths.iter().find(|p| spool::is_stream(p)) {
            Some(p) => Err(UsageError(format!("{}: {refusal}", named(p))).into()),
            None => Ok(None),
        },
        Inputs::RosFile(file) => spooled(file),
        Inputs::Recording(input) => {
            check_recording(input)?;
            let mut file = input.file.clone();
            let guard = spooled(&mut file)?;
            if guard.is_some() {
                input.set_file(file);
            }
            warn_implausible(input);
            Ok(guard)
        }
    }
}

/// A stream's name in messages: `<stdin>` for `-`.
fn named(path: &Path) -> String {
    if path.as_os_str() == "-" {
        spool::STDIN.to_string()
    } else {
        path.display().to_string()
    }
}

/// Copies `file` when it is a stream and puts the copy in its place.
fn spooled(file: &mut PathBuf) -> Result<Option<Spool>> {
    if !spool::is_stream(file) {
        return Ok(None);
    }
    let (copy, guard) = spool::spool(file)?;
    *file = copy;
    Ok(Some(guard))
}

/// Refuses, before reading, a `--topic` for an existing file that is no ROS recording, and a
/// folder that is not a rosbag2 recording.
fn check_recording(input: &InputConfig) -> Result<()> {
    if let Some(topic) = &input.topic {
        if !spool::is_stream(&input.file)
            && input.probe().container().is_none()
            && input.read.format == InputFormat::Auto
            && input.file.exists()
        {
            return Err(UsageError(format!(
                "invalid --topic {topic}: {} is not a ROS recording (ROS1 bag, MCAP, rosbag2 \
                 sqlite3)",
                input.file.display()
            ))
            .into());
        }
    }
    if input.file.is_dir() && !is_rosbag2_folder(&input.file) {
        anyhow::bail!(
            "{}: is a folder, not a recording (a rosbag2 folder holds metadata.yaml; gmwm wv \
             and gmwm calibrate also take a folder of recordings)",
            input.file.display()
        );
    }
    Ok(())
}

/// A warning when FILE is raw f64/f32 whose first values no sensor gives
/// ([`gmwm::raw_floats`]); silent when it is not raw floats or cannot be read
/// (the reader then says why).
pub fn warn_implausible(input: &InputConfig) {
    if input.read.format == InputFormat::Auto
        && (input.probe().container().is_some() || crate::input::is_wv(input))
    {
        return;
    }
    let layout = match gmwm::binary_layout(&input.file, &input.read) {
        Ok(layout) => layout,
        // a size that is no whole number of rows (the reader says so next): the values are
        // still looked at when the format was given, as text read as f64 often has that size
        Err(_) => matches!(input.read.format, InputFormat::F64 | InputFormat::F32).then(|| {
            gmwm::BinaryLayout {
                format: input.read.format,
                ncols: 1,
                names: Vec::new(),
            }
        }),
    };
    if let Some(layout) = layout {
        if let Ok(Some(bad)) = gmwm::raw_floats(&input.file, &layout) {
            eprintln!("gmwm: warning: {}", spool::shown(&bad.to_string()));
        }
    }
}

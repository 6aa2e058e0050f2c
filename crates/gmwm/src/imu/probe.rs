//! What a recording's path is, found once before it is read (issue 27: the input is probed
//! once): a ROS container, recognised by its magic bytes, which the readers open as a ROS
//! recording when the format is `auto`; a folder; or a file for the table and binary readers.
//! The probe travels with the read options to every reader and to the calibration's choice
//! between memory and streaming, so the file is sniffed once per command.

use super::read::{InputFormat, ReadOptions};
use super::ros::{container_of, RosContainer};
use std::path::{Path, PathBuf};

/// What a recording's path is, found once before it is read: a ROS container (read as one when
/// the format is `auto`), a folder, or a file for the table and binary readers. It travels with
/// the read options to every reader and to the calibration's choice between memory and
/// streaming, so that the file is sniffed once per command.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Probe {
    path: PathBuf,
    container: Option<RosContainer>,
    format: InputFormat,
    dir: bool,
}

impl Probe {
    /// Probes `path` under the read options `read` (their format decides whether a ROS
    /// container is read as one). Never fails: a path that cannot be read probes as a plain
    /// file, and its reader then says why.
    pub fn of(path: &Path, read: &ReadOptions) -> Probe {
        Probe {
            path: path.to_path_buf(),
            container: container_of(path),
            format: read.format,
            dir: path.is_dir(),
        }
    }

    /// The path probed.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The ROS container the path holds, whatever the format asked.
    pub fn container(&self) -> Option<RosContainer> {
        self.container
    }

    /// Whether the path is read as a ROS recording: a ROS container, format `auto`.
    pub fn is_ros(&self) -> bool {
        self.format == InputFormat::Auto && self.container.is_some()
    }

    /// Whether the path holds no file for the table and binary readers: a ROS container (of
    /// any format asked) or a folder.
    pub(crate) fn is_container_or_folder(&self) -> bool {
        self.container.is_some() || self.dir
    }
}

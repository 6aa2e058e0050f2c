//! rosbag2 sqlite3 storage in a build without SQLite (the `sqlite` feature off, as in the
//! WebAssembly build of `web/`): the file is recognised by its magic bytes and refused in one
//! line that says how to read it.

use super::error::RosError;
use super::{Collector, Encoding};
use crate::imu::ReadError;
use std::collections::HashMap;
use std::path::Path;

/// No database can be opened in this build: the type has no value.
pub(crate) enum Connection {}

pub(crate) use super::SqliteTopic as Topic;

/// Refuses the file: this build has no SQLite.
pub(crate) fn open(path: &Path) -> Result<Connection, ReadError> {
    Err(RosError::Sqlite {
        path: path.to_path_buf(),
        reason: "this build of gmwm has no SQLite (the browser and WebAssembly build); convert \
                 the bag to MCAP (`ros2 bag convert`) or use the gmwm command"
            .into(),
    }
    .into())
}

pub(crate) fn catalog(_: &Path, db: &Connection) -> Result<Vec<Topic>, RosError> {
    match *db {}
}

pub(crate) fn read(
    _: &Path,
    db: &Connection,
    _: &HashMap<i64, Encoding>,
    _: &mut Collector<'_>,
) -> Result<(), ReadError> {
    match *db {}
}

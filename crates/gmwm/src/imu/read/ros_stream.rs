//! A ROS recording's IMU topic streamed into a [`StreamedTable`]: the one decoder of
//! `imu::ros` hands the messages over in file order; a reorder buffer of [`REORDER`] messages
//! (a min-heap on log time, then file order) releases them in log-time order, the order
//! [`read_imu_messages`] sorts them into; each released message's selected values and its two
//! stamps (header stamp and log time, in s after the first, as `Recording::open` computes them)
//! go to the spool and to two streamed checks (`timing::StepStats`), the header stamps' report
//! chosen unless they do not advance (`Recording::open`'s rule, `recording::ros_timing`).
//!
//! A message logged before one already released (out of order beyond the buffer) stops the
//! streamed pass; the topic is then read again in memory by [`read_imu_messages`] (64 bytes a
//! message), sorted and spooled, and the notes say so. A streamed check beyond its bounds is
//! redone on its stamps read back from the spool (8 bytes a message), with a note.
//!
//! Memory: the reorder buffer (about 330 KB), the decoder's one chunk, the two checks (a few
//! KB for clock-quantised stamps, 6 MB at most) and the streamed WV; not the 64 bytes a
//! message of the in-memory reader. Measured (busy 2-core machine, indicative; `gmwm wv FILE
//! --json`, 10^6 messages at 200 Hz written by `write_imu_bag.py`, plus 10^5 String messages
//! on the bag; `--stream-from 1` against the in-memory default): ROS1 bag (386 MB,
//! uncompressed) 35 MB peak RSS against 87 MB, 0.31 s against 0.33 s; MCAP zstd 35 MB against
//! 86 MB, 0.64 s against 0.56 s. The WVs agreed within 3e-16.

use super::stream::{write_row, Spool, StreamedTable};
use crate::imu::recording::{
    ros_samples, ros_selection, ros_timing, RosAbout, HEADER_STAMP, LOG_TIME,
};
use crate::imu::ros::{read_imu_messages, read_topic, MessageSink};
use crate::imu::timing::{check_times, StepStats, TimeUnit, UnitSource};
use crate::imu::{ReadError, RecordingOptions};
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Messages the reorder buffer holds: 4096 (about 80 bytes each).
pub(crate) const REORDER: usize = 4096;

/// A message waiting in the reorder buffer.
#[derive(Debug, Clone, Copy)]
struct Pending {
    log_ns: i64,
    /// Place in file order.
    seq: u64,
    header_ns: i64,
    values: [f64; 6],
}

impl PartialEq for Pending {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Pending {}
impl PartialOrd for Pending {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Pending {
    fn cmp(&self, other: &Self) -> Ordering {
        (self.log_ns, self.seq).cmp(&(other.log_ns, other.seq))
    }
}

/// Messages in log-time order to the spool and the two streamed checks.
struct Released {
    out: BufWriter<File>,
    spool: Spool,
    columns: Vec<usize>,
    header: StepStats,
    log: StepStats,
    /// The first released message's stamps.
    first: Option<(i64, i64)>,
    row: Vec<f64>,
}

impl Released {
    fn new(columns: Vec<usize>) -> Result<Self, ReadError> {
        let (spool, out) = Spool::create(columns.len() + 2)?;
        Ok(Self {
            out,
            spool,
            row: Vec::with_capacity(columns.len() + 2),
            columns,
            header: StepStats::default(),
            log: StepStats::default(),
            first: None,
        })
    }

    fn release(&mut self, header_ns: i64, log_ns: i64, values: &[f64; 6]) -> Result<(), ReadError> {
        let (h0, l0) = *self.first.get_or_insert((header_ns, log_ns));
        // as `stamps_report`: whole nanoseconds after the first, exactly, then seconds
        let h = header_ns.wrapping_sub(h0) as f64 * 1e-9;
        let l = log_ns.wrapping_sub(l0) as f64 * 1e-9;
        self.header.push(h, None);
        self.log.push(l, None);
        self.row.clear();
        self.row.extend(self.columns.iter().map(|&k| values[k]));
        self.row.extend([h, l]);
        write_row(&mut self.out, &self.spool.path, &self.row)
    }

    /// The spool, flushed.
    fn flush(mut self) -> Result<(Spool, StepStats, StepStats), ReadError> {
        self.out.flush().map_err(|source| ReadError::Io {
            path: self.spool.path.clone(),
            source,
        })?;
        drop(self.out);
        Ok((self.spool, self.header, self.log))
    }
}

/// The bounded reorder buffer ([`REORDER`] messages) in front of [`Released`].
struct Reorder {
    heap: BinaryHeap<Reverse<Pending>>,
    capacity: usize,
    seq: u64,
    last: Option<i64>,
    /// A message came older than one released: the streamed pass is abandoned.
    disordered: bool,
    released: Released,
}

impl Reorder {
    fn new(capacity: usize, released: Released) -> Self {
        Self {
            heap: BinaryHeap::with_capacity(capacity + 1),
            capacity: capacity.max(1),
            seq: 0,
            last: None,
            disordered: false,
            released,
        }
    }

    fn pop(&mut self) -> Result<(), ReadError> {
        if let Some(Reverse(m)) = self.heap.pop() {
            self.last = Some(m.log_ns);
            self.released.release(m.header_ns, m.log_ns, &m.values)?;
        }
        Ok(())
    }

    /// Releases what the buffer holds.
    fn finish(mut self) -> Result<Released, ReadError> {
        while !self.heap.is_empty() {
            self.pop()?;
        }
        Ok(self.released)
    }
}

impl MessageSink for Reorder {
    fn message(&mut self, header_ns: i64, log_ns: i64, values: &[f64]) -> Result<(), ReadError> {
        // an IMU message: six values (the collector of IMU topics hands over no other)
        let mut six = [0.0; 6];
        for (d, v) in six.iter_mut().zip(values) {
            *d = *v;
        }
        let values = six;
        if self.disordered {
            // still decoded and checked: the errors are those of the in-memory read
            return Ok(());
        }
        if self.last.is_some_and(|l| log_ns < l) {
            self.disordered = true;
            self.heap = BinaryHeap::new();
            return Ok(());
        }
        self.heap.push(Reverse(Pending {
            log_ns,
            seq: self.seq,
            header_ns,
            values,
        }));
        self.seq += 1;
        if self.heap.len() > self.capacity {
            self.pop()?;
        }
        Ok(())
    }
}

/// Opens a ROS recording streamed (module docs): as `Recording::open` reads it.
pub(crate) fn open(path: &Path, opts: &RecordingOptions) -> Result<StreamedTable, ReadError> {
    open_with(path, opts, REORDER)
}

/// [`open`] with a reorder buffer of `capacity` messages.
pub(crate) fn open_with(
    path: &Path,
    opts: &RecordingOptions,
    capacity: usize,
) -> Result<StreamedTable, ReadError> {
    if let Some(f) = opts.read.freq_hz {
        crate::error::check_freq(f)?;
    }
    let columns = ros_selection(path, &opts.read.columns)?;
    let mut sink = Reorder::new(capacity, Released::new(columns.clone())?);
    let read = read_topic(path, opts.topic.as_deref(), |_, _| &mut sink)?;
    let mut streamed_notes = Vec::new();
    let released = if sink.disordered {
        streamed_notes.push(format!(
            "log times out of order beyond the streamed reader's buffer ({capacity} messages): \
             the topic was read again in memory (64 bytes a message), sorted and spooled"
        ));
        drop(sink);
        let msgs = read_imu_messages(path, opts.topic.as_deref())?;
        let mut released = Released::new(columns.clone())?;
        let [gx, gy, gz] = &msgs.angular_velocity;
        let [ax, ay, az] = &msgs.linear_acceleration;
        for i in 0..msgs.len() {
            let values = [gx[i], gy[i], gz[i], ax[i], ay[i], az[i]];
            released.release(msgs.header_stamp_ns[i], msgs.log_time_ns[i], &values)?;
        }
        released
    } else {
        sink.finish()?
    };
    let (spool, header, log) = released.flush()?;
    let at = columns.len();
    let report = |stats: StepStats, column: &str, k: usize, notes: &mut Vec<String>| match stats
        .finish(column, TimeUnit::Nanoseconds, UnitSource::Stated)
    {
        Some(r) => Ok(r),
        None => {
            notes.push(format!(
                    "{column}: more than {} distinct steps or {} gaps; the stamps were checked in memory (8 bytes a message)",
                    crate::imu::timing::STREAM_DISTINCT_STEPS,
                    crate::imu::timing::STREAM_LARGEST_STEPS
                ));
            let s = spool.column(k)?;
            Ok::<_, ReadError>(check_times(
                column,
                &s,
                TimeUnit::Nanoseconds,
                UnitSource::Stated,
            ))
        }
    };
    let header = report(header, HEADER_STAMP, at, &mut streamed_notes)?;
    let about = RosAbout {
        container: read.container,
        topic: read.topic,
        frame_id: read.frame_id,
        messages: read.messages,
        other_messages: read.other_messages,
    };
    let mut log_notes = Vec::new();
    let (mut notes, timing, freq_hz) = ros_timing(path, &about, opts.read.freq_hz, header, || {
        report(log, LOG_TIME, at + 1, &mut log_notes)
    })?;
    let names: Vec<String> = columns
        .iter()
        .map(|&k| crate::imu::recording::ROS_AXES[k].to_string())
        .collect();
    let samples = ros_samples(names.clone(), &about, &timing);
    notes.push(samples.to_string());
    notes.extend(streamed_notes);
    notes.extend(log_notes);
    Ok(StreamedTable::ros(
        path,
        names,
        (about.messages, freq_hz),
        timing,
        samples,
        notes,
        (about.topic, about.container),
        spool,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sink that records what the reorder buffer releases.
    fn released(input: &[(i64, u64)], capacity: usize) -> (Vec<(i64, f64)>, bool) {
        let mut r = Reorder::new(capacity, Released::new((0..6).collect()).unwrap());
        for &(log, tag) in input {
            r.message(0, log, &[tag as f64, 0.0, 0.0, 0.0, 0.0, 0.0])
                .unwrap();
        }
        let disordered = r.disordered;
        if disordered {
            return (Vec::new(), true);
        }
        let (spool, _, _) = r.finish().unwrap().flush().unwrap();
        let tags = spool.column(0).unwrap();
        let logs = spool.column(7).unwrap();
        (
            logs.iter()
                .map(|&l| (l * 1e9).round() as i64)
                .zip(tags)
                .collect(),
            false,
        )
    }

    #[test]
    fn the_reorder_buffer_sorts_within_its_capacity_stably() {
        // log times (ns after the first released) and a tag in file order
        let input = [(10, 0), (30, 1), (20, 2), (10, 3), (40, 4), (30, 5)];
        let (out, disordered) = released(&input, 3);
        assert!(!disordered);
        assert_eq!(
            out,
            [
                (0, 0.0),
                (0, 3.0),
                (10, 2.0),
                (20, 1.0),
                (20, 5.0),
                (30, 4.0)
            ]
        );
    }

    #[test]
    fn disorder_beyond_the_buffer_is_detected() {
        let input = [(10, 0), (20, 1), (30, 2), (40, 3), (5, 4)];
        assert!(released(&input, 2).1);
        assert!(!released(&input, 4).1);
    }
}

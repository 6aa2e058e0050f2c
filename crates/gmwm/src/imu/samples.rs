//! Row accounting: how many samples a reader read and handed on per column, what in the file
//! held none, and what it did not fill in.
//!
//! The readers never drop a sample nor fill one in: a value they cannot use (a non-number, a
//! non-finite value, a ragged row, a stamp out of order) is an error naming the file and line,
//! and a gap in the time stamps is reported, not filled. So every selected column holds the
//! same samples, `read` of them, and all of them are `used`; this account says so in numbers,
//! together with the lines, records or messages that held no sample (a header line, blank
//! lines, messages on other topics) and the samples the stamps say are missing.
//!
//! ```
//! use gmwm::{SampleAccount, Tally};
//! let account = SampleAccount {
//!     columns: vec!["gyro_x".into(), "gyro_y".into()],
//!     unit: "row",
//!     read: 1000,
//!     used: 1000,
//!     without_samples: vec![Tally { count: 1, what: "header line".into() }],
//!     missing: 0,
//! };
//! assert_eq!(
//!     account.to_string(),
//!     "1000 rows read, 1000 samples used in each of 2 columns (gyro_x, gyro_y); \
//!      no samples in 1 header line; nothing dropped or filled in"
//! );
//! ```

use serde::Serialize;
use std::fmt;

/// A count of something in a file (`3 blank lines`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Tally {
    /// How many.
    pub count: u64,
    /// What, in the singular (`header line`, `blank line`, `message on other topics`).
    pub what: String,
}

impl fmt::Display for Tally {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.count, plural(&self.what, self.count))
    }
}

/// What a reader did with a recording's samples (module docs).
///
/// Wire format: `columns` (the analysed columns), `unit` (`row`, `record`, `message`: what
/// holds one sample of every column), `read` (such units read), `used` (samples of each
/// column handed to the analysis), `without_samples` (`[{count, what}]`: parts of the file
/// holding no sample), `missing` (samples the time stamps say are missing, not filled in).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SampleAccount {
    /// The columns analysed, each with `used` samples.
    pub columns: Vec<String>,
    /// What holds one sample of every column: `row` (text, raw binary), `record` (binary IMU
    /// records) or `message` (a ROS IMU topic).
    pub unit: &'static str,
    /// Rows, records or messages read.
    pub read: u64,
    /// Samples of each column handed to the analysis.
    pub used: u64,
    /// Parts of the file that held no sample, with their counts.
    pub without_samples: Vec<Tally>,
    /// Samples the time stamps say are missing (the gaps' missing samples), not filled in:
    /// the wavelet variance skips the windows that span a gap unless asked to analyse the
    /// samples as contiguous (`GapPolicy`).
    pub missing: u64,
}

impl SampleAccount {
    /// An account of `read` units (`row`, `record`, `message`) in `columns`, every sample
    /// used, nothing without samples, nothing missing.
    pub fn all_used(columns: Vec<String>, unit: &'static str, read: u64) -> Self {
        Self {
            columns,
            unit,
            read,
            used: read,
            without_samples: Vec::new(),
            missing: 0,
        }
    }

    /// Adds `count` parts of the file holding no sample, `what` in the singular (a count of 0
    /// adds nothing).
    pub fn without(mut self, count: u64, what: &str) -> Self {
        if count > 0 {
            self.without_samples.push(Tally {
                count,
                what: what.to_string(),
            });
        }
        self
    }
}

impl fmt::Display for SampleAccount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const SHOWN: usize = 6;
        let k = self.columns.len();
        // names from a file: escaped and cut, so that the account stays one line
        let shown: Vec<String> = self.columns[..k.min(SHOWN)]
            .iter()
            .map(|n| super::quote(n))
            .collect();
        let mut names = shown.join(", ");
        if k > SHOWN {
            names.push_str(&format!(", ... ({} more)", k - SHOWN));
        }
        write!(
            f,
            "{} {} read, {} {} used in each of {k} {} ({names})",
            self.read,
            plural(self.unit, self.read),
            self.used,
            plural("sample", self.used),
            plural("column", k as u64),
        )?;
        if !self.without_samples.is_empty() {
            let parts: Vec<String> = self.without_samples.iter().map(Tally::to_string).collect();
            write!(f, "; no samples in {}", parts.join(", "))?;
        }
        let dropped = self.read.saturating_sub(self.used);
        match (dropped, self.missing) {
            (0, 0) => write!(f, "; nothing dropped or filled in"),
            (0, m) => write!(
                f,
                "; nothing dropped; {m} {} missing in the time stamps' gaps, not filled in",
                plural("sample", m)
            ),
            (d, 0) => write!(
                f,
                "; {d} {} not used; nothing filled in",
                plural(self.unit, d)
            ),
            (d, m) => write!(
                f,
                "; {d} {} not used; {m} missing in the time stamps' gaps, not filled in",
                plural(self.unit, d)
            ),
        }
    }
}

/// `what` in the plural when `n != 1`: the noun before any ` on ` phrase (`blank line` ->
/// `blank lines`, `message on other topics` -> `messages on other topics`).
fn plural(what: &str, n: u64) -> String {
    if n == 1 {
        return what.to_string();
    }
    match what.split_once(" on ") {
        Some((noun, rest)) => format!("{noun}s on {rest}"),
        None => format!("{what}s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plural_of_the_first_word() {
        assert_eq!(plural("blank line", 2), "blank lines");
        assert_eq!(plural("header line", 0), "header lines");
        assert_eq!(
            plural("message on other topics", 3),
            "messages on other topics"
        );
        assert_eq!(plural("row", 1), "row");
        assert_eq!(plural("row", 0), "rows");
    }

    #[test]
    fn display_states_gaps_and_parts_without_samples() {
        let a = SampleAccount::all_used(vec!["ax".into()], "record", 12)
            .without(0, "header line")
            .without(2, "blank line");
        assert_eq!(
            a.to_string(),
            "12 records read, 12 samples used in each of 1 column (ax); no samples in 2 blank \
             lines; nothing dropped or filled in"
        );
        let gaps = SampleAccount { missing: 5, ..a };
        assert!(gaps.to_string().ends_with(
            "nothing dropped; 5 samples missing in the time stamps' gaps, not filled in"
        ));
        let names: Vec<String> = (1..=8).map(|k| format!("c{k}")).collect();
        let many = SampleAccount::all_used(names, "row", 1);
        assert!(many
            .to_string()
            .contains("(c1, c2, c3, c4, c5, c6, ... (2 more))"));
    }
}

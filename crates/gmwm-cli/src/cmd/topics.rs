//! `gmwm topics`: the topics of a ROS recording, with the IMU topics marked.

use super::Command;
use crate::config::TopicsConfig;
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::Result;
use gmwm::{choose_topic, list_topics, RosContainer, TopicInfo};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// One topic in the JSON output.
#[derive(Serialize)]
struct TopicRow<'a> {
    topic: &'a str,
    message_type: &'a str,
    messages: u64,
    is_imu: bool,
}

/// The JSON document: `{"file", "container", "topics": [...]}`.
#[derive(Serialize)]
struct TopicsDoc<'a> {
    file: &'a Path,
    container: RosContainer,
    topics: Vec<TopicRow<'a>>,
}

/// Runs the subcommand.
pub fn run(config: &TopicsConfig, out: &mut impl Write) -> Result<()> {
    let (container, topics) = list_topics(&config.file)?;
    if config.json {
        let doc = TopicsDoc {
            file: &config.file,
            container,
            topics: topics
                .iter()
                .map(|t| TopicRow {
                    topic: &t.topic,
                    message_type: &t.message_type,
                    messages: t.messages,
                    is_imu: t.is_imu(),
                })
                .collect(),
        };
        serde_json::to_writer_pretty(&mut *out, &doc)?;
        writeln!(out)?;
    } else {
        table(out, &config.file, container, &topics)?;
    }
    Ok(())
}

/// Aligned table: topic, type, messages, and `IMU` / `IMU (default)` marks.
fn table(
    out: &mut impl Write,
    file: &Path,
    container: RosContainer,
    topics: &[TopicInfo],
) -> Result<()> {
    let picked = choose_topic(file, topics, None);
    let default = picked.as_ref().ok().map(|t| t.topic.as_str());
    let count = topics.len();
    writeln!(
        out,
        "{} ({container}): {count} topic{}",
        file.display(),
        if count == 1 { "" } else { "s" }
    )?;
    if topics.is_empty() {
        return Ok(());
    }
    // names from the file: control characters escaped and cut, so that a hostile name can
    // neither reach the terminal raw nor widen the table past what formatting allows
    let shown: Vec<(String, String)> = topics
        .iter()
        .map(|t| (shown_name(&t.topic), shown_name(&t.message_type)))
        .collect();
    let wt = shown
        .iter()
        .map(|t| t.0.chars().count())
        .max()
        .unwrap_or(0)
        .max(5);
    let wy = shown
        .iter()
        .map(|t| t.1.chars().count())
        .max()
        .unwrap_or(0)
        .max(4);
    writeln!(
        out,
        "  {:<wt$}  {:<wy$}  {:>10}  imu",
        "topic", "type", "messages"
    )?;
    for (t, (topic, message_type)) in topics.iter().zip(&shown) {
        let mark = match (t.is_imu(), Some(t.topic.as_str()) == default) {
            (true, true) => "IMU (default)",
            (true, false) => "IMU",
            _ => "",
        };
        let line = format!(
            "  {:<wt$}  {:<wy$}  {:>10}  {mark}",
            topic, message_type, t.messages
        );
        writeln!(out, "{}", line.trim_end())?;
    }
    // why no topic would be read by default (no IMU topic, several, or none with messages)
    if let Err(e) = picked {
        let text = e.to_string();
        let prefix = format!("{}: ", file.display());
        let reason = text.strip_prefix(&prefix).unwrap_or(&text);
        writeln!(out, "note: {reason}")?;
    }
    Ok(())
}

impl Command for TopicsConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::RosFile(&mut self.file)
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        None
    }

    fn run(&self, _: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        run(self, &mut out)
    }
}

/// Longest topic or type name shown whole, in characters; a longer one (no real topic is) is
/// cut with `...`.
const NAME_SHOWN: usize = 200;

/// A name from the file for the table: control characters escaped, cut to [`NAME_SHOWN`].
fn shown_name(name: &str) -> String {
    gmwm::quote_up_to(name, NAME_SHOWN)
}

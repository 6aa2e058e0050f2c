//! A covariate of a ROS recording (docs/methods.md §5.13), one value per IMU sample: a scalar
//! topic (`sensor_msgs/Temperature`, `sensor_msgs/FluidPressure`, `std_msgs/Float64`,
//! `std_msgs/Float32`) interpolated to the IMU messages, or a magnitude of the IMU messages'
//! own fields (`angular_rate`: |angular_velocity| in rad/s; `specific_force`:
//! |linear_acceleration| in m/s^2).
//!
//! **Which topic.** `--covariate NAME` names a topic (`/imu/temperature`, with or without the
//! leading `/`), or the last part of one (`temperature` finds `/imu/temperature` when it is
//! the only scalar topic ending so); `temperature` also finds the recording's only
//! `sensor_msgs/Temperature` topic whatever its name.
//!
//! **Alignment.** Both topics are placed on the recorder's clock, the log (receive) times: a
//! driver's header stamps may come from the device's clock for one topic and the host's for
//! the other, while the recorder stamps every message alike. Each IMU message (in log-time
//! order, the order of [`read_imu_messages`](super::read_imu_messages)'s samples) takes the
//! covariate interpolated linearly between the two covariate messages around it; IMU samples
//! before the first (after the last) covariate message take its first (last) value, counted
//! in the notes. A receive latency of milliseconds moves a temperature that drifts by degrees
//! per hour by a few µ°C. Topics with no overlap in time are an error
//! ([`RosError::NoOverlap`]).

use super::cdr::ScalarType;
use super::error::RosError;
use super::{choose_topic, read_messages, MessageKind, MessageSink, TopicInfo};
use crate::imu::timing::{check_times, TimeUnit, UnitSource};
use crate::imu::ReadError;
use std::path::Path;

/// A covariate derived from the IMU messages' own fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Derived {
    /// |angular_velocity|, rad/s.
    AngularRate,
    /// |linear_acceleration|, m/s^2.
    SpecificForce,
}

impl Derived {
    fn of(name: &str) -> Option<Self> {
        match name {
            "angular_rate" => Some(Derived::AngularRate),
            "specific_force" => Some(Derived::SpecificForce),
            _ => None,
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Derived::AngularRate => "|angular_velocity| in rad/s",
            Derived::SpecificForce => "|linear_acceleration| in m/s^2",
        }
    }
}

/// A covariate of a ROS recording, one value per IMU sample ([`read_ros_covariate`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RosCovariate {
    /// The scalar topic read (`None` for a magnitude of the IMU messages).
    pub topic: Option<String>,
    /// What the values are: `sensor_msgs/Temperature, field temperature in degC`, or
    /// `|angular_velocity| in rad/s of the IMU messages`.
    pub description: String,
    /// The unit by the message definition (`degC`, `Pa`, `rad/s`, `m/s^2`; `None` for a bare
    /// `std_msgs` number).
    pub unit: Option<&'static str>,
    /// One value per IMU message, in log-time order (the recording's samples).
    pub values: Vec<f64>,
    /// What was read and how it was aligned, one line each.
    pub notes: Vec<String>,
}

/// Log times (and, for a derived covariate, the magnitude) of the IMU messages.
#[derive(Default)]
struct ImuTimes {
    derived: Option<Derived>,
    log_ns: Vec<i64>,
    values: Vec<f64>,
}

impl MessageSink for ImuTimes {
    fn message(&mut self, _header_ns: i64, log_ns: i64, values: &[f64]) -> Result<(), ReadError> {
        self.log_ns.push(log_ns);
        // scaled, so that finite values of any size give a finite magnitude
        let norm = |v: &[f64]| {
            let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            if m == 0.0 {
                0.0
            } else {
                m * v.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt()
            }
        };
        match self.derived {
            Some(Derived::AngularRate) => self.values.push(norm(&values[..3])),
            Some(Derived::SpecificForce) => self.values.push(norm(&values[3..6])),
            None => {}
        }
        Ok(())
    }
}

/// (log time, value) of each scalar message.
#[derive(Default)]
struct Scalars(Vec<(i64, f64)>);

impl MessageSink for Scalars {
    fn message(&mut self, _header_ns: i64, log_ns: i64, values: &[f64]) -> Result<(), ReadError> {
        self.0.push((log_ns, values[0]));
        Ok(())
    }
}

/// Reads the covariate `name` of the ROS recording `path` (a file or a rosbag2 folder) as one
/// value per message of its IMU topic `imu_topic` (default: the only one): module docs.
///
/// # Errors
/// Those of [`read_imu_messages`](super::read_imu_messages) for either topic;
/// [`RosError::NoCovariate`] when no topic answers to `name`, [`RosError::NotScalar`] when the
/// topic named carries another type, [`RosError::AmbiguousCovariate`] when several do,
/// [`RosError::EmptyTopic`] when it holds no messages, [`RosError::NoOverlap`] when its messages
/// and the IMU topic's do not overlap in time.
///
/// ```no_run
/// use std::path::Path;
/// let t = gmwm::read_ros_covariate(Path::new("run.mcap"), None, "temperature")?;
/// println!("{} values; {}", t.values.len(), t.notes.join("; "));
/// # Ok::<(), gmwm::ReadError>(())
/// ```
pub fn read_ros_covariate(
    path: &Path,
    imu_topic: Option<&str>,
    name: &str,
) -> Result<RosCovariate, ReadError> {
    let derived = Derived::of(name);
    let mut imu = ImuTimes {
        derived,
        ..ImuTimes::default()
    };
    let read = read_messages(
        path,
        |topics| {
            Ok((
                choose_topic(path, topics, imu_topic)?.clone(),
                MessageKind::Imu,
            ))
        },
        |_, _| &mut imu,
    )?;
    let imu_name = read.topic;
    // the recording's sample order: log time, ties in file order
    let mut order: Vec<usize> = (0..imu.log_ns.len()).collect();
    order.sort_by_key(|&i| imu.log_ns[i]);
    let imu_ns: Vec<i64> = order.iter().map(|&i| imu.log_ns[i]).collect();
    if let Some(d) = derived {
        let values = order.iter().map(|&i| imu.values[i]).collect();
        return Ok(RosCovariate {
            topic: None,
            description: format!("{} of the IMU messages", d.describe()),
            unit: Some(match d {
                Derived::AngularRate => "rad/s",
                Derived::SpecificForce => "m/s^2",
            }),
            values,
            notes: vec![format!(
                "covariate {name}: {} of each message of topic {}",
                d.describe(),
                crate::imu::quote(&imu_name)
            )],
        });
    }
    let mut scalars = Scalars::default();
    let mut chosen_type = None;
    let read = read_messages(
        path,
        |topics| {
            let (t, ty) = choose_covariate(path, topics, name)?;
            chosen_type = Some(ty);
            Ok((t, MessageKind::Scalar(ty)))
        },
        |chosen, bytes| {
            // one pair per message at most, and never more than the bytes could hold
            let capacity = chosen.messages.min(bytes / 8);
            scalars = Scalars(Vec::with_capacity(usize::try_from(capacity).unwrap_or(0)));
            &mut scalars
        },
    )?;
    let Some(ty) = chosen_type else {
        return Err(not_found(path, name, &[]).into());
    };
    let mut msgs = scalars.0;
    msgs.sort_by_key(|m| m.0);
    let topic = read.topic;
    let description = format!(
        "{}, field {}{}",
        ty.name(),
        ty.field(),
        ty.unit().map(|u| format!(" in {u}")).unwrap_or_default()
    );
    let aligned = align(&imu_ns, &msgs).ok_or_else(|| RosError::NoOverlap {
        path: path.to_path_buf(),
        topic: topic.clone(),
        messages: msgs.len(),
        from_ns: msgs.first().map_or(0, |m| m.0),
        to_ns: msgs.last().map_or(0, |m| m.0),
        imu_topic: imu_name.clone(),
        imu_from_ns: imu_ns.first().copied().unwrap_or(0),
        imu_to_ns: imu_ns.last().copied().unwrap_or(0),
    })?;
    let first = msgs[0].0;
    let seconds: Vec<f64> = msgs
        .iter()
        .map(|m| m.0.wrapping_sub(first) as f64 * 1e-9)
        .collect();
    let column = format!("log time of {}", topic);
    let timing = check_times(&column, &seconds, TimeUnit::Nanoseconds, UnitSource::Stated);
    let span = seconds.last().copied().unwrap_or(0.0);
    let mut notes = vec![format!(
        "covariate {name}: topic {} ({description}): {} messages over {} s, interpolated \
         linearly in log time to the {} messages of {}",
        crate::imu::quote(&topic),
        msgs.len(),
        fmt_seconds(span),
        imu_ns.len(),
        crate::imu::quote(&imu_name)
    )];
    notes.extend(timing.warnings().iter().map(ToString::to_string));
    for (count, span_s, side, which) in [
        (aligned.before, aligned.before_s, "before", "first"),
        (aligned.after, aligned.after_s, "after", "last"),
    ] {
        if count > 0 {
            notes.push(format!(
                "covariate {name}: {count} IMU samples ({} s) {side} its {which} message take \
                 that message's value",
                fmt_seconds(span_s)
            ));
        }
    }
    Ok(RosCovariate {
        topic: Some(topic),
        description,
        unit: ty.unit(),
        values: aligned.values,
        notes,
    })
}

/// Seconds with 3 significant digits at least and no exponent (`0.005`, `655.4`).
fn fmt_seconds(s: f64) -> String {
    if s >= 100.0 {
        format!("{s:.1}")
    } else if s >= 1.0 {
        format!("{s:.2}")
    } else {
        format!("{s:.3}")
    }
}

fn not_found(path: &Path, name: &str, topics: &[TopicInfo]) -> RosError {
    RosError::NoCovariate {
        path: path.to_path_buf(),
        name: name.to_owned(),
        available: topics
            .iter()
            .map(|t| format!("{} ({})", t.topic, t.message_type))
            .collect(),
    }
}

/// The scalar topic `name` stands for (module docs).
fn choose_covariate(
    path: &Path,
    topics: &[TopicInfo],
    name: &str,
) -> Result<(TopicInfo, ScalarType), RosError> {
    let bare = name.trim_start_matches('/');
    let scalar = |t: &TopicInfo| ScalarType::of(&t.message_type);
    let pick = |t: &TopicInfo, ty: ScalarType| {
        if t.messages == 0 {
            Err(RosError::EmptyTopic {
                path: path.to_path_buf(),
                topics: vec![t.topic.clone()],
            })
        } else {
            Ok((t.clone(), ty))
        }
    };
    if let Some(t) = topics
        .iter()
        .find(|t| t.topic.trim_start_matches('/') == bare)
    {
        return match scalar(t) {
            Some(ty) => pick(t, ty),
            None => Err(RosError::NotScalar {
                path: path.to_path_buf(),
                topic: t.topic.clone(),
                message_type: t.message_type.clone(),
            }),
        };
    }
    let suffix = format!("/{bare}");
    let ending: Vec<&TopicInfo> = topics
        .iter()
        .filter(|t| scalar(t).is_some() && t.topic.ends_with(&suffix))
        .collect();
    match ending.as_slice() {
        [one] => return pick(one, scalar(one).unwrap_or(ScalarType::Float64)),
        [] => {}
        more => {
            return Err(RosError::AmbiguousCovariate {
                path: path.to_path_buf(),
                name: name.to_owned(),
                topics: more.iter().map(|t| t.topic.clone()).collect(),
            })
        }
    }
    if bare == "temperature" {
        let temperature: Vec<&TopicInfo> = topics
            .iter()
            .filter(|t| scalar(t) == Some(ScalarType::Temperature))
            .collect();
        match temperature.as_slice() {
            [one] => return pick(one, ScalarType::Temperature),
            [] => {}
            more => {
                return Err(RosError::AmbiguousCovariate {
                    path: path.to_path_buf(),
                    name: name.to_owned(),
                    topics: more.iter().map(|t| t.topic.clone()).collect(),
                })
            }
        }
    }
    Err(not_found(path, name, topics))
}

/// A covariate aligned to the IMU samples.
#[derive(Debug, Clone, PartialEq)]
struct Aligned {
    values: Vec<f64>,
    /// IMU samples before the first covariate message, and how long they last.
    before: usize,
    before_s: f64,
    /// IMU samples after the last covariate message, and how long they last.
    after: usize,
    after_s: f64,
}

/// The covariate messages `msgs` (log time, value; sorted by time) interpolated linearly to
/// the IMU log times `imu_ns` (sorted), held at the ends; `None` when the two do not overlap
/// in time (or either is empty). One pass over both: O(N + M).
fn align(imu_ns: &[i64], msgs: &[(i64, f64)]) -> Option<Aligned> {
    let (&(first, first_v), &(last, last_v)) = (msgs.first()?, msgs.last()?);
    let (&t0, &t1) = (imu_ns.first()?, imu_ns.last()?);
    if last < t0 || first > t1 {
        return None;
    }
    let mut values = Vec::with_capacity(imu_ns.len());
    let (mut before, mut after) = (0, 0);
    // msgs[j] is the last message at or before t (while t is inside the span)
    let mut j = 0;
    for &t in imu_ns {
        if t <= first {
            // an IMU sample at the first message's time takes its value, not counted
            before += usize::from(t < first);
            values.push(first_v);
            continue;
        }
        if t >= last {
            after += usize::from(t > last);
            values.push(last_v);
            continue;
        }
        while j + 1 < msgs.len() && msgs[j + 1].0 <= t {
            j += 1;
        }
        let (ta, va) = msgs[j];
        let (tb, vb) = msgs[j + 1];
        // ta <= t < tb here (tb > ta as t is strictly inside)
        let w = (t - ta) as f64 / (tb - ta) as f64;
        // a convex combination: finite for any finite ends (va + w (vb - va) overflows when
        // they are near the largest f64 of opposite signs)
        values.push((1.0 - w) * va + w * vb);
    }
    let seconds = |ns: i64| ns as f64 * 1e-9;
    Some(Aligned {
        values,
        before,
        before_s: if before > 0 { seconds(first - t0) } else { 0.0 },
        after,
        after_s: if after > 0 { seconds(t1 - last) } else { 0.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn align_interpolates_and_holds_the_ends() {
        let msgs = [(10, 1.0), (20, 2.0), (20, 3.0), (40, 5.0)];
        let imu = [0, 5, 10, 15, 20, 30, 40, 45];
        let a = align(&imu, &msgs).unwrap();
        // a tie at 20 takes the later message (file order)
        assert_eq!(a.values, [1.0, 1.0, 1.0, 1.5, 3.0, 4.0, 5.0, 5.0]);
        assert_eq!((a.before, a.after), (2, 1));
        assert!((a.before_s - 10e-9).abs() < 1e-20 && (a.after_s - 5e-9).abs() < 1e-20);
        assert_eq!(align(&[50, 60], &msgs), None);
        assert_eq!(align(&[0, 9], &msgs), None);
        assert!(align(&[0, 10], &msgs).is_some());
        assert_eq!(align(&[], &msgs), None);
        assert_eq!(align(&imu, &[]), None);
        // ends near the largest f64, of opposite signs: still finite
        let huge = align(&[0, 5, 10], &[(0, -1e308), (10, 1e308)]).unwrap();
        assert!(
            huge.values.iter().all(|v| v.is_finite()),
            "{:?}",
            huge.values
        );
        // one message inside the span: a constant
        let one = align(&imu, &[(12, 7.0)]).unwrap();
        assert!(one.values.iter().all(|&v| v == 7.0));
    }

    use crate::imu::ros::tests::t;

    #[test]
    fn covariate_names_resolve_to_topics() {
        let p = Path::new("b.mcap");
        let topics = [
            t("/imu0", "sensor_msgs/msg/Imu", 100),
            t("/imu/temp", "sensor_msgs/msg/Temperature", 5),
            t("/power/voltage", "std_msgs/msg/Float64", 5),
            t("/status", "std_msgs/msg/String", 5),
            t("/empty/pressure", "sensor_msgs/msg/FluidPressure", 0),
        ];
        let name = |n: &str| choose_covariate(p, &topics, n).map(|(t, _)| t.topic);
        assert_eq!(name("/imu/temp").unwrap(), "/imu/temp");
        assert_eq!(name("imu/temp").unwrap(), "/imu/temp");
        assert_eq!(name("temperature").unwrap(), "/imu/temp");
        assert_eq!(name("voltage").unwrap(), "/power/voltage");
        let e = name("/status").unwrap_err().to_string();
        assert!(
            e.starts_with("b.mcap: topic /status carries std_msgs/msg/String"),
            "{e}"
        );
        let e = name("pressure").unwrap_err().to_string();
        assert_eq!(e, "b.mcap: topic /empty/pressure holds no messages");
        let e = name("humidity").unwrap_err().to_string();
        assert!(e.starts_with("b.mcap: no covariate humidity:"), "{e}");
        assert!(e.contains("/imu/temp (sensor_msgs/msg/Temperature)"), "{e}");
        let two = [
            t("/a/temperature", "sensor_msgs/msg/Temperature", 5),
            t("/b/temperature", "sensor_msgs/msg/Temperature", 5),
        ];
        let e = choose_covariate(p, &two, "temperature")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "b.mcap: several topics answer to covariate temperature: /a/temperature, \
             /b/temperature; name one with --covariate TOPIC"
        );
    }
}

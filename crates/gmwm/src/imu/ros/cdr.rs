//! Decoding one serialized `sensor_msgs/Imu`: ROS2 CDR (XCDR1, either byte order) and the ROS1
//! serialization.
//!
//! Both layouts end with the same 37 packed float64 values after the header:
//! orientation (4), orientation_covariance (9), angular_velocity (3), its covariance (9),
//! linear_acceleration (3), its covariance (9). Only the stamp, frame_id, angular_velocity and
//! linear_acceleration are returned, but the length of every field is checked.

use super::error::MessageError;

/// The fields of a `sensor_msgs/Imu` this crate uses, borrowed from the serialized message.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ImuFields<'a> {
    /// `header.stamp` in ns since the epoch.
    pub(crate) stamp_ns: i64,
    /// `header.frame_id` bytes (without a terminating NUL).
    pub(crate) frame_id: &'a [u8],
    /// rad/s.
    pub(crate) angular_velocity: [f64; 3],
    /// m/s^2.
    pub(crate) linear_acceleration: [f64; 3],
}

/// Byte offsets, relative to the first float64 (orientation.x), of the fields after the header,
/// and where each ends: (name, end).
const BODY: [(&str, usize); 6] = [
    ("orientation", 32),
    ("orientation_covariance", 104),
    ("angular_velocity", 128),
    ("angular_velocity_covariance", 200),
    ("linear_acceleration", 224),
    ("linear_acceleration_covariance", 296),
];
/// Offset of angular_velocity.x from orientation.x.
const ANGULAR_VELOCITY: usize = 104;
/// Offset of linear_acceleration.x from orientation.x.
const LINEAR_ACCELERATION: usize = 200;

/// The value fields, in the order of [`ImuFields`] (for non-finite reports).
pub(crate) const VALUE_FIELDS: [&str; 6] = [
    "angular_velocity.x",
    "angular_velocity.y",
    "angular_velocity.z",
    "linear_acceleration.x",
    "linear_acceleration.y",
    "linear_acceleration.z",
];

#[derive(Clone, Copy)]
enum Order {
    Little,
    Big,
}

#[inline]
fn u32_at(b: &[u8], at: usize, order: Order) -> u32 {
    let mut a = [0u8; 4];
    a.copy_from_slice(&b[at..at + 4]);
    match order {
        Order::Little => u32::from_le_bytes(a),
        Order::Big => u32::from_be_bytes(a),
    }
}

#[inline]
fn f64_at(b: &[u8], at: usize, order: Order) -> f64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    match order {
        Order::Little => f64::from_le_bytes(a),
        Order::Big => f64::from_be_bytes(a),
    }
}

#[cold]
fn short(len: usize, field: &'static str, needed: usize) -> MessageError {
    MessageError::Short { len, field, needed }
}

/// Checks that the 37 floats starting at `body` (an offset into `msg`, which is `len` bytes as
/// reported, `shift` bytes longer than `msg`) fit, and reads the two vectors.
#[inline]
fn body(
    msg: &[u8],
    body: usize,
    shift: usize,
    order: Order,
) -> Result<([f64; 3], [f64; 3]), MessageError> {
    if msg.len() < body + 296 {
        let (field, end) = BODY
            .iter()
            .find(|(_, end)| body + end > msg.len())
            .copied()
            .unwrap_or(BODY[5]);
        return Err(short(msg.len() + shift, field, body + end + shift));
    }
    let v = |k: usize| f64_at(msg, body + k, order);
    let w = ANGULAR_VELOCITY;
    let a = LINEAR_ACCELERATION;
    Ok(([v(w), v(w + 8), v(w + 16)], [v(a), v(a + 8), v(a + 16)]))
}

/// Decodes a ROS1-serialized `sensor_msgs/Imu` (little-endian, packed): `header` = seq u32,
/// stamp (sec u32, nsec u32), frame_id (u32 length + bytes), then the 37 float64.
pub(crate) fn decode_ros1(msg: &[u8]) -> Result<ImuFields<'_>, MessageError> {
    let (stamp_ns, end) = ros1_header(msg)?;
    let (angular_velocity, linear_acceleration) = body(msg, end, 0, Order::Little)?;
    Ok(ImuFields {
        stamp_ns,
        frame_id: &msg[16..end],
        angular_velocity,
        linear_acceleration,
    })
}

/// A ROS1 `std_msgs/Header` at the start of `msg` (seq u32, stamp sec u32 and nsec u32,
/// frame_id u32 length + bytes): the stamp in ns and the offset of the byte after it, its
/// lengths checked.
fn ros1_header(msg: &[u8]) -> Result<(i64, usize), MessageError> {
    if msg.len() < 16 {
        return Err(short(msg.len(), "header", 16));
    }
    let sec = u32_at(msg, 4, Order::Little);
    let nsec = u32_at(msg, 8, Order::Little);
    let len = u32_at(msg, 12, Order::Little) as usize;
    let end = 16usize.saturating_add(len);
    if end > msg.len() {
        return Err(short(msg.len(), "header.frame_id", end));
    }
    Ok((i64::from(sec) * 1_000_000_000 + i64::from(nsec), end))
}

/// The CDR encapsulation header of `msg` (4 bytes): the byte order and the body after it.
fn cdr_encapsulation(msg: &[u8]) -> Result<(Order, &[u8]), MessageError> {
    if msg.len() < 4 {
        return Err(short(msg.len(), "CDR encapsulation header", 4));
    }
    let order = match (msg[0], msg[1]) {
        (0x00, 0x01) => Order::Little,
        (0x00, 0x00) => Order::Big,
        (a, b) => return Err(MessageError::Encapsulation(a, b)),
    };
    Ok((order, &msg[4..]))
}

/// A CDR `std_msgs/Header` at the start of the body `b` (stamp sec int32 and nanosec uint32,
/// frame_id uint32 length + bytes; lengths reported against `msg_len`, the message with its
/// 4-byte encapsulation): the stamp in ns and the offset of the byte after the string.
fn cdr_header(b: &[u8], order: Order, msg_len: usize) -> Result<(i64, usize), MessageError> {
    if b.len() < 12 {
        return Err(short(msg_len, "header", 16));
    }
    let sec = u32_at(b, 0, order) as i32;
    let nanosec = u32_at(b, 4, order);
    let len = u32_at(b, 8, order) as usize;
    let end = 12usize.saturating_add(len);
    if end > b.len() {
        return Err(short(msg_len, "header.frame_id", end.saturating_add(4)));
    }
    Ok((i64::from(sec) * 1_000_000_000 + i64::from(nanosec), end))
}

/// Decodes a CDR-serialized ROS2 `sensor_msgs/msg/Imu`: a 4-byte encapsulation header
/// (0x00 0x01 little-endian, 0x00 0x00 big-endian CDR; the two option bytes are ignored), then,
/// with alignment counted from the byte after that header, stamp (sec int32, nanosec uint32),
/// frame_id (uint32 length including the NUL, bytes), and the 37 float64 aligned to 8 bytes.
pub(crate) fn decode_cdr(msg: &[u8]) -> Result<ImuFields<'_>, MessageError> {
    let (order, b) = cdr_encapsulation(msg)?;
    let (stamp_ns, end) = cdr_header(b, order, msg.len())?;
    // the string's length counts its terminating NUL (an empty string may be written as 0)
    let frame_id = match b[12..end].split_last() {
        Some((0, text)) => text,
        _ => &b[12..end],
    };
    let aligned = end.div_ceil(8) * 8;
    let (angular_velocity, linear_acceleration) = body(b, aligned, 4, order)?;
    Ok(ImuFields {
        stamp_ns,
        frame_id,
        angular_velocity,
        linear_acceleration,
    })
}

/// A scalar message type read as a covariate: a measurement with a header (its stamp kept),
/// or a bare `std_msgs` number (no stamp: the log time stands for it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ScalarType {
    /// `sensor_msgs/Temperature`: header, float64 temperature (°C), float64 variance.
    Temperature,
    /// `sensor_msgs/FluidPressure`: header, float64 fluid_pressure (Pa), float64 variance.
    FluidPressure,
    /// `std_msgs/Float64`: float64 data.
    Float64,
    /// `std_msgs/Float32`: float32 data.
    Float32,
}

impl ScalarType {
    /// The type a container's type name stands for (ROS1 or ROS2 spelling).
    pub(crate) fn of(message_type: &str) -> Option<Self> {
        let (package, name) = message_type.split_once('/')?;
        let name = name.strip_prefix("msg/").unwrap_or(name);
        Some(match (package, name) {
            ("sensor_msgs", "Temperature") => ScalarType::Temperature,
            ("sensor_msgs", "FluidPressure") => ScalarType::FluidPressure,
            ("std_msgs", "Float64") => ScalarType::Float64,
            ("std_msgs", "Float32") => ScalarType::Float32,
            _ => return None,
        })
    }

    /// The ROS1 spelling, `sensor_msgs/Temperature`.
    pub(crate) fn name(self) -> &'static str {
        match self {
            ScalarType::Temperature => "sensor_msgs/Temperature",
            ScalarType::FluidPressure => "sensor_msgs/FluidPressure",
            ScalarType::Float64 => "std_msgs/Float64",
            ScalarType::Float32 => "std_msgs/Float32",
        }
    }

    /// The field read.
    pub(crate) fn field(self) -> &'static str {
        match self {
            ScalarType::Temperature => "temperature",
            ScalarType::FluidPressure => "fluid_pressure",
            ScalarType::Float64 | ScalarType::Float32 => "data",
        }
    }

    /// The unit the message definition gives the field (`None` for a bare number).
    pub(crate) fn unit(self) -> Option<&'static str> {
        match self {
            ScalarType::Temperature => Some("degC"),
            ScalarType::FluidPressure => Some("Pa"),
            ScalarType::Float64 | ScalarType::Float32 => None,
        }
    }

    fn has_header(self) -> bool {
        matches!(self, ScalarType::Temperature | ScalarType::FluidPressure)
    }
}

/// One scalar message: its header stamp (`None` without a header) and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScalarFields {
    pub(crate) stamp_ns: Option<i64>,
    pub(crate) value: f64,
}

/// The value of a scalar message whose body (after any header) starts at `at` of `b` (`shift`
/// bytes of encapsulation before `b`); ROS1 packs it, CDR aligns a float64 to 8 and a
/// float32 to 4.
fn scalar_body(
    b: &[u8],
    at: usize,
    shift: usize,
    order: Order,
    ty: ScalarType,
    cdr: bool,
) -> Result<f64, MessageError> {
    let align = |a: usize, to: usize| if cdr { a.div_ceil(to) * to } else { a };
    let field = ty.field();
    if ty == ScalarType::Float32 {
        let at = align(at, 4);
        if b.len() < at + 4 {
            return Err(short(b.len() + shift, field, at + 4 + shift));
        }
        let mut a = [0u8; 4];
        a.copy_from_slice(&b[at..at + 4]);
        return Ok(f64::from(match order {
            Order::Little => f32::from_le_bytes(a),
            Order::Big => f32::from_be_bytes(a),
        }));
    }
    let at = align(at, 8);
    // a header-bearing measurement also holds its variance: the whole message is checked
    let needed = at + if ty.has_header() { 16 } else { 8 };
    if b.len() < needed {
        let field = if b.len() < at + 8 { field } else { "variance" };
        let needed = if b.len() < at + 8 { at + 8 } else { needed };
        return Err(short(b.len() + shift, field, needed + shift));
    }
    Ok(f64_at(b, at, order))
}

/// Decodes a ROS1-serialized scalar message of type `ty`.
pub(crate) fn decode_scalar_ros1(msg: &[u8], ty: ScalarType) -> Result<ScalarFields, MessageError> {
    if !ty.has_header() {
        let value = scalar_body(msg, 0, 0, Order::Little, ty, false)?;
        return Ok(ScalarFields {
            stamp_ns: None,
            value,
        });
    }
    let (stamp_ns, end) = ros1_header(msg)?;
    let value = scalar_body(msg, end, 0, Order::Little, ty, false)?;
    Ok(ScalarFields {
        stamp_ns: Some(stamp_ns),
        value,
    })
}

/// Decodes a CDR-serialized ROS2 scalar message of type `ty` (encapsulation as
/// [`decode_cdr`]).
pub(crate) fn decode_scalar_cdr(msg: &[u8], ty: ScalarType) -> Result<ScalarFields, MessageError> {
    let (order, b) = cdr_encapsulation(msg)?;
    if !ty.has_header() {
        let value = scalar_body(b, 0, 4, order, ty, true)?;
        return Ok(ScalarFields {
            stamp_ns: None,
            value,
        });
    }
    let (stamp_ns, end) = cdr_header(b, order, msg.len())?;
    let value = scalar_body(b, end, 4, order, ty, true)?;
    Ok(ScalarFields {
        stamp_ns: Some(stamp_ns),
        value,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A CDR Imu with frame_id `f` (+ NUL), stamp (7, 9), gyro 1..3, accel 4..6, in `order`.
    fn cdr(frame: &str, big: bool) -> Vec<u8> {
        let u32b = |v: u32| {
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let f64b = |v: f64| {
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let mut m = vec![0, u8::from(!big), 0, 0];
        m.extend(u32b(7));
        m.extend(u32b(9));
        m.extend(u32b(frame.len() as u32 + 1));
        m.extend(frame.as_bytes());
        m.push(0);
        while (m.len() - 4) % 8 != 0 {
            m.push(0);
        }
        let mut values = [0.0f64; 37];
        values[3] = 1.0; // orientation.w
        values[13..16].copy_from_slice(&[1.0, 2.0, 3.0]);
        values[25..28].copy_from_slice(&[4.0, 5.0, 6.0]);
        for v in values {
            m.extend(f64b(v));
        }
        m
    }

    #[test]
    fn cdr_decodes_both_byte_orders_and_alignments() {
        for big in [false, true] {
            for frame in ["", "a", "imu", "imu_link", "imu_link_12"] {
                let m = cdr(frame, big);
                let d = decode_cdr(&m).unwrap();
                assert_eq!(d.stamp_ns, 7_000_000_009);
                assert_eq!(d.frame_id, frame.as_bytes());
                assert_eq!(d.angular_velocity, [1.0, 2.0, 3.0]);
                assert_eq!(d.linear_acceleration, [4.0, 5.0, 6.0]);
            }
        }
    }

    #[test]
    fn cdr_short_message_names_the_field() {
        let m = cdr("imu", false);
        // after the 4-byte encapsulation: 12 + 4 ("imu\0") = 16, already aligned to 8, so
        // orientation ends at 4 + 16 + 32 = 52
        let e = decode_cdr(&m[..50]).unwrap_err();
        assert_eq!(
            e,
            MessageError::Short {
                len: 50,
                field: "orientation",
                needed: 52
            }
        );
        let e = decode_cdr(&m[..m.len() - 1]).unwrap_err();
        assert!(matches!(
            e,
            MessageError::Short {
                field: "linear_acceleration_covariance",
                ..
            }
        ));
        assert!(matches!(
            decode_cdr(&m[..10]).unwrap_err(),
            MessageError::Short {
                field: "header",
                ..
            }
        ));
        let mut long = m.clone();
        long[12..16].copy_from_slice(&1000u32.to_le_bytes()); // frame_id of 1000 bytes
        assert!(matches!(
            decode_cdr(&long).unwrap_err(),
            MessageError::Short {
                field: "header.frame_id",
                ..
            }
        ));
    }

    #[test]
    fn cdr_rejects_other_encapsulations() {
        let mut m = cdr("imu", false);
        m[1] = 0x07;
        assert_eq!(
            decode_cdr(&m).unwrap_err(),
            MessageError::Encapsulation(0, 7)
        );
    }

    #[test]
    fn ros1_decodes_and_checks_lengths() {
        let mut m = Vec::new();
        m.extend(5u32.to_le_bytes());
        m.extend(7u32.to_le_bytes());
        m.extend(9u32.to_le_bytes());
        m.extend(3u32.to_le_bytes());
        m.extend(b"imu");
        let mut values = [0.0f64; 37];
        values[13..16].copy_from_slice(&[1.0, 2.0, 3.0]);
        values[25..28].copy_from_slice(&[4.0, 5.0, 6.0]);
        for v in values {
            m.extend(v.to_le_bytes());
        }
        let d = decode_ros1(&m).unwrap();
        assert_eq!(d.stamp_ns, 7_000_000_009);
        assert_eq!(d.frame_id, b"imu");
        assert_eq!(d.angular_velocity, [1.0, 2.0, 3.0]);
        assert_eq!(d.linear_acceleration, [4.0, 5.0, 6.0]);
        assert_eq!(
            decode_ros1(&m[..m.len() - 80]).unwrap_err(),
            MessageError::Short {
                len: m.len() - 80,
                field: "linear_acceleration",
                needed: 19 + 224
            }
        );
        assert!(decode_ros1(&m[..10]).is_err());
    }

    #[test]
    fn scalar_messages_decode_in_both_serializations() {
        // CDR Temperature: encapsulation, stamp (7, 9), frame "t\0" (len 2), pad to 8, value, variance
        let mut m = vec![0, 1, 0, 0];
        m.extend(7u32.to_le_bytes());
        m.extend(9u32.to_le_bytes());
        m.extend(2u32.to_le_bytes());
        m.extend(b"t\0");
        while (m.len() - 4) % 8 != 0 {
            m.push(0);
        }
        m.extend(21.5f64.to_le_bytes());
        m.extend(0.01f64.to_le_bytes());
        let d = decode_scalar_cdr(&m, ScalarType::Temperature).unwrap();
        assert_eq!(d.stamp_ns, Some(7_000_000_009));
        assert_eq!(d.value, 21.5);
        assert_eq!(
            decode_scalar_cdr(&m[..m.len() - 8], ScalarType::Temperature).unwrap_err(),
            MessageError::Short {
                len: m.len() - 8,
                field: "variance",
                needed: m.len()
            }
        );
        assert_eq!(
            decode_scalar_cdr(&m[..m.len() - 12], ScalarType::Temperature).unwrap_err(),
            MessageError::Short {
                len: m.len() - 12,
                field: "temperature",
                needed: m.len() - 8
            }
        );
        // CDR Float64 and Float32: no header
        let mut f = vec![0, 1, 0, 0];
        f.extend(3.25f64.to_le_bytes());
        let d = decode_scalar_cdr(&f, ScalarType::Float64).unwrap();
        assert_eq!((d.stamp_ns, d.value), (None, 3.25));
        let mut g = vec![0, 0, 0, 0];
        g.extend(1.5f32.to_be_bytes());
        assert_eq!(
            decode_scalar_cdr(&g, ScalarType::Float32).unwrap().value,
            1.5
        );
        assert!(decode_scalar_cdr(&g[..6], ScalarType::Float32).is_err());
        // ROS1 FluidPressure: seq, stamp, frame "p" (len 1), packed value and variance
        let mut r = Vec::new();
        for v in [1u32, 7, 9, 1] {
            r.extend(v.to_le_bytes());
        }
        r.push(b'p');
        r.extend(101325.0f64.to_le_bytes());
        r.extend(4.0f64.to_le_bytes());
        let d = decode_scalar_ros1(&r, ScalarType::FluidPressure).unwrap();
        assert_eq!((d.stamp_ns, d.value), (Some(7_000_000_009), 101325.0));
        assert!(decode_scalar_ros1(&r[..20], ScalarType::FluidPressure).is_err());
        assert_eq!(
            decode_scalar_ros1(&2.5f64.to_le_bytes(), ScalarType::Float64)
                .unwrap()
                .value,
            2.5
        );
    }

    #[test]
    fn scalar_types_by_name() {
        assert_eq!(
            ScalarType::of("sensor_msgs/msg/Temperature"),
            Some(ScalarType::Temperature)
        );
        assert_eq!(
            ScalarType::of("sensor_msgs/Temperature"),
            Some(ScalarType::Temperature)
        );
        assert_eq!(
            ScalarType::of("std_msgs/msg/Float32"),
            Some(ScalarType::Float32)
        );
        assert_eq!(ScalarType::of("sensor_msgs/msg/Imu"), None);
        assert_eq!(ScalarType::of("Temperature"), None);
    }
}

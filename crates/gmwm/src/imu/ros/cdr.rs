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
    let (angular_velocity, linear_acceleration) = body(msg, end, 0, Order::Little)?;
    Ok(ImuFields {
        stamp_ns: i64::from(sec) * 1_000_000_000 + i64::from(nsec),
        frame_id: &msg[16..end],
        angular_velocity,
        linear_acceleration,
    })
}

/// Decodes a CDR-serialized ROS2 `sensor_msgs/msg/Imu`: a 4-byte encapsulation header
/// (0x00 0x01 little-endian, 0x00 0x00 big-endian CDR; the two option bytes are ignored), then,
/// with alignment counted from the byte after that header, stamp (sec int32, nanosec uint32),
/// frame_id (uint32 length including the NUL, bytes), and the 37 float64 aligned to 8 bytes.
pub(crate) fn decode_cdr(msg: &[u8]) -> Result<ImuFields<'_>, MessageError> {
    if msg.len() < 4 {
        return Err(short(msg.len(), "CDR encapsulation header", 4));
    }
    let order = match (msg[0], msg[1]) {
        (0x00, 0x01) => Order::Little,
        (0x00, 0x00) => Order::Big,
        (a, b) => return Err(MessageError::Encapsulation(a, b)),
    };
    let b = &msg[4..];
    if b.len() < 12 {
        return Err(short(msg.len(), "header", 16));
    }
    let sec = u32_at(b, 0, order) as i32;
    let nanosec = u32_at(b, 4, order);
    let len = u32_at(b, 8, order) as usize;
    let end = 12usize.saturating_add(len);
    if end > b.len() {
        return Err(short(msg.len(), "header.frame_id", end.saturating_add(4)));
    }
    // the string's length counts its terminating NUL (an empty string may be written as 0)
    let frame_id = match b[12..end].split_last() {
        Some((0, text)) => text,
        _ => &b[12..end],
    };
    let aligned = end.div_ceil(8) * 8;
    let (angular_velocity, linear_acceleration) = body(b, aligned, 4, order)?;
    Ok(ImuFields {
        stamp_ns: i64::from(sec) * 1_000_000_000 + i64::from(nanosec),
        frame_id,
        angular_velocity,
        linear_acceleration,
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
}

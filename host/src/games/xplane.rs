//! X-Plane's `DATA` packets (X-Plane 10, 11 and 12): the data sets ticked for "Network via UDP" in Settings > Data
//! Output.
//!
//! Source: Laminar Research's "Exchanging Data with X-Plane" (`Instructions/X-Plane SPECS from Austin/Exchanging
//! Data with X-Plane.rtfd`, shipped with X-Plane), section "DATA: Data output/input", and the Data Output screen's
//! row names. Little-endian:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0-3 | `DATA` | the message's label |
//! | 4 | an internal-use byte | any value |
//! | 5 + 36 k | one record per ticked data set: `index` (i32) and 8 values (f32) | |
//!
//! The records read, by the rows' numbers in X-Plane 10 to 12:
//!
//! | index | row | values used |
//! |---|---|---|
//! | 1 | Times | 0: real time (s) |
//! | 4 | Mach, VVI, g-load | 4: g-load normal, 5: axial, 6: side (multiples of g, gravity's reaction included: normal is 1 at rest) |
//! | 16 | Angular velocities | 0: Q (pitch), 1: P (roll), 2: R (yaw), rad/s |
//!
//! Row 17 (pitch, roll, headings) is not needed: the g-loads already hold gravity's reaction, which is what the
//! attitude would add. X-Plane 9 and earlier numbered angular velocities 17 and attitude 18; index 17 is therefore
//! ambiguous, and ringpod reads only X-Plane 10's numbering (16 = angular velocities). Data set 4 is required (tick
//! it); without 16 the rates are 0; without 1 the arrival time is used.
//!
//! ## Conversion
//!
//! X-Plane's body axes are the aeronautical ones (x forward, y right, z down): P positive right wing down, Q
//! positive nose up, R positive nose right. The g-loads are taken as specific force: normal positive pushing the
//! pilot up into the seat, axial positive forwards (accelerating), side positive to the right (the signs of axial
//! and side are not stated in the document: check with a capture).
//!
//! | ringpod | from |
//! |---|---|
//! | force x | `g * axial` |
//! | force y | `-g * side` |
//! | force z | `g * normal` |
//! | rate roll | `P` |
//! | rate pitch | `-Q` |
//! | rate yaw | `-R` |
//! | time | real time (data set 1), if sent |
//!
//! X-Plane 12 is reported to send data set 16 as P, Q, R in deg/s (ArduPilot's X-Plane link,
//! `libraries/SITL/SIM_XPlane.cpp`, reads it so for version 12 and as Q, P, R in rad/s for 11; X-Plane 12's own
//! `Data.txt` headers read `Q,deg/s`). The packet does not carry the version; no X-Plane 12 recording was found to
//! settle it, so the rates are read as X-Plane 10 and 11 send them (the book says to leave row 16 off with 12).

use super::{Format, Le, Sample, Telemetry, Unreadable, G};

/// The label.
pub const MAGIC: &[u8; 4] = b"DATA";
/// Label and internal byte.
pub const HEADER: usize = 5;
/// One record: index and 8 values.
pub const RECORD: usize = 36;

/// Reads the g-loads, angular velocities and time of a `DATA` packet.
pub fn decode(bytes: &[u8]) -> Result<Sample, Unreadable> {
    let format = Format::Xplane;
    if bytes.len() < HEADER + RECORD || !(bytes.len() - HEADER).is_multiple_of(RECORD) {
        return Err(Unreadable::Size {
            format,
            got: bytes.len(),
            expected: "5 bytes and whole records of 36 (41, 77, 113, ...)",
        });
    }
    if !bytes.starts_with(MAGIC) {
        return Err(Unreadable::Header {
            format,
            why: "its first bytes are not DATA".into(),
        });
    }
    let le = Le(bytes);
    let (mut time, mut g_loads, mut rates) = (None, None, None);
    for at in (HEADER..bytes.len()).step_by(RECORD) {
        let value = |i: usize| le.f32(at + 4 + 4 * i);
        match le.i32(at) {
            1 => time = time.or(Some(value(0))),
            4 => g_loads = g_loads.or(Some([value(4), value(5), value(6)])),
            16 => rates = rates.or(Some([value(0), value(1), value(2)])),
            _ => {}
        }
    }
    let [normal, axial, side] = g_loads.ok_or_else(|| Unreadable::NoMotion {
        format,
        why: "no g-loads (tick data set 4, \"Mach, VVI, g-load\", for UDP)".into(),
    })?;
    let [q, p, r] = rates.unwrap_or([0.0; 3]);
    Ok(Sample {
        time,
        telemetry: Telemetry {
            force: [G * axial, -G * side, G * normal],
            rate: [p, -q, -r],
        },
        lap: None,
    })
}

#[cfg(test)]
mod tests {
    use super::super::packets::xplane::record;
    use super::super::testing::{close, decoded, Writer};
    use super::*;

    /// A packet at real time 812.5 s (the shared builder).
    fn packet(g_loads: [f32; 3], qpr: [f32; 3], with_rates: bool) -> Vec<u8> {
        super::super::packets::xplane::packet(812.5, g_loads, qpr, with_rates)
    }

    #[test]
    fn data_sets_in_vehicle_axes() {
        let g = G;
        // At rest, level: one g normal.
        let s = decoded(Format::Xplane, &packet([1.0, 0.0, 0.0], [0.0; 3], true));
        assert_eq!(s.time, Some(812.5));
        assert!(
            close(s.telemetry.force, [0.0, 0.0, g]) && close(s.telemetry.rate, [0.0; 3]),
            "{s:?}"
        );
        // The take-off roll: 0.3 g forwards.
        let s = decoded(Format::Xplane, &packet([1.0, 0.3, 0.0], [0.0; 3], true));
        assert!(close(s.telemetry.force, [0.3 * g, 0.0, g]), "{s:?}");
        // A left turn on the ground: pushed left (side negative), yawing left (R negative).
        let s = decoded(Format::Xplane, &packet([1.0, 0.0, -0.2], [0.0, 0.0, -0.25], true));
        assert!(close(s.telemetry.force, [0.0, 0.2 * g, g]), "{s:?}");
        assert!(close(s.telemetry.rate, [0.0, 0.0, 0.25]), "{s:?}");
        // Parked nose up 10 degrees: the g-loads hold gravity's reaction.
        let (sp, cp) = 10f32.to_radians().sin_cos();
        let s = decoded(Format::Xplane, &packet([cp, sp, 0.0], [0.0; 3], true));
        assert!(
            close(s.telemetry.force, [g * f64::from(sp), 0.0, g * f64::from(cp)]),
            "{s:?}"
        );
        // Rolling right wing down, pitching up.
        let s = decoded(Format::Xplane, &packet([1.0, 0.0, 0.0], [0.1, 0.2, 0.0], true));
        assert!(close(s.telemetry.rate, [0.2, -0.1, 0.0]), "{s:?}");
        // Without data set 16: no rates.
        let s = decoded(Format::Xplane, &packet([1.0, 0.0, 0.0], [0.1, 0.2, 0.3], false));
        assert_eq!(s.telemetry.rate, [0.0; 3]);
    }

    #[test]
    fn other_packets_are_refused() {
        let good = packet([1.0, 0.0, 0.0], [0.0; 3], true);
        assert!(matches!(decode(&good[..good.len() - 1]), Err(Unreadable::Size { .. })));
        assert!(decode(&good[..5]).is_err());
        let mut p = good.clone();
        p[..4].copy_from_slice(b"DREF");
        assert!(matches!(decode(&p), Err(Unreadable::Header { .. })));
        // No g-loads: data set 4 not ticked.
        let mut w = Writer::default();
        w.bytes(MAGIC).u8(0);
        record(&mut w, 16, [0.0; 8]);
        assert!(matches!(decode(&w.0), Err(Unreadable::NoMotion { .. })));
        let mut nan = good;
        let at = HEADER + 2 * RECORD + 4 + 4 * 4;
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(super::super::decode(Format::Xplane, &nan).is_err());
    }
}

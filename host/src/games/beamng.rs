//! BeamNG.drive and BeamNG.tech: the MotionSim UDP protocol (version 1).
//!
//! Source: BeamNG's "Protocols" page (documentation.beamng.com/modding/protocols, section "MotionSim UDP
//! protocol"), whose struct the game's own sender, `lua/vehicle/protocols/motionSim.lua`, mirrors ("do not modify
//! this format without also updating the documentation"). Enabled in Options > Other > Protocols (MotionSim, IP,
//! port, update rate, smoothing); port 4444 by default. 88 bytes, little-endian:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0-3 | `magic` | `BNG1` |
//! | 4-15 | `posX/Y/Z` | f32, world position, m |
//! | 16-27 | `velX/Y/Z` | f32, world velocity, m/s |
//! | 28-39 | `accX/Y/Z` | f32, "acceleration of the car, gravity not included", m/s^2, the car's axes |
//! | 40-51 | `upVecX/Y/Z` | f32, "a vector pointing up relative to the car", world axes (z up) |
//! | 52-63 | `rollPos`, `pitchPos`, `yawPos` | f32, rad |
//! | 64-75 | `rollRate`, `pitchRate`, `yawRate` | f32, rad/s |
//! | 76-87 | `rollAcc`, `pitchAcc`, `yawAcc` | f32, rad/s^2 |
//!
//! (OutGauge, on the same page, carries gauges only; the older OutSim script was a template, deprecated with the
//! protocol overhaul of 0.32.) The packet carries no time.
//!
//! ## Conversion
//!
//! The page gives the fields, not their senses; the sender and BeamNG's vehicle axes give them. The sender fills
//! `acc` with the vehicle's acceleration sensor negated alike on all three axes (`accX = -sensorX`, `accY =
//! -sensorY`, `accZ = -sensorZ`), negates `rollPos` and `yawPos` ("seems like that is the standard for motion sims")
//! and sends the rates as `getRollPitchYawAngularVelocity` gives them. The sensor reads in the vehicle's own axes,
//! which BeamNG's "Refnodes" page (documentation.beamng.com/modding/vehicle/sections/refnodes) defines as x to the
//! left, y to the back, z up; negated, `accX` is positive to the right, `accY` forward and `accZ` **down**. So a
//! bump (the car pushed up) is a negative `accZ`, and ringpod's up is `-accZ`. Gravity's reaction is added (the
//! acceleration has none):
//!
//! | ringpod | from | sign |
//! |---|---|---|
//! | force x | `accY + g sin(pitchPos)` | derived: sensor y is back (refnodes), negated by the sender |
//! | force y | `-accX + g cos(pitchPos) sin(-rollPos)` | derived: sensor x is left, negated by the sender |
//! | force z | `-accZ + g * upVecZ` | derived: sensor z is up, negated by the sender; `upVecZ` published ("pointing up relative to the car") |
//! | rate roll | `rollRate` | derived: BeamNG's right-handed z-up sense, not negated by the sender |
//! | rate pitch | `-pitchRate` | derived, as roll |
//! | rate yaw | `yawRate` | derived, as roll |
//! | time | none: the arrival time is used | published: the packet has no time |
//!
//! No sign is published as such: each is read from the sender's code against the refnodes' axes; a capture of a
//! drive in the game is the check.

use super::{gravity_from_attitude, Format, Le, Sample, Telemetry, Unreadable, G};

/// The magic word.
pub const MAGIC: &[u8; 4] = b"BNG1";
/// The packet's size.
pub const SIZE: usize = 4 + 21 * 4;

/// Reads one MotionSim packet.
pub fn decode(bytes: &[u8]) -> Result<Sample, Unreadable> {
    if bytes.len() != SIZE {
        return Err(Unreadable::Size {
            format: Format::Beamng,
            got: bytes.len(),
            expected: "88 bytes (MotionSim version 1)",
        });
    }
    if !bytes.starts_with(MAGIC) {
        return Err(Unreadable::Header {
            format: Format::Beamng,
            why: "its first bytes are not BNG1".into(),
        });
    }
    let le = Le(bytes);
    let [ax, ay, az] = le.vec3(28);
    let up_z = le.f32(48);
    let (roll, pitch) = (le.f32(52), le.f32(56));
    let [roll_rate, pitch_rate, yaw_rate] = le.vec3(64);
    let gravity = gravity_from_attitude(pitch, -roll);
    Ok(Sample {
        time: None,
        telemetry: Telemetry {
            force: [ay + gravity[0], -ax + gravity[1], -az + G * up_z],
            rate: [roll_rate, -pitch_rate, yaw_rate],
        },
        // MotionSim carries motion only.
        lap: None,
    })
}

#[cfg(test)]
mod tests {
    use super::super::packets::beamng::packet;
    use super::super::testing::{close, decoded};
    use super::*;

    const UP: [f32; 3] = [0.0, 0.0, 1.0];

    #[test]
    fn motion_sim_in_vehicle_axes() {
        let g = G;
        // At rest, level.
        let s = decoded(Format::Beamng, &packet([0.0; 3], UP, [0.0; 3], [0.0; 3]));
        assert_eq!(s.time, None);
        assert!(
            close(s.telemetry.force, [0.0, 0.0, g]) && close(s.telemetry.rate, [0.0; 3]),
            "{s:?}"
        );
        // Accelerating at 3 m/s^2.
        let s = decoded(Format::Beamng, &packet([0.0, 3.0, 0.0], UP, [0.0; 3], [0.0; 3]));
        assert!(close(s.telemetry.force, [3.0, 0.0, g]), "{s:?}");
        // A left turn: accelerating towards the left (accX < 0), yawing left.
        let s = decoded(Format::Beamng, &packet([-6.0, 0.0, 0.0], UP, [0.0; 3], [0.0, 0.0, 0.3]));
        assert!(close(s.telemetry.force, [0.0, 6.0, g]), "{s:?}");
        assert!(close(s.telemetry.rate, [0.0, 0.0, 0.3]), "{s:?}");
        // Nose up 10 degrees at rest; the up vector leans back.
        let p = 10f32.to_radians();
        let (sp, cp) = p.sin_cos();
        let s = decoded(
            Format::Beamng,
            &packet([0.0; 3], [0.0, -sp, cp], [0.0, p, 0.0], [0.0, 0.2, 0.0]),
        );
        let (sp, cp) = (f64::from(sp), f64::from(cp));
        assert!(close(s.telemetry.force, [g * sp, 0.0, g * cp]), "{s:?}");
        // Pitching up is a negative pitch rate about ringpod's left axis.
        assert!(close(s.telemetry.rate, [0.0, -0.2, 0.0]), "{s:?}");
        // A bump: the car pushed up at 4 m/s^2, its sensor reading +4 on its up axis, sent negated.
        let s = decoded(Format::Beamng, &packet([0.0, 0.0, -4.0], UP, [0.0; 3], [0.0; 3]));
        assert!(close(s.telemetry.force, [0.0, 0.0, g + 4.0]), "more than 1 g: {s:?}");
        // Right side down 10 degrees (rollPos negative, its sense being left side down): the seat pushes left.
        let s = decoded(
            Format::Beamng,
            &packet([0.0; 3], [sp as f32, 0.0, cp as f32], [-p, 0.0, 0.0], [0.0; 3]),
        );
        assert!(close(s.telemetry.force, [0.0, g * sp, g * cp]), "{s:?}");
    }

    #[test]
    fn other_packets_are_refused() {
        let good = packet([0.0; 3], UP, [0.0; 3], [0.0; 3]);
        assert!(matches!(decode(&good[..87]), Err(Unreadable::Size { .. })));
        let mut outgauge = good.clone();
        outgauge.resize(96, 0);
        assert!(decode(&outgauge).is_err());
        let mut p = good.clone();
        p[..4].copy_from_slice(b"BNG2");
        assert!(matches!(decode(&p), Err(Unreadable::Header { .. })));
        let mut nan = good;
        nan[28..32].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(super::super::decode(Format::Beamng, &nan).is_err());
    }
}

//! Forza "Data Out": Forza Motorsport 7 and Forza Motorsport (2023), Sled or Dash; Forza Horizon 4 and 5.
//!
//! Sources: Turn 10's "Forza Motorsport Data Out Documentation" (support.forzamotorsport.net, article
//! 21742934024211: sections "Configuration", "Output Structures", "Sled", "Dash"), which repeats the FM7 "Data Out
//! feature details" post (forums.forza.net, topic 74013), and Playground's "Forza Horizon 6 Data Out
//! Documentation" (support.forza.net, article 51744149102611) for the Horizon packet of 324 bytes. Little-endian:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0-3 | `IsRaceOn` | s32: 1 when the race is on, 0 in menus or when the race is stopped |
//! | 4-7 | `TimestampMS` | u32, ms ("can overflow to 0 eventually") |
//! | 8-19 | `EngineMaxRpm`, `EngineIdleRpm`, `CurrentEngineRpm` | f32 |
//! | 20-31 | `AccelerationX/Y/Z` | f32, m/s^2, "in the car's local space; X = right, Y = up, Z = forward" |
//! | 32-43 | `VelocityX/Y/Z` | f32, m/s, same axes |
//! | 44-55 | `AngularVelocityX/Y/Z` | f32, rad/s, "X = pitch, Y = yaw, Z = roll" |
//! | 56-67 | `Yaw`, `Pitch`, `Roll` | f32, rad |
//! | 68-211 | suspension, slip, wheel speed, rumble, puddle, surface rumble, slip angle, combined slip, suspension travel | 4 x 9 values |
//! | 212-231 | `CarOrdinal`, `CarClass`, `CarPerformanceIndex`, `DrivetrainType`, `NumCylinders` | s32; end of Sled (232 bytes) |
//! | 232-310 | Dash: position, speed, power, torque, tyre temperatures, boost, fuel, distance, lap times, lap, position, inputs, gear, steer, driving line | FM7 Dash: 311 bytes |
//! | 311-330 | `TireWearFL/FR/RL/RR`, `TrackOrdinal` | Forza Motorsport (2023) Dash: 331 bytes |
//!
//! Forza Horizon 4 and 5 send the Sled fields, 12 bytes of their own, the Dash fields and one more byte: 324 bytes.
//! Motion is in the Sled fields, at the same offsets in all four sizes.
//!
//! `IsRaceOn = 0` (menus, paused, the race stopped) is no motion, not a car at rest, and no error either: the game
//! keeps sending while the player is in its menus, so such a packet is skipped ([`Unreadable::Skipped`]) and
//! counted apart; the stream's idle path then washes out to neutral as it does when a game stops sending, and
//! `cue` rests through the pause.
//!
//! ## Conversion
//!
//! The car's local space (X right, Y up, Z forward) is left-handed, so its rotations turn by the left-hand rule:
//! a positive rate about X is nose down, about Y a turn to the right, about Z the right side rising. ringpod's axes
//! are right-handed (x forward, y left, z up). The acceleration is taken as the car's (without gravity, as its
//! name says), and gravity's reaction added from `Pitch` and `Roll`, taken in the same left-handed sense (positive
//! pitch nose down, positive roll right side up):
//!
//! | ringpod | from |
//! |---|---|
//! | force x | `AccelerationZ + g sin(-Pitch)` |
//! | force y | `-AccelerationX + g cos(Pitch) sin(-Roll)` |
//! | force z | `AccelerationY + g cos(Pitch) cos(Roll)` |
//! | rate roll | `-AngularVelocityZ` |
//! | rate pitch | `AngularVelocityX` |
//! | rate yaw | `-AngularVelocityY` |
//! | time | `TimestampMS / 1000` |
//! | lap | Dash: `DistanceTraveled` (m) and `LapNumber` (u16) at 280 and 300 (Horizon: 292 and 312); Sled: none |
//!
//! The documentation gives the axes, not the sense of the rotations nor whether the acceleration holds gravity.
//! Two real Forza Motorsport 7 laps (forza-telemetry, `austinbaccus/forza-telemetry`, `data/laguna-seca.csv` and
//! `data/nurburgring.csv`) settle all but one by their own kinematics and the tracks' real directions: a positive
//! `AngularVelocityY` turns right (anticlockwise Laguna Seca integrates to -2 pi, the clockwise Nürburgring to
//! +2 pi), `AccelerationX` is positive right (it follows `VelocityZ * AngularVelocityY`), `AccelerationZ` forwards
//! (it follows the speed's derivative), gravity is not in the acceleration, and a positive `Pitch` and
//! `AngularVelocityX` are nose down (`Pitch` against the road's slope: -0.998). The roll angle's sense is still
//! assumed (body roll and road banking confound it; the roll rate agrees with the angle's derivative): check it
//! with a capture (at rest on a camber sloping down to the right, force y > 0).

use super::{add, gravity_from_attitude, Format, LapPosition, Le, Sample, Telemetry, Unreadable};

/// Sled.
pub const SLED: usize = 232;
/// Forza Motorsport 7 Dash.
pub const DASH_FM7: usize = 311;
/// Forza Horizon 4 and 5.
pub const HORIZON: usize = 324;
/// Forza Motorsport (2023) Dash.
pub const DASH_FM2023: usize = 331;
/// Every size.
pub const SIZES: [usize; 4] = [SLED, DASH_FM7, HORIZON, DASH_FM2023];

/// Reads the Sled fields of any of the packets.
pub fn decode(bytes: &[u8]) -> Result<Sample, Unreadable> {
    if !SIZES.contains(&bytes.len()) {
        return Err(Unreadable::Size {
            format: Format::Forza,
            got: bytes.len(),
            expected: "232 (Sled), 311 (FM7 Dash), 324 (Horizon) or 331 (FM 2023 Dash) bytes",
        });
    }
    let le = Le(bytes);
    match le.i32(0) {
        1 => {}
        0 => {
            return Err(Unreadable::Skipped {
                format: Format::Forza,
                why: "IsRaceOn is 0: in the menus, paused or the race stopped".into(),
            })
        }
        other => {
            return Err(Unreadable::Header {
                format: Format::Forza,
                why: format!("IsRaceOn is {other}, where Forza sends 0 or 1"),
            })
        }
    }
    let [ax, ay, az] = le.vec3(20);
    let [wx, wy, wz] = le.vec3(44);
    let (pitch, roll) = (le.f32(60), le.f32(64));
    Ok(Sample {
        time: Some(f64::from(le.u32(4)) / 1000.0),
        telemetry: Telemetry {
            force: add([az, -ax, ay], gravity_from_attitude(-pitch, -roll)),
            rate: [-wz, wx, -wy],
        },
        lap: lap(bytes),
    })
}

/// `DistanceTraveled` (f32, m) and `LapNumber` (u16) of a Dash packet: 48 and 68 bytes into the Dash fields (after
/// position, speed, power, torque, four tyre temperatures, boost and fuel; and after the three lap times and
/// `CurrentRaceTime`), which start at 232 (FM7, FM 2023) or 244 (Horizon's 12 bytes of its own first). Sled has
/// neither.
fn lap(bytes: &[u8]) -> Option<LapPosition> {
    let dash = match bytes.len() {
        DASH_FM7 | DASH_FM2023 => SLED,
        HORIZON => SLED + 12,
        _ => return None,
    };
    let le = Le(bytes);
    Some(LapPosition::Travelled {
        distance: le.f32(dash + 48),
        lap: u32::from(le.u16(dash + 68)),
    })
}

#[cfg(test)]
mod tests {
    use super::super::testing::{close, decoded};
    use super::super::G;
    use super::*;

    /// A packet of `size` at 12.345 s (the shared builder).
    fn packet(size: usize, race_on: i32, accel: [f32; 3], ang_vel: [f32; 3], ypr: [f32; 3]) -> Vec<u8> {
        super::super::packets::forza::packet(size, race_on, 12_345, accel, ang_vel, ypr)
    }

    #[test]
    fn sled_and_dash_in_vehicle_axes() {
        let g = G;
        for size in SIZES {
            // At rest, level.
            let s = decoded(Format::Forza, &packet(size, 1, [0.0; 3], [0.0; 3], [1.0, 0.0, 0.0]));
            assert_eq!(s.time, Some(12.345));
            assert!(
                close(s.telemetry.force, [0.0, 0.0, g]) && close(s.telemetry.rate, [0.0; 3]),
                "{s:?}"
            );
            // Accelerating at 4 m/s^2 (Z forward).
            let s = decoded(Format::Forza, &packet(size, 1, [0.0, 0.0, 4.0], [0.0; 3], [0.0; 3]));
            assert!(close(s.telemetry.force, [4.0, 0.0, g]), "{s:?}");
            // A left turn: accelerating towards the car's left (X negative), yawing left (Y negative by the
            // left-hand rule about up).
            let s = decoded(
                Format::Forza,
                &packet(size, 1, [-5.0, 0.0, 0.0], [0.0, -0.4, 0.0], [0.0; 3]),
            );
            assert!(close(s.telemetry.force, [0.0, 5.0, g]), "{s:?}");
            assert!(close(s.telemetry.rate, [0.0, 0.0, 0.4]), "{s:?}");
            // Nose up 10 degrees at rest (Pitch negative: positive is nose down).
            let p = 10f32.to_radians();
            let s = decoded(Format::Forza, &packet(size, 1, [0.0; 3], [0.0; 3], [0.0, -p, 0.0]));
            let (sp, cp) = f64::from(p).sin_cos();
            assert!(close(s.telemetry.force, [g * sp, 0.0, g * cp]), "{s:?}");
            // Pitching nose down at 0.2 rad/s and rolling the right side up at 0.1 rad/s.
            let s = decoded(Format::Forza, &packet(size, 1, [0.0; 3], [0.2, 0.0, 0.1], [0.0; 3]));
            assert!(close(s.telemetry.rate, [-0.1, 0.2, 0.0]), "{s:?}");
        }
    }

    #[test]
    fn paused_and_wrong_packets_are_refused() {
        let paused = packet(SLED, 0, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(matches!(decode(&paused), Err(Unreadable::Skipped { .. })));
        let odd = packet(SLED, 7, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(matches!(decode(&odd), Err(Unreadable::Header { .. })));
        let good = packet(DASH_FM7, 1, [0.0; 3], [0.0; 3], [0.0; 3]);
        for len in [0, 231, 233, 310, 323, 400] {
            let mut p = good.clone();
            p.resize(len, 0);
            assert!(matches!(decode(&p), Err(Unreadable::Size { .. })), "{len}");
        }
        let mut nan = good;
        nan[24..28].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(super::super::decode(Format::Forza, &nan).is_err());
    }

    /// Dash (each size) carries `DistanceTraveled` and `LapNumber`, written field by field; Sled neither.
    #[test]
    fn dash_carries_the_distance_travelled_and_the_lap_number() {
        use super::super::packets::forza::on_lap;
        for size in [DASH_FM7, HORIZON, DASH_FM2023] {
            let p = on_lap(size, 1, 5, [0.0; 3], [0.0; 3], [0.0; 3], (4321.5, 7));
            assert_eq!(
                decoded(Format::Forza, &p).lap,
                Some(LapPosition::Travelled {
                    distance: 4321.5,
                    lap: 7
                }),
                "{size}"
            );
        }
        let sled = on_lap(SLED, 1, 5, [0.0; 3], [0.0; 3], [0.0; 3], (4321.5, 7));
        assert_eq!(decoded(Format::Forza, &sled).lap, None);
    }
}

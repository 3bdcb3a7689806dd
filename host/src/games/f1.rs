//! EA SPORTS F1 23, F1 24 and F1 25: the motion packet of the player's car.
//!
//! Source: EA's "F1 23 UDP Specification", "F1 24 UDP Specification" and "F1 25 UDP Specification" (the EA forums'
//! "General Discussion" threads, answers.ea.com/t5/General-Discussion/F1-23-UDP-Specification/td-p/12632888 and its
//! successors, with EA's C++ header "C++ structures for F1 25 UDP specification"): sections "Packet Header" and
//! "Motion Packet". Little-endian, packed:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0-1 | `m_packetFormat` | u16: 2023, 2024 or 2025 |
//! | 2 | `m_gameYear` | u8: 23, 24 or 25 |
//! | 3, 4, 5 | `m_gameMajorVersion`, `m_gameMinorVersion`, `m_packetVersion` | u8 |
//! | 6 | `m_packetId` | u8: 0 is motion |
//! | 7-14 | `m_sessionUID` | u64 |
//! | 15-18 | `m_sessionTime` | f32, s |
//! | 19-22, 23-26 | `m_frameIdentifier`, `m_overallFrameIdentifier` | u32 |
//! | 27 | `m_playerCarIndex` | u8, index into the cars |
//! | 28 | `m_secondaryPlayerCarIndex` | u8 |
//! | 29 + 60 i | `CarMotionData` of car i (22 cars) | 1349 bytes in all |
//!
//! `CarMotionData` (60 bytes): `m_worldPositionX/Y/Z` (3 f32, m), `m_worldVelocityX/Y/Z` (3 f32, m/s),
//! `m_worldForwardDirX/Y/Z` and `m_worldRightDirX/Y/Z` (6 i16, normalised: divide by 32767),
//! `m_gForceLateral`, `m_gForceLongitudinal`, `m_gForceVertical` (3 f32, g), `m_yaw`, `m_pitch`, `m_roll` (3 f32,
//! rad). F1 23, 24 and 25 use this same layout; F1 22 and earlier (format 2022 and below) had another header and
//! are refused. Every other packet id (session, lap data, car telemetry, ...: the game sends them all to the same
//! port) is skipped, not an error ([`Unreadable::Skipped`]; the motion packet is "only sent while player is in
//! control"; the extended motion packet, id 13, carries the player's angular velocity but no g-forces). A motion
//! packet while spectating (`m_playerCarIndex` 255) has no player's car: refused, saying so, rather than following
//! the spectated car. That car's index is only in the session packet (`m_spectatorCarIndex`), a packet sent a few
//! times a second, so the first motion packets would have no car to follow and a change of the spectated car would
//! throw the rider from one car's motion into another's; and a rig that moves with a car its rider does not drive
//! moves without warning. The rider drives a car of their own to cue it.
//!
//! ## Conversion
//!
//! The specification names the g-force components without their signs or whether gravity is in them ("Lateral
//! G-Force component", F1 23 to 25). A real F1 24 recording settles them by its own kinematics (five published
//! captures of every packet type, 63 to 95 motion packets each: `DavidHlavacek/IT52-NHLSF1`, `recordings/*.bin`,
//! commit `3918363`; no licence, so no excerpt is kept, only the derived check in `f1/recording.rs`): the world
//! velocity's change between motion packets under 0.1 s apart, projected on `m_worldRightDir`, against
//! `m_gForceLateral` correlates at -0.96 to -0.998 (slope -0.76 to -0.99), so lateral is positive towards the car's
//! *left*, as in Codemasters' DiRT games ([`super::codemasters`]); projected on `m_worldForwardDir` against
//! `m_gForceLongitudinal` at +0.87 to +0.995, positive forwards; projected on the car's up (right x forward, whose
//! world y is +0.96 to +1.00: the world is right-handed, y up) against `m_gForceVertical` at +0.69 to +0.88,
//! positive up, and its mean is -0.01 to 0.07 g, so no gravity is in any of them. ringpod adds gravity's reaction
//! from the direction vectors' up (y) components:
//!
//! | ringpod | from |
//! |---|---|
//! | force x | `g * m_gForceLongitudinal + g * forward.y` |
//! | force y | `g * m_gForceLateral - g * right.y` |
//! | force z | `g * m_gForceVertical + g * sqrt(1 - forward.y^2 - right.y^2)` |
//! | rate | 0: the motion packet has no angular rates (the cue comes from the forces alone) |
//! | time | `m_sessionTime` |
//! | lap | `m_lapDistance` of the player's car in the latest lap data packet (below) |
//!
//! ## Lap distance
//!
//! The motion packet has no lap distance: the lap data packet (id 2, "Frequency: Rate as specified in menus", as
//! the motion packet's) has it for every car, `LapData m_lapData[22]` after the header, then two bytes
//! (`m_timeTrialPBCarIdx`, `m_timeTrialRivalCarIdx`). The player's car is the header's `m_playerCarIndex`.
//! `m_lapDistance` is an f32 in metres, "Distance vehicle is around current lap in metres – could be negative if
//! line hasn't been crossed yet"; where it lies in `LapData` differs by year:
//!
//! | format | `LapData` | packet | `m_lapDistance` at | why |
//! |---|---|---|---|---|
//! | 2023 | 50 bytes | 1131 | 18 | after `m_deltaToCarInFrontInMS`, `m_deltaToRaceLeaderInMS` (u16 each) |
//! | 2024, 2025 | 57 bytes | 1285 | 20 | those deltas split into `..MSPart` (u16) and `..MinutesPart` (u8) |
//!
//! [`Reader`](super::Reader) keeps the player's last lap distance and gives it with each motion sample, so that a
//! motion sample's lap is at most one of the game's frames old.

use super::{add, gravity_from_axes, Format, LapPosition, Le, Sample, Telemetry, Unreadable, G};

/// The header's size.
pub const HEADER: usize = 29;
/// One car's motion data.
pub const CAR: usize = 60;
/// Cars in the packet.
pub const CARS: usize = 22;
/// The motion packet's size.
pub const MOTION_SIZE: usize = HEADER + CAR * CARS;
/// `m_playerCarIndex` while the game spectates: there is no player's car.
pub const SPECTATING: u8 = 255;

/// Whether the first bytes are an F1 23/24/25 header: the packet format, its year and a known packet id.
pub fn header_fits(bytes: &[u8]) -> bool {
    bytes.len() >= HEADER && {
        let format = Le(bytes).u16(0);
        (2023..=2025).contains(&format) && u16::from(bytes[2]) + 2000 == format && bytes[6] <= 15
    }
}

/// Reads the player's car from a motion packet.
pub fn decode(bytes: &[u8]) -> Result<Sample, Unreadable> {
    let format = Format::F1;
    if bytes.len() < HEADER {
        return Err(Unreadable::Size {
            format,
            got: bytes.len(),
            expected: "a 29-byte header, and 1349 bytes for the motion packet",
        });
    }
    let le = Le(bytes);
    let packet_format = le.u16(0);
    if !(2023..=2025).contains(&packet_format) {
        return Err(Unreadable::Header {
            format,
            why: format!("packet format {packet_format}, where F1 23, 24 and 25 send 2023, 2024 and 2025"),
        });
    }
    let id = bytes[6];
    if id != 0 {
        return Err(Unreadable::Skipped {
            format,
            why: format!("packet id {id}, not the motion packet (0)"),
        });
    }
    if bytes.len() != MOTION_SIZE {
        return Err(Unreadable::Size {
            format,
            got: bytes.len(),
            expected: "1349 bytes for the motion packet",
        });
    }
    let player = usize::from(bytes[27]);
    if player == usize::from(SPECTATING) {
        return Err(Unreadable::NoMotion {
            format,
            why: "player car index 255: the game is spectating, and ringpod cues the player's own car only: \
                  drive a car (a session of your own, not a spectated one) to cue it"
                .into(),
        });
    }
    if player >= CARS {
        return Err(Unreadable::NoMotion {
            format,
            why: format!("player car index {player}: not one of the {CARS} cars"),
        });
    }
    let at = HEADER + CAR * player;
    let dir = |i: usize| f64::from(le.i16(at + 24 + 2 * i)) / 32767.0;
    let (forward_up, right_up) = (dir(1), dir(4));
    let [lateral, longitudinal, vertical] = le.vec3(at + 36);
    // Gravity's reaction: unit vectors' y (world up) components, clamped against rounding of the i16s.
    let gravity = gravity_from_axes(forward_up.clamp(-1.0, 1.0), (-right_up).clamp(-1.0, 1.0));
    Ok(Sample {
        time: Some(le.f32(15)),
        telemetry: Telemetry {
            force: add([G * longitudinal, G * lateral, G * vertical], gravity),
            rate: [0.0; 3],
        },
        // In the lap data packet: the reader adds it.
        lap: None,
    })
}

/// The lap data packet's id.
pub const LAP_DATA: u8 = 2;

/// The player's lap distance (m) from a lap data packet (id 2) of F1 23, 24 or 25, or `None` for any other
/// datagram (another packet, another size, spectating).
pub fn lap(bytes: &[u8]) -> Option<LapPosition> {
    if !header_fits(bytes) || bytes[6] != LAP_DATA {
        return None;
    }
    let (car, at) = match Le(bytes).u16(0) {
        2023 => (50, 18),
        _ => (57, 20),
    };
    if bytes.len() != HEADER + CARS * car + 2 {
        return None;
    }
    let player = usize::from(bytes[27]);
    (player < CARS).then(|| LapPosition::Along(Le(bytes).f32(HEADER + car * player + at)))
}

#[cfg(test)]
mod recording;

#[cfg(test)]
mod tests {
    use super::super::recognise;
    use super::super::testing::{close, decoded};
    use super::*;

    /// A packet at session time 61.5 s (the shared builder).
    fn packet(format: u16, id: u8, player: u8, forward: [f32; 3], right: [f32; 3], g: [f32; 3]) -> Vec<u8> {
        super::super::packets::f1::packet(format, id, player, 61.5, forward, right, g)
    }

    const LEVEL_F: [f32; 3] = [0.0, 0.0, 1.0];
    const LEVEL_R: [f32; 3] = [1.0, 0.0, 0.0];

    #[test]
    fn the_players_car_in_vehicle_axes() {
        let g = G;
        for format in [2023, 2024, 2025] {
            // At rest, level.
            let s = decoded(Format::F1, &packet(format, 0, 3, LEVEL_F, LEVEL_R, [0.0; 3]));
            assert_eq!(s.time, Some(61.5));
            assert!(
                close(s.telemetry.force, [0.0, 0.0, g]) && s.telemetry.rate == [0.0; 3],
                "{s:?}"
            );
            // Accelerating at 0.5 g.
            let s = decoded(Format::F1, &packet(format, 0, 7, LEVEL_F, LEVEL_R, [0.0, 0.5, 0.0]));
            assert!(close(s.telemetry.force, [0.5 * g, 0.0, g]), "{s:?}");
            // A left turn: the car accelerates towards its left (lateral > 0), the seat pushes the rider left.
            let s = decoded(Format::F1, &packet(format, 0, 0, LEVEL_F, LEVEL_R, [2.0, 0.0, 0.0]));
            assert!(close(s.telemetry.force, [0.0, 2.0 * g, g]), "{s:?}");
            // Nose up 10 degrees at rest (forward has world y = sin 10 deg).
            let (sp, cp) = 10f32.to_radians().sin_cos();
            let s = decoded(Format::F1, &packet(format, 0, 21, [0.0, sp, cp], LEVEL_R, [0.0; 3]));
            let (sp, cp) = (f64::from(sp), f64::from(cp));
            assert!(close(s.telemetry.force, [g * sp, 0.0, g * cp]), "{s:?}");
            // Right side down 10 degrees (right has world y = -sin 10 deg): the seat pushes left.
            let s = decoded(
                Format::F1,
                &packet(format, 0, 1, LEVEL_F, [cp as f32, -sp as f32, 0.0], [0.0; 3]),
            );
            assert!(close(s.telemetry.force, [0.0, g * sp, g * cp]), "{s:?}");
        }
    }

    /// Each other packet type of each year, at its specified size: recognised as F1's (so that a session's first,
    /// non-motion packets name the game) and skipped, saying which id, never an error.
    #[test]
    fn every_other_packet_type_is_skipped() {
        use super::super::packets::f1::{other, other_ids};
        for format in [2023u16, 2024, 2025] {
            let ids: Vec<u8> = other_ids(format).iter().map(|(id, _)| *id).collect();
            let last = 13 + (format - 2023) as u8;
            assert_eq!(ids, (1..=last).collect::<Vec<_>>(), "{format}");
            for &(id, size) in other_ids(format) {
                let p = other(format, id, 12.5);
                assert_eq!(p.len(), size);
                assert_eq!(recognise(&p), Some(Format::F1), "{format} id {id}");
                match decode(&p) {
                    Err(Unreadable::Skipped {
                        format: Format::F1,
                        why,
                    }) => {
                        assert!(why.contains(&format!("packet id {id},")), "{why}")
                    }
                    other => panic!("{format} id {id}: {other:?}"),
                }
            }
        }
    }

    #[test]
    fn other_packets_and_games_are_refused() {
        let good = packet(2024, 0, 2, LEVEL_F, LEVEL_R, [0.0; 3]);
        // F1 22 (format 2022) and F1 2019.
        for old in [2022u16, 2019] {
            let mut p = good.clone();
            p[..2].copy_from_slice(&old.to_le_bytes());
            assert!(matches!(decode(&p), Err(Unreadable::Header { .. })), "{old}");
            assert_ne!(recognise(&p), Some(Format::F1));
        }
        // Wrong sizes.
        assert!(decode(&good[..1348]).is_err());
        assert!(decode(&good[..20]).is_err());
        // Spectating: no player car, said by name with what to do; another index beyond the cars.
        let mut p = good.clone();
        p[27] = SPECTATING;
        let e = decode(&p).unwrap_err();
        assert!(matches!(e, Unreadable::NoMotion { .. }), "{e}");
        assert!(
            e.to_string().contains("spectating") && e.to_string().contains("drive a car"),
            "{e}"
        );
        p[27] = 22;
        assert!(matches!(decode(&p), Err(Unreadable::NoMotion { .. })));
        // Not finite.
        let mut p = good;
        let at = HEADER + 2 * CAR + 36;
        p[at..at + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
        assert!(super::super::decode(Format::F1, &p).is_err());
    }

    /// The lap data packet of each year, every car's `LapData` written field by field: the player's
    /// `m_lapDistance` (not another car's), and the reader gives it with the next motion packets.
    #[test]
    fn the_players_lap_distance_comes_from_the_lap_data_packet() {
        use super::super::packets::f1::lap_data;
        use super::super::{Reader, TelemetryFormat};
        for format in [2023u16, 2024, 2025] {
            for player in [0u8, 5, 21] {
                let p = lap_data(format, player, 10.0, 2345.5);
                assert_eq!(lap(&p), Some(LapPosition::Along(2345.5)), "{format} slot {player}");
                assert!(matches!(decode(&p), Err(Unreadable::Skipped { .. })), "no motion in it");
            }
            let p = lap_data(format, 5, 10.0, -12.0);
            assert_eq!(lap(&p), Some(LapPosition::Along(-12.0)), "before the line: negative");
            assert_eq!(lap(&p[..p.len() - 1]), None, "{format}: another size");
            let mut spectating = p.clone();
            spectating[27] = SPECTATING;
            assert_eq!(lap(&spectating), None);
            let motion = packet(format, 0, 5, LEVEL_F, LEVEL_R, [0.0; 3]);
            assert_eq!(lap(&motion), None, "the motion packet has none");
            for asked in [TelemetryFormat::Game(Format::F1), TelemetryFormat::Auto] {
                let mut r = Reader::new(asked, None);
                assert_eq!(r.read(&motion).unwrap().unwrap().lap, None, "no lap data yet");
                assert_eq!(r.read(&p).unwrap(), None, "the lap data packet is no sample");
                assert_eq!(r.read(&motion).unwrap().unwrap().lap, Some(LapPosition::Along(-12.0)));
                r.read(&lap_data(format, 5, 10.1, 3.5)).unwrap();
                assert_eq!(r.read(&motion).unwrap().unwrap().lap, Some(LapPosition::Along(3.5)));
            }
            // A text reader takes nothing from F1's packets.
            let mut text = Reader::new(TelemetryFormat::Text, None);
            assert!(text.read(&p).is_err());
        }
    }
}

//! Live for Speed's `OutSimPack2`: the OutSim packet whose sections are chosen by `OutSim Opts` in `cfg.txt`.
//!
//! Source: Live for Speed's `docs/OutSimPack.txt` (0.7 series; later versions add the `OSO_EXTRA_1` bit) and
//! `docs/InSim.txt`, section "OutSim - MOTION SIMULATOR SUPPORT". `OutSim Opts` is hexadecimal; LFS writes the
//! sections in this order, each only when its bit is set, little-endian, packed:
//!
//! | bit | section | bytes | fields |
//! |---|---|---|---|
//! | 0x01 `OSO_HEADER` | `L`,`F`,`S`,`T` | 4 | the magic word |
//! | 0x02 `OSO_ID` | `ID` | 4 | i32, the `OutSim ID` of `cfg.txt` |
//! | 0x04 `OSO_TIME` | `Time` | 4 | u32, ms |
//! | 0x08 `OSO_MAIN` | `OSMain` | 60 | `AngVel`, `Heading`, `Pitch`, `Roll`, `Accel`, `Vel`, `Pos`: the classic packet's bytes 4-63 ([`super::outsim`]) |
//! | 0x10 `OSO_INPUTS` | `OSInputs` | 20 | `Throttle`, `Brake`, `InputSteer`, `Clutch`, `Handbrake`: 5 x f32 |
//! | 0x20 `OSO_DRIVE` | `Gear`, 3 spare bytes, `EngineAngVel`, `MaxTorqueAtVel` | 12 | |
//! | 0x40 `OSO_DISTANCE` | `CurrentLapDist`, `IndexedDistance` | 8 | 2 x f32, m |
//! | 0x80 `OSO_WHEELS` | `OSWheels[4]` | 160 | 4 x 40: 7 f32 (`SuspDeflect` ... `LeanRelToRoad`), 4 bytes (`AirTemp`, `SlipFraction`, `Touching`, spare), 2 f32 (`SlipRatio`, `TanSlipAngle`) |
//! | 0x100 `OSO_EXTRA_1` | `SteerTorque`, `Spare` | 8 | 2 x f32 |
//!
//! `ff` (all but extra) gives 272 bytes, `1ff` (all) 280. Cueing takes `OSMain`, converted exactly as the classic
//! packet (world axes, gravity's reaction added, turned into the car's frame, then x forward, y left, z up), and
//! `Time`; [`parse`] locates every section to find them and also returns the `ID`.
//!
//! ## Which sections, when only the bytes are known
//!
//! The packet does not say which bits were set, and sizes do not tell them apart: 4-byte `ID` and `Time`, 8-byte
//! `OSO_DISTANCE` and `OSO_EXTRA_1`, 20-byte inputs against drive plus distance, all trade places. [`parse`] takes
//! the `OutSim Opts` value and is exact. [`decode`] (the `outsim2` format without a value) needs the header (bit 1,
//! so that it is recognisable at all) and the main section (bit 8, or there is no motion), and of the sections
//! before `OSMain` only whether `ID` and `Time` are there changes what cueing reads; so among the bit sets that fit
//! the size it takes, deliberately: both `ID` and `Time` if some fitting set has both, else `Time` alone, else `ID`
//! alone, else neither. That is exact for `ff`, `1ff` and every set with both `ID` and `Time`, and for header plus
//! main alone (64 bytes, or 224 with wheels); a set with only one of `ID` and `Time` can be taken for the other
//! (an `ID` read as a time that never advances makes every sample after the first "not after the last one"), so
//! set both, or give the value.

use super::outsim;
use super::{Format, Le, Sample, Telemetry, Unreadable};

/// `OutSim Opts`: which sections a packet carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Opts(pub u16);

impl Opts {
    /// The `LFST` magic word.
    pub const HEADER: u16 = 0x01;
    /// The `OutSim ID`.
    pub const ID: u16 = 0x02;
    /// `Time` (ms).
    pub const TIME: u16 = 0x04;
    /// `OSMain`: the motion.
    pub const MAIN: u16 = 0x08;
    /// `OSInputs`.
    pub const INPUTS: u16 = 0x10;
    /// Gear and engine.
    pub const DRIVE: u16 = 0x20;
    /// Lap distance.
    pub const DISTANCE: u16 = 0x40;
    /// The four wheels.
    pub const WHEELS: u16 = 0x80;
    /// Steering torque.
    pub const EXTRA_1: u16 = 0x100;

    /// The sections in the order LFS writes them, with their sizes.
    const SECTIONS: [(u16, usize); 9] = [
        (Self::HEADER, 4),
        (Self::ID, 4),
        (Self::TIME, 4),
        (Self::MAIN, 60),
        (Self::INPUTS, 20),
        (Self::DRIVE, 12),
        (Self::DISTANCE, 8),
        (Self::WHEELS, 160),
        (Self::EXTRA_1, 8),
    ];

    fn has(self, bit: u16) -> bool {
        self.0 & bit != 0
    }

    /// Where each present section starts, in LFS's order, and the packet's size.
    pub fn layout(self) -> (Vec<(u16, usize)>, usize) {
        let mut at = 0;
        let mut sections = Vec::new();
        for (bit, size) in Self::SECTIONS {
            if self.has(bit) {
                sections.push((bit, at));
                at += size;
            }
        }
        (sections, at)
    }

    /// The packet's size.
    pub fn size(self) -> usize {
        self.layout().1
    }

    /// Where a section starts, if present (the tests hold the layout to the documented offsets).
    #[cfg(test)]
    pub fn offset(self, bit: u16) -> Option<usize> {
        self.layout().0.into_iter().find(|(b, _)| *b == bit).map(|(_, at)| at)
    }

    /// The bit set [`decode`] takes for a packet of `len` bytes with the header and the main section (the rule is
    /// in the module's documentation), or `None` when no such set has that size.
    pub fn infer(len: usize) -> Option<Opts> {
        let rank = |o: Opts| match (o.has(Self::ID), o.has(Self::TIME)) {
            (true, true) => 0,
            (false, true) => 1,
            (true, false) => 2,
            (false, false) => 3,
        };
        (0..0x200u16)
            .map(Opts)
            .filter(|o| o.has(Self::HEADER) && o.has(Self::MAIN) && o.size() == len)
            .min_by_key(|o| (rank(*o), o.0))
    }
}

/// The largest packet (`1ff`).
pub const MAX_SIZE: usize = 280;

/// What a packet carries that ringpod reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Packet {
    /// The `OutSim ID`, when `OSO_ID` is set.
    pub id: Option<i32>,
    /// `Time` (s), when `OSO_TIME` is set.
    pub time: Option<f64>,
    /// The motion in ringpod's axes, when `OSO_MAIN` is set.
    pub motion: Option<Telemetry<f64>>,
}

/// Reads a packet sent with `OutSim Opts` = `opts`: its size must be the one these sections make, and its header,
/// if the bit is set, `LFST`.
pub fn parse(bytes: &[u8], opts: Opts) -> Result<Packet, Unreadable> {
    let (sections, size) = opts.layout();
    if bytes.len() != size {
        return Err(Unreadable::Size {
            format: Format::Outsim2,
            got: bytes.len(),
            expected: "the size its OutSim Opts make",
        });
    }
    let le = Le(bytes);
    let mut packet = Packet {
        id: None,
        time: None,
        motion: None,
    };
    for (bit, at) in sections {
        match bit {
            Opts::HEADER if &bytes[at..at + 4] != b"LFST" => {
                return Err(Unreadable::Header {
                    format: Format::Outsim2,
                    why: "its first bytes are not LFST".into(),
                });
            }
            Opts::ID => packet.id = Some(le.i32(at)),
            Opts::TIME => packet.time = Some(f64::from(le.u32(at)) / 1000.0),
            Opts::MAIN => packet.motion = Some(outsim::main(le, at)),
            // Inputs, drive, distance, wheels and the extra section are not cueing's; their sizes placed the
            // sections after them.
            _ => {}
        }
    }
    Ok(packet)
}

/// Reads a packet whose `OutSim Opts` are not known: with the header, the main section, and the sections the
/// module's rule infers from its size.
pub fn decode(bytes: &[u8]) -> Result<Sample, Unreadable> {
    if !bytes.starts_with(b"LFST") {
        return Err(Unreadable::Header {
            format: Format::Outsim2,
            why: "no LFST header (set bit 1 of OutSim Opts, e.g. OutSim Opts ff)".into(),
        });
    }
    let opts = Opts::infer(bytes.len()).ok_or(Unreadable::Size {
        format: Format::Outsim2,
        got: bytes.len(),
        expected: "the size of a header, the main section and other sections (64 to 120, or 224 to 280, bytes)",
    })?;
    let packet = parse(bytes, opts)?;
    let telemetry = packet.motion.ok_or_else(|| Unreadable::NoMotion {
        format: Format::Outsim2,
        why: "no main section (set bit 8 of OutSim Opts)".into(),
    })?;
    Ok(Sample {
        time: packet.time,
        telemetry,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testing::{close, decoded};
    use super::super::G;
    use super::*;

    /// A packet as LFS writes it for `opts` (the shared builder), at 2.5 s, of the size the layout says.
    fn packet(opts: u16, ang_vel: [f32; 3], hpr: [f32; 3], accel: [f32; 3]) -> Vec<u8> {
        let bytes = super::super::packets::outsim2::packet(opts, 2500, ang_vel, hpr, accel);
        assert_eq!(bytes.len(), Opts(opts).size(), "{opts:#x}");
        bytes
    }

    #[test]
    fn sizes_are_the_documented_ones() {
        assert_eq!(Opts(0xff).size(), 272);
        assert_eq!(Opts(0x1ff).size(), MAX_SIZE);
        assert_eq!(Opts(0x09).size(), 64);
        assert_eq!(Opts(0xff).offset(Opts::MAIN), Some(12));
        assert_eq!(Opts(0xff).offset(Opts::WHEELS), Some(112));
        assert_eq!(Opts(0x1ff).offset(Opts::EXTRA_1), Some(272));
        assert_eq!(Opts::infer(272), Some(Opts(0xff)));
        assert_eq!(Opts::infer(280), Some(Opts(0x1ff)));
        assert_eq!(Opts::infer(64), Some(Opts(0x09)));
        // 68: ID or Time; Time is taken.
        assert_eq!(Opts::infer(68), Some(Opts(0x0d)));
        assert_eq!(Opts::infer(63), None);
        assert_eq!(Opts::infer(300), None);
    }

    #[test]
    fn every_section_set_places_the_motion() {
        let g = G;
        let p = 10f32.to_radians();
        let (sp, cp) = f64::from(p).sin_cos();
        for opts in (0..0x200u16).filter(|o| o & Opts::MAIN != 0) {
            // Nose up 10 degrees at rest, turning left at 0.5 rad/s (world z is up at heading 0).
            let bytes = packet(opts, [0.0, 0.0, 0.5], [0.0, p, 0.0], [0.0; 3]);
            let read = parse(&bytes, Opts(opts)).unwrap();
            assert_eq!(read.id, (opts & Opts::ID != 0).then_some(42), "{opts:#x}");
            assert_eq!(read.time, (opts & Opts::TIME != 0).then_some(2.5), "{opts:#x}");
            let m = read.motion.unwrap();
            assert!(close(m.force, [g * sp, 0.0, g * cp]), "{opts:#x}: {m:?}");
            assert!(m.rate[2] > 0.49, "{opts:#x}: {m:?}");
            // The wrong size for these sections is refused.
            assert!(parse(&bytes[..bytes.len() - 4], Opts(opts)).is_err());
        }
        // Without the main section: no motion.
        let bytes = packet(0xf7, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert_eq!(parse(&bytes, Opts(0xf7)).unwrap().motion, None);
    }

    #[test]
    fn all_sections_decode_without_the_opts() {
        let g = G;
        for opts in [0xff, 0x1ff, 0x0f, 0x8f, 0x09] {
            // At rest, level.
            let s = decoded(Format::Outsim2, &packet(opts, [0.0; 3], [1.0, 0.0, 0.0], [0.0; 3]));
            assert!(close(s.telemetry.force, [0.0, 0.0, g]), "{opts:#x}: {s:?}");
            assert_eq!(s.time, (opts & Opts::TIME != 0).then_some(2.5));
            // Accelerating forward at 3 m/s^2 facing world y.
            let s = decoded(Format::Outsim2, &packet(opts, [0.0; 3], [0.0; 3], [0.0, 3.0, 0.0]));
            assert!(close(s.telemetry.force, [3.0, 0.0, g]), "{opts:#x}: {s:?}");
            // A left turn: centripetal acceleration to world -x (the car's left), yaw rate up.
            let s = decoded(
                Format::Outsim2,
                &packet(opts, [0.0, 0.0, 0.5], [0.0; 3], [-4.0, 0.0, 0.0]),
            );
            assert!(close(s.telemetry.force, [0.0, 4.0, g]), "{opts:#x}: {s:?}");
            assert!(close(s.telemetry.rate, [0.0, 0.0, 0.5]), "{opts:#x}: {s:?}");
            // Nose up 10 degrees at rest: pushed back as when accelerating.
            let p = 10f32.to_radians();
            let s = decoded(Format::Outsim2, &packet(opts, [0.0; 3], [0.0, p, 0.0], [0.0; 3]));
            assert!(s.telemetry.force[0] > 1.6, "{opts:#x}: {s:?}");
        }
    }

    #[test]
    fn wrong_packets_are_refused() {
        let mut bytes = packet(0xff, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(decode(&bytes[..271]).is_err());
        bytes[0] = b'X';
        assert!(matches!(decode(&bytes), Err(Unreadable::Header { .. })));
        // No header bit: not readable without the opts, readable with them.
        let bytes = packet(0xfe, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(decode(&bytes).is_err());
        assert!(parse(&bytes, Opts(0xfe)).unwrap().motion.is_some());
        // A header and no main section.
        let bytes = packet(0x07, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(decode(&bytes).is_err());
        let mut nan = packet(0xff, [0.0; 3], [0.0; 3], [0.0; 3]);
        nan[12 + 24..12 + 28].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(matches!(
            super::super::decode(Format::Outsim2, &nan),
            Err(Unreadable::NotFinite { .. })
        ));
    }
}

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
//! `ID` + `Time`, `OSO_DISTANCE` and `OSO_EXTRA_1`, 20-byte `OSO_INPUTS` against `ID` + `Time` + `OSO_DRIVE`, all
//! trade places (`ff` and `1f9` are both 272 bytes). Cueing reads `OSMain`, placed by whether `ID` and `Time` come
//! before it, and `Time`. [`parse`] takes the `OutSim Opts` value (`--outsim-opts HEX`, [`Opts::parse_hex`]) and
//! is exact for every set. [`decode`] without it needs the header (bit 1, or the packet is not recognisable) and
//! decodes a packet only when every set with the header bit that has its size agrees on `ID` and `Time` (no set
//! without the main section has the size of one with it: 8 to 60 or 164 to 220 bytes against 64 to 120 or 224 to
//! 280), so it is exact whenever it answers (`1ff`, header plus main, 64 bytes, and others); for a size that
//! several placements fit it refuses, naming them and `--outsim-opts`, rather than read another section as the
//! time.

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

    /// Every bit LFS defines.
    pub const ALL: u16 = 0x1ff;

    /// The sets with the header bit that make a packet of `len` bytes, by whether they have `ID` and `Time` (the
    /// placements of what cueing reads), each placement with its smallest set.
    fn fitting(len: usize) -> Vec<((bool, bool), Opts)> {
        let mut found: Vec<((bool, bool), Opts)> = Vec::new();
        for o in (0..=Self::ALL)
            .map(Opts)
            .filter(|o| o.has(Self::HEADER) && o.size() == len)
        {
            let placement = (o.has(Self::ID), o.has(Self::TIME));
            if !found.iter().any(|(p, _)| *p == placement) {
                found.push((placement, o));
            }
        }
        found
    }

    /// The set [`decode`] reads a packet of `len` bytes with: one whose placement of `ID` and `Time` every fitting
    /// set shares, or why there is none (no fitting set, or several placements).
    pub fn infer(len: usize) -> Result<Opts, Unreadable> {
        let fitting = Self::fitting(len);
        match fitting.as_slice() {
            [] => Err(Unreadable::Size {
                format: Format::Outsim2,
                got: len,
                expected: "the size of a header, the main section and other sections (64 to 120, or 224 to 280, bytes)",
            }),
            [(_, o)] => Ok(*o),
            several => {
                let named: Vec<String> = several
                    .iter()
                    .map(|((id, time), o)| {
                        let what = match (id, time) {
                            (true, true) => "ID and Time",
                            (false, true) => "Time only",
                            (true, false) => "ID only",
                            (false, false) => "neither ID nor Time",
                        };
                        format!("{:x} ({what})", o.0)
                    })
                    .collect();
                Err(Unreadable::Ambiguous {
                    format: Format::Outsim2,
                    why: format!(
                        "{len} bytes fit OutSim Opts that place the time differently: {}; give the OutSim Opts of \
                         LFS's cfg.txt with --outsim-opts HEX",
                        named.join(", ")
                    ),
                })
            }
        }
    }

    /// `OutSim Opts` as LFS's `cfg.txt` writes it, hexadecimal (`1ff`, `0x1ff`): bits LFS defines only, and the
    /// main section's among them (without it a packet carries no motion).
    pub fn parse_hex(text: &str) -> Result<Opts, String> {
        let digits = text.trim();
        let digits = digits
            .strip_prefix("0x")
            .or_else(|| digits.strip_prefix("0X"))
            .unwrap_or(digits);
        let shown: String = text.chars().take(20).collect();
        let value = u16::from_str_radix(digits, 16)
            .ok()
            .filter(|v| *v <= Self::ALL && !digits.is_empty() && digits.len() <= 4)
            .ok_or_else(|| format!("OutSim Opts `{shown}` is not a hexadecimal number from 0 to 1ff"))?;
        if value & Self::MAIN == 0 {
            return Err(format!(
                "OutSim Opts {value:x} has no main section (bit 8): its packets carry no motion"
            ));
        }
        Ok(Opts(value))
    }

    /// The option set a reader of `format` takes: `given` (the command line's), else the cueing file's
    /// `outsim_opts` (its profile's), checked; none for a format that does not read `OutSimPack2`, so that one
    /// cueing file serves every game.
    pub fn chosen(
        format: super::TelemetryFormat,
        given: Option<Opts>,
        cue_config: Option<&std::path::Path>,
        profile: Option<&str>,
    ) -> Result<Option<Opts>, crate::input::cueing::CueingFileError> {
        if !format.reads_outsim2() {
            return Ok(None);
        }
        if given.is_some() {
            return Ok(given);
        }
        let Some(hex) = crate::input::cueing::load_outsim_opts(cue_config, profile)? else {
            return Ok(None);
        };
        Opts::parse_hex(&hex)
            .map(Some)
            .map_err(|e| crate::input::cueing::CueingFileError::File {
                path: cue_config.map(std::path::Path::to_path_buf).unwrap_or_default(),
                reason: format!("outsim_opts: {e}"),
            })
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

/// Reads a packet sent with `opts` when given, else one whose sections its size tells (the module's rule): its
/// time and motion.
pub fn decode(bytes: &[u8], opts: Option<Opts>) -> Result<Sample, Unreadable> {
    let opts = match opts {
        Some(opts) => opts,
        None if !bytes.starts_with(b"LFST") => {
            return Err(Unreadable::Header {
                format: Format::Outsim2,
                why: "no LFST header (set bit 1 of OutSim Opts, e.g. OutSim Opts 1ff, or give --outsim-opts)".into(),
            });
        }
        None => Opts::infer(bytes.len())?,
    };
    let packet = parse(bytes, opts)?;
    let telemetry = packet.motion.ok_or_else(|| Unreadable::NoMotion {
        format: Format::Outsim2,
        why: "no main section (set bit 8 of OutSim Opts)".into(),
    })?;
    Ok(Sample {
        time: packet.time,
        telemetry,
        lap: None,
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
        assert_eq!(Opts(0x1f9).size(), 272);
        assert_eq!(Opts::infer(280), Ok(Opts(0x1ff)));
        assert_eq!(Opts::infer(64), Ok(Opts(0x09)));
        // The sizes of the sets the issue of exactness is about: each fits a set with ID and Time too.
        for (opts, len) in [
            (0x19, 84),
            (0x49, 72),
            (0x109, 72),
            (0x1f9, 272),
            (0xff, 272),
            (0x0d, 68),
        ] {
            assert_eq!(Opts(opts).size(), len);
            let e = Opts::infer(len).unwrap_err().to_string();
            assert!(
                e.contains(&format!("{len} bytes")) && e.contains("--outsim-opts"),
                "{e}"
            );
        }
        assert!(matches!(Opts::infer(63), Err(Unreadable::Size { .. })));
        assert!(matches!(Opts::infer(300), Err(Unreadable::Size { .. })));
        // No set without the main section has the size of one with it.
        for a in (0..=Opts::ALL).filter(|o| o & Opts::MAIN == 0) {
            for b in (0..=Opts::ALL).filter(|o| o & Opts::MAIN != 0) {
                assert!(Opts(a).size() != Opts(b).size() || a & 1 != b & 1, "{a:x} {b:x}");
            }
        }
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

    /// Every one of the 512 `OutSim Opts` sets (the 256 with the main section among them), packets built field by
    /// field: with the value given, each set with the main section decodes exactly (its time, or none, and its
    /// motion) and each without is refused as carrying no motion; without the value, a set with the header decodes
    /// exactly or is refused naming the ambiguity and `--outsim-opts`, never read wrongly.
    #[test]
    fn every_option_set_decodes_exactly_or_is_refused_by_name() {
        let g = G;
        let (mut exact, mut ambiguous) = (0, 0);
        for opts in 0..=Opts::ALL {
            // Accelerating forward at 3 m/s^2 facing world y, turning left at 0.5 rad/s.
            let bytes = packet(opts, [0.0, 0.0, 0.5], [0.0; 3], [0.0, 3.0, 0.0]);
            let time = (opts & Opts::TIME != 0).then_some(2.5);
            let given = decode(&bytes, Some(Opts(opts)));
            if opts & Opts::MAIN == 0 {
                assert!(matches!(given, Err(Unreadable::NoMotion { .. })), "{opts:x}: {given:?}");
                assert!(Opts::parse_hex(&format!("{opts:x}")).is_err(), "{opts:x}");
                continue;
            }
            assert_eq!(Opts::parse_hex(&format!("{opts:x}")), Ok(Opts(opts)));
            let s = given.unwrap_or_else(|e| panic!("{opts:x}: {e}"));
            assert_eq!(s.time, time, "{opts:x}");
            assert!(close(s.telemetry.force, [3.0, 0.0, g]), "{opts:x}: {s:?}");
            assert!(close(s.telemetry.rate, [0.0, 0.0, 0.5]), "{opts:x}: {s:?}");
            if opts & Opts::HEADER == 0 {
                assert!(
                    matches!(decode(&bytes, None), Err(Unreadable::Header { .. })),
                    "{opts:x}"
                );
                continue;
            }
            match decode(&bytes, None) {
                Ok(inferred) => {
                    exact += 1;
                    assert_eq!(inferred, s, "{opts:x}");
                    assert_eq!(decoded(Format::Outsim2, &bytes), s, "{opts:x}");
                }
                Err(e) => {
                    ambiguous += 1;
                    let text = e.to_string();
                    assert!(matches!(e, Unreadable::Ambiguous { .. }), "{opts:x}: {text}");
                    assert!(text.contains(&format!("{} bytes", bytes.len())), "{text}");
                    assert!(
                        text.contains(&format!("{opts:x} (")) || text.contains("--outsim-opts"),
                        "{text}"
                    );
                }
            }
        }
        // 1ff, 09 and the other sizes one placement has are read without the value.
        assert_eq!(exact + ambiguous, 128);
        assert!(exact >= 2, "{exact}");
        // A packet of another set's size is refused with the value given, not misread.
        let bytes = packet(0xff, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(decode(&bytes, Some(Opts(0x1ff))).is_err());
    }

    #[test]
    fn option_values_are_read_as_cfg_txt_writes_them() {
        assert_eq!(Opts::parse_hex("1ff"), Ok(Opts(0x1ff)));
        assert_eq!(Opts::parse_hex(" 0x1F9 "), Ok(Opts(0x1f9)));
        for bad in ["", "0x", "200", "ffff", "g", "-1", "1ff1", "7"] {
            assert!(Opts::parse_hex(bad).is_err(), "{bad}");
        }
        assert!(Opts::parse_hex(&"9".repeat(300)).unwrap_err().len() < 120);
    }

    #[test]
    fn wrong_packets_are_refused() {
        let mut bytes = packet(0xff, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(decode(&bytes[..271], None).is_err());
        bytes[0] = b'X';
        assert!(matches!(decode(&bytes, None), Err(Unreadable::Header { .. })));
        // No header bit: not readable without the opts, readable with them.
        let bytes = packet(0xfe, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(decode(&bytes, None).is_err());
        assert!(parse(&bytes, Opts(0xfe)).unwrap().motion.is_some());
        // A header and no main section.
        let bytes = packet(0x07, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert!(decode(&bytes, None).is_err());
        let mut nan = packet(0x1ff, [0.0; 3], [0.0; 3], [0.0; 3]);
        nan[12 + 24..12 + 28].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(matches!(
            super::super::decode(Format::Outsim2, &nan),
            Err(Unreadable::NotFinite { .. })
        ));
    }
}

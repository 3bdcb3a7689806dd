//! Live for Speed's classic OutSim packet (`OutSimPack`, sent when `OutSim Opts` is 0), and its motion data, which
//! `OutSimPack2`'s `OSMain` section repeats byte for byte ([`main`]).
//!
//! Source: Live for Speed's `docs/InSim.txt`, section "OutSim - MOTION SIMULATOR SUPPORT", and
//! `docs/OutSimPack.txt` (the `OutSimMain` struct: "like old OutSimPack but without Time (first element) or ID
//! (last element)"), shipped with the game (0.6 and 0.7 series). Little-endian:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0-3 | `Time` | u32, ms |
//! | 4-15 | `AngVel` | 3 x f32, rad/s, world axes |
//! | 16-19, 20-23, 24-27 | `Heading`, `Pitch`, `Roll` | f32, rad |
//! | 28-39 | `Accel` | 3 x f32, m/s^2, world axes |
//! | 40-51 | `Vel` | 3 x f32, m/s |
//! | 52-63 | `Pos` | 3 x i32, 1 m = 65536 |
//! | 64-67 | `ID` | i32, only when an `OutSim ID` is set |
//!
//! Conversion: world axes are x right, y forward, z up at zero heading; heading turns about z ("anticlockwise from
//! above"), pitch about the car's right (x) axis ("anticlockwise from right"), roll about its forward (y) axis
//! ("anticlockwise from front"), applied in that order. The acceleration is the car's (gravity not in it), so
//! gravity's reaction (`+g` on world z) is added; the sum and the angular velocity are turned into the car's frame
//! and then into ringpod's axes (x = car y, y = -car x, z = car z). This is the conversion of `datagram::outsim`,
//! moved here unchanged.

use super::{Format, Le, Sample, Telemetry, Unreadable, G};

/// Size without an ID.
pub const SIZE: usize = 64;

/// The motion data of a classic packet or of `OutSimPack2`'s `OSMain` (60 bytes from `at`), in ringpod's axes.
pub(crate) fn main(le: Le<'_>, at: usize) -> Telemetry<f64> {
    let ang_vel = le.vec3(at);
    let (heading, pitch, roll) = (le.f32(at + 12), le.f32(at + 16), le.f32(at + 20));
    let accel = le.vec3(at + 24);
    // Specific force in world axes: acceleration minus gravity (gravity is -g on z).
    let specific = [accel[0], accel[1], accel[2] + G];
    let to_car = |v: [f64; 3]| {
        // The car's axes in world axes: R = Rz(heading) Rx(pitch) Ry(roll); world to car is R^T.
        let v = rotate_z(v, -heading);
        let v = rotate_x(v, -pitch);
        rotate_y(v, -roll)
    };
    let (fc, wc) = (to_car(specific), to_car(ang_vel));
    // Car axes x right, y forward, z up -> ringpod's x forward, y left, z up.
    let ours = |v: [f64; 3]| [v[1], -v[0], v[2]];
    Telemetry {
        force: ours(fc),
        rate: ours(wc),
    }
}

/// Reads one classic packet (64 bytes, or 68 with an ID).
pub fn decode(bytes: &[u8]) -> Result<Sample, Unreadable> {
    if bytes.len() != SIZE && bytes.len() != SIZE + 4 {
        return Err(Unreadable::Size {
            format: Format::Outsim,
            got: bytes.len(),
            expected: "64 bytes, or 68 with an OutSim ID",
        });
    }
    let le = Le(bytes);
    Ok(Sample {
        time: Some(f64::from(le.u32(0)) / 1000.0),
        telemetry: main(le, 4),
        lap: None,
    })
}

fn rotate_z(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

fn rotate_x(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]
}

fn rotate_y(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]
}

#[cfg(test)]
mod tests {
    use super::super::packets::outsim::packet;
    use super::super::testing::{close, decoded};
    use super::*;

    #[test]
    fn classic_packets_in_vehicle_axes() {
        let g = G;
        // At rest, level, any heading.
        let s = decoded(
            Format::Outsim,
            &packet(1500, [0.0; 3], [2.0, 0.0, 0.0], [0.0; 3], false),
        );
        assert_eq!(s.time, Some(1.5));
        assert!(
            close(s.telemetry.force, [0.0, 0.0, g]) && close(s.telemetry.rate, [0.0; 3]),
            "{s:?}"
        );
        // Heading a quarter turn anticlockwise (facing world -x), accelerating that way at 3 m/s^2.
        let quarter = std::f32::consts::FRAC_PI_2;
        let s = decoded(
            Format::Outsim,
            &packet(0, [0.0; 3], [quarter, 0.0, 0.0], [-3.0, 0.0, 0.0], true),
        );
        assert!(close(s.telemetry.force, [3.0, 0.0, g]), "{s:?}");
        // A left turn at heading 0: the centripetal acceleration points to world -x, the car's left.
        let s = decoded(
            Format::Outsim,
            &packet(0, [0.0, 0.0, 0.5], [0.0; 3], [-4.0, 0.0, 0.0], false),
        );
        assert!(
            close(s.telemetry.force, [0.0, 4.0, g]) && close(s.telemetry.rate, [0.0, 0.0, 0.5]),
            "{s:?}"
        );
        // Nose up 10 degrees at rest: gravity pushes the rider back, as accelerating does.
        let p = 10f32.to_radians();
        let s = decoded(Format::Outsim, &packet(0, [0.0; 3], [0.0, p, 0.0], [0.0; 3], false));
        let (sp, cp) = f64::from(p).sin_cos();
        assert!(close(s.telemetry.force, [g * sp, 0.0, g * cp]), "{s:?}");
        for len in [0, 63, 65, 72] {
            assert!(decode(&vec![0u8; len]).is_err(), "{len} bytes");
        }
    }
}

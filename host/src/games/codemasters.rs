//! Codemasters' UDP telemetry with `extradata="3"`: DiRT Rally, DiRT Rally 2.0, DiRT 4, GRID (2019), GRID
//! Autosport and the other EGO-engine games that send this 264-byte packet.
//!
//! Sources: Codemasters' "Setting up UDP output for DiRT 4" (June 6, 2017; sections "3 UDP", "3.1 Config Setup"
//! and "9 Appendix: Custom UDP for UDP mode 3", the channel list of extradata 3) and Codemasters' "F1 2017 UDP
//! Specification" (forums.codemasters.com), whose `UDPPacket` begins with the same 66 floats and names the
//! direction vectors. All 66 fields are little-endian f32:
//!
//! | float | field | |
//! |---|---|---|
//! | 0 | total time | s |
//! | 1, 2, 3 | lap time, lap distance, total distance | s, m, m |
//! | 4-6 | world position x, y, z | m; the world's y is up |
//! | 7 | speed | m/s |
//! | 8-10 | world velocity x, y, z | m/s |
//! | 11-13 | world space right direction x, y, z | unit vector ("roll vector") |
//! | 14-16 | world space forward direction x, y, z | unit vector ("pitch vector") |
//! | 17-28 | suspension position, suspension velocity, wheel speed | 4 each, RL RR FL FR |
//! | 29-33 | throttle, steer, brake, clutch, gear | |
//! | 34 | g-force lateral | g |
//! | 35 | g-force longitudinal | g |
//! | 36-65 | lap, engine rate, SLI Pro support, race position, KERS, DRS, TC, ABS, fuel, pits, sector and times, brake temperatures, tyre pressures, team, laps, track size, last lap, max and idle rpm, max gears | |
//!
//! Enable it in `Documents/My Games/<game>/hardwaresettings/hardware_settings_config.xml`:
//! `<udp enabled="true" extradata="3" ip="127.0.0.1" port="20777" delay="1" />`. The other extradata modes (0 to
//! 2, shorter packets) are refused: they lack the g-forces or the directions.
//!
//! ## Conversion
//!
//! The packet has no vertical acceleration and no angular rates. The g-forces are the car's acceleration in g
//! without gravity, lateral positive towards the car's *left*, longitudinal positive forwards. The documents give
//! no signs; both come from real DiRT Rally 2.0 runs (dr2_logger's three published runs, `ErlerPhilipp/dr2_logger`,
//! `img/plots/*/*.npz`): against each run's own kinematics, the world velocity's derivative projected on the
//! packet's right vector, lateral correlates at -0.98 to -0.99 with slope -0.99 to -1.00, longitudinal on the forward
//! vector at +0.96 to +0.97 with slope 1.02 to 1.03 (no gravity in either), and in a left corner the right wheels turn faster, so the right vector
//! is the car's right. Gravity's reaction comes from the direction vectors' up (y) components:
//!
//! | ringpod | from |
//! |---|---|
//! | force x | `g * longitudinal + g * forward.y` |
//! | force y | `g * lateral - g * right.y` |
//! | force z | `g * sqrt(1 - forward.y^2 - right.y^2)`: no heave beyond the attitude's |
//! | rate | 0: none published |
//! | time | total time |
//! | lap | float 2, lap distance (m, from the line; a rally stage's distance never wraps, and gives no preview) |

use super::{add, gravity_from_axes, Format, LapPosition, Le, Sample, Telemetry, Unreadable, G};

/// The packet's size: 66 floats.
pub const SIZE: usize = 66 * 4;

/// Reads one extradata-3 packet.
pub fn decode(bytes: &[u8]) -> Result<Sample, Unreadable> {
    if bytes.len() != SIZE {
        return Err(Unreadable::Size {
            format: Format::Codemasters,
            got: bytes.len(),
            expected: "264 bytes (extradata=\"3\")",
        });
    }
    let le = Le(bytes);
    let float = |i: usize| le.f32(4 * i);
    let (right_up, forward_up) = (float(12), float(15));
    // The vectors are unit vectors; their up components are clamped against the game's rounding.
    let gravity = gravity_from_axes(forward_up.clamp(-1.0, 1.0), (-right_up).clamp(-1.0, 1.0));
    let (lateral, longitudinal) = (float(34), float(35));
    Ok(Sample {
        time: Some(float(0)),
        telemetry: Telemetry {
            force: add([G * longitudinal, G * lateral, 0.0], gravity),
            rate: [0.0; 3],
        },
        lap: Some(LapPosition::Along(float(2))),
    })
}

#[cfg(test)]
mod recording;

#[cfg(test)]
mod tests {
    use super::super::testing::{close, decoded};
    use super::*;

    /// A packet at 95.25 s (the shared builder).
    fn packet(right: [f32; 3], forward: [f32; 3], g_lat: f32, g_long: f32) -> Vec<u8> {
        super::super::packets::codemasters::packet(95.25, right, forward, g_lat, g_long)
    }

    const RIGHT: [f32; 3] = [1.0, 0.0, 0.0];
    const FORWARD: [f32; 3] = [0.0, 0.0, 1.0];

    #[test]
    fn extradata_3_in_vehicle_axes() {
        let g = G;
        // At rest, level.
        let s = decoded(Format::Codemasters, &packet(RIGHT, FORWARD, 0.0, 0.0));
        assert_eq!(s.time, Some(95.25));
        assert!(
            close(s.telemetry.force, [0.0, 0.0, g]) && s.telemetry.rate == [0.0; 3],
            "{s:?}"
        );
        // Accelerating at 0.6 g.
        let s = decoded(Format::Codemasters, &packet(RIGHT, FORWARD, 0.0, 0.6));
        assert!(close(s.telemetry.force, [0.6 * g, 0.0, g]), "{s:?}");
        // A left turn at 1.5 g: accelerating towards the left (lateral positive), the seat pushes left.
        let s = decoded(Format::Codemasters, &packet(RIGHT, FORWARD, 1.5, 0.0));
        assert!(close(s.telemetry.force, [0.0, 1.5 * g, g]), "{s:?}");
        // Nose up 10 degrees at rest.
        let (sp, cp) = 10f32.to_radians().sin_cos();
        let s = decoded(Format::Codemasters, &packet(RIGHT, [0.0, sp, cp], 0.0, 0.0));
        let (sp, cp) = (f64::from(sp), f64::from(cp));
        assert!(close(s.telemetry.force, [g * sp, 0.0, g * cp]), "{s:?}");
        // Right side down 10 degrees at rest: the seat pushes left.
        let s = decoded(
            Format::Codemasters,
            &packet([cp as f32, -sp as f32, 0.0], FORWARD, 0.0, 0.0),
        );
        assert!(close(s.telemetry.force, [0.0, g * sp, g * cp]), "{s:?}");
    }

    #[test]
    fn other_modes_are_refused() {
        let good = packet(RIGHT, FORWARD, 0.0, 0.0);
        // extradata 0 (38 floats) and 1, and a longer F1 2017 packet.
        for len in [152, 200, 263, 265, 1289] {
            let mut p = good.clone();
            p.resize(len, 0);
            assert!(matches!(decode(&p), Err(Unreadable::Size { .. })), "{len}");
        }
        let mut nan = good;
        nan[34 * 4..35 * 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(super::super::decode(Format::Codemasters, &nan).is_err());
    }

    /// Float 2, the lap distance, written channel by channel.
    #[test]
    fn extradata_3_carries_the_lap_distance() {
        for d in [0.0, 1234.5, 4999.0] {
            let p = super::super::packets::codemasters::on_lap(10.0, d, RIGHT, FORWARD, 0.0, 0.0);
            assert_eq!(
                decoded(Format::Codemasters, &p).lap,
                Some(LapPosition::Along(f64::from(d)))
            );
        }
    }
}

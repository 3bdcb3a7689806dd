//! Two corners of a real F1 24 session, as derived from the game's motion packets.
//!
//! Source: the IT52-NHLSF1 project's captures of every packet type F1 24 (packet format 2024, game version 1.21)
//! sent while driven (`github.com/DavidHlavacek/IT52-NHLSF1`, commit `3918363`, `recordings/*.bin`: a packet
//! count, then each datagram as it arrived with its time and length). The repository states no licence, so no
//! datagram is kept here: only what the method of `super::super::codemasters::recording` derives from them, each
//! window's world velocity change over its span and its packets' mean direction vectors and g-forces (the
//! player's car, slot 0).

use super::super::packets::f1::packet;
use super::super::testing::{decoded, dot};
use super::super::{Format, G};

/// One window of consecutive motion packets (none more than 0.07 s after the one before).
struct Window {
    /// Where: file, the motion packets' `m_frameIdentifier`s at its ends.
    what: &'static str,
    /// Its span (s) in `m_sessionTime`.
    dt: f64,
    /// `m_worldVelocity` at its end minus at its start (m/s).
    dv: [f64; 3],
    /// The mean `m_worldForwardDir` and `m_worldRightDir`.
    forward: [f32; 3],
    right: [f32; 3],
    /// The mean `m_gForceLateral`, `m_gForceLongitudinal`, `m_gForceVertical` (g).
    g: [f32; 3],
}

const CORNERS: [Window; 2] = [
    // A right-hand corner under braking at 40 m/s: 8 packets, 0.30 s.
    Window {
        what: "high_speed_corners_20260112_161911.bin, frames 935 to 953",
        dt: 0.3003,
        dv: [-2.653, 0.021, -5.833],
        forward: [-0.6670, -0.0072, 0.7431],
        right: [-0.7423, -0.0414, -0.6666],
        g: [-1.9562, -0.8804, 0.1643],
    },
    // A left-hand corner, braking lightly: 4 packets, 0.15 s.
    Window {
        what: "full_lap_20260112_160501.bin, frames 2413 to 2422",
        dt: 0.1501,
        dv: [-1.502, -0.100, -1.676],
        forward: [0.8940, -0.0024, -0.4467],
        right: [0.4460, -0.0551, 0.8927],
        g: [1.3490, -0.3910, -0.3103],
    },
];

/// The recording's own kinematics against what ringpod decodes: the world velocity's change projected on the
/// car's left (minus its right vector) and forward is the acceleration the sway and surge cues must follow.
#[test]
fn real_corners_sway_towards_them() {
    for w in &CORNERS {
        let (right, forward) = (w.right.map(f64::from), w.forward.map(f64::from));
        let kinematic = [dot(w.dv, forward) / w.dt, -dot(w.dv, right) / w.dt];
        // The premise: a real corner, either way.
        assert!(kinematic[1].abs() > 12.0, "{}: {kinematic:?}", w.what);
        let s = decoded(Format::F1, &packet(2024, 0, 0, 16.0, w.forward, w.right, w.g));
        // Without gravity's share (g times the forward and left vectors' up components).
        let decoded = [
            s.telemetry.force[0] - G * forward[1],
            s.telemetry.force[1] - G * -right[1],
        ];
        for (axis, (d, k)) in ["surge", "sway"].iter().zip(decoded.iter().zip(kinematic)) {
            assert!(
                (d - k).abs() < 1.5,
                "{}: decoded {axis} {d:.2} m/s^2, the car accelerates {k:.2} m/s^2",
                w.what
            );
        }
    }
}

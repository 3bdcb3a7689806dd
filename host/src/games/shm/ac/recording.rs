//! Two corners of a real Assetto Corsa lap at Monza, as AC's UDP telemetry sent them.
//!
//! Source: Python_UDP_Receiver (vthinsel, CC0 1.0 Universal, `github.com/vthinsel/Python_UDP_Receiver`, commit
//! 7483eb5), `AssettoCorsa_monza_A8LMS`: 8,641 `RTCarInfo` datagrams of AC's remote telemetry (a car at
//! Monza, about 58 a second), each with its arrival time. Its records 4313 to 4320 (a right-hand corner at 33 m/s)
//! and 1667 to 1674 (a left-hand one at 13 m/s, braking). The datagram's three `accG` floats (bytes 28 to 39, which
//! Kunos' document names vertical, horizontal and frontal) are the car's `accG` vector in the shared memory's order
//! x, y, z: over the lap the first follows the path's centripetal acceleration, positive to the car's left
//! (correlation -0.997, slope -1.00 against the path's turn in the world's x-z plane, which at clockwise Monza is
//! to the right), the second averages 0.006 g (vertical, no gravity) and the third the speed's derivative (0.991,
//! slope 0.99).

use super::super::super::G;
use super::super::testing::Page;
use super::super::Game;
use super::decode;
use super::tests::physics;

/// One datagram: `lapTime` (ms), `speed_Ms`, the three `accG` floats, `wheelAngularSpeed[4]` (FL, FR, RL, RR),
/// `carCoordinates[3]` (m, y up).
type Datagram = [f32; 12];

#[rustfmt::skip]
const RIGHT: [Datagram; 8] = [
    [284848.0, 33.51662, -1.6954112, 0.09990193, -0.15607512, 99.47765, 96.78955, 94.69234, 92.536835, 1043.1798, -2.1546257, -971.9522],
    [284868.0, 33.46909, -1.720715, 0.16409552, -0.1632744, 99.29537, 96.7068, 94.56012, 92.45989, 1042.9845, -2.1689184, -971.31195],
    [284880.0, 33.441013, -1.7731763, 0.12538064, -0.1359219, 99.14051, 96.664764, 94.46258, 92.41672, 1042.8641, -2.1773252, -970.92926],
    [284900.0, 33.391167, -1.7795073, 0.24929182, -0.16180068, 98.961464, 96.58966, 94.29657, 92.35518, 1042.6584, -2.190844, -970.2939],
    [284912.0, 33.36225, -1.8577076, 0.23090303, -0.16228962, 98.78031, 96.517944, 94.181206, 92.33096, 1042.532, -2.1986587, -969.9141],
    [284932.0, 33.312843, -1.8031657, 0.31666535, -0.15101731, 98.619736, 96.44644, 94.03885, 92.23075, 1042.3159, -2.2110393, -969.2838],
    [284948.0, 33.275322, -1.7166468, 0.17690538, -0.15025067, 98.45838, 96.39982, 93.90298, 92.166306, 1042.1387, -2.220496, -968.78186],
    [284964.0, 33.238506, -1.6988065, 0.12182467, -0.15299487, 98.31247, 96.35794, 93.755844, 92.119, 1041.9575, -2.229717, -968.28186],
];

#[rustfmt::skip]
const LEFT: [Datagram; 8] = [
    [240056.0, 13.7814245, 1.8363928, 0.14142482, -0.4023689, 34.485153, 38.957035, 36.57555, 37.809555, -80.60026, -2.796276, -551.55774],
    [240068.0, 13.689975, 1.8006195, 0.7251086, -0.5991743, 35.398064, 37.42292, 36.31687, 37.753895, -80.53086, -2.8050618, -551.7064],
    [240088.0, 13.51372, 2.1969054, 1.3370118, -0.7923275, 34.952324, 39.05137, 35.972744, 39.57155, -80.42124, -2.8162541, -551.954],
    [240104.0, 13.350275, 2.8745568, 1.4183885, -0.8332169, 35.29555, 39.197105, 35.6519, 39.025997, -80.34101, -2.821289, -552.1522],
    [240120.0, 13.179697, 2.9845405, 1.8617715, -0.8869902, 35.297592, 39.790535, 35.544285, 39.07917, -80.2684, -2.8219907, -552.35046],
    [240136.0, 13.040718, 2.7295609, 1.7245077, -0.71928984, 35.28761, 39.761112, 35.62447, 39.07791, -80.203125, -2.8178556, -552.5489],
    [240156.0, 12.915465, 2.6043365, 1.0779923, -0.5638513, 35.28761, 39.479065, 35.244297, 37.75928, -80.13113, -2.8072705, -552.7972],
    [240168.0, 12.844104, 2.3359065, 0.87304693, -0.5925063, 35.28761, 39.14336, 35.078655, 39.389404, -80.09264, -2.7987738, -552.9462],
];

/// The `accG` vector written where AC's `SPageFilePhysics` holds it, the car level (the datagram has no attitude;
/// Monza is flat).
fn page(d: &Datagram) -> Vec<u8> {
    let l = physics(Game::Ac);
    let mut p = Page::zeros(l.size);
    p.i32(l.at("packetId"), 1)
        .f32s(l.at("accG"), &[d[2], d[3], d[4]].map(f64::from));
    p.0
}

/// The heading (rad) of the path from one datagram's coordinates to the next's, in the world's x-z plane.
fn heading(a: &Datagram, b: &Datagram) -> f64 {
    f64::from(b[11] - a[11]).atan2(f64::from(b[9] - a[9]))
}

/// The recording's own physics against what ringpod decodes: the outer wheels turn faster (FL, FR, RL, RR), the
/// path's heading turns at a rate that, times the speed, is the centripetal acceleration, and the speed falls as
/// the frontal channel says; the sway cue must point into the corner at that acceleration, the surge follow the
/// speed.
#[test]
fn real_corners_sway_towards_them() {
    for (corner, left) in [(&RIGHT, false), (&LEFT, true)] {
        let side = if left { 1.0 } else { -1.0 };
        assert!(
            corner.iter().all(|d| (d[6] > d[5] && d[8] > d[7]) == left),
            "the premise: the outer wheels turn faster"
        );
        let (first, last) = (&corner[0], &corner[corner.len() - 1]);
        let turn = heading(&corner[corner.len() - 2], last) - heading(first, &corner[1]);
        let dt = f64::from(last[0] + corner[corner.len() - 2][0] - first[0] - corner[1][0]) / 2000.0;
        let n = corner.len() as f64;
        let speed = corner.iter().map(|d| f64::from(d[1])).sum::<f64>() / n;
        let centripetal = speed * turn.abs() / dt;
        let braking = f64::from(last[1] - first[1]) / (f64::from(last[0] - first[0]) / 1000.0);
        let decoded = corner.iter().fold([0.0; 3], |sum, d| {
            let f = decode(Game::Ac, &page(d), &[]).unwrap().sample.telemetry.force;
            [sum[0] + f[0] / n, sum[1] + f[1] / n, sum[2] + f[2] / n]
        });
        let name = if left { "left" } else { "right" };
        assert!(
            (side * decoded[1] - centripetal).abs() < 0.15 * centripetal,
            "{name} corner: sway {:.2} m/s^2, the path's centripetal acceleration {centripetal:.2}",
            decoded[1]
        );
        assert!(
            (decoded[0] - braking).abs() < 3.0 && braking < 0.0,
            "{name} corner: surge {:.2} m/s^2, the speed changes at {braking:.2}",
            decoded[0]
        );
        assert!(decoded[2] > G, "{name}: {decoded:?}");
    }
}

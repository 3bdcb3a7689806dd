//! Tip-over under a lateral acceleration: reference values worked out by hand (a square, the trainer-ch5
//! carriages of KINEMATICS.md 2.1), and the bad inputs each answered by a typed error.

use nalgebra::Vector3;
use ringpod_core::kinematics::{presets, Pose, RingPlatform, TipOver, TipOverError, GRAVITY};

const G: f64 = GRAVITY;

fn square() -> [Vector3<f64>; 4] {
    [
        Vector3::new(-1.0, -1.0, 0.0),
        Vector3::new(1.0, -1.0, 0.0),
        Vector3::new(1.0, 1.0, 0.0),
        Vector3::new(-1.0, 1.0, 0.0),
    ]
}

fn close(a: f64, b: f64) {
    assert!((a - b).abs() < 1e-9 * (1.0 + b.abs()), "{a} != {b}");
}

#[test]
fn square_with_the_centre_of_mass_off_centre() {
    // Centre of mass at x = 0.2, 2 above the plane: the edge x = 1 is 0.8 away, x = -1 is 1.2, y = +-1 are 1.
    let t = TipOver::new(&square(), Vector3::new(0.2, 0.0, 2.0), G).unwrap();
    close(t.static_margin, 0.8);
    close(t.weakest, G * 0.8 / 2.0);
    // The weakest acceleration points away from the nearest edge (-X): the load throws the mass towards it.
    close(t.weakest_direction.abs(), std::f64::consts::PI);
    close(t.limit(0.0), G * 1.2 / 2.0);
    close(t.limit(std::f64::consts::PI), G * 0.8 / 2.0);
    close(t.limit(std::f64::consts::FRAC_PI_2), G * 1.0 / 2.0);
    close(t.limit(-std::f64::consts::FRAC_PI_2), G * 1.0 / 2.0);
    // Diagonally (+X+Y) the edges x = -1 (1.2 away) and y = -1 (1 away) are approached at cos 45 deg each.
    close(
        t.limit(std::f64::consts::FRAC_PI_4),
        G * 1.0 / (2.0 * std::f64::consts::FRAC_1_SQRT_2),
    );
    // Sampled over directions, nothing is weaker than the weakest.
    let sampled = (0..3600)
        .map(|k| t.limit(k as f64 * std::f64::consts::TAU / 3600.0))
        .fold(f64::INFINITY, f64::min);
    close(sampled, t.weakest);
}

#[test]
fn an_acceleration_at_the_limit_puts_the_point_on_the_edge() {
    let t = TipOver::new(&square(), Vector3::new(0.2, 0.0, 2.0), G).unwrap();
    let limit = G * 1.2 / 2.0;
    let at = t.under([limit, 0.0]).unwrap();
    close(at.point[0], -1.0);
    close(at.point[1], 0.0);
    assert!(at.margin.abs() < 1e-12);
    let below = t.under([limit * 0.99, 0.0]).unwrap();
    assert!(!below.tips && below.margin > 0.0 && below.acceleration_margin > 0.0);
    close(below.acceleration_margin, limit * 0.01);
    let above = t.under([limit * 1.01, 0.0]).unwrap();
    assert!(above.tips && above.margin < 0.0 && above.acceleration_margin < 0.0);
    // Towards +Y: the projection moves by a h / g.
    let side = t.under([0.0, 3.0]).unwrap();
    close(side.point[1], -3.0 * 2.0 / G);
    close(side.margin, 1.0 - 3.0 * 2.0 / G);
    // At rest the margin is the static one.
    close(t.under([0.0, 0.0]).unwrap().margin, 0.8);
}

#[test]
fn clockwise_corners_give_the_same_answer() {
    let mut cw = square();
    cw.reverse();
    let a = TipOver::new(&square(), Vector3::new(0.2, -0.1, 1.5), G).unwrap();
    let b = TipOver::new(&cw, Vector3::new(0.2, -0.1, 1.5), G).unwrap();
    close(a.static_margin, b.static_margin);
    close(a.weakest, b.weakest);
    close(a.limit(1.0), b.limit(1.0));
}

#[test]
fn outside_already_tips_at_any_acceleration() {
    let t = TipOver::new(&square(), Vector3::new(1.5, 0.0, 1.0), G).unwrap();
    close(t.static_margin, -0.5);
    assert_eq!(t.weakest, 0.0);
    assert_eq!(t.limit(0.3), 0.0);
    assert!(t.under([0.0, 0.0]).unwrap().tips);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let c = Vector3::new(0.0, 0.0, 1.0);
    assert_eq!(TipOver::new(&square()[..2], c, G), Err(TipOverError::Degenerate));
    let line = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(2.0, 0.0, 0.0),
    ];
    assert_eq!(TipOver::new(&line, c, G), Err(TipOverError::Degenerate));
    assert_eq!(
        TipOver::new(&square(), Vector3::new(f64::NAN, 0.0, 1.0), G),
        Err(TipOverError::NonFinite)
    );
    let mut bad = square();
    bad[2].y = f64::INFINITY;
    assert_eq!(TipOver::new(&bad, c, G), Err(TipOverError::NonFinite));
    assert_eq!(
        TipOver::new(&square(), Vector3::new(0.0, 0.0, 0.0), G),
        Err(TipOverError::NotAbove)
    );
    assert_eq!(
        TipOver::new(&square(), Vector3::new(0.0, 0.0, -1.0), G),
        Err(TipOverError::NotAbove)
    );
    let t = TipOver::new(&square(), c, G).unwrap();
    assert_eq!(t.under([f64::NAN, 0.0]), Err(TipOverError::NonFinite));
    assert_eq!(t.under([0.0, f64::NEG_INFINITY]), Err(TipOverError::NonFinite));
}

#[test]
fn trainer_ch5_at_home_stands_on_its_four_carriages() {
    // KINEMATICS.md 2.1: at (0, 0, 1, 0, 0, 0) the carriages are B1 = (-1, -sqrt 8), B2 = (1, -sqrt 8),
    // B3 = (3/sqrt 5, 6/sqrt 5), B4 = (-3/sqrt 5, 6/sqrt 5): symmetric about X = 0.
    let ring = RingPlatform::<f64>::new(&presets::TRAINER_CH5);
    let pose = Pose::from_array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    // A payload 0.5 above the platform centre: 1.5 above the ring plane, over the origin.
    let t = ring.tip_over(&pose, Vector3::new(0.0, 0.0, 0.5)).unwrap();
    let s8 = 8f64.sqrt();
    let (bx, by) = (3.0 / 5f64.sqrt(), 6.0 / 5f64.sqrt());
    // Distances of the origin to the four edges: the rear (y = -sqrt 8), the front (y = 6/sqrt 5), and the sides
    // through (1, -sqrt 8) and (bx, by): |x1 y2 - x2 y1| / length.
    let side = (1.0 * by + bx * s8).abs() / ((bx - 1.0).powi(2) + (by + s8).powi(2)).sqrt();
    let nearest = s8.min(by).min(side);
    close(t.static_margin, nearest);
    close(t.weakest, G * nearest / 1.5);
    // Forwards (+Y) the mass is thrown back onto the rear edge, sideways onto a side edge at its angle.
    close(t.limit(std::f64::consts::FRAC_PI_2), G * s8 / 1.5);
    close(t.limit(-std::f64::consts::FRAC_PI_2), G * by / 1.5);
    // The side edge's inward normal makes an angle with X whose cosine is its rise over its length.
    let cos_side = (by + s8) / ((bx - 1.0).powi(2) + (by + s8).powi(2)).sqrt();
    close(t.limit(std::f64::consts::PI), G * side / (1.5 * cos_side));
    close(t.limit(0.0), t.limit(std::f64::consts::PI));
    // A payload moved by the pose: the platform 0.1 to +X takes the centre of mass with it.
    let moved = ring
        .tip_over(
            &Pose::from_array([0.1, 0.0, 1.0, 0.0, 0.0, 0.0]),
            Vector3::new(0.0, 0.0, 0.5),
        )
        .unwrap();
    assert_eq!(moved.com, Vector3::new(0.1, 0.0, 1.5));
}

#[test]
fn a_pose_without_carriages_is_a_kinematics_error() {
    let ring = RingPlatform::<f64>::new(&presets::TRAINER_CH5);
    let far = Pose::from_array([0.0, 0.0, 5.0, 0.0, 0.0, 0.0]);
    assert!(matches!(
        ring.tip_over(&far, Vector3::new(0.0, 0.0, 0.1)),
        Err(TipOverError::Kinematics(_))
    ));
    let pose = Pose::from_array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    assert_eq!(
        ring.tip_over(&pose, Vector3::new(0.0, f64::NAN, 0.1)),
        Err(TipOverError::NonFinite)
    );
}

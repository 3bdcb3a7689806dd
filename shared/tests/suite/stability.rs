//! A vehicle's static stability (chapter 5.2's tests): hand-computed cases, the roll-compliant threshold against
//! Gillespie's closed form and the slope's against a fixed-point iteration, invariants, and every bad input refused.

use proptest::prelude::*;
use ringpod_core::vehicle::{gravity_in_platform, Roll, Vehicle, VehicleError, GRAVITY};

const DEG: f64 = std::f64::consts::PI / 180.0;

/// The gravity in a platform tilted by an angle one way.
type Tilt = dyn Fn(f64) -> [f64; 3];

/// A passenger car: track 1.5 m, wheelbase 2.7 m, centre of gravity 0.6 m up and 1.2 m ahead of the rear axle.
fn car() -> Vehicle {
    Vehicle::new(1.5, 2.7, 0.6, 1.2).unwrap()
}

/// The same car on a suspension of 60 kN m/rad carrying 1500 kg about a roll axis 0.3 m up.
fn sprung_car() -> Vehicle {
    let roll = Roll {
        stiffness: 60_000.0,
        mass: 1500.0,
        centre_height: 0.3,
    };
    Vehicle::with_roll(1.5, 2.7, 0.6, 1.2, Some(roll)).unwrap()
}

/// Rigid, by hand: `atan(1.5 / 1.2) = 51.340 deg` on the slope, `atan(1.2 / 0.6) = 63.435 deg` climbing,
/// `atan(1.5 / 0.6) = 68.199 deg` descending, `sqrt(1.25 g 50) = 24.757 m/s` in a 50 m turn.
#[test]
fn a_rigid_car_by_hand() {
    let s = car().stability();
    assert!((s.slope / DEG - 51.340_192).abs() < 1e-5, "{}", s.slope / DEG);
    assert!((s.incline / DEG - 63.434_949).abs() < 1e-5);
    assert!((s.decline / DEG - 68.198_591).abs() < 1e-5);
    assert_eq!(s.roll_at_slope, 0.0);
    assert_eq!(s.roll_rate, 0.0);
    assert!((s.rollover_g - 1.25).abs() < 1e-12);
    assert!((car().critical_speed(50.0).unwrap() - 24.757_133).abs() < 1e-5);
}

/// With roll: the roll rate `R = m g (h - h_r) / (K - m g (h - h_r)) = 0.079389`; the threshold against Gillespie's
/// form `(T / 2h) / (1 + R (1 - h_r / h))` = 1.202276 g, 24.280 m/s in the 50 m turn; the slope's angle against a
/// fixed-point iteration of `theta = atan(T/2 / (h + (h - h_r) R(g cos theta)))`, 50.663 deg, the body rolled 3.419 deg
/// there.
#[test]
fn a_sprung_car_against_independent_forms() {
    let v = sprung_car();
    let s = v.stability();
    let moment = 1500.0 * GRAVITY * 0.3;
    let r = moment / (60_000.0 - moment);
    assert!((s.roll_rate - r).abs() < 1e-12 && (r - 0.079_389).abs() < 1e-6);
    let gillespie = 1.25 / (1.0 + r * (1.0 - 0.3 / 0.6));
    assert!((s.rollover_g - gillespie).abs() < 1e-12, "{}", s.rollover_g);
    assert!((s.rollover_g - 1.202_276).abs() < 1e-6);
    assert!((v.critical_speed(50.0).unwrap() - 24.279_933).abs() < 1e-5);
    let mut theta: f64 = 0.5;
    for _ in 0..200 {
        let m = 1500.0 * GRAVITY * theta.cos() * 0.3;
        theta = (0.75 / (0.6 + 0.3 * m / (60_000.0 - m))).atan();
    }
    assert!((s.slope - theta).abs() < 1e-12, "{} vs {}", s.slope / DEG, theta / DEG);
    assert!((s.slope / DEG - 50.663_306).abs() < 1e-5);
    assert!((s.roll_at_slope / DEG - 3.418_714).abs() < 1e-5);
    // Softer than rigid, as the roll moves the centre of gravity outwards.
    assert!(s.slope < car().stability().slope && s.rollover_g < 1.25);
}

/// The margin through a platform's tilt is zero at each computed angle: positive just before, negative just after.
#[test]
fn the_margin_on_a_tilted_platform_crosses_zero_at_the_computed_angles() {
    for v in [car(), sprung_car()] {
        let s = v.stability();
        // The slope as a roll of the platform, the climb as a negative pitch (the +X nose up).
        let cases: [(&Tilt, f64); 3] = [
            (&|a| gravity_in_platform(a, 0.0), s.slope),
            (&|a| gravity_in_platform(-a, 0.0), s.slope),
            (&|a| gravity_in_platform(0.0, -a), s.incline),
        ];
        for (g, angle) in cases {
            assert!(v.margin(g(angle)).abs() < 1e-9, "{}", v.margin(g(angle)));
            assert!(v.margin(g(angle - 1e-3)) > 0.0 && v.margin(g(angle + 1e-3)) < 0.0);
        }
        let descending = v.margin(gravity_in_platform(0.0, s.decline));
        assert!(descending.abs() < 1e-9);
        // Level, the centre of gravity stands the nearer distance inside: half the track here.
        assert!((v.margin(gravity_in_platform(0.0, 0.0)) - 0.75).abs() < 1e-12);
        assert_eq!(v.margin([0.0, 0.0, 1.0]), f64::NEG_INFINITY);
        assert_eq!(v.margin([f64::NAN, 0.0, -9.8]), f64::NEG_INFINITY);
    }
}

#[test]
fn bad_vehicles_are_refused() {
    let rigid = |t, l, h, b| Vehicle::new(t, l, h, b);
    assert_eq!(rigid(f64::NAN, 2.7, 0.6, 1.2), Err(VehicleError::NonFinite("track")));
    assert_eq!(rigid(0.0, 2.7, 0.6, 1.2), Err(VehicleError::OutOfRange("track")));
    assert_eq!(rigid(1.5, -1.0, 0.6, 1.2), Err(VehicleError::OutOfRange("wheelbase")));
    assert_eq!(
        rigid(1.5, 2.7, f64::INFINITY, 1.2),
        Err(VehicleError::NonFinite("cg_height"))
    );
    assert_eq!(rigid(1.5, 2.7, 2e3, 1.2), Err(VehicleError::OutOfRange("cg_height")));
    assert_eq!(rigid(1.5, 2.7, 0.6, 2.7), Err(VehicleError::OutsideWheelbase));
    assert_eq!(rigid(1.5, 2.7, 0.6, 0.0), Err(VehicleError::OutsideWheelbase));
    assert_eq!(
        rigid(1.5, 2.7, 0.6, f64::NAN),
        Err(VehicleError::NonFinite("cg_from_rear"))
    );
    let sprung = |stiffness, mass, centre_height| {
        Vehicle::with_roll(
            1.5,
            2.7,
            0.6,
            1.2,
            Some(Roll {
                stiffness,
                mass,
                centre_height,
            }),
        )
    };
    assert_eq!(sprung(6e4, 0.0, 0.3), Err(VehicleError::NoMass));
    assert_eq!(sprung(6e4, f64::NAN, 0.3), Err(VehicleError::NonFinite("mass")));
    assert_eq!(sprung(6e4, 1e7, 0.3), Err(VehicleError::OutOfRange("mass")));
    assert_eq!(
        sprung(-1.0, 1500.0, 0.3),
        Err(VehicleError::OutOfRange("roll_stiffness"))
    );
    assert_eq!(
        sprung(f64::NAN, 1500.0, 0.3),
        Err(VehicleError::NonFinite("roll_stiffness"))
    );
    assert_eq!(sprung(6e4, 1500.0, 0.6), Err(VehicleError::RollCentre));
    assert_eq!(sprung(6e4, 1500.0, -0.1), Err(VehicleError::RollCentre));
    assert_eq!(
        sprung(6e4, 1500.0, f64::NAN),
        Err(VehicleError::NonFinite("roll_centre_height"))
    );
    // 1500 kg at 0.3 m above the roll axis overturns 4413 N m per radian: 4000 N m/rad does not hold it.
    assert_eq!(sprung(4_000.0, 1500.0, 0.3), Err(VehicleError::RollUnstable));
    assert!(sprung(4_500.0, 1500.0, 0.3).is_ok());
    for r in [0.0, -5.0, f64::NAN, f64::INFINITY, 1e6] {
        assert!(car().critical_speed(r).is_err(), "{r}");
    }
}

fn vehicles() -> impl Strategy<Value = (f64, f64, f64, f64, f64, f64)> {
    // track, wheelbase, cg height, share of the wheelbase behind the cg, roll stiffness over the body's own
    // overturning moment (above 1), roll centre's share of the cg height.
    (0.05..3.0, 0.05..5.0, 0.02..2.0, 0.05..0.95, 1.05..50.0, 0.0..0.9)
}

fn build(p: (f64, f64, f64, f64, f64, f64), mass: f64) -> Vehicle {
    let (t, l, h, share, over, hr) = p;
    let centre_height = hr * h;
    let stiffness = over * mass * GRAVITY * (h - centre_height);
    let roll = Some(Roll {
        stiffness,
        mass,
        centre_height,
    });
    Vehicle::with_roll(t, l, h, share * l, roll).unwrap()
}

proptest! {
    /// A higher centre of gravity tips sooner everywhere; a wider track later across; a softer suspension sooner;
    /// roll never helps; every angle is inside (0, 90 deg).
    #[test]
    fn tip_angles_fall_with_height_and_rise_with_track(p in vehicles(), mass in 0.1..3000.0f64) {
        let v = build(p, mass);
        let s = v.stability();
        for a in [s.slope, s.incline, s.decline] {
            prop_assert!(a > 0.0 && a < 90.0 * DEG);
        }
        prop_assert!(s.slope <= (v.stability_factor()).atan() + 1e-12);
        prop_assert!(s.rollover_g <= v.stability_factor() + 1e-12);
        prop_assert!(s.roll_at_slope >= 0.0);
        let (t, l, h, share, over, hr) = p;
        let higher = build((t, l, h * 1.2, share, over, hr), mass).stability();
        prop_assert!(higher.slope < s.slope && higher.incline < s.incline && higher.decline < s.decline);
        prop_assert!(higher.rollover_g < s.rollover_g);
        let wider = build((t * 1.2, l, h, share, over, hr), mass).stability();
        prop_assert!(wider.slope > s.slope && wider.rollover_g > s.rollover_g);
        prop_assert!((wider.incline - s.incline).abs() < 1e-15);
        let softer = build((t, l, h, share, 1.0 + (over - 1.0) * 0.5, hr), mass).stability();
        prop_assert!(softer.slope < s.slope && softer.rollover_g < s.rollover_g);
        prop_assert!(softer.roll_at_slope > s.roll_at_slope);
    }

    /// The margin's zero on the tilted platform is the computed slope, and the critical speed squared grows with
    /// the radius in proportion.
    #[test]
    fn the_margin_crosses_zero_at_the_slope(p in vehicles(), mass in 0.1..3000.0f64, radius in 0.1..500.0f64) {
        let v = build(p, mass);
        let s = v.stability();
        prop_assert!(v.margin(gravity_in_platform(s.slope, 0.0)).abs() < 1e-9 * (1.0 + p.0));
        prop_assert!(v.margin(gravity_in_platform(s.slope * 0.99, 0.0)) > 0.0);
        prop_assert!(v.margin(gravity_in_platform(s.slope * 1.01, 0.0)) < 0.0);
        let v1 = v.critical_speed(radius).unwrap();
        let v2 = v.critical_speed(2.0 * radius).unwrap();
        prop_assert!((v2 * v2 / (v1 * v1) - 2.0).abs() < 1e-9);
        prop_assert!((v1 * v1 - s.rollover_g * GRAVITY * radius).abs() < 1e-9 * v1 * v1);
    }
}

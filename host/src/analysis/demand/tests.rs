use super::*;

#[test]
fn a_wrapped_yaw_is_followed_the_short_way() {
    let mut yaw = [6.0, 6.2, 0.1, 0.3, 6.2];
    unwrap(&mut yaw);
    let tau = std::f64::consts::TAU;
    let want = [6.0, 6.2, 0.1 + tau, 0.3 + tau, 6.2];
    assert!(yaw.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12), "{yaw:?}");
}

#[test]
fn three_point_derivatives_are_exact_for_a_parabola_on_uneven_steps() {
    let t = [0.0, 0.1, 0.25, 0.3, 0.5];
    let v: Vec<f64> = t.iter().map(|t| 3.0 * t * t - t + 2.0).collect();
    for i in 1..4 {
        let (rate, accel) = derivatives(&t, &v, i);
        assert!((rate - (6.0 * t[i] - 1.0)).abs() < 1e-12, "{i}");
        assert!((accel - 6.0).abs() < 1e-9, "{i}");
    }
}

//! The classical washout: each filter against its analytic response, tilt coordination, neutral at rest, refusals,
//! and f32 against f64.

use proptest::prelude::*;
use ringpod_core::cueing::filter::{Biquad, Section};
use ringpod_core::cueing::{delivered, CueConfig, Forward, SampleError, Telemetry, Washout, YawMode, G};

const DT: f64 = 0.001;

/// Runs a filter on a unit step for `seconds` at `DT` and returns its output at each sample.
fn step_response(mut f: Biquad<f64>, seconds: f64) -> Vec<f64> {
    (0..(seconds / DT) as usize).map(|_| f.step(1.0, DT)).collect()
}

/// Tustin at 1 kHz against a continuous response whose fastest pole is a few rad/s: within 1e-5 of the step.
fn assert_close(got: &[f64], want: impl Fn(f64) -> f64, what: &str) {
    for (k, g) in got.iter().enumerate() {
        // Tustin's output at sample k approximates the continuous response at t = (k + 1) dt, half a sample
        // early on a step (the step is taken as the average of the samples around it): compare at t = (k+1/2) dt.
        let t = (k as f64 + 0.5) * DT;
        let w = want(t);
        assert!((g - w).abs() < 1e-5, "{what} at {t} s: {g} vs {w}");
    }
}

#[test]
fn each_filter_matches_its_analytic_step_response() {
    let (w, z) = (4.0f64, 0.7f64);
    let wd = w * (1.0 - z * z).sqrt();
    // Low-pass: 1 - e^(-z w t) (cos wd t + z w / wd sin wd t).
    assert_close(
        &step_response(Biquad::new(Section::low_pass(w, z)), 5.0),
        |t| 1.0 - (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin()),
        "low-pass",
    );
    // High-pass: e^(-z w t) (cos wd t - z w / wd sin wd t).
    assert_close(
        &step_response(Biquad::new(Section::high_pass(w, z)), 5.0),
        |t| (-z * w * t).exp() * ((wd * t).cos() - z * w / wd * (wd * t).sin()),
        "high-pass",
    );
    // Acceleration step to position through the high-pass and a double integration: the low-pass over w^2.
    assert_close(
        &step_response(Biquad::new(Section::high_pass_position(w, z)), 5.0),
        |t| (1.0 - (-z * w * t).exp() * ((wd * t).cos() + z * w / wd * (wd * t).sin())) / (w * w),
        "high-pass position",
    );
    // Rate step to angle through the high-pass and one integration: e^(-z w t) sin(wd t) / wd.
    assert_close(
        &step_response(Biquad::new(Section::high_pass_angle(w, z)), 5.0),
        |t| (-z * w * t).exp() * (wd * t).sin() / wd,
        "high-pass angle",
    );
    // First-order high-pass: e^(-w t).
    assert_close(
        &step_response(Biquad::first_order(Section::first_order_high_pass(w)), 5.0),
        |t| (-w * t).exp(),
        "first-order high-pass",
    );
}

#[test]
fn the_interval_of_each_sample_is_its_own() {
    // A smooth input sampled by a jittery 60 Hz source (12 and 21 ms alternately) and by a steady 1 kHz one: both
    // approximate the same continuous response to second order, so they agree at the jittery samples' times.
    // Coefficients kept from one interval for the other would not.
    let section = Section::low_pass(3.0f64, 1.0);
    let input = |t: f64| (2.0 * t).sin() + 0.5 * (5.0 * t).sin();
    let mut fine = Biquad::new(section);
    let mut coarse = Biquad::new(section);
    let mut fine_ms = 0u32;
    let mut t_ms = 0u32;
    for k in 0..120 {
        let dt_ms = if k % 2 == 0 { 12 } else { 21 };
        t_ms += dt_ms;
        let y = coarse.step(input(f64::from(t_ms) / 1000.0), f64::from(dt_ms) / 1000.0);
        let mut reference = 0.0;
        while fine_ms < t_ms {
            fine_ms += 1;
            reference = fine.step(input(f64::from(fine_ms) / 1000.0), DT);
        }
        assert!((y - reference).abs() < 1e-3, "at {t_ms} ms: {y} vs {reference}");
    }
}

fn at_rest() -> Telemetry<f64> {
    Telemetry {
        force: [0.0, 0.0, G],
        rate: [0.0; 3],
    }
}

#[test]
fn zero_input_at_rest_is_neutral_exactly() {
    let mut w = Washout::<f64>::new(CueConfig::default()).unwrap();
    for _ in 0..10_000 {
        assert_eq!(w.step(&at_rest(), 1.0 / 60.0).unwrap(), [0.0; 6]);
    }
    let mut w = Washout::<f32>::new(CueConfig::default()).unwrap();
    let rest = Telemetry {
        force: [0.0, 0.0, G as f32],
        rate: [0.0; 3],
    };
    assert_eq!(w.step(&rest, 0.001).unwrap(), [0.0; 6]);
}

#[test]
fn a_sustained_force_tilts_slowly_while_translation_washes_out() {
    let config = CueConfig::default();
    let tilt_rate = config.tilt_rate_deg[0].to_radians();
    for (axis, sign) in [(0usize, 1.0f64), (0, -1.0), (1, 1.0), (1, -1.0)] {
        let mut w = Washout::<f64>::new(config).unwrap();
        let a = 3.0 * sign;
        let mut force = [0.0, 0.0, G];
        force[axis] = a;
        let sample = Telemetry { force, rate: [0.0; 3] };
        let dt = 0.01;
        let mut last = w.step(&sample, dt).unwrap();
        let mut peak = 0.0f64;
        for _ in 0..3000 {
            let now = w.step(&sample, dt).unwrap();
            // Never faster than the tilt-rate limit.
            for tilt in [3, 4] {
                assert!((now[tilt] - last[tilt]).abs() <= tilt_rate * dt * (1.0 + 1e-9));
            }
            peak = peak.max(now[axis].abs());
            last = now;
        }
        // Onset: the platform moved the way of the force; then back to neutral (third order).
        assert!(peak > 0.005, "axis {axis}: peak {peak}");
        assert!(last[axis].abs() < 1e-4, "axis {axis}: {last:?}");
        // Sustained: tilted to asin(scaled force / g), the way that makes gravity deliver it.
        let want = (a * config.tilt_scale[axis] / G).asin();
        let (roll, pitch) = (last[3], last[4]);
        if axis == 0 {
            assert!((pitch + want).abs() < 1e-9 && roll == 0.0, "{last:?}");
        } else {
            assert!((roll - want).abs() < 1e-9 && pitch == 0.0, "{last:?}");
        }
        let f = delivered([0.0; 3], roll, pitch);
        assert!((f[axis] - a * config.tilt_scale[axis]).abs() < 1e-9, "{f:?}");
    }
}

#[test]
fn yaw_follows_the_heading_or_washes_out() {
    let mut heading = Washout::<f64>::new(CueConfig::default()).unwrap();
    let mut washout = Washout::<f64>::new(CueConfig {
        yaw: YawMode::Washout,
        ..CueConfig::default()
    })
    .unwrap();
    let turning = Telemetry {
        force: [0.0, 0.0, G],
        rate: [0.0, 0.0, 0.5],
    };
    for _ in 0..6000 {
        heading.step(&turning, 0.01).unwrap();
        washout.step(&turning, 0.01).unwrap();
    }
    // 60 s at 0.5 rad/s: 30 rad, nearly five turns, continuous.
    assert!((heading.offset()[5] - 30.0).abs() < 1e-9);
    assert!(washout.offset()[5].abs() < 1e-6);
    // Beyond the yaw-rate limit: the limit.
    let mut fast = Washout::<f64>::new(CueConfig::default()).unwrap();
    let spin = Telemetry {
        force: [0.0, 0.0, G],
        rate: [0.0, 0.0, 5.0],
    };
    fast.step(&spin, 1.0).unwrap();
    assert!((fast.offset()[5] - 1.9).abs() < 1e-12);
}

#[test]
fn forward_turns_the_cues_to_the_platform() {
    let braking = Telemetry {
        force: [-4.0, 0.0, G],
        rate: [0.0; 3],
    };
    let mut by_forward = Vec::new();
    for forward in [Forward::PlusX, Forward::PlusY, Forward::MinusX, Forward::MinusY] {
        let mut w = Washout::<f64>::new(CueConfig {
            forward,
            ..CueConfig::default()
        })
        .unwrap();
        let mut o = [0.0; 6];
        for _ in 0..100 {
            o = w.step(&braking, 0.01).unwrap();
        }
        by_forward.push(o);
    }
    let [px, py, mx, my] = [by_forward[0], by_forward[1], by_forward[2], by_forward[3]];
    // Braking moves the platform backward, wherever backward is, and pitches its nose down there.
    assert!(px[0] < 0.0 && px[1] == 0.0 && px[4] > 0.0);
    assert!(py[1] < 0.0 && py[0] == 0.0 && py[3] < 0.0, "{py:?}");
    assert!(mx[0] > 0.0 && mx[4] < 0.0);
    assert!(my[1] > 0.0 && my[3] > 0.0, "{my:?}");
    assert_eq!(px[0], -mx[0]);
    assert_eq!(py[1], -my[1]);
}

#[test]
fn bad_samples_and_bad_parameters_are_refused_by_name() {
    let mut w = Washout::<f64>::new(CueConfig::default()).unwrap();
    let good = at_rest();
    let mut nan = good;
    nan.force[0] = f64::NAN;
    assert_eq!(w.step(&nan, 0.01), Err(SampleError::NonFinite));
    let mut inf = good;
    inf.rate[2] = f64::INFINITY;
    assert_eq!(w.step(&inf, 0.01), Err(SampleError::NonFinite));
    // Beyond any vehicle's, on any axis, either sign; at the bound itself, taken.
    for (i, v) in [(0, 1.0001e4), (2, -1e30), (3, 1.0001e3), (5, -2e3)] {
        let mut huge = good;
        if i < 3 {
            huge.force[i] = v;
        } else {
            huge.rate[i - 3] = v;
        }
        assert_eq!(w.step(&huge, 0.01), Err(SampleError::Implausible), "{i} {v}");
        assert_eq!(w.begin(&huge), Err(SampleError::Implausible), "{i} {v}");
    }
    assert_eq!(w.offset(), [0.0; 6], "refused samples change nothing");
    let mut edge = Washout::<f64>::new(CueConfig::default()).unwrap();
    let mut hard = good;
    hard.force[1] = -1e4;
    hard.rate[0] = 1e3;
    assert!(edge.step(&hard, 0.01).is_ok());
    for dt in [0.0, -0.01, 2.0, f64::NAN] {
        assert!(w.step(&good, dt).is_err(), "dt {dt}");
    }
    assert_eq!(w.offset(), [0.0; 6], "refused samples change nothing");
    let bad = [
        (
            CueConfig {
                tilt_rate_deg: [3.0, -1.0],
                ..CueConfig::default()
            },
            "tilt_rate_deg",
        ),
        (
            CueConfig {
                translation_scale: [0.1, f64::NAN, 0.1],
                ..CueConfig::default()
            },
            "translation_scale",
        ),
        (
            CueConfig {
                tilt_limit_deg: [60.0; 2],
                ..CueConfig::default()
            },
            "tilt_limit_deg",
        ),
    ];
    for (config, key) in bad {
        assert_eq!(Washout::<f64>::new(config).err().map(|e| e.key), Some(key));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// f32 (the MCU) and f64 agree over random 10 s drives at 30 Hz to 1 kHz: within a micrometre and 2e-5 rad
    /// (measured: 3e-8 m, 1e-6 rad of tilt, 5e-6 rad of yaw after tens of radians).
    #[test]
    fn f32_agrees_with_f64(seed in prop::array::uniform6(-1.0f64..1.0), rate_hz in 30.0f64..1000.0) {
        let mut a = Washout::<f64>::new(CueConfig::default()).unwrap();
        let mut b = Washout::<f32>::new(CueConfig::default()).unwrap();
        let dt = 1.0 / rate_hz;
        let mut worst = [0.0f64; 6];
        for k in 0..(10.0 * rate_hz) as usize {
            let t = k as f64 * dt;
            let s = |i: usize, f: f64| seed[i] * (f * t + seed[(i + 1) % 6] * 3.0).sin();
            let sample = Telemetry {
                force: [4.0 * s(0, 1.3), 3.0 * s(1, 0.7), G + 2.0 * s(2, 5.0)],
                rate: [0.5 * s(3, 2.0), 0.5 * s(4, 1.1), 0.6 * s(5, 0.3)],
            };
            let single = Telemetry {
                force: sample.force.map(|v| v as f32),
                rate: sample.rate.map(|v| v as f32),
            };
            let x = a.step(&sample, dt).unwrap();
            let y = b.step(&single, dt as f32).unwrap();
            for i in 0..6 {
                worst[i] = worst[i].max((x[i] - f64::from(y[i])).abs());
            }
        }
        // Translation within a micrometre, angles within 2e-5 rad (the yaw integrates tens of radians).
        for (i, w) in worst.iter().enumerate() {
            let tol = if i < 3 { 1e-6 } else { 2e-5 };
            prop_assert!(*w < tol, "axis {i} at {rate_hz} Hz: {w}");
        }
    }
}

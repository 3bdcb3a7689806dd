//! Per-axis parameters, input smoothing, the first sample, and live retuning without a jump.

use proptest::prelude::*;
use ringpod_core::cueing::{
    Corner, CueConfig, Live, OptimalConfig, Smoother, Smoothing, Telemetry, Washout, G, HANDOVER_S,
};

fn sample(force: [f64; 3], rate: [f64; 3]) -> Telemetry<f64> {
    Telemetry { force, rate }
}

fn at_rest() -> Telemetry<f64> {
    sample([0.0, 0.0, G], [0.0; 3])
}

#[test]
fn per_axis_corners_give_each_axis_its_own_response() {
    let config = CueConfig {
        translation_high_pass: [
            Corner { omega: 2.0, zeta: 1.0 },
            Corner { omega: 6.0, zeta: 0.7 },
            Corner { omega: 4.0, zeta: 1.0 },
        ],
        translation_break: [0.0; 3],
        ..CueConfig::default()
    };
    let step = sample([3.0, 3.0, G + 3.0], [0.0; 3]);
    let mut w = Washout::<f64>::new(config).unwrap();
    let mut same = Washout::<f64>::new(CueConfig {
        translation_break: [0.0; 3],
        ..CueConfig::default()
    })
    .unwrap();
    let (mut peak, mut peak_same) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..300 {
        let o = w.step(&step, 0.01).unwrap();
        let s = same.step(&step, 0.01).unwrap();
        for i in 0..3 {
            peak[i] = peak[i].max(o[i].abs());
            peak_same[i] = peak_same[i].max(s[i].abs());
        }
    }
    // One corner for all: the same response on every axis. Per axis: the slower corner moves further (the
    // second-order position settles at f / omega^2).
    assert!((peak_same[0] - peak_same[1]).abs() < 1e-12 && (peak_same[0] - peak_same[2]).abs() < 1e-12);
    let f = 0.3;
    assert!((peak[0] - f / 4.0).abs() < 2e-3, "{peak:?}");
    assert!(peak[1] < f / 36.0 * 1.1 && peak[1] > f / 36.0 * 0.9, "{peak:?}");
    assert!((peak[2] - peak_same[2]).abs() < 1e-12, "heave keeps the default corner");
    // Tilt per axis: a lower limit on y (roll) only.
    let config = CueConfig {
        tilt_limit_deg: [15.0, 2.0],
        ..CueConfig::default()
    };
    let mut w = Washout::<f64>::new(config).unwrap();
    let corner = sample([4.0, 4.0, G], [0.0; 3]);
    for _ in 0..2000 {
        w.step(&corner, 0.01).unwrap();
    }
    let c = w.channels();
    assert!((c.tilt[0] - 2f64.to_radians()).abs() < 1e-9, "{c:?}");
    assert!(c.tilt[1].abs() > 10f64.to_radians(), "{c:?}");
}

#[test]
fn one_value_for_every_axis_reads_as_that_value_on_each_axis() {
    let old = r#"{"translation_high_pass": {"omega": 3, "zeta": 0.8}, "tilt_low_pass": {"omega": 4, "zeta": 1},
        "tilt_limit_deg": 12, "tilt_rate_deg": 2.5, "rotation_limit": 0.8, "translation_break": 0.5}"#;
    let old: CueConfig = serde_json::from_str(old).unwrap();
    let want = CueConfig {
        translation_high_pass: [Corner { omega: 3.0, zeta: 0.8 }; 3],
        tilt_low_pass: [Corner { omega: 4.0, zeta: 1.0 }; 2],
        tilt_limit_deg: [12.0; 2],
        tilt_rate_deg: [2.5; 2],
        rotation_limit: [0.8; 2],
        translation_break: [0.5; 3],
        ..CueConfig::default()
    };
    assert_eq!(old, want);
    let each = r#"{"translation_high_pass": [{"omega": 3, "zeta": 0.8}, {"omega": 3, "zeta": 0.8},
        {"omega": 3, "zeta": 0.8}], "tilt_limit_deg": [12, 12]}"#;
    let each: CueConfig = serde_json::from_str(each).unwrap();
    assert_eq!(each.translation_high_pass, want.translation_high_pass);
    assert_eq!(each.tilt_limit_deg, want.tilt_limit_deg);
    // A list of the wrong length, an unknown key: refused.
    assert!(serde_json::from_str::<CueConfig>(r#"{"tilt_limit_deg": [1, 2, 3]}"#).is_err());
    assert!(serde_json::from_str::<CueConfig>(r#"{"translation_break": [1, 2]}"#).is_err());
    assert!(serde_json::from_str::<CueConfig>(r#"{"smoothing": {"kind": "median", "corner_hz": 3}}"#).is_err());
    // Out of range: the key and the axis.
    let mut bad = CueConfig::default();
    bad.translation_high_pass[1].omega = 0.0;
    let e = bad.validate().unwrap_err();
    assert_eq!((e.key, e.axis), ("translation_high_pass", Some("sway")));
    assert!(e.to_string().starts_with("translation_high_pass (sway) must be"), "{e}");
    bad = CueConfig {
        smoothing: Smoothing::Median { window: 4 },
        ..CueConfig::default()
    };
    assert_eq!(bad.validate().unwrap_err().key, "smoothing.window");
    let s: CueConfig = serde_json::from_str(r#"{"smoothing": {"kind": "low_pass", "corner_hz": 8}}"#).unwrap();
    assert_eq!(
        s.smoothing,
        Smoothing::LowPass {
            corner_hz: 8.0,
            order: 2
        }
    );
}

/// The largest deviation of the smoothed force on x from rest when one sample spikes by 40 m/s^2.
fn spike_effect(smoothing: Smoothing) -> f64 {
    let mut s = Smoother::<f64>::new(&smoothing);
    s.begin(&at_rest());
    let mut worst = 0.0f64;
    for k in 0..200 {
        let spiky = if k == 50 {
            sample([40.0, 0.0, G], [0.0; 3])
        } else {
            at_rest()
        };
        let out = s.step(&spiky, 0.01);
        worst = worst.max(out.force[0].abs());
        assert_eq!(&out.force[1..], &[0.0, G][..]);
    }
    worst
}

#[test]
fn a_median_removes_a_spike_and_a_low_pass_attenuates_it() {
    assert_eq!(spike_effect(Smoothing::Off), 40.0);
    assert_eq!(spike_effect(Smoothing::Median { window: 3 }), 0.0);
    assert_eq!(spike_effect(Smoothing::Median { window: 15 }), 0.0);
    // 2 Hz at 100 samples a second: less than a sixth of the spike gets through.
    for order in [1, 2] {
        let low = spike_effect(Smoothing::LowPass { corner_hz: 2.0, order });
        assert!(low > 0.0 && low < 6.0, "order {order}: {low}");
    }
    // Through the washout too: behind a median, the spike on a steady input leaves no trace.
    let config = |smoothing| CueConfig {
        smoothing,
        ..CueConfig::default()
    };
    let mut with = Washout::<f64>::new(config(Smoothing::Median { window: 5 })).unwrap();
    let mut without = with.clone();
    let clean = sample([-3.0, 2.0, G], [0.0, 0.0, 0.2]);
    with.begin(&clean).unwrap();
    without.begin(&clean).unwrap();
    for k in 1..300 {
        let mut spiky = clean;
        if k == 100 {
            spiky.force[0] += 40.0;
        }
        assert_eq!(with.step(&spiky, 0.01), without.step(&clean, 0.01));
    }
    // A steady input passes each smoothing unchanged, from the first sample on.
    for smoothing in [
        Smoothing::Median { window: 7 },
        Smoothing::LowPass {
            corner_hz: 1.0,
            order: 2,
        },
    ] {
        let mut w = Washout::<f64>::new(config(smoothing)).unwrap();
        for _ in 0..100 {
            assert_eq!(w.step(&at_rest(), 0.01).unwrap(), [0.0; 6], "{smoothing:?}");
        }
    }
}

#[test]
fn the_first_sample_reaches_the_filters() {
    // Braking at 5 m/s^2 from the first sample on: the first interval's input is the first sample's, so the
    // translation after one interval is the exact position of a step applied at the first sample's time (to the
    // trapezoidal rule's order), not half of it as if the input had ramped up from rest.
    let config = CueConfig {
        translation_break: [0.0; 3],
        ..CueConfig::default()
    };
    let braking = sample([-5.0, 0.0, G], [0.0; 3]);
    let dt = 0.01;
    let mut fed = Washout::<f64>::new(config).unwrap();
    assert_eq!(fed.begin(&braking).unwrap(), [0.0; 6], "no time has passed");
    let x = fed.step(&braking, dt).unwrap()[0];
    // Continuous: x'' = -0.5 m/s^2 from t = 0: x = -0.25 dt^2 (the high-pass shaves a few percent off).
    let exact = -0.5 * dt * dt / 2.0;
    assert!((x - exact).abs() < 0.05 * exact.abs(), "{x} vs {exact}");
    let mut unfed = Washout::<f64>::new(config).unwrap();
    let y = unfed.step(&braking, dt).unwrap()[0];
    assert!(
        (y - exact / 2.0).abs() < 0.05 * exact.abs(),
        "{y}: the first sample taken as a ramp from rest"
    );
    // A first sample that is not finite is refused.
    assert!(fed.begin(&sample([f64::NAN, 0.0, G], [0.0; 3])).is_err());
}

/// A drive: a slalom with braking, bumps and a turning heading, at `dt`.
fn drive(t: f64) -> Telemetry<f64> {
    sample(
        [3.0 * (0.7 * t).sin(), 4.0 * (1.3 * t).sin(), G + 0.8 * (9.0 * t).sin()],
        [0.2 * (2.0 * t).sin(), 0.1 * (1.1 * t).cos(), 0.4 * (0.3 * t).sin()],
    )
}

/// The largest change of the offset between consecutive samples over `[from, to)` (s), per axis, with a
/// retune to `to_config` at `at` (or none).
fn max_step(retune: Option<(f64, CueConfig)>, base: CueConfig, from: f64, to: f64) -> [f64; 6] {
    let dt = 0.01;
    let mut live = Live::<f64>::new(base).unwrap();
    let mut last = live.begin(&drive(0.0)).unwrap();
    let mut worst = [0.0f64; 6];
    let mut pending = retune;
    for k in 1..(to / dt) as usize {
        let t = k as f64 * dt;
        if let Some((at, config)) = pending {
            if t >= at {
                assert!(live.retune(config).unwrap());
                pending = None;
            }
        }
        let o = live.step(&drive(t), dt).unwrap();
        if t >= from {
            for i in 0..6 {
                worst[i] = worst[i].max((o[i] - last[i]).abs());
            }
        }
        last = o;
    }
    worst
}

fn retuned_config() -> CueConfig {
    CueConfig {
        translation_scale: [0.15, 0.05, 0.1],
        translation_high_pass: [
            Corner { omega: 2.0, zeta: 0.8 },
            Corner { omega: 6.0, zeta: 1.0 },
            Corner { omega: 3.0, zeta: 1.0 },
        ],
        translation_break: [0.5, 0.0, 2.0],
        tilt_scale: [0.3, 0.8],
        tilt_low_pass: [Corner { omega: 2.0, zeta: 1.0 }; 2],
        rotation_high_pass: [Corner { omega: 3.0, zeta: 0.7 }; 2],
        smoothing: Smoothing::Median { window: 5 },
        ..CueConfig::default()
    }
}

#[test]
fn a_retune_blends_in_without_a_jump() {
    let (old, new) = (CueConfig::default(), retuned_config());
    // Around the retune at 10 s: the hand-over's steps against the larger of the two configurations' own.
    let with = max_step(Some((10.0, new)), old, 9.0, 12.0);
    let a = max_step(None, old, 9.0, 12.0);
    let b = max_step(None, new, 9.0, 12.0);
    // The two washouts' offsets apart during the hand-over (what a switch without the blend would jump by).
    let dt = 0.01;
    let mut w_old = Washout::<f64>::new(old).unwrap();
    w_old.begin(&drive(0.0)).unwrap();
    for k in 1..1000 {
        w_old.step(&drive(k as f64 * dt), dt).unwrap();
    }
    let mut w_new = w_old.retuned(new).unwrap();
    let mut apart = [0.0f64; 6];
    for k in 1000..1100 {
        let (o, n) = (
            w_old.step(&drive(k as f64 * dt), dt).unwrap(),
            w_new.step(&drive(k as f64 * dt), dt).unwrap(),
        );
        for i in 0..6 {
            apart[i] = apart[i].max((n[i] - o[i]).abs());
        }
    }
    for i in 0..6 {
        let motion = a[i].max(b[i]);
        // The documented bound: the motion's own step plus the weight's step (1.5 dt / 1 s) times the offsets'
        // distance.
        let bound = motion + 1.5 * dt / HANDOVER_S * apart[i];
        println!(
            "axis {i}: largest step {:.3e} with the retune, {:.3e} old, {:.3e} new; bound {:.3e}; without the \
             blend the switch would move up to {:.3e}",
            with[i], a[i], b[i], bound, apart[i]
        );
        assert!(with[i] <= bound * (1.0 + 1e-9) + 1e-12, "axis {i}");
    }
    // A switch without the blend (the new washout's offset at once) would jump: the blend is what saves it.
    let dt = 0.01;
    let mut live = Live::<f64>::new(old).unwrap();
    live.begin(&drive(0.0)).unwrap();
    for k in 1..1000 {
        live.step(&drive(k as f64 * dt), dt).unwrap();
    }
    let before = live.offset();
    live.retune(new).unwrap();
    assert_eq!(live.offset(), before, "at the switch nothing moves");
    assert!(live.handing_over());
    for k in 1000..(1000 + (HANDOVER_S / dt) as usize + 1) {
        live.step(&drive(k as f64 * dt), dt).unwrap();
    }
    assert!(!live.handing_over());
    assert_eq!(live.config(), &new);
}

#[test]
fn a_bad_retune_is_refused_and_the_old_keeps_running() {
    let mut live = Live::<f64>::new(CueConfig::default()).unwrap();
    let mut reference = Live::<f64>::new(CueConfig::default()).unwrap();
    live.begin(&drive(0.0)).unwrap();
    reference.begin(&drive(0.0)).unwrap();
    let bad = CueConfig {
        tilt_rate_deg: [3.0, f64::NAN],
        ..CueConfig::default()
    };
    let e = live.retune(bad).unwrap_err();
    assert_eq!((e.key, e.axis), ("tilt_rate_deg", Some("y")));
    assert!(
        !live.retune(CueConfig::default()).unwrap(),
        "the same configuration changes nothing"
    );
    for k in 1..300 {
        let t = k as f64 * 0.01;
        assert_eq!(live.step(&drive(t), 0.01), reference.step(&drive(t), 0.01));
    }
    // A retune during a hand-over waits for its end.
    assert!(live.retune(retuned_config()).unwrap());
    assert!(live.retune(CueConfig::default()).unwrap());
    assert_eq!(live.config(), &retuned_config());
    for k in 300..410 {
        live.step(&drive(k as f64 * 0.01), 0.01).unwrap();
    }
    assert_eq!(live.config(), &CueConfig::default());
    assert!(live.handing_over());
}

fn any_corner() -> impl Strategy<Value = Corner> {
    (prop_oneof![Just(f64::NAN), -1.0..2000.0f64], -1.0..12.0f64).prop_map(|(omega, zeta)| Corner { omega, zeta })
}

fn any_number(hi: f64) -> impl Strategy<Value = f64> {
    prop_oneof![Just(f64::INFINITY), Just(-0.0), -1.0..hi]
}

prop_compose! {
    fn any_config()(
        ts in prop::array::uniform3(any_number(12.0)),
        tl in prop::array::uniform3(any_number(120.0)),
        thp in prop::array::uniform3(any_corner()),
        tb in prop::array::uniform3(any_number(1200.0)),
        ls in prop::array::uniform2(any_number(12.0)),
        llp in prop::array::uniform2(any_corner()),
        lim in prop::array::uniform2(any_number(50.0)),
        rate in prop::array::uniform2(any_number(100.0)),
        rs in prop::array::uniform2(any_number(12.0)),
        rhp in prop::array::uniform2(any_corner()),
        window in 0u8..20,
        corner_hz in any_number(1200.0),
        order in 0u8..4,
        kind in 0u8..3,
    ) -> CueConfig {
        CueConfig {
            translation_scale: ts,
            translation_limit: tl,
            translation_high_pass: thp,
            translation_break: tb,
            tilt_scale: ls,
            tilt_low_pass: llp,
            tilt_limit_deg: lim,
            tilt_rate_deg: rate,
            rotation_scale: rs,
            rotation_high_pass: rhp,
            smoothing: match kind {
                0 => Smoothing::Off,
                1 => Smoothing::Median { window },
                _ => Smoothing::LowPass { corner_hz, order },
            },
            ..CueConfig::default()
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Any configuration is either valid, and then cues a drive to finite offsets and hands over to and from
    /// the defaults, or refused with a key; nothing panics.
    #[test]
    fn random_configs_validate_or_are_refused(config in any_config(), dt in 0.001f64..0.05) {
        match config.validate() {
            Err(e) => {
                prop_assert!(!e.key.is_empty());
                prop_assert!(Washout::<f64>::new(config).is_err());
                let mut live = Live::<f64>::new(CueConfig::default()).unwrap();
                prop_assert!(live.retune(config).is_err());
            }
            Ok(()) => {
                let mut live = Live::<f64>::new(config).unwrap();
                live.begin(&drive(0.0)).unwrap();
                for k in 1..200 {
                    if k == 50 {
                        live.retune(CueConfig::default()).unwrap();
                    }
                    if k == 150 {
                        live.retune(config).unwrap();
                    }
                    let o = live.step(&drive(k as f64 * dt), dt).unwrap();
                    prop_assert!(o.iter().all(|v| v.is_finite()), "{o:?}");
                }
            }
        }
    }
}

/// Every key of `[optimal]` refused out of its range, as not a number and as infinite, with the key named; a
/// value at each end of its range taken.
#[test]
fn every_optimal_key_is_refused_out_of_range_by_name() {
    type Set = fn(&mut OptimalConfig, f64);
    let keys: [(&str, Set, f64, f64); 17] = [
        ("optimal.horizon", |o, v| o.horizon = v as u32, 2.0, 60.0),
        ("optimal.step_s", |o, v| o.step_s = v, 0.005, 0.5),
        ("optimal.force_weight", |o, v| o.force_weight[2] = v, 0.0, 1e6),
        ("optimal.rotation_weight", |o, v| o.rotation_weight[1] = v, 0.0, 1e6),
        ("optimal.position_weight", |o, v| o.position_weight[0] = v, 0.0, 1e6),
        ("optimal.velocity_weight", |o, v| o.velocity_weight[1] = v, 0.0, 1e6),
        ("optimal.tilt_weight", |o, v| o.tilt_weight[0] = v, 0.0, 1e6),
        ("optimal.tilt_loss_weight", |o, v| o.tilt_loss_weight = v, 0.0, 1e6),
        ("optimal.plan_weight", |o, v| o.plan_weight = v, 0.0, 1e6),
        (
            "optimal.acceleration_weight",
            |o, v| o.acceleration_weight[1] = v,
            1e-9,
            1e6,
        ),
        ("optimal.rate_weight", |o, v| o.rate_weight[1] = v, 1e-9, 1e6),
        ("optimal.max_velocity", |o, v| o.max_velocity[2] = v, 1e-6, 10.0),
        (
            "optimal.max_acceleration",
            |o, v| o.max_acceleration[0] = v,
            1e-6,
            100.0,
        ),
        ("optimal.max_rate_deg", |o, v| o.max_rate_deg[1] = v, 1e-6, 720.0),
        ("optimal.envelope_share", |o, v| o.envelope_share = v, 0.05, 1.0),
        ("optimal.tilt_share", |o, v| o.tilt_share = v, 0.05, 1.0),
        ("optimal.budget_ms", |o, v| o.budget_ms = v, 0.01, 1000.0),
    ];
    let with = |set: Set, v: f64| {
        let mut c = CueConfig::default();
        set(&mut c.optimal, v);
        c.validate()
    };
    for (key, set, lo, hi) in keys {
        assert!(with(set, lo).is_ok() && with(set, hi).is_ok(), "{key} at {lo} or {hi}");
        let integer = key == "optimal.horizon";
        let mut bad = vec![if integer { lo - 1.0 } else { lo * 0.5 - 1e-3 }, hi * 2.0 + 1.0];
        if !integer {
            bad.extend([f64::NAN, f64::INFINITY, -f64::INFINITY]);
        }
        if lo > 0.0 && !integer {
            // Zero, where the range starts above it.
            bad.push(0.0);
        }
        for v in bad {
            let e = with(set, v).expect_err(key);
            assert_eq!(e.key, key, "{key} = {v}");
            assert!(e.to_string().starts_with(key), "{e}");
        }
    }
    // Unknown keys and lists of the wrong length are refused by the parser.
    assert!(serde_json::from_str::<CueConfig>(r#"{"optimal": {"horizont": 8}}"#).is_err());
    assert!(serde_json::from_str::<CueConfig>(r#"{"optimal": {"force_weight": [1, 2]}}"#).is_err());
    assert!(serde_json::from_str::<CueConfig>(r#"{"optimal": {"horizon": -1}}"#).is_err());
    let one: CueConfig = serde_json::from_str(r#"{"optimal": {"force_weight": 3}}"#).unwrap();
    assert_eq!(one.optimal.force_weight, [3.0; 3]);
}

use super::*;

const LENGTH: f64 = 1000.0;
const SPEED: f64 = 25.0;
const DT: f64 = 0.01;

/// The lap's surge force at distance `s`: smooth, with a braking-like dip at 400-450 m.
fn lap_force(s: f64) -> f64 {
    3.0 * (core::f64::consts::TAU * s / 200.0).sin() - if (400.0..450.0).contains(&s) { 6.0 } else { 0.0 }
}

fn sample(ax: f64) -> Telemetry<f64> {
    Telemetry {
        force: [ax, 0.0, G],
        rate: [0.0; 3],
    }
}

/// Drives `laps` laps at constant speed from time `t0`: lap `n`'s force at distance `s` is `force(n, s)`; each
/// sample's preview ahead (8 steps of 0.15 s) and state returned.
fn drive(
    p: &mut LapPreview,
    laps: usize,
    force: impl Fn(usize, f64) -> f64,
) -> Vec<(Vec<Telemetry<f64>>, State, Telemetry<f64>)> {
    let per_lap = (LENGTH / SPEED / DT).round() as usize;
    let mut out = Vec::new();
    for n in 0..laps {
        for k in 0..per_lap {
            let s = k as f64 * SPEED * DT;
            let t = (n * per_lap + k) as f64 * DT;
            let x = sample(force(n, s));
            p.observe(t, s, &x);
            out.push((p.ahead(&x, 8, 0.15), p.state(), x));
        }
    }
    out
}

#[test]
fn a_lap_shifted_in_distance_is_matched_at_its_shift_and_previews_what_comes() {
    let mut p = LapPreview::new(Settings::default());
    // The second lap's features come 6 m later: its distance s sees the first lap's s - 6.
    let out = drive(&mut p, 2, |n, s| lap_force(if n == 0 { s } else { s - 6.0 }));
    assert_eq!(p.counts().laps, 1);
    assert_eq!(p.counts().kept, 1);
    let (m, shift) = p.matched.unwrap();
    let bin = LENGTH / 2048.0;
    assert_eq!(m, 0);
    assert!((shift * bin + 6.0).abs() < 1.5 * bin, "shift {} m", shift * bin);
    // Half a second before the second lap's dip (at 406 m), the preview's reference sees it coming: the held
    // sample does not.
    let at = 40 * 100 + ((406.0 - 0.5 * SPEED) / SPEED / DT) as usize;
    let (ahead, state, held) = &out[at];
    assert_eq!(state.confidence, 1.0);
    assert_eq!(state.matched, Some(0));
    assert!(held.force[0] > -2.0, "{held:?}");
    let least = ahead.iter().map(|s| s.force[0]).fold(f64::INFINITY, f64::min);
    assert!(least < -4.0, "{ahead:?}");
    // No departure on a lap that only shifted.
    assert_eq!(p.counts().departures, 0);
}

#[test]
fn a_departure_is_detected_within_a_fraction_of_a_second_and_the_preview_fades_without_a_jump() {
    let mut p = LapPreview::new(Settings::default());
    // On the third lap the car leaves the track at 600 m: a steady 10 m/s^2 it never had, for 4 s.
    let off = |s: f64| (600.0..700.0).contains(&s);
    let out = drive(&mut p, 4, |n, s| if n == 2 && off(s) { 10.0 } else { lap_force(s) });
    let per_lap = 4000;
    let leaves = 2 * per_lap + (600.0 / SPEED / DT) as usize;
    let noticed = (leaves..out.len()).find(|&k| out[k].1.confidence < 1.0).unwrap();
    // The settings' hold (0.15 s) plus the window's reaction: within 25 samples.
    assert!(noticed - leaves <= 25, "noticed after {} samples", noticed - leaves);
    assert_eq!(p.counts().departures, 1);
    // The fade: the share moves by at most dt / fade_s a sample, and the reference with it.
    let step = DT / Settings::default().fade_s;
    let mut largest = 0.0f64;
    for k in leaves..leaves + 200 {
        let (a, b) = (&out[k - 1], &out[k]);
        assert!((b.1.confidence - a.1.confidence).abs() <= step + 1e-12);
        if let (Some(x), Some(y)) = (a.0.first(), b.0.first()) {
            if a.2.force[0] == b.2.force[0] {
                largest = largest.max((y.force[0] - x.force[0]).abs());
            }
        }
    }
    // Cut at once, the reference would step by the lap's force against 10 m/s^2 (7-16 m/s^2); the fade moves it
    // by the share's step times that, and the lap's own change.
    assert!(largest > 0.0 && largest < 0.4, "{largest}");
    // Faded out while off; back on the fourth lap (the lap with the departure not kept: one lap of reference
    // fewer).
    let during = &out[leaves + 150].1;
    assert_eq!(during.confidence, 0.0);
    assert_eq!(out.last().unwrap().1.confidence, 1.0);
    assert_eq!((p.counts().laps, p.counts().kept), (3, 2));
}

#[test]
fn two_runs_give_the_same_preview_bit_for_bit() {
    let run = || {
        let mut p = LapPreview::new(Settings::default());
        let out = drive(&mut p, 3, |n, s| {
            lap_force(s + n as f64 * 2.0) * (1.0 + 0.03 * n as f64)
        });
        let bits: Vec<u64> = out
            .iter()
            .flat_map(|(a, s, _)| {
                a.iter()
                    .flat_map(|x| x.force.iter().chain(&x.rate).map(|v| v.to_bits()))
                    .chain([s.confidence.to_bits(), s.error.to_bits()])
                    .collect::<Vec<_>>()
            })
            .collect();
        (bits, p.counts())
    };
    let (a, ca) = run();
    let (b, cb) = run();
    assert!(a == b);
    assert_eq!(ca, cb);
    assert!(ca.state.unwrap().matched.is_some(), "{ca:?}");
    assert!(ca.previewed_s > 30.0, "{ca:?}");
}

#[test]
fn bad_lap_distances_are_counted_and_fade_the_preview_without_a_panic() {
    let mut p = LapPreview::new(Settings::default());
    drive(&mut p, 2, |_, s| lap_force(s));
    assert_eq!(p.state().confidence, 1.0);
    let t0 = 80.0;
    let mut t = t0;
    let mut s = 100.0;
    let mut confidence = vec![p.state().confidence];
    let mut feed = |p: &mut LapPreview, t: f64, s: f64, ax: f64| {
        p.observe(t, s, &sample(ax));
        let _ = p.ahead(&sample(ax), 8, 0.15);
        confidence.push(p.state().confidence);
    };
    // NaN and infinite distances, a NaN force, backwards, a jump forward, a wrap backwards over the line, time
    // not moving on: none panics, each counted, and the share never steps by more than the fade's rate.
    for bad in [f64::NAN, f64::INFINITY, -1.0, 5.0, 900.0] {
        for _ in 0..20 {
            t += DT;
            s += SPEED * DT;
            feed(&mut p, t, s, lap_force(s));
        }
        t += DT;
        let d = if bad == -1.0 || bad == 5.0 {
            s - 20.0 * bad.abs()
        } else {
            bad
        };
        feed(&mut p, t, d, lap_force(s));
    }
    feed(&mut p, t, s, f64::NAN);
    feed(&mut p, t - 1.0, s, 0.0);
    let c = p.counts();
    assert!(c.bad_distance >= 5, "{c:?}");
    assert!(c.departures >= 1, "{c:?}");
    let step = DT / Settings::default().fade_s;
    assert!(
        confidence.windows(2).all(|w| (w[1] - w[0]).abs() <= step + 1e-12),
        "{confidence:?}"
    );
    assert!(p
        .ahead(&sample(0.0), 8, 0.15)
        .iter()
        .all(|x| x.force.iter().all(|f| f.is_finite())));
    // And it comes back: a clean lap after all that is matched again.
    let mut q = p.clone();
    let base = t + 1.0;
    for k in 0..8000 {
        let d = (k as f64 * SPEED * DT) % LENGTH;
        q.observe(base + k as f64 * DT, d, &sample(lap_force(d)));
    }
    assert_eq!(q.state().confidence, 1.0, "{:?} {:?}", q.state(), q.counts());
}

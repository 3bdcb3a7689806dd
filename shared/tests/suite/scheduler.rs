//! The step scheduler over thousands of random trajectories: exact counts, position at every period boundary,
//! minimum pulse spacing, DIR setup and hold, and nothing lost when a target is beyond the top rate.

use proptest::prelude::*;
use ringpod_core::motion::{AxisMove, Direction, SchedulerConfig, StepScheduler};

/// One emitted edge on the absolute timeline (ns).
#[derive(Debug, Clone, Copy)]
struct Step {
    t: i64,
    dir: Direction,
}

/// Runs the scheduler over per-period targets for one axis (the others mirror it with other signs), and checks
/// every invariant on the emitted times. Returns the steps of axis 0.
fn run(config: SchedulerConfig, targets: &[i64], start: i64) -> Result<(), TestCaseError> {
    let mut s = StepScheduler::new(config, [start, -start, 0, start, 0, 0]);
    let period = i64::from(config.period_ns);
    let mut steps: Vec<Vec<Step>> = vec![Vec::new(); 6];
    let mut dir_changes: Vec<Vec<(i64, Direction)>> = vec![Vec::new(); 6];
    let mut positions = [start, -start, 0, start, 0, 0];
    for (p, &target) in targets.iter().enumerate() {
        let axis_targets = [target, -target, 0, target, target / 2, target - start];
        let moves = s.plan(&axis_targets);
        for (i, m) in moves.iter().enumerate() {
            let t0 = p as i64 * period;
            if let Some(c) = m.dir_change_ns {
                prop_assert!(m.count > 0);
                dir_changes[i].push((t0 + i64::from(c), m.direction));
            }
            for t in m.times() {
                prop_assert!(t >= m.start_ns && t < config.period_ns, "step outside its period");
                steps[i].push(Step {
                    t: t0 + i64::from(t),
                    dir: m.direction,
                });
            }
            positions[i] += m.signed();
            // Within the top rate the position at every boundary is exactly the target.
            prop_assert_eq!(positions[i], s.position()[i]);
            if (axis_targets[i] - (positions[i] - m.signed())).unsigned_abs()
                <= u64::from(config.max_steps_per_period() / 2)
            {
                prop_assert_eq!(positions[i], axis_targets[i], "axis {} period {}", i, p);
            }
        }
    }
    for i in 0..6 {
        for w in steps[i].windows(2) {
            prop_assert!(
                w[1].t - w[0].t >= i64::from(config.min_spacing_ns),
                "spacing {} ns",
                w[1].t - w[0].t
            );
        }
        for (t, dir) in &dir_changes[i] {
            // Steps are in time order: the ones around the change by binary search.
            let at = steps[i].partition_point(|s| s.t < *t);
            if let Some(before) = at.checked_sub(1).map(|k| steps[i][k]) {
                prop_assert!(before.dir != *dir, "a DIR change between steps of the same direction");
                prop_assert!(
                    t - before.t >= i64::from(config.dir_hold_ns),
                    "DIR hold {} ns",
                    t - before.t
                );
            }
            let after = steps[i][at];
            prop_assert!(
                after.t - t >= i64::from(config.dir_setup_ns),
                "DIR setup {} ns",
                after.t - t
            );
            prop_assert!(after.dir == *dir);
        }
        // Every direction switch between consecutive steps has a DIR change between them.
        for w in steps[i].windows(2) {
            if w[0].dir != w[1].dir {
                let k = dir_changes[i].partition_point(|(t, _)| *t <= w[0].t);
                prop_assert!(dir_changes[i].get(k).is_some_and(|(t, _)| *t < w[1].t));
            }
        }
    }
    Ok(())
}

/// Random trajectories: per-period changes up to 100 steps (100 k steps/s at 1 kHz), with reversals.
fn trajectory() -> impl Strategy<Value = Vec<i64>> {
    prop::collection::vec(-100i64..=100, 1..300).prop_map(|deltas| {
        deltas
            .iter()
            .scan(0i64, |p, d| {
                *p += d;
                Some(*p)
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn random_trajectories_keep_every_invariant(targets in trajectory(), start in -1_000_000i64..1_000_000) {
        let targets: Vec<i64> = targets.iter().map(|t| t + start).collect();
        run(SchedulerConfig::default(), &targets, start)?;
    }

    #[test]
    fn slow_drivers_and_fast_loops(targets in trajectory()) {
        // A 4 kHz loop with drivers that need 10 us pulses, 20 us spacing and 20 us DIR setup and hold.
        let config = SchedulerConfig { period_ns: 250_000, pulse_ns: 10_000, min_spacing_ns: 20_000, dir_setup_ns: 20_000, dir_hold_ns: 20_000 };
        prop_assert!(config.is_valid());
        let targets: Vec<i64> = targets.iter().map(|t| t / 10).collect();
        run(config, &targets, 0)?;
    }

    /// Beyond the top rate the scheduler carries steps over and never loses one.
    #[test]
    fn over_rate_targets_are_caught_up(jump in 200i64..2000, sign in prop::bool::ANY) {
        let jump = if sign { jump } else { -jump };
        let config = SchedulerConfig::default();
        let mut s = StepScheduler::new(config, [0; 6]);
        let mut emitted = 0i64;
        let mut periods = 0;
        while s.position()[0] != jump {
            emitted += s.plan(&[jump, 0, 0, 0, 0, 0])[0].signed();
            periods += 1;
            prop_assert!(periods < 100);
        }
        prop_assert_eq!(emitted, jump);
        prop_assert!(s.carried() > 0);
        let fastest = i64::from(config.max_steps_per_period());
        prop_assert!(periods as i64 <= jump.abs() / (fastest - 2) + 1, "{} periods", periods);
    }
}

#[test]
fn six_axes_at_100k_steps_per_second() {
    let config = SchedulerConfig::default();
    let mut s = StepScheduler::new(config, [0; 6]);
    for p in 1..=1000i64 {
        let t = [100 * p, -100 * p, 100 * p, -100 * p, 100 * p, -100 * p];
        let moves = s.plan(&t);
        assert!(moves.iter().all(|m| m.count == 100));
    }
    assert_eq!(s.position(), [100_000, -100_000, 100_000, -100_000, 100_000, -100_000]);
    assert_eq!(s.carried(), 0);
}

#[test]
fn invalid_timing_is_detected() {
    let ok = SchedulerConfig::default();
    assert!(ok.is_valid());
    assert!(
        !SchedulerConfig {
            min_spacing_ns: 4_000,
            ..ok
        }
        .is_valid(),
        "low time shorter than the pulse"
    );
    assert!(!SchedulerConfig {
        dir_setup_ns: 1_000_000,
        ..ok
    }
    .is_valid());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2_000, ..ProptestConfig::default() })]

    /// The incremental step times are exactly the closed form, for any window and count (large counts take the
    /// closed form itself), up to periods near 2^32, where the increment past the last step exceeds u32.
    #[test]
    fn incremental_step_times_equal_the_closed_form(
        period in prop_oneof![1u32..=1_000_000_000, u32::MAX - 1_000..=u32::MAX],
        start_fraction in 0.0..1.0f64,
        count in prop_oneof![1u32..=400, 400u32..=200_000, Just(u32::MAX / 2 + 7)],
    ) {
        let start = ((f64::from(period) * start_fraction) as u32).min(period - 1);
        let m = AxisMove { direction: Direction::Forward, dir_change_ns: None, start_ns: start, count, period_ns: period };
        let take = count.min(2_000);
        for (k, t) in m.times().take(take as usize).enumerate() {
            prop_assert_eq!(t, m.step_ns(k as u32), "step {}", k);
        }
        if count <= 2_000 {
            prop_assert_eq!(m.times().count(), count as usize);
        }
    }

    /// The last step's time by one division is the closed form's, for every window and count a valid period holds
    /// (up to a second, at least 2.5 ns a step as the shortest valid spacing allows), the ends included.
    #[test]
    fn the_last_step_time_is_the_closed_forms(
        period in prop_oneof![1u32..=2_000, 1u32..=1_000_000_000, Just(1_000_000_000u32)],
        start_fraction in prop_oneof![0.0..1.0f64, Just(0.0), Just(1.0)],
        count_fraction in prop_oneof![0.0..1.0f64, Just(1.0)],
    ) {
        let start = ((f64::from(period) * start_fraction) as u32).min(period - 1);
        let room = ((period - start) / 2).max(1);
        let count = ((f64::from(room) * count_fraction) as u32).clamp(1, room);
        let m = AxisMove { direction: Direction::Backward, dir_change_ns: None, start_ns: start, count, period_ns: period };
        prop_assert_eq!(m.last_step_ns(), m.step_ns(count - 1), "start {} count {}", start, count);
    }
}

/// Positions at the ends of `i64` and targets beyond their reach: the new position is never past the target (the
/// scheduler adds a move's count without saturation, since it cannot overflow), and a period in which several
/// axes fall short counts once.
#[test]
fn positions_at_the_ends_of_i64_move_toward_the_target_and_carry_once_a_period() {
    let config = SchedulerConfig::default();
    let fastest = i64::from(config.max_steps_per_period());
    let start = [i64::MAX - 1, i64::MIN + 1, i64::MAX, i64::MIN, 0, -5];
    let mut s = StepScheduler::new(config, start);
    let targets = [i64::MIN, i64::MAX, i64::MAX, i64::MIN, i64::MAX, i64::MIN];
    for period in 1..=3u32 {
        let before = s.position();
        let moves = s.plan(&targets);
        for i in 0..6 {
            let after = s.position()[i];
            assert_eq!(
                i128::from(after),
                i128::from(before[i]) + i128::from(moves[i].signed()),
                "axis {i}"
            );
            let (lo, hi) = (before[i].min(targets[i]), before[i].max(targets[i]));
            assert!(lo <= after && after <= hi, "axis {i}: {after} outside [{lo}, {hi}]");
            assert!(moves[i].signed().abs() <= fastest);
        }
        assert_eq!(s.carried(), period, "four axes short, one period");
    }
    assert_eq!(s.position()[2], i64::MAX);
    assert_eq!(s.position()[3], i64::MIN);
}

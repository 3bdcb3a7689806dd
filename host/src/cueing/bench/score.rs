//! A cued drive's score: what the rider perceives on the platform against what the vehicle's occupant perceives
//! (the core's perception model on both), the false cues, the share of the envelope used.

use ringpod_core::cueing::perception::{Perception, FORCE_THRESHOLD, ROTATION_THRESHOLD_DEG};
use ringpod_core::cueing::{Forward, G};
use ringpod_core::kinematics::Pose;
use serde::Serialize;

use crate::cueing::offline::{delivered_forces, Cued};
use crate::cueing::optimal::Ranges;

/// False cues on one axis: the platform's perceived cue above the threshold and opposite in sign to the
/// vehicle's.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct FalseCues {
    /// Separate episodes.
    pub count: usize,
    /// Their time together (s).
    pub seconds: f64,
}

/// One drive cued by one algorithm, scored.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Score {
    /// Samples scored.
    pub samples: usize,
    /// RMS perceived specific-force error, x, y, z (m/s^2).
    pub force_rms: [f64; 3],
    /// Peak perceived specific-force error, x, y, z (m/s^2).
    pub force_peak: [f64; 3],
    /// RMS perceived angular-velocity error, roll, pitch, yaw (rad/s).
    pub rotation_rms: [f64; 3],
    /// False specific-force cues, x, y, z.
    pub false_force: [FalseCues; 3],
    /// False rotation cues, roll, pitch.
    pub false_rotation: [FalseCues; 2],
    /// The largest share of each axis's range about home used: x, y, z, roll, pitch (1 = the range's edge).
    pub envelope_share: [f64; 5],
}

impl Score {
    /// The RMS perceived specific-force error of the three axes together (m/s^2): the number to lower.
    pub fn force_total(&self) -> f64 {
        self.force_rms.iter().map(|r| r * r).sum::<f64>().sqrt()
    }

    /// False cues of every axis.
    pub fn false_total(&self) -> usize {
        self.false_force
            .iter()
            .chain(&self.false_rotation)
            .map(|f| f.count)
            .sum()
    }
}

/// A platform-axes vector in vehicle axes (the inverse of the washout's turn for `forward`).
fn to_vehicle(forward: Forward, [x, y, z]: [f64; 3]) -> [f64; 3] {
    match forward {
        Forward::PlusX => [x, y, z],
        Forward::PlusY => [y, -x, z],
        Forward::MinusX => [-x, -y, z],
        Forward::MinusY => [-y, x, z],
    }
}

/// Runs of a condition, sample by sample: episodes and their time.
#[derive(Default)]
struct Runs {
    cues: FalseCues,
    on: bool,
}

impl Runs {
    fn add(&mut self, on: bool, dt: f64) {
        if on {
            self.cues.seconds += dt;
            if !self.on {
                self.cues.count += 1;
            }
        }
        self.on = on;
    }
}

/// Whether the platform's perceived cue is a false one: above `threshold` and against the vehicle's.
fn false_cue(platform: f64, vehicle: f64, threshold: f64) -> bool {
    platform.abs() > threshold && platform * vehicle < 0.0
}

/// One sample's perceived specific force (less g), vehicle's and platform's, vehicle axes (m/s^2).
#[derive(Debug, Clone, Copy)]
pub struct Trace {
    /// Time (s).
    pub t: f64,
    /// The vehicle's occupant perceives.
    pub vehicle: [f64; 3],
    /// The rider on the platform perceives.
    pub platform: [f64; 3],
}

/// Widens each axis's largest share of its range about home (x, y, z, roll, pitch; 1 = the range's edge) to
/// cover `offset` from home.
pub fn widen_shares(shares: &mut [f64; 5], offset: &[f64], ranges: &Ranges) {
    for (i, share) in shares.iter_mut().enumerate() {
        let edge = if offset[i] >= 0.0 { ranges[i].1 } else { ranges[i].0 };
        if edge != 0.0 {
            *share = share.max(offset[i] / edge);
        }
    }
}

/// Scores a cued drive about `neutral` in `ranges`, the platform facing `forward`; with each sample's perceived
/// forces.
pub fn score(cued: &[Cued], neutral: &Pose<f64>, ranges: &Ranges, forward: Forward) -> (Score, Vec<Trace>) {
    score_from(cued, 0, neutral, ranges, forward)
}

/// [`score`] of the samples from index `from` on (a multi-lap drive scored on the laps after the first: the
/// perception runs from the start, the errors, false cues and shares count from `from`).
pub fn score_from(
    cued: &[Cued],
    from: usize,
    neutral: &Pose<f64>,
    ranges: &Ranges,
    forward: Forward,
) -> (Score, Vec<Trace>) {
    let mut s = Score {
        samples: cued.len().saturating_sub(from),
        ..Score::default()
    };
    let mut traces = Vec::with_capacity(cued.len());
    if cued.len() < 2 {
        return (s, traces);
    }
    let delivered = delivered_forces(cued);
    let (mut vehicle, mut platform) = (Perception::<f64>::new(), Perception::<f64>::new());
    let less_g = |f: [f64; 3]| [f[0], f[1], f[2] - G];
    let rotation_threshold = ROTATION_THRESHOLD_DEG.map(f64::to_radians);
    let mut force_runs: [Runs; 3] = Default::default();
    let mut rotation_runs: [Runs; 2] = Default::default();
    let (mut sum_f, mut sum_w) = ([0.0; 3], [0.0; 3]);
    let n = neutral.to_array();
    vehicle.begin(less_g(cued[0].input.force), cued[0].input.rate);
    platform.begin([0.0; 3], [0.0; 3]);
    for k in 1..cued.len() {
        let (a, b) = (&cued[k - 1], &cued[k]);
        let dt = b.t - a.t;
        if !(dt > 0.0 && dt <= 1.0) {
            continue;
        }
        let (pa, pb) = (a.pose.to_array(), b.pose.to_array());
        let rate_platform = [(pb[3] - pa[3]) / dt, (pb[4] - pa[4]) / dt, (pb[5] - pa[5]) / dt];
        let (roll, pitch) = {
            let r = to_vehicle(forward, [rate_platform[0], rate_platform[1], 0.0]);
            (r[0], r[1])
        };
        let pv = vehicle.step(less_g(b.input.force), b.input.rate, dt);
        let force = to_vehicle(forward, delivered[k]);
        let pp = platform.step(less_g(force), [roll, pitch, rate_platform[2]], dt);
        traces.push(Trace {
            t: b.t,
            vehicle: pv.force,
            platform: pp.force,
        });
        if k < from {
            continue;
        }
        for i in 0..3 {
            let e = pp.force[i] - pv.force[i];
            sum_f[i] += e * e;
            s.force_peak[i] = s.force_peak[i].max(e.abs());
            let w = pp.rate[i] - pv.rate[i];
            sum_w[i] += w * w;
            force_runs[i].add(false_cue(pp.force[i], pv.force[i], FORCE_THRESHOLD[i]), dt);
        }
        for i in 0..2 {
            rotation_runs[i].add(false_cue(pp.rate[i], pv.rate[i], rotation_threshold[i]), dt);
        }
        let offset: [f64; 5] = core::array::from_fn(|i| pb[i] - n[i]);
        widen_shares(&mut s.envelope_share, &offset, ranges);
    }
    // Every interval from `from` on (those skipped over a pause included, as ever).
    let m = cued.len().saturating_sub(from.max(1)).max(1) as f64;
    s.force_rms = sum_f.map(|v| (v / m).sqrt());
    s.rotation_rms = sum_w.map(|v| (v / m).sqrt());
    s.false_force = force_runs.map(|r| r.cues);
    s.false_rotation = [rotation_runs[0].cues, rotation_runs[1].cues];
    (s, traces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_false_cue_is_counted_once_per_episode_with_its_time() {
        let mut r = Runs::default();
        for on in [false, true, true, false, true, false] {
            r.add(on, 0.01);
        }
        assert_eq!(r.cues.count, 2);
        assert!((r.cues.seconds - 0.03).abs() < 1e-12);
        assert!(false_cue(0.5, -1.0, 0.17) && !false_cue(0.1, -1.0, 0.17) && !false_cue(0.5, 1.0, 0.17));
    }

    #[test]
    fn turning_back_to_vehicle_axes_undoes_the_washouts_turn() {
        for f in [Forward::PlusX, Forward::PlusY, Forward::MinusX, Forward::MinusY] {
            let o = ringpod_core::cueing::to_platform(f, [1.0, 2.0, 3.0], 0.0, 0.0, 0.0);
            assert_eq!(to_vehicle(f, [o[0], o[1], o[2]]), [1.0, 2.0, 3.0], "{f:?}");
        }
    }
}

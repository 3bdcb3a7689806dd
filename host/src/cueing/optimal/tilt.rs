//! The tilt's coupled room. Each axis's range about home is found with the others at home, but a ring platform's
//! roll and pitch share one envelope: on the trainer model it reaches 21.5 deg of roll or 20.3 deg of pitch alone,
//! and only 16-18 deg in a diagonal, less again with the platform moved off home. The optimal cueing plans x
//! (pitch) and y (roll) in separate programmes, each with an interval on its angle; planning both to their own
//! range's edge asks for a corner the envelope does not hold, and the envelope limiter then cuts every such pose
//! back along its ray to home. A cut that changes from one sample to the next is a step of the angle, which the
//! canals' lead (12 times at high frequency) makes a false rotation cue.
//!
//! So the two share it, sample by sample, asking the rig itself with the limiter's own margins: the axis whose
//! force asks for more of its range plans first, in the interval its angle can take beside the other's present
//! angle; the other then plans in the interval that holds beside every angle the first one's plan passes. Both
//! at the platform's present translations and heading. An interval is found by stepping the angle out from home
//! in quarter degrees to the first pose the limiter would cut (at most some 80 evaluations of IK and the checks
//! each way, some tens of microseconds). A bound closes in no faster than the axis's tilt rate limit: one that
//! jumps in makes the plan pull the angle back at once, felt as a rotation and a dip of force (on the shipped
//! drives that cost more false cues than the limiter's cuts it saved).
//!
//! The translations still plan in their own ranges: their corners, with the tilt, can leave the envelope, and
//! the limiter cuts those poses.

use ringpod_core::cueing::{self, Forward, G};
use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::{envelope, EnvelopeMargins};

use super::{Axis, X, Z};

/// The angle's step when the room is searched (rad): a quarter of a degree.
const STEP: f64 = 0.25 * core::f64::consts::PI / 180.0;

/// The angle bound's place among a horizontal axis's bounds ([`super::cost_and_bounds`]).
pub const ANGLE_BOUND: usize = 2;

/// The position bound's place among the vertical axis's bounds.
pub const HEAVE_BOUND: usize = 0;

/// The heave's step when its room is searched (m).
const HEAVE_STEP: f64 = 0.001;

/// How fast the heave's bound may close in (m/s): the default velocity limit, so that the heave is not pulled
/// back faster than it can move (on the laps 0.1 m/s cut more poses and gave 0.6 % more force error).
const HEAVE_CLOSING: f64 = 0.5;

/// How much more of its range the other axis's force must ask for before it plans first: a small hysteresis,
/// so that two forces asking about as much do not swap the order (and the bounds) from sample to sample.
const SWAP: f64 = 0.05;

/// The two horizontal axes sharing the tilt's room, sample by sample.
#[derive(Debug, Clone)]
pub struct Sharing {
    mechanism: RingPlatform<f64>,
    neutral: Pose<f64>,
    forward: Forward,
    margins: EnvelopeMargins,
    /// Each axis's own interval on its angle (x's is minus the pitch, y's the roll): its share of the range and
    /// the tilt limit.
    base: [(f64, f64); 2],
    /// The axis that planned first at the last sample.
    first: usize,
    /// Each axis's bound at the last sample.
    last: [(f64, f64); 2],
    /// How fast a bound may close in on an axis (rad/s): its tilt rate limit.
    closing: [f64; 2],
    /// The heave's bound at the last sample (none before the first).
    heave: Option<(f64, f64)>,
}

impl Sharing {
    /// Shares the room of `mechanism` about `neutral`, the platform facing `forward`, between the axes whose
    /// own angle intervals are `base`.
    pub fn new(
        mechanism: RingPlatform<f64>,
        neutral: Pose<f64>,
        forward: Forward,
        base: [(f64, f64); 2],
        closing: [f64; 2],
    ) -> Self {
        Self {
            mechanism,
            neutral,
            forward,
            margins: EnvelopeMargins::default(),
            base,
            first: X,
            last: base,
            closing,
            heave: None,
        }
    }

    /// Axis `i`'s bound over a sample of `dt`: the room found, closing in no faster than the axis's tilt rate
    /// (a bound that jumps in makes the plan pull the angle back at once: a rotation cue and a dip of force).
    pub(super) fn bound_over(
        &mut self,
        i: usize,
        first: bool,
        axes: &[Axis; 3],
        h: f64,
        yaw: f64,
        dt: f64,
    ) -> (f64, f64) {
        let (lo, hi) = self.bound(i, first, axes, h, yaw);
        let (last_lo, last_hi) = self.last[i];
        let step = self.closing[i] * dt;
        let b = (lo.min(last_lo + step), hi.max(last_hi - step));
        self.last[i] = b;
        b
    }

    /// The heave's interval over a sample of `dt`: within its own `base`, the room beside every pair of angles the
    /// two tilts' plans (steps of `h` seconds) pass, at the platform's present horizontal translations and
    /// heading `yaw`; closing in no faster than [`HEAVE_CLOSING`]. The heave plans after both tilts, and a heave
    /// that makes up their loss of vertical force at its range's edge asks for a corner the envelope does not hold
    /// beside a full tilt: the limiter's cut would take the tilt back with it.
    pub(super) fn heave_bound_over(
        &mut self,
        axes: &[Axis; 3],
        base: (f64, f64),
        h: f64,
        yaw: f64,
        dt: f64,
    ) -> (f64, f64) {
        let [(xa, xb), (ya, yb)] = [X, 1].map(|i| axes[i].planned_span(h));
        let corners = [(xa, ya), (xa, yb), (xb, ya), (xb, yb)];
        let holds = |z: f64| {
            corners.iter().all(|&(x, y)| {
                let offset = cueing::to_platform(self.forward, [axes[X].x[0], axes[1].x[0], z], y, -x, yaw);
                let pose = cueing::pose(&self.neutral, &offset);
                !envelope::limit(&self.mechanism, &self.neutral, &pose, &self.margins, 1).is_limited()
            })
        };
        let reach = |end: f64| {
            if holds(end) {
                return end;
            }
            let step = HEAVE_STEP.copysign(end);
            let mut v = 0.0;
            while (v + step).abs() < end.abs() && holds(v + step) {
                v += step;
            }
            v
        };
        let (lo, hi) = if holds(0.0) {
            (reach(base.0), reach(base.1))
        } else {
            base
        };
        let (last_lo, last_hi) = self.heave.unwrap_or(base);
        let step = HEAVE_CLOSING * dt;
        let b = (lo.min(last_lo + step), hi.max(last_hi - step));
        self.heave = Some(b);
        b
    }

    /// The order the axes plan in at a sample of specific force `force`: the axis whose force asks for more
    /// of its angle's range first, then the other, then z.
    pub fn order(&mut self, force: [f64; 3]) -> [usize; 3] {
        let asks = |i: usize| {
            let (lo, hi) = self.base[i];
            let wanted = force[i] / G;
            if wanted >= 0.0 {
                wanted / hi.max(1e-9)
            } else {
                wanted / lo.min(-1e-9)
            }
        };
        let other = 1 - self.first;
        if asks(other) > asks(self.first) + SWAP {
            self.first = other;
        }
        [self.first, 1 - self.first, Z]
    }

    /// Axis `i`'s angle interval now: within its own, the room beside the other axis's angle, as it is
    /// (`first`) or as its plan just solved (steps of `h` seconds) will move it; at the platform's present
    /// translations and heading `yaw`.
    fn bound(&self, i: usize, first: bool, axes: &[Axis; 3], h: f64, yaw: f64) -> (f64, f64) {
        let other = &axes[1 - i];
        let (a, b) = if first {
            (other.angle(), other.angle())
        } else {
            other.planned_span(h)
        };
        let translation = [axes[X].x[0], axes[1].x[0], axes[Z].x[0]];
        // The vehicle's roll is y's angle, its pitch minus x's.
        // The other's angles to hold beside: one when it stays where it is.
        let others: &[f64] = if a == b { &[a] } else { &[a, b] };
        let holds = |angle: f64| {
            others.iter().all(|&o| {
                let (roll, pitch) = if i == X { (o, -angle) } else { (angle, -o) };
                let offset = cueing::to_platform(self.forward, translation, roll, pitch, yaw);
                let pose = cueing::pose(&self.neutral, &offset);
                !envelope::limit(&self.mechanism, &self.neutral, &pose, &self.margins, 1).is_limited()
            })
        };
        let (lo, hi) = self.base[i];
        // The end itself when it holds; else out in steps to the last that holds: a quarter degree inside the
        // edge at most, which keeps the plan (its solver's tolerance and the step between its points) inside.
        let reach = |end: f64| {
            if holds(end) {
                return end;
            }
            let step = STEP.copysign(end);
            let mut v = 0.0;
            while (v + step).abs() < end.abs() && holds(v + step) {
                v += step;
            }
            v
        };
        // Nothing holds even at zero (the translations alone are outside): the angle keeps to its own interval,
        // and the limiter has the pose.
        if !holds(0.0) {
            return (lo, hi);
        }
        (reach(lo), reach(hi))
    }
}

impl Axis {
    /// The platform's angle on this axis (a horizontal one): its tilt and its rotation.
    fn angle(&self) -> f64 {
        self.x[2] + self.x[3]
    }

    /// The angles this axis passes from now over its last plan's steps of `h` seconds (from its current
    /// angle; the plan's inputs 1 and 2 are the two parts' rates).
    fn planned_span(&self, h: f64) -> (f64, f64) {
        let mut a = self.angle();
        let (mut lo, mut hi) = (a, a);
        for step in self.plan.as_slice().chunks_exact(3) {
            a += h * (step[1] + step[2]);
            lo = lo.min(a);
            hi = hi.max(a);
        }
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Envelope, Optimal, Y};
    use super::*;
    use ringpod_core::cueing::{Algorithm, CueConfig, Telemetry};
    use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL};

    /// The trainer model's envelope (its ranges about home as the workspace scan finds them), and a
    /// configuration that tilts to 0.95 of them.
    fn trainer() -> (Envelope, CueConfig) {
        let envelope = Envelope {
            ranges: [
                (-0.129, 0.129),
                (-0.055, 0.095),
                (-0.067, 0.059),
                (-0.454, 0.384),
                (-0.358, 0.358),
            ],
            rig: Some((
                RingPlatform::new(&TRAINER_MODEL),
                Pose::from_array(Preset::TrainerModel.home()),
            )),
        };
        let mut c = CueConfig {
            algorithm: Algorithm::Optimal,
            tilt_limit_deg: [30.0, 30.0],
            tilt_rate_deg: [18.75, 18.75],
            ..CueConfig::default()
        };
        c.optimal.tilt_share = 0.95;
        c.optimal.envelope_share = 0.2;
        c.optimal.budget_ms = 1000.0;
        (envelope, c)
    }

    /// Whether the limiter would leave the platform at vehicle roll and pitch offsets (facing +x, home
    /// otherwise) as they are.
    fn holds(envelope: &Envelope, roll: f64, pitch: f64) -> bool {
        let (m, n) = envelope.rig.unwrap();
        let pose = cueing::pose(&n, &cueing::to_platform(Forward::PlusX, [0.0; 3], roll, pitch, 0.0));
        !envelope::limit(&m, &n, &pose, &EnvelopeMargins::default(), 1).is_limited()
    }

    #[test]
    fn pitch_gets_the_room_the_roll_leaves_and_no_more() {
        let (envelope, config) = trainer();
        let mut o = Optimal::new(config, &envelope).unwrap();
        let t = o.tilt.clone().unwrap();
        let base = t.base[X];
        assert_eq!(t.bound(X, true, &o.axes, 0.15, 0.0), base, "with the roll at home");
        // Rolled to 0.95 of the roll's range (y's angle is the roll).
        let roll = envelope.ranges[3].0 * 0.95;
        o.axes[Y].x[2] = roll;
        let (lo, hi) = t.bound(X, true, &o.axes, 0.15, 0.0);
        assert!(hi - lo < 0.5 * (base.1 - base.0), "{:?} against {base:?}", (lo, hi));
        // x's angle is minus the pitch: both ends hold, a step past each does not.
        for (end, past) in [(lo, lo - STEP), (hi, hi + STEP)] {
            assert!(holds(&envelope, roll, -end), "{end}");
            assert!(!holds(&envelope, roll, -past), "{past}");
        }
    }

    #[test]
    fn a_bound_closes_in_no_faster_than_the_tilt_rate() {
        let (envelope, config) = trainer();
        let mut o = Optimal::new(config, &envelope).unwrap();
        let mut t = o.tilt.clone().unwrap();
        let dt = 0.01;
        let open = t.bound_over(X, true, &o.axes, 0.15, 0.0, dt);
        o.axes[Y].x[2] = envelope.ranges[3].0 * 0.95;
        let room = t.bound(X, true, &o.axes, 0.15, 0.0);
        let rate = config.tilt_rate_deg[0].to_radians();
        let mut last = open;
        for _ in 0..200 {
            let now = t.bound_over(X, true, &o.axes, 0.15, 0.0, dt);
            assert!(
                now.0 - last.0 <= rate * dt + 1e-12 && last.1 - now.1 <= rate * dt + 1e-12,
                "{now:?} after {last:?}"
            );
            last = now;
        }
        assert_eq!(last, room);
        // Opening again is at once.
        o.axes[Y].x[2] = 0.0;
        assert_eq!(t.bound_over(X, true, &o.axes, 0.15, 0.0, dt), open);
    }

    /// Braking and cornering at once, hard enough to ask both angles for their whole ranges: planned in their own
    /// ranges alone the poses leave the envelope at the corner and the limiter cuts 352 of 399; sharing the room,
    /// 36, while the surge's translation grows beside the tilt (the translations keep to their own ranges).
    #[test]
    fn braking_in_a_corner_is_cut_a_fraction_as_often() {
        let (envelope, config) = trainer();
        let limited = |e: &Envelope| {
            let mut o = Optimal::new(config, e).unwrap();
            let (m, n) = envelope.rig.unwrap();
            let mut count = 0;
            let sample = |k: usize| {
                let s = (k as f64 / 100.0).min(1.0);
                Telemetry {
                    force: [-9.0 * s, 9.0 * s, G],
                    rate: [0.0; 3],
                }
            };
            o.begin(&sample(0)).unwrap();
            for k in 1..400 {
                let offset = o.step(&sample(k), 0.01, &[]).unwrap();
                let pose = cueing::pose(&n, &offset);
                count += usize::from(envelope::limit(&m, &n, &pose, &EnvelopeMargins::default(), 1).is_limited());
            }
            count
        };
        let (alone, shared) = (limited(&envelope.ranges.into()), limited(&envelope));
        assert!(
            alone > 300 && shared * 5 < alone,
            "{alone} cut in their own ranges, {shared} sharing"
        );
    }
}

//! An outer polytope of the rig's envelope: half-spaces `a . offset <= b` in the platform's offset `[x, y, z,
//! alpha, beta]` from neutral (yaw at neutral) that every pose the envelope limiter passes keeps. The envelope is
//! not convex and its ranges about home are found one axis at a time; a programme can only be bounded by
//! something convex, and a bound that holds every pose of the envelope is what a floor needs (no cueing inside
//! the envelope can do better than the best motion inside something larger).
//!
//! Each face's `b` is the envelope's support in the face's direction, `max a . p` over the poses that pass: found
//! on the envelope's boundary, point by point along rays from neutral (the envelope limiter's own assumption:
//! each ray leaves the envelope once), first over every face's own direction and many spread directions, then
//! climbed ray by ray until no nearby ray reaches further. A support found this way can only fall short of the
//! true one (a pose further out was not found), which would make the polytope too small; the search's last
//! gain per face ([`Polytope::last_gain`]) says how far from settled it is, and [`SLACK`] is added on top.

use ringpod_core::cueing;
use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::{envelope, EnvelopeMargins};

use super::Ranges;

/// Added to each face's support, as a share of the face's reach in the ranges' scale: the boundary is found to
/// 2^-16 of a ray, and the climb stops within its last, smallest step.
pub const SLACK: f64 = 0.01;

/// How far along a ray the boundary is looked for, in units of the ranges: the coupled envelope reaches further
/// than an axis's range when the other axes are offset (on the trainer model roll to 1.6 times its own).
const REACH: f64 = 4.0;

/// The climb's nudges of a ray's direction, coarse to fine.
const NUDGES: [f64; 9] = [
    0.25,
    0.125,
    0.0625,
    0.03125,
    0.015625,
    0.0078125,
    0.00390625,
    0.001953125,
    0.0009765625,
];

/// The outer polytope.
#[derive(Debug, Clone)]
pub struct Polytope {
    /// `(a, b)`: each face's normal in offset units (m, rad) and its support.
    pub faces: Vec<([f64; 5], f64)>,
    /// The largest gain of a face's support at the climb's finest nudge, as a share of the support: how far
    /// from settled the search ended.
    pub last_gain: f64,
}

/// Poses of `mechanism` about `neutral` the envelope limiter passes (its default margins).
struct Rig<'a> {
    mechanism: &'a RingPlatform<f64>,
    neutral: &'a Pose<f64>,
    margins: EnvelopeMargins,
    /// Each offset axis's scale: its range's larger end.
    scale: [f64; 5],
}

impl Rig<'_> {
    fn passes(&self, u: &[f64; 5]) -> bool {
        let offset = [
            u[0] * self.scale[0],
            u[1] * self.scale[1],
            u[2] * self.scale[2],
            u[3] * self.scale[3],
            u[4] * self.scale[4],
            0.0,
        ];
        let pose = cueing::pose(self.neutral, &offset);
        !envelope::limit(self.mechanism, self.neutral, &pose, &self.margins, 1).is_limited()
    }

    /// The last point that passes along the ray `d` (scaled units), to 2^-16 of its length.
    fn boundary(&self, d: &[f64; 5]) -> [f64; 5] {
        let at = |s: f64| d.map(|v| v * s);
        let (mut lo, mut hi) = (0.0, REACH);
        if self.passes(&at(hi)) {
            return at(hi);
        }
        for _ in 0..16 {
            let mid = 0.5 * (lo + hi);
            if self.passes(&at(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        at(lo)
    }
}

fn dot(a: &[f64; 5], b: &[f64; 5]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn unit(v: [f64; 5]) -> [f64; 5] {
    let n = dot(&v, &v).sqrt().max(1e-12);
    v.map(|x| x / n)
}

/// The faces' directions in the ranges' scale: every vector of -1, 0 and 1 with at most `most` of them not 0.
pub fn directions(most: usize) -> Vec<[f64; 5]> {
    (0..3usize.pow(5))
        .map(|mut code| {
            [0; 5].map(|_| {
                let v = (code % 3) as f64 - 1.0;
                code /= 3;
                v
            })
        })
        .filter(|v| {
            let n = v.iter().filter(|x| **x != 0.0).count();
            n > 0 && n <= most
        })
        .map(unit)
        .collect()
}

/// A rough spread of `n` ray directions (a fixed sequence: the polytope is the same on every run).
fn spread(n: usize) -> Vec<[f64; 5]> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        // xorshift64*: enough to spread rays, and the same every run.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n).map(|_| unit([0; 5].map(|_| next()))).collect()
}

impl Polytope {
    /// The outer polytope of `mechanism`'s envelope about `neutral`, with a face for each of `directions` (in
    /// the scale of `ranges`), its supports searched from `rays` spread rays and then climbed.
    pub fn of(
        mechanism: &RingPlatform<f64>,
        neutral: &Pose<f64>,
        ranges: &Ranges,
        directions: &[[f64; 5]],
        rays: usize,
    ) -> Self {
        let rig = Rig {
            mechanism,
            neutral,
            margins: EnvelopeMargins::default(),
            scale: ranges.map(|(lo, hi)| lo.abs().max(hi.abs()).max(1e-9)),
        };
        let points: Vec<[f64; 5]> = directions
            .iter()
            .chain(&spread(rays))
            .map(|d| rig.boundary(d))
            .collect();
        let mut last_gain = 0.0f64;
        let faces = directions
            .iter()
            .map(|a| {
                let (mut best, mut support) = points
                    .iter()
                    .map(|p| (*p, dot(a, p)))
                    .fold(([0.0; 5], f64::MIN), |m, c| if c.1 > m.1 { c } else { m });
                // Climb: nudge the best ray along each axis, keep what reaches further, halve the nudge when
                // nothing does. What the finest nudge still gained says how far from settled the support is.
                let mut gained = 0.0;
                for step in NUDGES {
                    gained = 0.0;
                    loop {
                        let before = support;
                        for j in 0..5 {
                            for sign in [-1.0, 1.0] {
                                let mut d = unit(best);
                                d[j] += sign * step;
                                let p = rig.boundary(&unit(d));
                                if dot(a, &p) > support {
                                    (best, support) = (p, dot(a, &p));
                                }
                            }
                        }
                        if support <= before {
                            break;
                        }
                        gained += support - before;
                    }
                }
                last_gain = last_gain.max(gained / support.max(1e-9));
                // Back to offset units: a . u <= b with u = offset / scale.
                let normal = core::array::from_fn(|j| a[j] / rig.scale[j]);
                (normal, support + SLACK)
            })
            .collect();
        Self { faces, last_gain }
    }

    /// Whether `offset` (x, y, z, alpha, beta) keeps every face.
    #[cfg(test)]
    pub fn holds(&self, offset: &[f64; 5]) -> bool {
        self.faces.iter().all(|(a, b)| dot(a, offset) <= *b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL};

    const RANGES: Ranges = [
        (-0.129, 0.129),
        (-0.055, 0.095),
        (-0.067, 0.059),
        (-0.454, 0.384),
        (-0.358, 0.358),
    ];

    #[test]
    fn the_directions_are_every_sign_pattern_up_to_the_count() {
        assert_eq!(directions(1).len(), 10);
        assert_eq!(directions(2).len(), 10 + 40);
        assert_eq!(directions(5).len(), 242);
        for d in directions(3) {
            assert!((dot(&d, &d) - 1.0).abs() < 1e-12);
        }
    }

    /// Every pose the limiter passes keeps the polytope, and the polytope is no box: poses inside every range
    /// but outside the envelope's diagonal fall outside it.
    #[test]
    fn every_pose_that_passes_keeps_the_polytope_and_the_ranges_corners_do_not() {
        let mechanism = RingPlatform::new(&TRAINER_MODEL);
        let neutral = Pose::from_array(Preset::TrainerModel.home());
        let p = Polytope::of(&mechanism, &neutral, &RANGES, &directions(2), 200);
        let rig = Rig {
            mechanism: &mechanism,
            neutral: &neutral,
            margins: EnvelopeMargins::default(),
            scale: [1.0; 5],
        };
        let mut inside = 0;
        for u in spread(400) {
            // Points spread through the ranges' box, scaled by a ray-dependent depth.
            let depth = 0.3 + 0.7 * u[0].abs();
            let offset: [f64; 5] =
                core::array::from_fn(|j| u[j] * depth * 1.5 * RANGES[j].1.abs().max(RANGES[j].0.abs()));
            if rig.passes(&offset) {
                inside += 1;
                assert!(p.holds(&offset), "{offset:?} passes but is outside the polytope");
            }
        }
        assert!(inside > 50, "{inside}");
        // Roll and pitch both at 95 % of their ranges: each alone passes, together the envelope does not.
        let corner = [0.0, 0.0, 0.0, 0.95 * RANGES[3].0, 0.95 * RANGES[4].1];
        assert!(!rig.passes(&corner));
        assert!(!p.holds(&corner), "{:?}", p.faces);
        assert!(p.last_gain < 0.05, "{}", p.last_gain);
    }
}

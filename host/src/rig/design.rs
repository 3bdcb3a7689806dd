//! `ringpod rig design`: dimensions for a rig's joint limits and spec ranges, by random-restart hill climbing (the
//! search that found the trainer model's dimensions, `shared/examples/trainer_model_design.rs`, as a command).
//!
//! The template rig file gives what is fixed: the chains' kinds and branches, the joint limits (an elbow chain's
//! shoulder travel and elbow angle limits among them), the centre of mass and the spec ranges. The search moves the
//! ring radius, the rod length, the home height, every platform joint and every elbow chain's arm (shoulder radius
//! and height, upper arm, forearm), or with [`Free::Arms`] the arms alone, scoring a candidate by its smallest margin
//! over the spec poses, each check's margin divided by a scale at which it matters (5 mm, 0.1 rad, 0.05 of the
//! singularity index): the design with the most room wins. An elbow arm's reach margin (its elbow angle limits and
//! shoulder travel, in metres) and its forearm's platform cone are among those checks.

use ringpod_core::kinematics::geometry::DEG;
use ringpod_core::kinematics::{Check, Mechanism, Pose, RingPlatform};

use super::{KindSpec, RigError, RigFile};

/// What the design must cover.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Each spec axis over its range alone, at any yaw (how simulator spec tables are read).
    EachAxis,
    /// All spec axes at once: the corners of the box and random poses inside it, at any yaw.
    Combined,
}

/// Which dimensions the search moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Free {
    /// Everything: the ring radius, the rod length, the home height, every platform joint and every elbow arm.
    All,
    /// Only the elbow chains' arms (shoulder radius and height, upper arm, forearm): a machine whose ring, rods and
    /// platform are built, getting elbow arms in place of another drive (how `trainer-elbow` came about).
    Arms,
}

/// Settings of the search.
#[derive(Debug, Clone, Copy)]
pub struct Search {
    /// What to cover.
    pub target: Target,
    /// What moves.
    pub free: Free,
    /// Random starts.
    pub starts: u32,
    /// Hill-climbing steps from each start.
    pub steps: u32,
    /// Seed of the random numbers (the same seed gives the same design).
    pub seed: u64,
}

/// The best design found and its score (its smallest scaled margin; at least 0 when every spec pose is inside).
pub struct Found {
    /// The rig file of the design.
    pub file: RigFile,
    /// Its score.
    pub score: f64,
}

/// xorshift: repeatable numbers in `[0, 1)` without a dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// Spec poses around a home height of zero (the candidate's home height is added): offsets and yaw.
fn spec_poses(ranges: &[f64; 5], target: Target, rng: &mut Rng) -> Vec<[f64; 6]> {
    let mut poses = Vec::new();
    match target {
        Target::EachAxis => {
            for (axis, range) in ranges.iter().enumerate() {
                for k in 0..=8 {
                    for y in 0..24 {
                        let mut p = [0.0, 0.0, 0.0, 0.0, 0.0, y as f64 * 15.0 * DEG];
                        p[axis] = range * (k as f64 / 4.0 - 1.0);
                        poses.push(p);
                    }
                }
            }
        }
        Target::Combined => {
            for corner in 0..32u32 {
                for y in 0..8 {
                    let mut p = [0.0, 0.0, 0.0, 0.0, 0.0, y as f64 * 45.0 * DEG];
                    for (axis, range) in ranges.iter().enumerate() {
                        p[axis] = if corner & (1 << axis) == 0 { -range } else { *range };
                    }
                    poses.push(p);
                }
            }
            for _ in 0..200 {
                let mut p: [f64; 6] = core::array::from_fn(|_| rng.range(-1.0, 1.0));
                for (axis, range) in ranges.iter().enumerate() {
                    p[axis] *= range;
                }
                p[5] *= std::f64::consts::PI;
                poses.push(p);
            }
        }
    }
    poses
}

/// The smallest scaled margin of a candidate over the poses; an unreachable pose scores by its reach margin, minus
/// one, and an invalid candidate -10.
fn score(candidate: &RigFile, poses: &[[f64; 6]]) -> f64 {
    let Ok(geometry) = candidate.geometry_named("candidate") else {
        return -10.0;
    };
    let m = RingPlatform::<f64>::new(&geometry);
    let z0 = candidate.home[2];
    let mut worst = f64::INFINITY;
    let mut unreachable = false;
    for p in poses {
        let pose = Pose::new(p[0], p[1], z0 + p[2], p[3], p[4], p[5]);
        match m.inverse_checked(&pose) {
            Ok((_, r)) => {
                let scaled = [
                    r.margin(Check::Reach).unwrap_or(1.0) / 0.005,
                    r.margin(Check::CarriageSpacing).unwrap_or(1.0) / 0.1,
                    r.margin(Check::RodCrossing).unwrap_or(1.0) / 0.1,
                    r.margin(Check::JointCones).unwrap_or(1.0) / 0.1,
                    r.margin(Check::Singularity).unwrap_or(1.0) / 0.05,
                    r.margin(Check::Stability).unwrap_or(1.0) / 0.005,
                ];
                worst = scaled.iter().fold(worst, |w, v| w.min(*v));
            }
            Err(_) => {
                worst = worst.min(m.reach_margin(&pose) / 0.005);
                unreachable = true;
            }
        }
    }
    if unreachable {
        worst.min(0.0) - 1.0
    } else {
        worst
    }
}

/// A neighbour of a candidate: every free dimension moved by up to `scale` of its range.
fn perturb(c: &RigFile, rng: &mut Rng, scale: f64, size: f64, free: Free) -> RigFile {
    let mut d = c.clone();
    let mut jitter = |v: &mut f64, lo: f64, hi: f64| *v = (*v + scale * (hi - lo) * (rng.next() - 0.5)).clamp(lo, hi);
    if free == Free::All {
        // Joints move within a quarter of their range a step at most (a whole range scatters the start).
        jitter(&mut d.ring_radius, 0.3 * size, 2.0 * size);
        jitter(&mut d.rod_length, 0.3 * size, 3.0 * size);
        jitter(&mut d.home[2], 0.2 * size, 2.5 * size);
        let reach = d.ring_radius;
        for chain in &mut d.chains {
            jitter(&mut chain.platform_point[0], -reach, reach);
            jitter(&mut chain.platform_point[1], -reach, reach);
        }
    }
    // The arms' ranges scale with the ring, as the rods' do: a shoulder from half the ring radius out to beyond
    // the ring, below or above the ring plane, arms from a sixth of the radius to the radius. Every elbow chain's
    // arm moves by the same amounts, so arms the template makes alike (the same parts) stay alike.
    let ranges = [(0.5, 1.3), (-0.3, 0.6), (0.15, 1.0), (0.15, 1.0)].map(|(lo, hi)| (lo * size, hi * size));
    let moves = ranges.map(|(lo, hi)| scale * (hi - lo) * (rng.next() - 0.5));
    for chain in d.chains.iter_mut().filter(|c| c.kind == KindSpec::Elbow) {
        let arm = [
            &mut chain.shoulder_radius,
            &mut chain.shoulder_height,
            &mut chain.upper_arm,
            &mut chain.forearm,
        ];
        for ((value, (lo, hi)), step) in arm.into_iter().zip(ranges).zip(moves) {
            if let Some(v) = value {
                *v = (*v + step).clamp(lo, hi);
            }
        }
    }
    d
}

/// A design rounded to a tenth of a millimetre, what a builder can make.
fn rounded(file: &RigFile) -> RigFile {
    let tenth = |v: f64| (v * 1e4).round() / 1e4;
    let mut r = file.clone();
    r.ring_radius = tenth(r.ring_radius);
    r.rod_length = tenth(r.rod_length);
    r.home[2] = tenth(r.home[2]);
    for chain in &mut r.chains {
        chain.platform_point = chain.platform_point.map(tenth);
        for v in [
            &mut chain.shoulder_radius,
            &mut chain.shoulder_height,
            &mut chain.upper_arm,
            &mut chain.forearm,
        ]
        .into_iter()
        .flatten()
        {
            *v = tenth(*v);
        }
    }
    r
}

/// Searches dimensions for the template's topology, limits and spec ranges.
pub fn design(template: &RigFile, search: &Search) -> Result<Found, RigError> {
    template.platform()?;
    let Some(spec) = &template.spec else {
        return Err(RigError {
            key: "spec".into(),
            why: "the design needs the [spec] ranges to cover".into(),
        });
    };
    if search.free == Free::Arms && !template.chains.iter().any(|c| c.kind == KindSpec::Elbow) {
        return Err(RigError {
            key: "chains".into(),
            why: "designing the arms alone needs elbow chains (kind = \"elbow\")".into(),
        });
    }
    let ranges = spec.si();
    let mut rng = Rng(search.seed.max(1));
    let poses = spec_poses(&ranges, search.target, &mut rng);
    let size = template.ring_radius;
    let mut best = (score(template, &poses), template.clone());
    for start in 0..search.starts {
        // The first start is the template itself; the others are scattered around it.
        let mut d = if start == 0 {
            template.clone()
        } else {
            perturb(template, &mut rng, 0.3, size, search.free)
        };
        let mut s = score(&d, &poses);
        for step in 0..search.steps {
            let scale = 0.08 * (1.0 - f64::from(step) / f64::from(search.steps)) + 0.005;
            let next = perturb(&d, &mut rng, scale, size, search.free);
            let t = score(&next, &poses);
            if t > s {
                (d, s) = (next, t);
            }
        }
        if s > best.0 {
            best = (s, d);
        }
    }
    let (score, file) = best;
    // Kept rounded only if the rounded design is still as good.
    let rounded = self::rounded(&file);
    let rounded_score = self::score(&rounded, &poses);
    Ok(if rounded_score >= score.min(0.0) && rounded.check().is_ok() {
        Found {
            file: rounded,
            score: rounded_score,
        }
    } else {
        Found { file, score }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::ChainSpec;
    use ringpod_core::kinematics::presets::{self, Preset};

    fn template() -> RigFile {
        RigFile::of(
            &presets::TRAINER_MODEL,
            Preset::TrainerModel.home(),
            Some(presets::TRAINER_MODEL_RANGES),
            Vec::new(),
        )
    }

    fn quick(target: Target, seed: u64) -> Search {
        Search {
            target,
            free: Free::All,
            starts: 3,
            steps: 60,
            seed,
        }
    }

    #[test]
    fn the_design_is_valid_no_worse_than_the_template_and_repeatable() {
        let t = template();
        let mut rng = Rng(1);
        let poses = spec_poses(&presets::TRAINER_MODEL_RANGES, Target::EachAxis, &mut rng);
        let before = score(&t, &poses);
        let found = design(&t, &quick(Target::EachAxis, 7)).unwrap();
        assert!(found.file.check().is_ok());
        assert!(found.score >= before, "{} < {before}", found.score);
        assert!(found.score >= 0.0, "the model's own dimensions already cover each axis");
        let again = design(&t, &quick(Target::EachAxis, 7)).unwrap();
        assert_eq!(again.file, found.file);
        // The combined box scores every corner: worse than one axis at a time.
        let combined = design(&t, &quick(Target::Combined, 7)).unwrap();
        assert!(combined.score < found.score);
    }

    /// The elbow trainer with arms that cannot cover its spec: a forearm so short the arm barely spans its home.
    fn short_armed_elbow() -> RigFile {
        let mut t = RigFile::of(
            &presets::TRAINER_ELBOW,
            Preset::TrainerElbow.home(),
            Some(presets::TRAINER_MODEL_RANGES),
            Vec::new(),
        );
        for chain in t.chains.iter_mut().filter(|c| c.kind == KindSpec::Elbow) {
            chain.upper_arm = Some(0.12);
            chain.forearm = Some(0.12);
        }
        t
    }

    #[test]
    fn the_arms_alone_are_designed_to_cover_the_spec_and_nothing_else_moves() {
        let t = short_armed_elbow();
        let mut rng = Rng(1);
        let poses = spec_poses(&presets::TRAINER_MODEL_RANGES, Target::EachAxis, &mut rng);
        let before = score(&t, &poses);
        assert!(before < 0.0, "the short arms do not cover the spec: {before}");
        let search = Search {
            free: Free::Arms,
            starts: 4,
            steps: 150,
            ..quick(Target::EachAxis, 3)
        };
        let found = design(&t, &search).unwrap();
        assert!(found.score >= 0.0, "the arms found cover each axis: {}", found.score);
        let f = &found.file;
        assert!(f.check().is_ok());
        assert_eq!(
            (f.ring_radius, f.rod_length, f.home),
            (t.ring_radius, t.rod_length, t.home)
        );
        for (new, old) in f.chains.iter().zip(&t.chains) {
            assert_eq!(new.platform_point, old.platform_point);
            assert_eq!(new.kind, old.kind);
            if new.kind == KindSpec::Elbow {
                assert_ne!(
                    (new.upper_arm, new.forearm),
                    (old.upper_arm, old.forearm),
                    "the arms moved"
                );
            }
        }
        // The template's two arms are alike and stay alike.
        let arms: Vec<_> = f.chains.iter().filter(|c| c.kind == KindSpec::Elbow).collect();
        assert_eq!(arms.len(), 2);
        let dims = |c: &ChainSpec| (c.shoulder_radius, c.shoulder_height, c.upper_arm, c.forearm);
        assert_eq!(dims(arms[0]), dims(arms[1]));
    }

    #[test]
    fn designing_arms_without_elbow_chains_is_refused_by_key() {
        let search = Search {
            free: Free::Arms,
            ..quick(Target::EachAxis, 1)
        };
        let e = design(&template(), &search).err().expect("refused");
        assert_eq!(e.key, "chains");
    }

    #[test]
    fn a_template_without_spec_ranges_is_refused_by_key() {
        let mut t = template();
        t.spec = None;
        let e = design(&t, &quick(Target::EachAxis, 1)).err().expect("refused");
        assert_eq!(e.key, "spec");
    }

    /// A template whose ring radius is no length (NaN, infinite, negative) or another invalid mechanism is refused
    /// by key before the search scales anything by it (NaN reached `f64::clamp`, which panics).
    #[test]
    fn an_invalid_template_is_refused_by_key_not_searched() {
        for radius in [f64::NAN, f64::INFINITY, -0.2, 0.0] {
            let mut t = template();
            t.ring_radius = radius;
            let e = design(&t, &quick(Target::EachAxis, 1)).err().expect("refused");
            assert_eq!(e.key, "ring_radius", "{radius}");
        }
        let mut t = template();
        t.chains[0].branch = None;
        assert_eq!(
            design(&t, &quick(Target::EachAxis, 1)).err().expect("refused").key,
            "chains[0].branch"
        );
    }
}

//! How the trainer-model dimensions were chosen: a random search over ring radius, rod length, platform joint
//! positions and nominal heave, scoring each candidate by its worst workspace margin over the model's spec box
//! (surge/sway +-50 mm, heave +-40 mm, pitch/roll +-20 deg, any yaw).
//!
//! `cargo run --release -p ringpod-core --example trainer_model_design` prints the best candidate and the worst
//! margin of every check over the box for the shipped preset.

use ringpod_core::kinematics::geometry::{Branch, Chain, ChainKind, RingGeometry, RingLimits, DEG, SOURCE_SPACING};
use ringpod_core::kinematics::{presets, Check, Mechanism, Pose, RingPlatform};

/// Deterministic xorshift, so the search is repeatable without a dependency.
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

/// Poses of the spec box around heave `z0`: every corner at eight yaws, plus random interior poses.
fn spec_poses(z0: f64, random: usize) -> Vec<Pose<f64>> {
    let (t, h, r) = (0.050, 0.040, 20.0 * DEG);
    let mut poses = Vec::new();
    for corner in 0..32u32 {
        let s = |bit: u32| if corner & (1 << bit) == 0 { -1.0 } else { 1.0 };
        for k in 0..8 {
            let yaw = k as f64 * 45.0 * DEG;
            poses.push(Pose::new(s(0) * t, s(1) * t, z0 + s(2) * h, s(3) * r, s(4) * r, yaw));
        }
    }
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..random {
        poses.push(Pose::new(
            rng.range(-t, t),
            rng.range(-t, t),
            z0 + rng.range(-h, h),
            rng.range(-r, r),
            rng.range(-r, r),
            rng.range(-std::f64::consts::PI, std::f64::consts::PI),
        ));
    }
    poses
}

/// Poses of each spec axis swept over its whole range with the others at neutral, at 24 yaws, and the
/// full-turn yaw itself: the usual reading of a simulator's spec table (one excursion at a time).
fn axis_poses(z0: f64, steps: usize) -> Vec<Pose<f64>> {
    let ranges = presets::TRAINER_MODEL_RANGES;
    let mut poses = Vec::new();
    for (axis, range) in ranges.iter().enumerate() {
        for k in 0..=steps {
            let v = -range + 2.0 * range * k as f64 / steps as f64;
            for y in 0..24 {
                let mut c = [0.0, 0.0, z0, 0.0, 0.0, y as f64 * 15.0 * DEG];
                c[axis] += v;
                poses.push(Pose::from_array(c));
            }
        }
    }
    poses
}

/// Worst margin of each check over the poses (None if some pose is unreachable), and the stroke range used.
fn evaluate(g: &RingGeometry, poses: &[Pose<f64>]) -> Option<([f64; 6], [f64; 2], f64)> {
    let m = RingPlatform::<f64>::new(g);
    let mut worst = [f64::INFINITY; 6];
    let mut stroke = [f64::INFINITY, 0.0f64];
    let mut min_index = f64::INFINITY;
    for pose in poses {
        let (q, report) = m.inverse_checked(pose).ok()?;
        for s in &q.0[4..] {
            stroke = [stroke[0].min(*s), stroke[1].max(*s)];
        }
        for (i, c) in Check::ALL.iter().enumerate() {
            worst[i] = worst[i].min(report.margin(*c).unwrap_or(f64::INFINITY));
        }
        min_index = min_index.min(report.singularity_index);
    }
    Some((worst, stroke, min_index))
}

/// Design parameters: ring radius, rod length, heave, rod pair joint (x, y), radial pair joint (x, y), flipped.
#[derive(Clone, Copy, Debug)]
struct Design {
    rr: f64,
    rod: f64,
    z0: f64,
    rod_pt: [f64; 2],
    radial_pt: [f64; 2],
    flipped: bool,
}

impl Design {
    fn geometry(&self, stroke: [f64; 2], min_index: f64) -> Option<RingGeometry> {
        let c = |kind, x: f64, y: f64| Chain {
            kind,
            platform_point: [x, y, 0.0],
        };
        let (b1, b2) = if self.flipped {
            (Branch::Minus, Branch::Plus)
        } else {
            (Branch::Plus, Branch::Minus)
        };
        RingGeometry::new(
            "candidate",
            self.rr,
            self.rod,
            &[
                c(ChainKind::Rod(b1), -self.rod_pt[0], -self.rod_pt[1]),
                c(ChainKind::Rod(b2), self.rod_pt[0], -self.rod_pt[1]),
                c(ChainKind::Radial, self.radial_pt[0], self.radial_pt[1]),
                c(ChainKind::Radial, -self.radial_pt[0], self.radial_pt[1]),
            ],
            RingLimits {
                stroke,
                carriage_spacing: SOURCE_SPACING,
                base_cone: 11.0 * DEG,
                platform_cone: 22.0 * DEG,
                min_singularity_index: min_index,
                centre_of_mass: presets::TRAINER_MODEL.limits.centre_of_mass,
            },
        )
        .ok()
    }

    fn perturb(&self, rng: &mut Rng, scale: f64) -> Self {
        let mut d = *self;
        let mut j = |v: &mut f64, lo: f64, hi: f64| *v = (*v + scale * (hi - lo) * (rng.next() - 0.5)).clamp(lo, hi);
        j(&mut d.rr, 0.08, 0.40);
        j(&mut d.rod, 0.08, 0.60);
        j(&mut d.z0, 0.06, 0.50);
        j(&mut d.rod_pt[0], 0.0, 0.20);
        j(&mut d.rod_pt[1], 0.0, 0.20);
        j(&mut d.radial_pt[0], 0.0, 0.20);
        j(&mut d.radial_pt[1], 0.0, 0.20);
        d
    }

    /// Smallest normalised margin over the poses (margins in units of 0.1 rad, 5 mm, and 0.05 for the
    /// singularity index); an unreachable pose scores by its reach margin, minus one.
    fn score(&self, poses: &[Pose<f64>]) -> f64 {
        let Some(g) = self.geometry([0.001, 10.0], 0.0) else {
            return -10.0;
        };
        let m = RingPlatform::<f64>::new(&g);
        let mut worst = f64::INFINITY;
        let mut unreachable = 0;
        for p in poses {
            let pose = Pose { z: p.z + self.z0, ..*p };
            match m.inverse_checked(&pose) {
                Ok((_, r)) => {
                    let n = [
                        r.margin(Check::Reach).unwrap_or(1.0) / 0.005,
                        r.margin(Check::CarriageSpacing).unwrap_or(1.0) / 0.1,
                        r.margin(Check::RodCrossing).unwrap_or(1.0) / 0.1,
                        r.margin(Check::JointCones).unwrap_or(1.0) / 0.1,
                        r.singularity_index / 0.05,
                        r.margin(Check::Stability).unwrap_or(1.0) / 0.005,
                    ];
                    worst = n.iter().fold(worst, |w, v| w.min(*v));
                }
                Err(_) => {
                    worst = worst.min(m.reach_margin(&pose) / 0.005);
                    unreachable += 1;
                }
            }
        }
        if unreachable > 0 {
            worst.min(0.0) - 1.0
        } else {
            worst
        }
    }
}

fn print(name: &str, worst: &[f64; 6], stroke: [f64; 2], index: f64) {
    println!("{name}: worst margins over the spec box");
    for (c, m) in Check::ALL.iter().zip(worst) {
        println!("  {:<17} {:>10.5} {}", c.name(), m, c.unit());
    }
    println!(
        "  stroke used [{:.4}, {:.4}] m, smallest singularity index {:.4}",
        stroke[0], stroke[1], index
    );
}

fn main() {
    let box_mode = std::env::args().any(|a| a == "--box");
    let quick = if box_mode {
        spec_poses(0.0, 100)
    } else {
        axis_poses(0.0, 8)
    };
    let mut rng = Rng(42);
    let mut best: Option<(f64, Design)> = None;
    for start in 0..60 {
        // Starts: platform joints near the ring (rods steep and short in reach), scattered around that.
        let rr = rng.range(0.12, 0.30);
        let rod = rr * rng.range(0.6, 1.6);
        let mut d = Design {
            rr,
            rod,
            z0: rod * rng.range(0.5, 0.9),
            rod_pt: [rr * rng.range(0.3, 0.8), rr * rng.range(0.2, 0.7)],
            radial_pt: [rr * rng.range(0.3, 0.8), rr * rng.range(0.2, 0.7)],
            flipped: start % 2 == 1,
        };
        let mut score = d.score(&quick);
        for step in 0..400 {
            let scale = 0.2 * (1.0 - step as f64 / 400.0) + 0.01;
            let next = d.perturb(&mut rng, scale);
            let s = next.score(&quick);
            if s > score {
                (d, score) = (next, s);
            }
        }
        if best.as_ref().is_none_or(|(s, _)| score > *s) {
            println!("start {start}: score {score:.3} {d:.4?}");
            best = Some((score, d));
        }
    }
    if let Some((_, d)) = best {
        let full = if box_mode {
            spec_poses(d.z0, 5_000)
        } else {
            axis_poses(d.z0, 200)
        };
        if let Some(g) = d.geometry([0.001, 10.0], 0.0) {
            match evaluate(&g, &full) {
                Some((worst, stroke, index)) => print("best design", &worst, stroke, index),
                None => println!("best design: unreachable somewhere in the full sample"),
            }
        }
    }
    let g = &presets::TRAINER_MODEL;
    for (name, poses) in [
        (
            "trainer-model preset, each axis over its range",
            axis_poses(presets::TRAINER_MODEL_HOME_Z, 200),
        ),
        (
            "trainer-model preset, whole combined box",
            spec_poses(presets::TRAINER_MODEL_HOME_Z, 20_000),
        ),
    ] {
        match evaluate(g, &poses) {
            Some((worst, stroke, index)) => print(name, &worst, stroke, index),
            None => println!("{name}: some pose is unreachable"),
        }
        let m = RingPlatform::<f64>::new(g);
        let inside = poses
            .iter()
            .filter(|p| m.inverse_checked(p).is_ok_and(|(_, r)| r.all_pass()))
            .count();
        println!(
            "  {inside} of {} poses pass every check ({:.1} %)",
            poses.len(),
            100.0 * inside as f64 / poses.len() as f64
        );
    }
}

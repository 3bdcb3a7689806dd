//! How the `trainer-elbow` arm dimensions were chosen: the trainer model (ring, rods, platform joints and home pose
//! unchanged) with its two radial chains replaced by elbow chains (dissertation ch. 5.1, fig. 5.2), and a random
//! search over the arms' shoulder radius and height, upper arm, forearm and branch. Each candidate is scored by
//! its worst normalised margin over the model's spec table, each axis swept over its whole range at 24 yaws (how
//! `presets::TRAINER_MODEL` was judged): reach with elbow angle limits of 25..155 degrees, joint cones, singularity
//! index and stability; the shoulder's travel is then what the sweep needs plus 15 degrees each way.
//!
//! `cargo run --release -p ringpod-core --example trainer_elbow_design` prints the best candidate and the worst
//! margin of every check over the sweep for the shipped preset.

use ringpod_core::kinematics::geometry::{Chain, ChainKind, Elbow, ElbowBranch, RingGeometry, DEG};
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

/// Each spec axis swept over its range with the others at neutral, at 24 yaws.
fn axis_poses(steps: usize) -> Vec<Pose<f64>> {
    let ranges = presets::TRAINER_MODEL_RANGES;
    let mut poses = Vec::new();
    for (axis, range) in ranges.iter().enumerate() {
        for k in 0..=steps {
            let v = -range + 2.0 * range * k as f64 / steps as f64;
            for y in 0..24 {
                let mut c = [0.0, 0.0, presets::TRAINER_MODEL_HOME_Z, 0.0, 0.0, y as f64 * 15.0 * DEG];
                c[axis] += v;
                poses.push(Pose::from_array(c));
            }
        }
    }
    poses
}

#[derive(Clone, Copy, Debug)]
struct Arm {
    rs: f64,
    hs: f64,
    l1: f64,
    l2: f64,
    up: bool,
}

fn geometry(arm: &Arm, travel: [f64; 2]) -> Option<RingGeometry> {
    let model = presets::TRAINER_MODEL;
    let mut chains: Vec<Chain> = model.chains().to_vec();
    for c in chains.iter_mut().skip(2) {
        c.kind = ChainKind::Elbow(Elbow {
            shoulder_radius: arm.rs,
            shoulder_height: arm.hs,
            upper_arm: arm.l1,
            forearm: arm.l2,
            branch: if arm.up { ElbowBranch::Up } else { ElbowBranch::Down },
            shoulder_angle: travel,
            elbow_angle: [25.0 * DEG, 155.0 * DEG],
        });
    }
    RingGeometry::new("candidate", model.ring_radius, model.rod_length, &chains, model.limits).ok()
}

/// Worst margin of each check and the shoulder angles' range over the poses, and the worst of the arms' own
/// margins (elbow angle in units of 10 degrees, forearm to platform plane in units of 5 degrees, singularity index
/// above 0.02 in units of 0.02); None if a pose is unreachable.
fn evaluate(g: &RingGeometry, arm: &Arm, poses: &[Pose<f64>]) -> Option<([f64; 6], [f64; 2], f64)> {
    let m = RingPlatform::<f64>::new(g);
    let mut worst = [f64::INFINITY; 6];
    let mut travel = [f64::INFINITY, f64::NEG_INFINITY];
    let mut own = f64::INFINITY;
    for pose in poses {
        let (q, report) = m.inverse_checked(pose).ok()?;
        for s in &q.0[4..] {
            travel = [travel[0].min(*s), travel[1].max(*s)];
        }
        for (i, c) in Check::ALL.iter().enumerate() {
            worst[i] = worst[i].min(report.margin(*c).unwrap_or(f64::INFINITY));
        }
        own = own.min((report.singularity_index - 0.02) / 0.02);
        let joints = m.joints(pose);
        let normal = pose.rotation().column(2).into_owned();
        for (k, a) in joints[2..4].iter().enumerate() {
            let rho = (a.x * a.x + a.y * a.y).sqrt();
            let (c, s) = (a.x / rho, a.y / rho);
            let shoulder = q.0[4 + k];
            let r = arm.rs - arm.l1 * shoulder.cos();
            let elbow = nalgebra::Vector3::new(r * c, r * s, arm.hs + arm.l1 * shoulder.sin());
            let u = (a - elbow).normalize();
            let d2 = (arm.rs - rho).powi(2) + (a.z - arm.hs).powi(2);
            let angle = ((arm.l1 * arm.l1 + arm.l2 * arm.l2 - d2) / (2.0 * arm.l1 * arm.l2))
                .clamp(-1.0, 1.0)
                .acos();
            let elbow_margin = (angle - 25.0 * DEG).min(155.0 * DEG - angle) / (10.0 * DEG);
            let cone = (u.dot(&normal).asin() - 22.0 * DEG) / (5.0 * DEG);
            own = own.min(elbow_margin).min(cone);
        }
    }
    Some((worst, travel, own))
}

/// The candidate's score with the travel the sweep needs (wide open while measuring it), that travel and the
/// worst margins of the checks.
fn judge(arm: &Arm, poses: &[Pose<f64>]) -> Option<(f64, [f64; 2], [f64; 6])> {
    let open = [-180.0 * DEG, 180.0 * DEG];
    let (_, needed, _) = evaluate(&geometry(arm, open)?, arm, poses)?;
    let travel = [needed[0] - 15.0 * DEG, needed[1] + 15.0 * DEG];
    let (worst, _, own) = evaluate(&geometry(arm, travel)?, arm, poses)?;
    Some((own, travel, worst))
}

fn main() {
    let coarse = axis_poses(4);
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut best: Option<(f64, Arm)> = None;
    for _ in 0..4000 {
        let arm = Arm {
            rs: rng.range(0.22, 0.33),
            hs: rng.range(0.0, 0.12),
            l1: rng.range(0.06, 0.24),
            l2: rng.range(0.06, 0.24),
            up: rng.next() < 0.5,
        };
        if let Some((s, _, _)) = judge(&arm, &coarse) {
            if best.is_none_or(|(b, _)| s > b) {
                best = Some((s, arm));
            }
        }
    }
    let fine = axis_poses(20);
    if let Some((_, arm)) = best {
        if let Some((s, travel, worst)) = judge(&arm, &fine) {
            println!(
                "best: {arm:?} score {s:.3} travel {:.1}..{:.1} deg",
                travel[0] / DEG,
                travel[1] / DEG
            );
            for (c, w) in Check::ALL.iter().zip(worst) {
                println!("  {c}: {w:.4}");
            }
        }
    }
    let shipped = presets::TRAINER_ELBOW;
    let e = presets::TRAINER_ELBOW_ARM;
    let arm = Arm {
        rs: e.shoulder_radius,
        hs: e.shoulder_height,
        l1: e.upper_arm,
        l2: e.forearm,
        up: e.branch == ElbowBranch::Up,
    };
    let (worst, needed, own) = evaluate(&shipped, &arm, &fine).expect("the shipped preset reaches the sweep");
    println!(
        "shipped: score {own:.3}, shoulder {:.1}..{:.1} deg over the sweep",
        needed[0] / DEG,
        needed[1] / DEG
    );
    for (c, w) in Check::ALL.iter().zip(worst) {
        println!("  {c}: {w:.4}");
    }
}

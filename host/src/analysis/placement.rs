//! A ring platform placed at a pose for drawing: each chain's carriage, an elbow chain's shoulder and elbow axes,
//! and its platform joint, from the core's inverse kinematics (the workbench's 3D view and `ringpod draw`).

use ringpod_core::kinematics::{ChainKind, Mechanism, Pose, RingPlatform};
use serde::Serialize;

/// The mechanism at one pose: each chain's carriage on the ring, an elbow chain's shoulder and elbow axes, and
/// its platform joint (m, base frame).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Placed {
    pub carriages: Vec<[f64; 3]>,
    /// Per chain: `[shoulder, elbow]` of an elbow chain, none for the others.
    pub arms: Vec<Option<[[f64; 3]; 2]>>,
    pub joints: Vec<[f64; 3]>,
}

/// Places the mechanism at `pose`: `None` where the pose has no inverse kinematics.
///
/// An elbow chain's shoulder angle `s` is the actuator after every carriage and every radial length, in chain
/// order; the upper arm points along `cos(s) u + sin(s) z`, with `u` the horizontal unit vector from the shoulder
/// toward the ring axis (KINEMATICS, the rig file's `elbow` chain).
pub fn place(m: &RingPlatform<f64>, pose: &Pose<f64>) -> Option<Placed> {
    let q = m.inverse(pose).ok()?;
    let chains = m.geometry().chains();
    let n = chains.len();
    let r = m.geometry().ring_radius;
    let joints = m.joints(pose);
    let radial = chains.iter().filter(|c| c.kind == ChainKind::Radial).count();
    let mut next_shoulder = n + radial;
    let arms = chains
        .iter()
        .enumerate()
        .map(|(i, c)| match c.kind {
            ChainKind::Elbow(e) => {
                let (s, (sq, cq)) = (q.0.get(next_shoulder).copied()?, q.0[i].sin_cos());
                next_shoulder += 1;
                let reach = e.shoulder_radius - e.upper_arm * s.cos();
                Some(Some([
                    [e.shoulder_radius * cq, e.shoulder_radius * sq, e.shoulder_height],
                    [reach * cq, reach * sq, e.shoulder_height + e.upper_arm * s.sin()],
                ]))
            }
            _ => Some(None),
        })
        .collect::<Option<Vec<_>>>()?;
    Some(Placed {
        carriages: (0..n)
            .map(|i| {
                let a = q.0[i];
                [r * a.cos(), r * a.sin(), 0.0]
            })
            .collect(),
        arms,
        joints: joints.iter().take(n).map(|j| [j.x, j.y, j.z]).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::kinematics::presets::{Preset, PresetGeometry};

    #[test]
    fn the_mechanism_is_placed_on_its_ring_and_joints() {
        let PresetGeometry::Ring(g) = Preset::TrainerModel.geometry() else {
            unreachable!("the trainer model is a ring platform")
        };
        let m = RingPlatform::<f64>::new(g);
        let home = Pose::from_array(Preset::TrainerModel.home());
        let p = place(&m, &home).unwrap();
        assert_eq!(p.carriages.len(), g.chains().len());
        for c in &p.carriages {
            let r = (c[0] * c[0] + c[1] * c[1]).sqrt();
            assert!((r - g.ring_radius).abs() < 1e-12, "on the ring: {r}");
        }
        // Each rod chain's joint is a rod length from its carriage.
        for (i, c) in g.chains().iter().enumerate() {
            if c.kind != ChainKind::Radial {
                let (a, j) = (p.carriages[i], p.joints[i]);
                let d = ((a[0] - j[0]).powi(2) + (a[1] - j[1]).powi(2) + (a[2] - j[2]).powi(2)).sqrt();
                assert!((d - g.rod_length).abs() < 1e-9, "chain {i}: {d}");
            }
        }
        assert!(
            place(&m, &Pose::new(0.0, 0.0, 10.0, 0.0, 0.0, 0.0)).is_none(),
            "out of reach"
        );
    }

    #[test]
    fn an_elbow_chain_is_placed_with_its_arms_lengths() {
        let PresetGeometry::Ring(g) = Preset::TrainerElbow.geometry() else {
            unreachable!("the elbow trainer is a ring platform")
        };
        let m = RingPlatform::<f64>::new(g);
        let p = place(&m, &Pose::from_array(Preset::TrainerElbow.home())).unwrap();
        let d =
            |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        let mut elbows = 0;
        for (i, c) in g.chains().iter().enumerate() {
            if let ChainKind::Elbow(e) = c.kind {
                let [shoulder, elbow] = p.arms[i].expect("an elbow chain has arms");
                assert!(
                    (d(shoulder, elbow) - e.upper_arm).abs() < 1e-9,
                    "upper arm of chain {i}"
                );
                assert!((d(elbow, p.joints[i]) - e.forearm).abs() < 1e-9, "forearm of chain {i}");
                elbows += 1;
            } else {
                assert!(p.arms[i].is_none());
            }
        }
        assert_eq!(elbows, 2);
    }
}

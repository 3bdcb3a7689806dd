//! Spatial loops of seven variables and one degree of freedom, R-C-S-R (revolute input, cylindrical, spherical,
//! revolute), R-U-S-R (a Hooke's joint in place of the cylindrical pair) and R-H-S-C (a screw pair, and a
//! cylindrical pair closing the loop): each closed from a perturbed guess and from a three-point sketch, moved along a path with warm starts, and
//! its rates and accelerations checked against finite differences of the closed positions.

use nalgebra::{Matrix4, Vector3};

use super::super::*;

const LOOPS: [[Joint; 4]; 3] = [
    [Joint::Revolute, Joint::Cylindrical, Joint::Spherical, Joint::Revolute],
    [Joint::Revolute, Joint::Hooke, Joint::Spherical, Joint::Revolute],
    [
        Joint::Revolute,
        Joint::Screw { pitch: 0.01 },
        Joint::Spherical,
        Joint::Cylindrical,
    ],
];

/// The pose the loop is built to close at.
const AT: [f64; 7] = [0.3, -0.8, 0.05, 0.6, 2.0, -0.4, 0.9];

fn link(a: f64, alpha: f64, d: f64, theta: f64) -> Matrix4<f64> {
    translation(Vector3::new(a, 0.0, d)) * rot_x(alpha) * rot_z(theta)
}

/// Three skew links; the fourth closes the loop at [`AT`].
fn built(joints: [Joint; 4]) -> Result<Loop<4>, LoopError> {
    let mut l = Loop {
        joints,
        links: [
            link(0.12, 0.9, 0.02, 0.3),
            link(0.35, -1.5, 0.04, -0.7),
            link(0.20, 0.7, -0.03, 0.2),
            Matrix4::identity(),
        ],
    };
    let open = l.closure(&AT)?;
    l.links[3] = inverse(&open);
    Ok(l)
}

fn close_at(l: &Loop<4>, guess: &[f64; 7]) -> Result<[f64; 7], LoopError> {
    let (q, _) = l.close(0, guess, 1e-13, 30)?;
    assert!((l.closure(&q)? - Matrix4::identity()).amax() < 1e-10);
    Ok(q)
}

#[test]
fn closes_from_a_perturbed_guess() -> Result<(), LoopError> {
    for joints in LOOPS {
        let l = built(joints)?;
        assert_eq!(l.variables(), 7);
        let mut guess = AT;
        for (k, v) in guess.iter_mut().enumerate().skip(1) {
            *v += if k % 2 == 0 { 0.06 } else { -0.05 };
        }
        let (q, iterations) = l.close(0, &guess, 1e-12, 30)?;
        assert!((l.closure(&q)? - Matrix4::identity()).amax() < 1e-10);
        assert!(
            q.iter().zip(&AT).all(|(a, b)| (a - b).abs() < 1e-9),
            "{joints:?}: {q:?} after {iterations}"
        );
        assert!(iterations <= 8, "{iterations} iterations");
    }
    Ok(())
}

#[test]
fn closes_from_a_sketch_of_three_points_per_frame() -> Result<(), LoopError> {
    for joints in LOOPS {
        let l = built(joints)?;
        // Sketch each pair's two frames (before and after its motion) by three points, each point a millimetre or so
        // off, as drawn; read the pair's variables from A_ij = A_0i^-1 A_0j.
        let mut before = Matrix4::identity();
        let (mut guess, mut v) = ([0.0; 7], 0);
        let mut wobble = 0.0;
        for (i, joint) in l.joints.iter().enumerate() {
            let n = joint.variables();
            let after = before * joint.transform(&AT[v..v + n]);
            let sketch = |a: &Matrix4<f64>, w: f64| {
                let p = |x: f64, z: f64| {
                    (a * nalgebra::Vector4::new(1.0, x + w, w, z - w))
                        .fixed_rows::<3>(1)
                        .into_owned()
                };
                frame(&p(0.0, 0.0), &p(0.1, 0.0), &p(0.0, 0.1))
            };
            wobble += 0.0007;
            let got = values(*joint, &relative(&sketch(&before, wobble)?, &sketch(&after, -wobble)?));
            guess[v..v + n].copy_from_slice(&got[..n]);
            before = after * l.links[i];
            v += n;
        }
        guess[0] = AT[0];
        let q = close_at(&l, &guess)?;
        assert!(
            q.iter().zip(&AT).all(|(a, b)| (a - b).abs() < 1e-9),
            "{joints:?}: {q:?} from {guess:?}"
        );
    }
    Ok(())
}

#[test]
fn follows_a_path_with_warm_starts_and_its_rates_match_finite_differences() -> Result<(), LoopError> {
    for joints in LOOPS {
        let l = built(joints)?;
        let (h, step) = (1e-5, 0.02);
        let mut q = AT;
        for _ in 0..40 {
            let mut next = q;
            next[0] += step;
            let (closed, iterations) = l.close(0, &next, 1e-13, 30)?;
            assert!(iterations <= 5, "{iterations} iterations at {}", next[0]);
            q = closed;
            let shifted = |d: f64| {
                let mut g = q;
                g[0] += d;
                close_at(&l, &g)
            };
            let (up, down) = (shifted(h)?, shifted(-h)?);
            let rates = l.rates(0, &q, 1.0)?;
            let accels = l.accelerations(0, &q, &rates, 0.0)?;
            let (rates_up, rates_down) = (l.rates(0, &up, 1.0)?, l.rates(0, &down, 1.0)?);
            for k in 0..7 {
                let fd = (up[k] - down[k]) / (2.0 * h);
                assert!(
                    (rates[k] - fd).abs() < 1e-6 * fd.abs().max(1.0),
                    "rate {k}: {} vs {fd}",
                    rates[k]
                );
                let fd2 = (rates_up[k] - rates_down[k]) / (2.0 * h);
                assert!(
                    (accels[k] - fd2).abs() < 1e-5 * fd2.abs().max(1.0),
                    "accel {k}: {} vs {fd2}",
                    accels[k]
                );
            }
        }
    }
    Ok(())
}

#[test]
fn a_wrong_number_of_variables_is_refused() -> Result<(), LoopError> {
    for joints in LOOPS {
        let l = built(joints)?;
        assert_eq!(l.closure(&[0.0; 4]), Err(LoopError::Shape));
        assert_eq!(l.close(0, &[0.0; 6], 1e-12, 5), Err(LoopError::Shape));
        assert_eq!(l.rates(7, &AT, 1.0), Err(LoopError::Shape));
    }
    Ok(())
}

/// The frame after each pair, at `q`.
fn frames(l: &Loop<4>, q: &[f64; 7]) -> [Matrix4<f64>; 4] {
    let (mut acc, mut v) = (Matrix4::identity(), 0);
    core::array::from_fn(|i| {
        let n = l.joints[i].variables();
        let here = acc * l.joints[i].transform(&q[v..v + n]);
        acc = here * l.links[i];
        v += n;
        here
    })
}

#[test]
fn the_mass_matches_finite_differences_of_the_link_frames() -> Result<(), LoopError> {
    let h = 1e-6;
    let inertia = [
        Some(rod_along_x(1.0, 0.12)),
        Some(rod_along_x(2.0, 0.35)),
        Some(rod_along_x(1.5, 0.20)),
        None,
    ];
    for joints in LOOPS {
        let l = built(joints)?;
        let shifted = |d: f64| {
            let mut g = AT;
            g[0] += d;
            close_at(&l, &g)
        };
        let (up, down) = (frames(&l, &shifted(h)?), frames(&l, &shifted(-h)?));
        let mut want = 0.0;
        for i in 0..4 {
            if let Some(j) = &inertia[i] {
                let c = (up[i] - down[i]) / (2.0 * h);
                want += (c * j * c.transpose()).trace();
            }
        }
        let got = l.mass(0, &AT, &inertia)?;
        assert!((got - want).abs() < 1e-6 * want, "{joints:?}: {got} vs {want}");
    }
    Ok(())
}

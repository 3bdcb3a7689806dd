//! The dissertation's printed matrices and the tool carrier's printed angles, reproduced from what the source
//! evidently computed with (the book's "Every number of the source" chapter gives each row's reason).

// Index loops over the printed matrices' rows and columns read more plainly than zips here.
#![allow(clippy::needless_range_loop)]

use ringpod_core::kinematics::presets::{self, Preset};
use ringpod_core::kinematics::{
    Actuators, Branch, Chain, ChainKind, Check, KinematicsError, Mechanism, Pose, RingGeometry, RingPlatform,
    ToolCarrier,
};

/// Difference of two angles modulo a turn, in (-pi, pi].
fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

/// The source's columns are `(alpha, beta, gamma, x, y, z)`; ringpod's `(x, y, z, alpha, beta, gamma)`.
const SOURCE_COLUMN: [usize; 6] = [3, 4, 5, 0, 1, 2];

/// Chapter 4.1's platform: pairs 0.087 apart around 0, 120 and 240 degrees on a circle of radius `r` (the
/// chapter's matrix `P1` written with `r`).
fn rotopod(r: f64, rod: f64) -> RingGeometry {
    let (s, c) = (std::f64::consts::FRAC_PI_3.sin(), 0.5);
    let d = 0.087;
    let points = [
        (r - d * s, -d / 2.0),
        (r - d * s, d / 2.0),
        (-r * c + d * s, r * s - d * c),
        (-r * c, r * s - d),
        (-r * c, -r * s + d),
        (-r * c + d * s, -r * s + d * c),
    ];
    let chains: Vec<Chain> = points
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| Chain {
            kind: ChainKind::Rod(if i % 2 == 0 { Branch::Minus } else { Branch::Plus }),
            platform_point: [x, y, 0.0],
        })
        .collect();
    RingGeometry::new("rotopod-printed", 1.0198, rod, &chains, presets::ROTOPOD_CH4.limits).unwrap()
}

const ROTOPOD_Q: [f64; 6] = [5.53, 0.754, 1.341, 2.848, 3.435, 4.942];

/// Chapter 4.1's printed `A` at `(0, 0, 0.7, 0, 0, 0)`, source columns.
const ROTOPOD_A: [[f64; 6]; 6] = [
    [-0.061, -1.328, 1.259, 0.409, 1.308, 1.4],
    [0.061, -1.328, -1.260, 0.411, -1.309, 1.4],
    [1.181, -0.611, 1.863, -2.360, 0.290, 1.4],
    [1.120, 0.717, 0.674, -1.489, 1.009, 1.4],
    [-1.120, 0.717, 1.864, 0.928, -2.190, 1.4],
    [-1.181, -0.611, -1.259, -1.338, 0.299, 1.4],
];

/// The entries of [`ROTOPOD_A`] that are not transcription slips: every row's alpha and z; rows 1 and 2 whole;
/// rows 4 and 5 but gamma and one of x, y; row 6 but the sign of beta; row 3's alpha only.
const ROTOPOD_A_KEPT: [[bool; 6]; 6] = [
    [true; 6],
    [true; 6],
    [true, false, false, false, false, true],
    [true, true, false, false, true, true],
    [true, true, false, true, false, true],
    [true, false, true, true, true, true],
];

/// The second print of chapter 4.1's `B` (the diagonal used for the direct problem).
const ROTOPOD_B: [f64; 6] = [-1.259, 1.260, -1.259, 1.259, -1.260, 1.259];

/// The printed carriage angles are the formulas' with the platform circle of radius 1.024 that the chapter's
/// derivative `F11` is written with (`0.0435 sqrt 3 - 1.024`), not with its stated `r = 0.95`; rods 0.98 long.
#[test]
fn rotopod_printed_angles_come_from_a_platform_radius_of_1_024() {
    let pose = Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0);
    let q = RingPlatform::<f64>::new(&rotopod(1.024, 0.98)).inverse(&pose).unwrap();
    for (got, want) in q.0.iter().zip(ROTOPOD_Q) {
        assert!(angle_diff(*got, want).abs() < 7e-4, "{got} vs {want}");
    }
    // The stated radius misses them by about 0.02 rad.
    let q = RingPlatform::<f64>::new(&presets::ROTOPOD_CH4).inverse(&pose).unwrap();
    let worst =
        q.0.iter()
            .zip(ROTOPOD_Q)
            .map(|(g, w)| angle_diff(*g, w).abs())
            .fold(0.0, f64::max);
    assert!(worst > 0.02, "{worst}");
}

/// Rods of 0.967 on the stated platform also fit the printed angles, but not the printed `A`: its beta column,
/// `-2 z a_x`, is -1.328 for `a_x = 0.9487` (radius 1.024), -1.224 for the stated `a_x = 0.8746`.
#[test]
fn rotopod_rods_of_0_967_fit_the_angles_but_not_the_matrix() {
    let pose = Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0);
    let short = RingPlatform::<f64>::new(&rotopod(0.95, 0.967_09));
    let q = short.inverse(&pose).unwrap();
    for (got, want) in q.0.iter().zip(ROTOPOD_Q) {
        assert!(angle_diff(*got, want).abs() < 7e-4, "{got} vs {want}");
    }
    let a = short.jacobians(&pose, &q).a;
    assert!((a[(0, 4)] - ROTOPOD_A[0][1]).abs() > 0.1, "{}", a[(0, 4)]);
}

#[test]
fn rotopod_printed_matrices_with_a_platform_radius_of_1_024() {
    let pose = Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0);
    let m = RingPlatform::<f64>::new(&rotopod(1.024, 0.98));
    let j = m.jacobians(&pose, &Actuators(ROTOPOD_Q));
    let mut kept = 0;
    for r in 0..6 {
        for c in 0..6 {
            let got = j.a[(r, SOURCE_COLUMN[c])];
            if ROTOPOD_A_KEPT[r][c] {
                assert!((got - ROTOPOD_A[r][c]).abs() < 1.5e-3, "A[{r}][{c}]: {got}");
                kept += 1;
            } else {
                // The slips are real: none is within rounding of the formula.
                assert!((got - ROTOPOD_A[r][c]).abs() > 0.1, "A[{r}][{c}]: {got}");
            }
        }
        assert!((j.b[(r, r)] - ROTOPOD_B[r]).abs() < 1.5e-3, "B[{r}]: {}", j.b[(r, r)]);
    }
    assert_eq!(kept, 27);
    // Row 6's beta is the formula's with the sign turned.
    assert!((j.a[(5, 4)] + ROTOPOD_A[5][1]).abs() < 1.5e-3);
}

/// Chapter 4.2's printed `A` (source columns; rows: the radial chains at (1, 2) and (-1, 2), the rod chains at
/// (-1, -2) and (1, -2), the two planarity constraints) and `B`'s diagonal.
const CH42_A: [[f64; 6]; 6] = [
    [0.688, -0.688, 0.0, -0.684, -1.366, 0.344],
    [0.688, 0.344, 0.0, 0.684, -1.366, 0.344],
    [-0.688, 0.344, -1.663, 0.0, 1.658, 0.344],
    [-0.688, -0.344, 1.66, 0.0, 1.657, 0.344],
    [0.0, 0.0, -5.589, 2.235, -1.118, 0.0],
    [0.0, 0.0, 5.594, -2.238, -1.118, 0.0],
];
const CH42_B: [f64; 6] = [-1.566, -1.566, 1.663, -1.66, 5.588, -5.598];

/// Chapter 4.2's matrices are the Jacobians at chapter 5's carriage angles (copied into this case with `L = 1`,
/// `z = 0.172`, where the rods would have to be 0.847 long) and the radial lengths 0.783 that do hold; its
/// planarity rows are ringpod's times 2.5 and -2.5 (a constraint times a constant: the same velocities), and its
/// first row's beta, -0.688, is a slip for -0.344 (`-2 z a_x`, as the mirror row's 0.344).
#[test]
fn ch4_2_printed_matrices_are_the_jacobians_at_chapter_5s_angles() {
    let g = presets::TRAINER_CH4;
    let ch5 = RingPlatform::<f64>::new(&presets::TRAINER_CH5)
        .inverse(&Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0))
        .unwrap();
    // The printed q: 1.107, 2.034, 4.373, 5.052 are chapter 5's carriages 3, 4, 1, 2.
    for (got, want) in [ch5.0[2], ch5.0[3], ch5.0[0], ch5.0[1]]
        .iter()
        .zip([1.107, 2.034, 4.373, 5.052])
    {
        assert!(angle_diff(*got, want).abs() < 5e-4, "{got} vs {want}");
    }
    let s = ((3.0 - 5f64.sqrt()).powi(2) + 0.172f64.powi(2)).sqrt();
    let q = Actuators([ch5.0[0], ch5.0[1], ch5.0[2], ch5.0[3], s, s]);
    let pose = Pose::new(0.0, 0.0, 0.172, 0.0, 0.0, 0.0);
    let m = RingPlatform::<f64>::new(&g);
    let j = m.jacobians(&pose, &q);
    // The source's row i is ringpod's row ROW[i] times SCALE[i]; its diagonal B entry is ringpod's B[ROW, COL].
    const ROW: [usize; 6] = [2, 3, 0, 1, 4, 5];
    const SCALE: [f64; 6] = [1.0, 1.0, 1.0, 1.0, 2.5, -2.5];
    const COL: [usize; 6] = [4, 5, 0, 1, 2, 3];
    for i in 0..6 {
        // The source's rounding: its entries are those of the angles rounded to three decimals (the rods' gamma
        // entries -+1.663 where the exact angles give -+1.657), and an angle rounded by 5e-4 moves an entry by up to
        // 2 R rho 5e-4 = 7e-3; the planarity rows' factor is printed within 0.2 %.
        let tol = if i < 4 { 7e-3 } else { 0.012 };
        for c in 0..6 {
            let got = SCALE[i] * j.a[(ROW[i], SOURCE_COLUMN[c])];
            let want = if (i, c) == (0, 1) { -0.344 } else { CH42_A[i][c] };
            assert!((got - want).abs() < tol, "A[{i}][{c}]: {got} vs {want}");
        }
        let got = SCALE[i] * j.b[(ROW[i], COL[i])];
        assert!((got - CH42_B[i]).abs() < tol, "B[{i}]: {got} vs {}", CH42_B[i]);
    }
    // The copied angles do not close the rods of length 1: they would need 0.847.
    let f = m.residuals(&pose, &q);
    let needed = (f[0] + 1.0).sqrt();
    assert!((needed - 0.8465).abs() < 1e-3, "{needed}");
}

/// Degrees and minutes.
fn dm(d: f64, m: f64) -> f64 {
    d + m / 60.0
}

/// The tool carrier's third example: `(0, 0, 400 mm)`, alpha 15 deg 13', beta 25 deg 20'.
fn third_example() -> Pose<f64> {
    Pose::new(
        0.0,
        0.0,
        0.4,
        dm(15.0, 13.0).to_radians(),
        dm(25.0, 20.0).to_radians(),
        0.0,
    )
}

/// The third example's printed dyad angles: `q2`, `q2'`, `q4` within a minute of the formulas' at the printed pose
/// (the source rounds 134 deg 07.9' and 34 deg 21.6' up and cuts 65 deg 01.6' down), and `q4'` 169 deg 20.4' where
/// the source prints 169 deg 22': a slip of 1.6' in the source (with `q4 + q4' = 2 eta`, `eta` = 101 deg 51', its
/// 169 deg 22' would need `q4` at 34 deg 20').
#[test]
fn tool5_third_example_q4_prime_is_169_deg_20_4() {
    let base = ToolCarrier::<f64>::new(&presets::TOOL5_EX);
    let minus = base.with_branches([Branch::Minus, Branch::Minus]);
    let plus = base.with_branches([Branch::Plus, Branch::Plus]);
    let printed = [dm(65.0, 1.0), dm(134.0, 8.0), dm(34.0, 22.0), dm(169.0, 22.0)];
    let pose = third_example();
    let (m, p) = (minus.inverse(&pose).unwrap(), plus.inverse(&pose).unwrap());
    let at = [m.0[1], p.0[1], m.0[3], p.0[3]].map(f64::to_degrees);
    for k in 0..3 {
        assert!((at[k] - printed[k]).abs() < 1.0 / 60.0, "{k}: {}", at[k]);
    }
    assert!((at[3] - dm(169.0, 20.4)).abs() < 0.05 / 60.0, "{}", at[3]);
    assert!((at[3] - printed[3]).abs() > 1.5 / 60.0);
}

/// The source's formulas (3.8, 3.9) contain the pivots' `y` and `z` only: their `x`, 155 mm, moves each dyad's
/// plane along X, which changes no angle. ringpod keeps it in the preset and draws with it.
#[test]
fn tool5_pivots_x_changes_no_drive() {
    let pose = third_example();
    let base = ToolCarrier::<f64>::new(&presets::TOOL5_EX).inverse(&pose).unwrap();
    let mut moved = presets::TOOL5_EX;
    moved.pivot_b[0] = 0.0;
    moved.pivot_d[0] = -0.3;
    let q = ToolCarrier::<f64>::new(&moved).inverse(&pose).unwrap();
    assert_eq!(q, base);
    assert!((base.0[0] - 0.128_365).abs() < 1e-6, "q1 = x + L1 sin(beta), printed 0");
}

/// Chapter 4's direct problem: a step of 0.1 rad on every carriage (the lengths held) turns the platform 0.1 rad
/// about Z and moves nothing else, for the rotopod (as computed and as stated) and for chapter 4.2's mechanism.
#[test]
fn ch4_carriage_steps_of_0_1_give_a_pure_yaw_of_0_1() {
    let rotopods = [rotopod(1.024, 0.98), presets::ROTOPOD_CH4];
    for g in &rotopods {
        let m = RingPlatform::<f64>::new(g);
        let pose = Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0);
        let q = m.inverse(&pose).unwrap();
        check_pure_yaw(&m, &pose, &q, [0.1; 6]);
    }
    let g = presets::TRAINER_CH4;
    let m = RingPlatform::<f64>::new(&g);
    let pose = Pose::new(0.0, 0.0, 0.172, 0.0, 0.0, 0.0);
    let q = m.inverse(&pose).unwrap();
    check_pure_yaw(&m, &pose, &q, [0.1, 0.1, 0.1, 0.1, 0.0, 0.0]);
}

/// `dp = -A^-1 B dq` is `(0, 0, 0, 0, 0, 0.1)`.
fn check_pure_yaw(m: &RingPlatform<f64>, pose: &Pose<f64>, q: &Actuators<f64>, dq: [f64; 6]) {
    let j = m.jacobians(pose, q);
    let rhs = -(j.b * nalgebra::Vector6::from(dq));
    let dp = j.a.lu().solve(&rhs).unwrap();
    let want = nalgebra::Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.1);
    assert!((dp - want).norm() < 1e-12, "{dp:?}");
}

/// Chapter 5.1's model at `(0, 0, 1, 0, 0, 0)`: rods `l1 = l2 = 1.298`, radial lengths printed 1.259 (1.25841: the
/// source rounds up), carriages `q1 = 4.371` (4.3726: a slip of 0.0016 in its `arctg 2.828 + pi`), `q2 = -1.231`,
/// `q3 = 1.107`, `q4 = 2.033` (2.0344, the same slip).
#[test]
fn ch5_printed_lengths_and_carriage_angles() {
    let g = &presets::TRAINER_CH5;
    assert!((g.rod_length - 1.298).abs() < 6e-4);
    let q = RingPlatform::<f64>::new(g)
        .inverse(&Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0))
        .unwrap();
    assert!((q.0[4] - 1.258_41).abs() < 1e-5 && (q.0[4] - 1.259).abs() > 5e-4);
    assert_eq!(q.0[4], q.0[5]);
    for (got, want, slip) in [
        (q.0[0], 4.371, true),
        (q.0[1], -1.231, false),
        (q.0[2], 1.107, false),
        (q.0[3], 2.033, true),
    ] {
        let err = angle_diff(got, want).abs();
        if slip {
            assert!(err > 1e-3 && err < 2e-3, "{got} vs {want}");
        } else {
            assert!(err < 5e-4, "{got} vs {want}");
        }
    }
}

/// Chapter 3.2's mechanism (`trainer-ch3`): every check passes at heave 0.948 to 0.997 at the centre, bounded below
/// by the actuators' shortest length (0.95 = `sqrt((R - r)^2 + z^2)`) and above by the rods' reach (`L = 1`).
#[test]
fn ch3_2_preset_heave_range() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_CH3);
    let at = |z: f64| m.inverse_checked(&Pose::new(0.0, 0.0, z, 0.0, 0.0, 0.0));
    let (q, report) = at(0.947).unwrap();
    assert_eq!(report.first_failure(), Some(Check::Reach));
    assert!(q.0[4] < 0.95);
    for z in [0.948, presets::TRAINER_CH3_HOME_Z, 0.997] {
        assert!(at(z).unwrap().1.all_pass(), "{z}");
    }
    assert!(matches!(at(0.998), Err(KinematicsError::Unreachable { chain: 2, .. })));
    // The radial carriages on their joints' radii, the rods' as the chapter's phi13 -+ phi33.
    let q = at(presets::TRAINER_CH3_HOME_Z).unwrap().0;
    assert!((q.0[0] - 0.75 * std::f64::consts::PI).abs() < 1e-12);
    assert!((angle_diff(q.0[1], -0.75 * std::f64::consts::PI)).abs() < 1e-12);
    assert!(q.0[2] < -std::f64::consts::FRAC_PI_4 + 0.5 && q.0[2] > -std::f64::consts::FRAC_PI_4);
}

/// Chapter 4.2's mechanism (`trainer-ch4`): its radial lengths at the chapter's pose are the printed 0.783; that
/// pose fails the joint cones and the singularity index; the home passes everything.
#[test]
fn ch4_2_preset_at_the_chapters_pose_and_at_home() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_CH4);
    let (q, report) = m.inverse_checked(&Pose::new(0.0, 0.0, 0.172, 0.0, 0.0, 0.0)).unwrap();
    assert!((q.0[4] - 0.783).abs() < 5e-4 && q.0[4] == q.0[5]);
    assert!(!report.passes(Check::JointCones) && !report.passes(Check::Singularity));
    let h = Preset::TrainerCh4.home();
    let home = Pose::new(h[0], h[1], h[2], h[3], h[4], h[5]);
    assert!(m.inverse_checked(&home).unwrap().1.all_pass());
    let h = Preset::TrainerCh3.home();
    let home = Pose::new(h[0], h[1], h[2], h[3], h[4], h[5]);
    assert!(RingPlatform::<f64>::new(&presets::TRAINER_CH3)
        .inverse_checked(&home)
        .unwrap()
        .1
        .all_pass());
}

//! The structural analysis against the source: chapter 5.1's three chains (their printed matrices and
//! determinants), chapter 2's mobility counts, the trainer's wrench matrix; and the transmitted wrenches against
//! their definition (reciprocal to every unactuated joint, work on their own drive).

use nalgebra::{Matrix6, Vector6};
use ringpod_core::kinematics::presets::{Preset, ROTOPOD_CH4, TOOL5_EX, TRAINER_CH5, TRAINER_MODEL};
use ringpod_core::kinematics::{Mechanism, Pose, RingPlatform, ToolCarrier};
use ringpod_core::screws::layouts::{ring_chains, tool_chains, Chains, Figure};
use ringpod_core::screws::reciprocal;
use ringpod_core::screws::structure::{analyse, wrench_determinant, Chain, ChainAnalysis, Mobility};

/// The source's matrices of chapter 5.1 as printed (rows: the joints' screws), figs. 5.1 (A = (0.5, 0.2, 1)),
/// 5.1 first (A = (0.5, 0, 1)), 5.2 and 5.3.
const PRINTED: [(Figure, [[f64; 6]; 6]); 4] = [
    (
        Figure::Fig5_1,
        [
            [0., 0., 1., 0., 0., 0.],
            [1., 0., 0., 0., 0., 0.],
            [0., 1., 0., 0., 0., 1.],
            [0., 0., 1., 0., -1., 0.],
            [1., 0., 0., 0., 1., -0.2],
            [0., 1., 0., -1., 0., 0.5],
        ],
    ),
    (
        Figure::Fig5_1Singular,
        [
            [0., 0., 1., 0., 0., 0.],
            [1., 0., 0., 0., 0., 0.],
            [0., 1., 0., 0., 0., 1.],
            [0., 0., 1., 0., -1., 0.],
            [1., 0., 0., 0., 1., 0.],
            [0., 1., 0., -1., 0., 0.5],
        ],
    ),
    (
        Figure::Fig5_2,
        [
            [0., 0., 1., 0., 0., 0.],
            [0., 1., 0., 0., 0., 1.],
            [0., 1., 0., 0., 0., 0.5],
            [1., 0., 0., 0., 1., 0.],
            [0., 1., 0., -1., 0., 0.5],
            [0., 0., 1., 0., -0.5, 0.],
        ],
    ),
    (
        Figure::Fig5_3,
        [
            [0., 0., 1., 0., 0., 0.],
            [0., 1., 0., 0., 0., 1.],
            [0., 0., 0., -0.5, 0., 1.],
            [1., 0., 0., 0., 1., 0.],
            [0., 1., 0., -1., 0., 0.5],
            [0., 0., 1., 0., -0.5, 0.],
        ],
    ),
];

#[test]
fn chapter_5_chains_reproduce_the_printed_matrices_and_determinants() {
    for (figure, printed) in PRINTED {
        let chain = figure.chain().unwrap();
        let a = analyse(&chain).unwrap();
        // The printed rows are the joints' screws, the prismatic one written as B -> A.
        let scale = if figure == Figure::Fig5_3 { 1.25f64.sqrt() } else { 1.0 };
        for (i, (j, row)) in chain.joints().iter().zip(printed).enumerate() {
            let s = if i == 2 { scale } else { 1.0 };
            for (got, want) in j.twist.iter().zip(row) {
                assert!(
                    (got * s - want).abs() < 1e-12,
                    "{figure:?} row {i}: {:?} vs {row:?}",
                    j.twist
                );
            }
        }
        let det = a.determinant_source.unwrap();
        assert!((det - figure.published()).abs() < 1e-12, "{figure:?}: {det}");
        // Independently of our rows: the printed matrix's own determinant.
        let m = Matrix6::from_fn(|r, c| printed[r][c]);
        assert!((m.determinant() - figure.published()).abs() < 1e-12);
        let unit = a.determinant.unwrap();
        assert!((unit * scale - det).abs() < 1e-12, "{figure:?}: unit {unit}");
    }
    let unit = analyse(&Figure::Fig5_3.chain().unwrap()).unwrap().determinant.unwrap();
    assert!((unit - 0.559017).abs() < 1e-6, "{unit}");
}

/// Every transmitted wrench is reciprocal to every unactuated joint; each drive's own wrench does work on its
/// drive and none on the chain's other drives; the constraint wrenches do no work on any joint.
fn check_wrenches(chain: &Chain, a: &ChainAnalysis) {
    assert!(a.per_drive);
    let drives: Vec<usize> = (0..chain.joints().len())
        .filter(|&i| chain.joints()[i].actuated)
        .collect();
    assert_eq!(a.count, a.constraints + drives.len());
    for (k, w) in a.wrenches[..a.count].iter().enumerate() {
        assert!((w.fixed_rows::<3>(0).norm() - 1.0).abs() < 1e-9 || (w.fixed_rows::<3>(3).norm() - 1.0).abs() < 1e-9);
        for (i, j) in chain.joints().iter().enumerate() {
            let work = reciprocal(&j.twist, w);
            let own = k >= a.constraints && drives[k - a.constraints] == i;
            if own {
                assert!(work.abs() > 1e-6, "wrench {k} does no work on its drive {i}");
            } else {
                assert!(work.abs() < 1e-9, "wrench {k} works {work} on joint {i}");
            }
        }
    }
}

#[test]
fn fig_5_1_transmits_a_force_along_ab_and_fig_5_2_two_forces_through_a() {
    let chain = Figure::Fig5_1.chain().unwrap();
    let a = analyse(&chain).unwrap();
    check_wrenches(&chain, &a);
    assert_eq!((a.count, a.constraints), (1, 0));
    // The force along B -> A: (-0.5, 0.2, 1) / |.|, through B = (1, 0, 0).
    let d = Vector6::new(-0.5, 0.2, 1.0, 0.0, 0.0, 0.0) / (0.25f64 + 0.04 + 1.0).sqrt();
    let m = nalgebra::Vector3::new(1.0, 0.0, 0.0).cross(&nalgebra::Vector3::new(d[0], d[1], d[2]));
    let want = Vector6::new(d[0], d[1], d[2], m.x, m.y, m.z);
    assert!((a.wrenches[0] - want).norm() < 1e-9, "{:?}", a.wrenches[0]);
    for figure in [Figure::Fig5_2, Figure::Fig5_3] {
        let chain = figure.chain().unwrap();
        let a = analyse(&chain).unwrap();
        check_wrenches(&chain, &a);
        assert_eq!((a.count, a.constraints), (2, 0));
        // Both through A = (0.5, 0, 1): moment = A x force.
        for w in &a.wrenches[..2] {
            let f = nalgebra::Vector3::new(w[0], w[1], w[2]);
            let m = nalgebra::Vector3::new(0.5, 0.0, 1.0).cross(&f);
            assert!(
                (nalgebra::Vector3::new(w[3], w[4], w[5]) - m).norm() < 1e-9,
                "{figure:?} {w:?}"
            );
        }
    }
}

#[test]
fn the_singular_chain_is_reported_without_per_drive_wrenches() {
    let a = analyse(&Figure::Fig5_1Singular.chain().unwrap()).unwrap();
    assert!(a.determinant.unwrap().abs() < 1e-12);
    assert!(!a.per_drive);
}

fn analyses(chains: &Chains) -> Vec<ChainAnalysis> {
    chains.iter().map(|c| analyse(c).unwrap()).collect()
}

#[test]
fn chapter_2_mobility_counts() {
    // Trainer: W = 6 (12 - 1) - 5 x 8 - 4 x 2 - 3 x 4 = 6; with plain spherical pairs 6 x 11 - 5 x 8 - 3 x 6 = 8.
    let trainer = RingPlatform::<f64>::new(&TRAINER_CH5);
    let chains = ring_chains(&trainer, &Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0)).unwrap();
    let all: Vec<Chain> = chains.iter().copied().collect();
    let m = Mobility::of(&all);
    assert_eq!((m.moving_links, m.pairs, m.w), (11, [0, 0, 4, 2, 8], 6));
    let plain = Mobility::without_pins(&all);
    assert_eq!((plain.pairs, plain.w), ([0, 0, 6, 0, 8], 8));
    // Rotopod: six rod chains, 13 moving links, 6 carriages, 6 spherical and 6 pin-spherical pairs.
    let rotopod = RingPlatform::<f64>::new(&ROTOPOD_CH4);
    let chains = ring_chains(&rotopod, &Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0)).unwrap();
    let all: Vec<Chain> = chains.iter().copied().collect();
    assert_eq!(Mobility::of(&all).w, 6);
    assert_eq!(Mobility::without_pins(&all).w, 12);
    // Tool carrier: five freedoms.
    let carrier = ToolCarrier::<f64>::new(&TOOL5_EX);
    let h = Preset::Tool5Ex.home();
    let chains = tool_chains(&carrier, &Pose::new(h[0], h[1], h[2], h[3], h[4], h[5])).unwrap();
    let all: Vec<Chain> = chains.iter().copied().collect();
    assert_eq!(Mobility::of(&all).w, 5);
}

#[test]
fn trainer_wrench_determinant_has_the_sources_value_and_sign() {
    let m = RingPlatform::<f64>::new(&TRAINER_CH5);
    let pose = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0);
    let chains = ring_chains(&m, &pose).unwrap();
    let a = analyses(&chains);
    for (c, a) in chains.iter().zip(&a) {
        check_wrenches(c, a);
        assert!(
            a.determinant.unwrap().abs() > 1e-3,
            "a chain of the trainer is singular at its reference pose"
        );
    }
    let det = wrench_determinant(&a).unwrap();
    // The source's matrix (chains 1 to 4, each radial chain's line then its tangent force) with the sign of row
    // 4's last entry corrected: -8.039 from its three-digit entries.
    let printed: [[f64; 6]; 6] = [
        [0., 0.638, 0.77, -2.178, 0.77, -0.638],
        [0., 0.638, 0.77, -2.178, -0.77, 0.638],
        [-0.272, -0.542, 0.794, 2.13, -1.066, 0.003],
        [0.894, -0.447, 0., 0.447, 0.894, -2.235],
        [0.272, -0.542, 0.794, 2.13, 1.066, -0.002],
        [0.894, 0.447, 0., -0.447, 0.894, -2.235],
    ];
    let source = Matrix6::from_fn(|r, c| printed[r][c]).determinant();
    assert!((source + 8.039).abs() < 1e-3, "{source}");
    assert!(
        (det - source).abs() < 0.05,
        "ours {det}, the source's corrected {source}"
    );
    assert!((det + 8.0649).abs() < 1e-3, "{det}");
    // The same lines as the workspace check's wrench matrix (other order and senses): the same |det|.
    let q = m.inverse(&pose).unwrap();
    assert!((m.wrench_matrix(&pose, &q).determinant().abs() - det.abs()).abs() < 1e-9);
    // Each radial chain's wrenches are the source's: its tangent force (the carriage's) and the line B -> A.
    let tangent = Vector6::new(0.894427, -0.447214, 0.0, 0.447214, 0.894427, -2.236068);
    assert!((a[2].wrenches[0] - tangent).norm() < 1e-5, "{:?}", a[2].wrenches[0]);
}

#[test]
fn every_preset_transmits_six_independent_wrenches_at_home() {
    for preset in Preset::ALL {
        let h = preset.home();
        let pose = Pose::new(h[0], h[1], h[2], h[3], h[4], h[5]);
        let chains = match preset.geometry() {
            ringpod_core::kinematics::presets::PresetGeometry::Ring(g) => {
                ring_chains(&RingPlatform::<f64>::new(g), &pose).unwrap()
            }
            ringpod_core::kinematics::presets::PresetGeometry::Tool(g) => {
                tool_chains(&ToolCarrier::<f64>::new(g), &pose).unwrap()
            }
        };
        let a = analyses(&chains);
        for (c, a) in chains.iter().zip(&a) {
            check_wrenches(c, a);
        }
        let det = wrench_determinant(&a).unwrap();
        assert!(det.abs() > 1e-6, "{}: {det}", preset.name());
    }
    // A pose of the model away from home: still six.
    let m = RingPlatform::<f64>::new(&TRAINER_MODEL);
    let chains = ring_chains(&m, &Pose::new(0.01, -0.02, 0.23, 0.05, -0.04, 0.7)).unwrap();
    assert!(wrench_determinant(&analyses(&chains)).unwrap().abs() > 1e-9);
}

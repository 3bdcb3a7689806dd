//! Built-in geometries. Each is validated in `const` context: a preset that cannot be built fails compilation.

use super::geometry::{
    unwrap_geometry, Branch, Chain, ChainKind, RingGeometry, RingLimits, ToolGeometry, DEG, SOURCE_SPACING,
};

const fn rod(branch: Branch, x: f64, y: f64) -> Chain {
    Chain { kind: ChainKind::Rod(branch), platform_point: [x, y, 0.0] }
}

const fn radial(x: f64, y: f64) -> Chain {
    Chain { kind: ChainKind::Radial, platform_point: [x, y, 0.0] }
}

/// Trainer of dissertation ch. 5 (normalised units): ring radius 3, platform 2 x 4, `L = sqrt(1 + (sqrt 8 - 2)^2)`.
pub const TRAINER_CH5: RingGeometry = unwrap_geometry(RingGeometry::new(
    "trainer-ch5",
    3.0,
    1.298_572_870_891_441_2,
    &[rod(Branch::Plus, -1.0, -2.0), rod(Branch::Minus, 1.0, -2.0), radial(1.0, 2.0), radial(-1.0, 2.0)],
    RingLimits {
        stroke: [0.3, 2.0],
        carriage_spacing: SOURCE_SPACING,
        base_cone: 11.0 * DEG,
        platform_cone: 22.0 * DEG,
        min_singularity_index: 0.01,
        centre_of_mass: [0.0; 3],
    },
));

/// Rotopod of dissertation ch. 4 (normalised units): six rod chains in pairs at 0, 120 and 240 degrees.
pub const ROTOPOD_CH4: RingGeometry = unwrap_geometry(RingGeometry::new(
    "rotopod-ch4",
    1.0198,
    0.98,
    &[
        rod(Branch::Minus, 0.8746, -0.0435),
        rod(Branch::Plus, 0.8746, 0.0435),
        rod(Branch::Minus, -0.3996, 0.7792),
        rod(Branch::Plus, -0.4750, 0.7357),
        rod(Branch::Minus, -0.4750, -0.7357),
        rod(Branch::Plus, -0.3996, -0.7792),
    ],
    RingLimits {
        stroke: [0.0, 1.0],
        carriage_spacing: SOURCE_SPACING,
        base_cone: 11.0 * DEG,
        platform_cone: 22.0 * DEG,
        min_singularity_index: 0.01,
        centre_of_mass: [0.0; 3],
    },
));

/// Tool carrier of the worked position problem, in metres (`L1 = 0.3, L2 = L3 = 0.33, a = 0.4, b = 1.1`,
/// `B = (0.155, 0.55, 0.27)`, `D = (0.155, -0.55, 0.27)`; the source's `L4 = 0.27` is the pivots' height).
pub const TOOL5_EX: ToolGeometry = unwrap_geometry(ToolGeometry::new(
    "tool5-ex",
    0.300,
    0.330,
    0.330,
    0.400,
    1.100,
    [0.155, 0.550, 0.270],
    [0.155, -0.550, 0.270],
    [Branch::Minus, Branch::Minus],
    0.02,
));

/// Nominal heave of the trainer model: the centre of its motion range (m).
pub const TRAINER_MODEL_HOME_Z: f64 = 0.120;

/// The 1:20 model of the trainer that the firmware drives (KINEMATICS.md 6), in metres.
pub const TRAINER_MODEL: RingGeometry = unwrap_geometry(RingGeometry::new(
    "trainer-model",
    0.150,
    0.150,
    &[rod(Branch::Plus, -0.050, -0.050), rod(Branch::Minus, 0.050, -0.050), radial(0.050, 0.050), radial(-0.050, 0.050)],
    RingLimits {
        stroke: [0.040, 0.200],
        carriage_spacing: SOURCE_SPACING,
        base_cone: 11.0 * DEG,
        platform_cone: 22.0 * DEG,
        min_singularity_index: 0.01,
        centre_of_mass: [0.0, 0.0, 0.020],
    },
));

/// All ring presets, by name.
pub const RING: [&RingGeometry; 3] = [&TRAINER_CH5, &ROTOPOD_CH4, &TRAINER_MODEL];

/// All tool-carrier presets, by name.
pub const TOOL: [&ToolGeometry; 1] = [&TOOL5_EX];

//! Built-in geometries. Each is validated in `const` context: a preset that cannot be built fails compilation.

use super::geometry::{
    unwrap_geometry, Branch, Chain, ChainKind, Elbow, ElbowBranch, RingGeometry, RingLimits, ToolGeometry, DEG,
    SOURCE_SPACING,
};

const fn rod(branch: Branch, x: f64, y: f64) -> Chain {
    Chain {
        kind: ChainKind::Rod(branch),
        platform_point: [x, y, 0.0],
    }
}

const fn radial(x: f64, y: f64) -> Chain {
    Chain {
        kind: ChainKind::Radial,
        platform_point: [x, y, 0.0],
    }
}

/// Trainer of dissertation ch. 5 (normalised units): ring radius 3, platform 2 x 4, `L = sqrt(1 + (sqrt 8 - 2)^2)`.
pub const TRAINER_CH5: RingGeometry = unwrap_geometry(RingGeometry::new(
    "trainer-ch5",
    3.0,
    1.298_572_870_891_441_2,
    &[
        rod(Branch::Plus, -1.0, -2.0),
        rod(Branch::Minus, 1.0, -2.0),
        radial(1.0, 2.0),
        radial(-1.0, 2.0),
    ],
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
/// `B = (0.155, 0.55, 0.27)`, `D = (0.155, -0.55, 0.27)`; the source's `L4 = 0.27` is the pivots' height). The source
/// gives no length for the X guide: the carriage's stroke of `+-0.5` m (about half the frame's width `b`) is assumed.
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
    [-0.5, 0.5],
    0.02,
));

/// Four-chain mechanism of dissertation ch. 3.2 (normalised units): linear actuators 0.95..1.05 in chains 1, 2 (side
/// by side, as a car's rear suspension), rods of 1 in chains 3, 4 (`phi3 = phi13 + phi33`, `phi4 = phi13 - phi33`),
/// platform joints on the square of half-side 0.672 (on the rotopod's circle, `r = 0.95`), ring radius 1.0198.
pub const TRAINER_CH3: RingGeometry = unwrap_geometry(RingGeometry::new(
    "trainer-ch3",
    1.0198,
    1.0,
    &[
        radial(-0.672, 0.672),
        radial(-0.672, -0.672),
        rod(Branch::Plus, 0.672, -0.672),
        rod(Branch::Minus, 0.672, 0.672),
    ],
    RingLimits {
        stroke: [0.95, 1.05],
        ..TRAINER_CH5.limits
    },
));

/// Four-chain mechanism of dissertation ch. 4.2 (normalised units): chapter 5's ring and platform with rods of 1 and
/// linear actuators of 0.2..1.2. The rods' carriages sit inside their pair (chapter 5's branches put them 141 deg
/// from the radial carriages at every height, past the 120 deg limit); the chapter's own pose, heave 0.172, tilts the
/// rods past the joint cones and lies near a type 2 singularity, so the home is the middle of the heave that passes
/// every check (0.375..0.565).
pub const TRAINER_CH4: RingGeometry = unwrap_geometry(RingGeometry::new(
    "trainer-ch4",
    3.0,
    1.0,
    &[
        rod(Branch::Minus, -1.0, -2.0),
        rod(Branch::Plus, 1.0, -2.0),
        radial(1.0, 2.0),
        radial(-1.0, 2.0),
    ],
    RingLimits {
        stroke: [0.2, 1.2],
        ..TRAINER_CH5.limits
    },
));

/// Home heave of [`TRAINER_CH3`]: every check passes from 0.948 (the actuators' shortest, 0.95) to 0.997 (the rods'
/// reach).
pub const TRAINER_CH3_HOME_Z: f64 = 0.97;

/// Home heave of [`TRAINER_CH4`].
pub const TRAINER_CH4_HOME_Z: f64 = 0.47;

/// Nominal heave of the trainer model: the centre of its heave range (m).
pub const TRAINER_MODEL_HOME_Z: f64 = 0.227;

/// The 1:20 model of the trainer that the firmware drives (KINEMATICS.md 6), in metres.
///
/// Ring radius 0.286 m, rods 0.312 m, platform joints of the rod pair at `(-+0.194, -0.031)` and of the radial
/// pair at `(+-0.181, 0.160)`, nominal heave 0.227 m. Found by `examples/trainer_model_design.rs` (a hill climb on
/// the worst normalised margin) and rounded to millimetres: every axis of the spec table swept over its whole range
/// (surge/sway +-50 mm, heave +-40 mm, pitch/roll +-20 deg), at any yaw, passes all six checks with the source's joint
/// limits. The combined corners of all ranges at once are not all reachable; the book's trainer-model geometry gives the share that is.
/// Linear actuators: 160..310 mm of travel between the end stops, of which 166..310 mm is the working stroke: the
/// lower end switch sits at 165 mm (homing leaves the actuator 2 mm above it), and limited motion keeps the 2 mm
/// reach margin above 166 mm, so it never trips the switch (the spec ranges use 174..294 mm).
pub const TRAINER_MODEL: RingGeometry = unwrap_geometry(RingGeometry::new(
    "trainer-model",
    0.286,
    0.312,
    &[
        rod(Branch::Plus, -0.194, -0.031),
        rod(Branch::Minus, 0.194, -0.031),
        radial(0.181, 0.160),
        radial(-0.181, 0.160),
    ],
    RingLimits {
        stroke: [0.166, 0.310],
        carriage_spacing: SOURCE_SPACING,
        base_cone: 11.0 * DEG,
        platform_cone: 22.0 * DEG,
        min_singularity_index: 0.02,
        centre_of_mass: [0.0, 0.0, 0.020],
    },
));

/// The arm of [`TRAINER_ELBOW`]'s elbow chains, in metres.
///
/// Found by a random search (as `ringpod rig design --arms-only` searches any rig with elbow chains) over shoulder
/// radius 0.22..0.33 m, height, upper arm, forearm and branch, scoring the arms' worst margin over the model's spec
/// table swept axis by axis at 24 yaws, and rounded to millimetres: the shoulder 28 mm
/// inside the ring, 17 mm above it; upper arm 105 mm, forearm 189 mm, elbow up. Over that sweep the elbow's interior
/// angle stays 20 degrees or more inside its 25..155 degree limits, the forearm 10 degrees or more above the platform
/// cone, the singularity index above 0.05; the shoulder needs 114..175 degrees (the upper arm points outward and up),
/// and its travel is that plus 14..15 degrees each way (index or end switch below 100 degrees). An arm whose shoulder
/// sits up to 0.40 m out (an outrigger) scored only a little better.
pub const TRAINER_ELBOW_ARM: Elbow = Elbow {
    shoulder_radius: 0.258,
    shoulder_height: 0.017,
    upper_arm: 0.105,
    forearm: 0.189,
    branch: ElbowBranch::Up,
    shoulder_angle: [100.0 * DEG, 190.0 * DEG],
    elbow_angle: [25.0 * DEG, 155.0 * DEG],
};

const fn elbow(x: f64, y: f64) -> Chain {
    Chain {
        kind: ChainKind::Elbow(TRAINER_ELBOW_ARM),
        platform_point: [x, y, 0.0],
    }
}

/// The 1:20 trainer model with the arms of dissertation ch. 5.1 (fig. 5.2) in place of its linear actuators: the
/// same ring, rods, platform joints, limits and home pose, and two elbow chains whose shoulders are driven by rotary
/// motors (actuators: four carriages, then the two shoulder angles). See [`TRAINER_ELBOW_ARM`] for the arms.
pub const TRAINER_ELBOW: RingGeometry = unwrap_geometry(RingGeometry::new(
    "trainer-elbow",
    TRAINER_MODEL.ring_radius,
    TRAINER_MODEL.rod_length,
    &[
        rod(Branch::Plus, -0.194, -0.031),
        rod(Branch::Minus, 0.194, -0.031),
        elbow(0.181, 0.160),
        elbow(-0.181, 0.160),
    ],
    // The model's limits; no linear actuators, so the stroke is a rig file's default for none.
    RingLimits {
        stroke: [0.0, 1.0],
        ..TRAINER_MODEL.limits
    },
));

/// Motion ranges of the model's spec table around [`TRAINER_MODEL_HOME_Z`]: surge, sway, heave (m), roll, pitch
/// (rad); yaw is continuous.
pub const TRAINER_MODEL_RANGES: [f64; 5] = [0.050, 0.050, 0.040, 20.0 * DEG, 20.0 * DEG];

/// A built-in geometry, selectable by name (CLI `--mechanism`, protocol configuration).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Preset {
    /// [`TRAINER_CH5`].
    TrainerCh5,
    /// [`ROTOPOD_CH4`].
    RotopodCh4,
    /// [`TRAINER_MODEL`].
    TrainerModel,
    /// [`TRAINER_ELBOW`].
    TrainerElbow,
    /// [`TOOL5_EX`].
    Tool5Ex,
    /// [`TRAINER_CH3`].
    TrainerCh3,
    /// [`TRAINER_CH4`].
    TrainerCh4,
}

/// The geometry of a preset: a ring platform or a tool carrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PresetGeometry {
    /// Trainer or rotopod.
    Ring(&'static RingGeometry),
    /// Tool carrier.
    Tool(&'static ToolGeometry),
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 7] = [
        Preset::TrainerModel,
        Preset::TrainerElbow,
        Preset::TrainerCh5,
        Preset::RotopodCh4,
        Preset::Tool5Ex,
        Preset::TrainerCh3,
        Preset::TrainerCh4,
    ];

    /// The preset's name, as in the reference files.
    pub const fn name(self) -> &'static str {
        match self {
            Preset::TrainerCh5 => "trainer-ch5",
            Preset::RotopodCh4 => "rotopod-ch4",
            Preset::TrainerModel => "trainer-model",
            Preset::TrainerElbow => "trainer-elbow",
            Preset::Tool5Ex => "tool5-ex",
            Preset::TrainerCh3 => "trainer-ch3",
            Preset::TrainerCh4 => "trainer-ch4",
        }
    }

    /// The preset of a name.
    pub fn from_name(name: &str) -> Option<Preset> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// One line on what the preset is.
    pub const fn description(self) -> &'static str {
        match self {
            Preset::TrainerCh5 => "trainer of dissertation ch. 5, normalised units (ring radius 3)",
            Preset::RotopodCh4 => "rotopod of dissertation ch. 4, six rod chains, normalised units",
            Preset::TrainerModel => "1:20 trainer model driven by the firmware, metres (ring radius 0.286 m)",
            Preset::TrainerElbow => {
                "the 1:20 trainer model with elbow arms (ch. 5.1 fig. 5.2) for its linear actuators"
            }
            Preset::Tool5Ex => "five-DOF tool carrier of the worked position problem, metres",
            Preset::TrainerCh3 => "four chains of dissertation ch. 3.2, normalised units (ring radius 1.0198)",
            Preset::TrainerCh4 => "four chains of dissertation ch. 4.2, normalised units (ring radius 3, rods 1)",
        }
    }

    /// The geometry.
    pub const fn geometry(self) -> PresetGeometry {
        match self {
            Preset::TrainerCh5 => PresetGeometry::Ring(&TRAINER_CH5),
            Preset::RotopodCh4 => PresetGeometry::Ring(&ROTOPOD_CH4),
            Preset::TrainerModel => PresetGeometry::Ring(&TRAINER_MODEL),
            Preset::TrainerElbow => PresetGeometry::Ring(&TRAINER_ELBOW),
            Preset::Tool5Ex => PresetGeometry::Tool(&TOOL5_EX),
            Preset::TrainerCh3 => PresetGeometry::Ring(&TRAINER_CH3),
            Preset::TrainerCh4 => PresetGeometry::Ring(&TRAINER_CH4),
        }
    }

    /// The motion ranges of its spec table, `+-` around home (surge, sway, heave in m, roll, pitch in rad), for the
    /// 1:20 model and its elbow variant; `None` for the reference geometries.
    pub const fn spec_ranges(self) -> Option<[f64; 5]> {
        match self {
            Preset::TrainerModel | Preset::TrainerElbow => Some(TRAINER_MODEL_RANGES),
            _ => None,
        }
    }

    /// The neutral pose `[x, y, z, alpha, beta, gamma]`: the reference pose of the source, or the model's home.
    pub const fn home(self) -> [f64; 6] {
        match self {
            Preset::TrainerCh5 => [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            Preset::RotopodCh4 => [0.0, 0.0, 0.7, 0.0, 0.0, 0.0],
            Preset::TrainerModel | Preset::TrainerElbow => [0.0, 0.0, TRAINER_MODEL_HOME_Z, 0.0, 0.0, 0.0],
            Preset::Tool5Ex => [0.0, 0.0, 0.4, 0.0, 0.0, 0.0],
            Preset::TrainerCh3 => [0.0, 0.0, TRAINER_CH3_HOME_Z, 0.0, 0.0, 0.0],
            Preset::TrainerCh4 => [0.0, 0.0, TRAINER_CH4_HOME_Z, 0.0, 0.0, 0.0],
        }
    }
}

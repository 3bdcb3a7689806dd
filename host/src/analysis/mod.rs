//! The offline questions: kinematics (`presets`, `ik`, `check`, `fk`, `loads`; `branches`: the tool carrier's
//! assemblies for `ik --branch`), `rates`, `structure`, `reactions`,
//! paper 003's Gram determinants over a slice (`gram`), tip-over (`check --tip-over`), the drawing of a platform at a pose (`draw`),
//! `workspace`, paper 002's matrix method and equation of motion (`dynamics`), each on any preset's mechanism or a rig file, answered as text or JSON without a device.

pub mod branches;
pub mod demand;
pub mod draw;
pub mod dynamics;
pub mod gram;
pub mod kinematics;
pub mod mechanism;
pub mod placement;
pub mod rates;
pub mod reactions;
pub mod structure;
pub mod tipover;
pub mod units;
pub mod workspace;

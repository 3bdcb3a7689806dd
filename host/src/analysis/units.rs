//! How the analysis commands read and print angles: radians, or degrees with `--degrees`, for poses, actuators and
//! check margins alike. Shared by `ik`/`check`/`fk` and the tool carrier's assemblies (`ik --branch all`).

use ringpod_core::kinematics::{AxisKind, Check, Pose};

/// Angle conversion for `--degrees`.
pub(crate) struct Units {
    pub(crate) degrees: bool,
}

impl Units {
    pub(crate) fn angle_out(&self, rad: f64) -> f64 {
        if self.degrees {
            rad.to_degrees()
        } else {
            rad
        }
    }
    pub(crate) fn angle_in(&self, v: f64) -> f64 {
        if self.degrees {
            v.to_radians()
        } else {
            v
        }
    }
    pub(crate) fn angle_unit(&self) -> &'static str {
        if self.degrees {
            "deg"
        } else {
            "rad"
        }
    }
    /// Pose from the command line: metres, then angles.
    pub(crate) fn pose_in(&self, v: [f64; 6]) -> Pose<f64> {
        Pose::from_array(std::array::from_fn(|i| if i < 3 { v[i] } else { self.angle_in(v[i]) }))
    }
    pub(crate) fn pose_out(&self, p: &Pose<f64>) -> [f64; 6] {
        let v = p.to_array();
        std::array::from_fn(|i| if i < 3 { v[i] } else { self.angle_out(v[i]) })
    }
    pub(crate) fn axis_unit(&self, kind: AxisKind) -> &'static str {
        match kind {
            AxisKind::Linear => "m",
            AxisKind::Ring | AxisKind::Angle => self.angle_unit(),
        }
    }
    pub(crate) fn axis_out(&self, kind: AxisKind, v: f64) -> f64 {
        match kind {
            AxisKind::Linear => v,
            AxisKind::Ring | AxisKind::Angle => self.angle_out(v),
        }
    }
    pub(crate) fn margin_unit(&self, check: Check) -> &'static str {
        if check.unit() == "rad" {
            self.angle_unit()
        } else {
            check.unit()
        }
    }
    pub(crate) fn margin_out(&self, check: Check, v: f64) -> f64 {
        if check.unit() == "rad" {
            self.angle_out(v)
        } else {
            v
        }
    }
}

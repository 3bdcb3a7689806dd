//! The workspace checks of KINEMATICS.md 4, each with a margin: positive inside, negative outside.

use core::fmt;

use crate::Real;

/// One workspace check. Each has its own unit of margin, given on the variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Check {
    /// 1. Rod reach and actuator stroke: the smallest slack of any reach condition or stroke limit (m).
    Reach,
    /// 2. Central angle between neighbouring carriages within `[min, max]` (rad).
    CarriageSpacing,
    /// 3. Neighbouring carriages keep their cyclic order, so rods cannot cross: smallest signed gap (rad).
    RodCrossing,
    /// 4. Ball-joint cones: smallest angle of a chain to the base or platform plane above its limit (rad).
    JointCones,
    /// 5. Scale-free singularity index of the transmitted wrenches above its threshold (dimensionless).
    Singularity,
    /// 6. Centre of mass projected inside the carriage polygon: distance to its nearest edge (m).
    Stability,
}

impl Check {
    /// All checks, in the order of KINEMATICS.md 4.
    pub const ALL: [Check; 6] = [
        Check::Reach,
        Check::CarriageSpacing,
        Check::RodCrossing,
        Check::JointCones,
        Check::Singularity,
        Check::Stability,
    ];

    /// Short name for reports.
    pub const fn name(self) -> &'static str {
        match self {
            Check::Reach => "reach",
            Check::CarriageSpacing => "carriage-spacing",
            Check::RodCrossing => "rod-crossing",
            Check::JointCones => "joint-cones",
            Check::Singularity => "singularity",
            Check::Stability => "stability",
        }
    }

    /// Unit of the margin.
    pub const fn unit(self) -> &'static str {
        match self {
            Check::Reach | Check::Stability => "m",
            Check::CarriageSpacing | Check::RodCrossing | Check::JointCones => "rad",
            Check::Singularity => "1",
        }
    }

    pub(crate) const fn index(self) -> usize {
        self as usize
    }
}

impl fmt::Display for Check {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The margins of all six checks at one pose. `None`: the check does not apply to the mechanism.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkspaceReport<T> {
    /// Margins in the order of [`Check::ALL`]; one that does not apply is zero and its bit in `applies` clear.
    /// (Not `[Option<T>; 6]`: its tags make an odd-sized copy, a byte-wise `memcpy` call on the M4F every pose.)
    margins: [T; 6],
    applies: u8,
    /// The raw singularity index behind [`Check::Singularity`] (before the threshold is subtracted).
    pub singularity_index: T,
}

impl<T: Real> WorkspaceReport<T> {
    /// A report from margins in the order of [`Check::ALL`].
    pub fn new(margins: [Option<T>; 6], singularity_index: T) -> Self {
        let mut applies = 0;
        for (i, m) in margins.iter().enumerate() {
            if m.is_some() {
                applies |= 1 << i;
            }
        }
        Self {
            margins: margins.map(|m| m.unwrap_or(T::zero())),
            applies,
            singularity_index,
        }
    }

    /// Margin of one check (`None` when it does not apply). NaN never passes.
    pub fn margin(&self, check: Check) -> Option<T> {
        let i = check.index();
        (self.applies & (1 << i) != 0).then(|| self.margins[i])
    }

    /// Whether one check passes (a check that does not apply passes).
    pub fn passes(&self, check: Check) -> bool {
        self.margin(check).is_none_or(|m| m >= T::zero())
    }

    /// Whether every check passes.
    pub fn all_pass(&self) -> bool {
        Check::ALL.iter().all(|c| self.passes(*c))
    }

    /// The first failing check in the order of [`Check::ALL`].
    pub fn first_failure(&self) -> Option<Check> {
        Check::ALL.into_iter().find(|c| !self.passes(*c))
    }

    /// The first check, in the order of [`Check::ALL`], whose margin is below its entry of `room` (a check that
    /// does not apply passes; NaN never passes).
    pub fn first_below(&self, room: &[T; 6]) -> Option<Check> {
        Check::ALL
            .into_iter()
            .find(|c| self.margin(*c).is_some_and(|m| short_of(m, room[c.index()])))
    }

    /// The check with the smallest margin among those in the same unit is not meaningful across units, so this
    /// returns each check with its margin, for display.
    pub fn iter(&self) -> impl Iterator<Item = (Check, Option<T>)> + '_ {
        Check::ALL.into_iter().map(|c| (c, self.margin(c)))
    }
}

/// Whether a margin is below the room it must leave: anything but at least `room`, so NaN is short.
#[inline]
// The negated comparison is the point (NaN is short); through `partial_cmp` and a match the M4F's envelope search
// took 170 instructions more (measured under QEMU).
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub(crate) fn short_of<T: Real>(margin: T, room: T) -> bool {
    !(margin >= room)
}

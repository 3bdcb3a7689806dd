//! Geometry definitions of the mechanisms, validated when they are built.
//!
//! Geometries are data (`f64`, SI units) with `const fn` constructors that return a [`GeometryError`] for a
//! mechanism that cannot be built. The built-in presets are evaluated in `const` context through
//! [`unwrap_geometry`], so a bad preset is a compile error, not a runtime surprise.

use core::fmt;

/// Why a geometry cannot be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum GeometryError {
    /// A dimension is NaN or infinite.
    NonFinite,
    /// A length that must be positive (ring radius, rod, link, frame side) is zero or negative.
    NonPositiveLength,
    /// Two joints that must be distinct coincide (platform points, base pivots).
    CoincidentPoints,
    /// A ring platform needs three to six chains whose actuators add up to exactly six.
    ChainCount,
    /// A limit interval is empty or out of its physical range (stroke, spacing, cone, singularity index).
    BadLimits,
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NonFinite => "a dimension is NaN or infinite",
            Self::NonPositiveLength => "a length that must be positive is not",
            Self::CoincidentPoints => "two joints that must be distinct coincide",
            Self::ChainCount => "a ring platform needs 3..=6 chains with exactly six actuators in all",
            Self::BadLimits => "a limit interval is empty or out of range",
        })
    }
}

/// Unwraps a geometry in `const` context: a preset that fails validation fails the build.
#[track_caller]
pub const fn unwrap_geometry<G: Copy>(g: Result<G, GeometryError>) -> G {
    match g {
        Ok(g) => g,
        // Only reachable in const evaluation of a preset, where it is a compile error.
        #[allow(clippy::panic)]
        Err(_) => panic!("invalid built-in geometry"),
    }
}

/// Which of the two solutions `q = theta +- phi` a rod chain takes (KINEMATICS.md 2.1, 2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Branch {
    /// `q = theta + phi`.
    Plus,
    /// `q = theta - phi`.
    Minus,
}

/// Which of the two assemblies of its arm an elbow chain takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum ElbowBranch {
    /// The elbow on the higher side of the shoulder-to-joint line (while the joint is nearer the ring axis than the
    /// shoulder): `s = psi + phi` in the arm's plane, counter-clockwise from the shoulder-to-joint direction `psi`
    /// seen with `u` (toward the ring axis) to the right and `z` up.
    Up,
    /// The elbow on the lower side: `s = psi - phi`.
    Down,
}

/// The arm of an elbow chain (chapter 5.1, fig. 5.2): on the carriage, a shoulder revolute whose axis is tangent to
/// the ring, an upper arm, an elbow revolute parallel to it, a forearm to the platform's spherical joint. The arm
/// moves in the carriage's vertical radial plane; its drive is the shoulder (a rotary motor).
///
/// The shoulder angle `s` (rad) is measured in that plane from `u`, the horizontal unit vector from the shoulder
/// toward the ring axis, toward `z` (up): the upper arm points along `cos(s) u + sin(s) z`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Elbow {
    /// Distance of the shoulder axis from the ring axis, on the carriage's radius (m).
    pub shoulder_radius: f64,
    /// Height of the shoulder axis above the ring plane (m).
    pub shoulder_height: f64,
    /// Shoulder axis to elbow axis (m).
    pub upper_arm: f64,
    /// Elbow axis to the platform joint's centre (m).
    pub forearm: f64,
    /// Which assembly the arm takes.
    pub branch: ElbowBranch,
    /// The shoulder's travel `[min, max]` (rad), at most one turn: the reach check keeps `s` inside, and IK gives
    /// `s` within half a turn of its middle.
    pub shoulder_angle: [f64; 2],
    /// Allowed interior angle at the elbow between upper arm and forearm `[min, max]` (rad, within `[0, pi]`):
    /// 0 is folded, `pi` stretched (both singular).
    pub elbow_angle: [f64; 2],
}

impl Elbow {
    /// Checks the arm's dimensions and limits.
    pub const fn validate(&self) -> Result<(), GeometryError> {
        let e = self;
        let finite = e.shoulder_radius.is_finite()
            && e.shoulder_height.is_finite()
            && e.upper_arm.is_finite()
            && e.forearm.is_finite()
            && e.shoulder_angle[0].is_finite()
            && e.shoulder_angle[1].is_finite()
            && e.elbow_angle[0].is_finite()
            && e.elbow_angle[1].is_finite();
        if !finite {
            return Err(GeometryError::NonFinite);
        }
        if e.shoulder_radius <= 0.0 || e.upper_arm <= 0.0 || e.forearm <= 0.0 {
            return Err(GeometryError::NonPositiveLength);
        }
        let [s0, s1] = e.shoulder_angle;
        let [e0, e1] = e.elbow_angle;
        // Written as "all in range" so that NaN, which compares false, fails.
        let ok =
            s0 < s1 && s1 - s0 <= 2.0 * core::f64::consts::PI && e0 >= 0.0 && e0 < e1 && e1 <= core::f64::consts::PI;
        if !ok {
            return Err(GeometryError::BadLimits);
        }
        Ok(())
    }
}

/// The kind of a chain from a ring carriage to the platform.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum ChainKind {
    /// Carriage -> spherical joint -> rod of fixed length -> spherical joint. One actuator: the carriage angle.
    Rod(Branch),
    /// Carriage -> revolute joint tangent to the ring -> linear actuator -> spherical joint; the actuator stays in
    /// the vertical plane through the ring centre. Two actuators: the carriage angle and the length.
    Radial,
    /// Carriage -> shoulder revolute tangent to the ring (driven) -> upper arm -> elbow revolute -> forearm ->
    /// spherical joint; the arm stays in the vertical plane through the ring centre. Two actuators: the carriage
    /// angle and the shoulder angle.
    Elbow(Elbow),
}

impl ChainKind {
    /// Whether the chain's platform joint stays in its carriage's vertical radial plane (radial and elbow chains):
    /// a second actuator, a planarity constraint and a second transmitted wrench (through the joint, tangent to the
    /// ring).
    pub const fn is_planar(&self) -> bool {
        matches!(self, Self::Radial | Self::Elbow(_))
    }
}

/// One chain: its kind and its platform joint in platform coordinates (m).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Chain {
    /// Rod, radial or elbow chain.
    pub kind: ChainKind,
    /// Platform joint `a_i` in the platform frame (m).
    pub platform_point: [f64; 3],
}

/// Limits that the workspace checks of KINEMATICS.md 4 enforce.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RingLimits {
    /// Linear-actuator length range `[s_min, s_max]` (m).
    pub stroke: [f64; 2],
    /// Allowed central angle between neighbouring carriages `[min, max]` (rad); source: 12 and 120 degrees.
    pub carriage_spacing: [f64; 2],
    /// Minimum angle between a chain and the base plane, `90deg - acos(u . z)` (rad); source: 11 degrees.
    pub base_cone: f64,
    /// Minimum angle between a chain and the platform plane, `90deg - acos(u . n)` (rad); source: 22 degrees.
    pub platform_cone: f64,
    /// Minimum scale-free singularity index of the wrench matrix (0 = singular, 1 = orthogonal lines).
    pub min_singularity_index: f64,
    /// Centre of mass of the platform and payload, in platform coordinates (m).
    pub centre_of_mass: [f64; 3],
}

/// The source's joint limits: 12..120 degree spacing, 11 degree base cone, 22 degree platform cone.
pub const SOURCE_SPACING: [f64; 2] = [12.0 * DEG, 120.0 * DEG];
/// One degree in radians.
pub const DEG: f64 = core::f64::consts::PI / 180.0;

/// A mechanism whose carriages run on a circular guide (KINEMATICS.md 2.1 and 2.2).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RingGeometry {
    /// Preset name, for reports.
    pub name: &'static str,
    /// Ring radius `Rr` (m).
    pub ring_radius: f64,
    /// Rod length `L` of the rod chains (m).
    pub rod_length: f64,
    chains: [Chain; 6],
    chain_count: usize,
    /// Workspace limits.
    pub limits: RingLimits,
}

const fn finite3(p: [f64; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}

const fn distinct(a: [f64; 3], b: [f64; 3]) -> bool {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz > 1e-18
}

/// `lo <= v < hi`, false for NaN.
const fn in_range(v: f64, lo: f64, hi: f64) -> bool {
    v >= lo && v < hi
}

const fn valid_interval(lo: f64, hi: f64) -> bool {
    lo.is_finite() && hi.is_finite() && lo >= 0.0 && lo < hi
}

impl RingGeometry {
    /// Builds and validates a ring geometry.
    ///
    /// Actuators are numbered as in KINEMATICS.md: first the carriage angle of every chain in chain order, then
    /// the length of every radial chain in chain order, then the shoulder angle of every elbow chain in chain order;
    /// there must be exactly six. Chains are listed counter-
    /// clockwise around the ring, which is the order the spacing and crossing checks assume.
    pub const fn new(
        name: &'static str,
        ring_radius: f64,
        rod_length: f64,
        chains: &[Chain],
        limits: RingLimits,
    ) -> Result<Self, GeometryError> {
        if !ring_radius.is_finite() || !rod_length.is_finite() {
            return Err(GeometryError::NonFinite);
        }
        if ring_radius <= 0.0 || rod_length <= 0.0 {
            return Err(GeometryError::NonPositiveLength);
        }
        let n = chains.len();
        if n < 3 || n > 6 {
            return Err(GeometryError::ChainCount);
        }
        let mut stored = [Chain {
            kind: ChainKind::Radial,
            platform_point: [0.0; 3],
        }; 6];
        let mut actuators = n;
        let mut i = 0;
        while i < n {
            let c = chains[i];
            if !finite3(c.platform_point) {
                return Err(GeometryError::NonFinite);
            }
            match c.kind {
                ChainKind::Rod(_) => {}
                ChainKind::Radial => actuators += 1,
                ChainKind::Elbow(e) => {
                    if let Err(e) = e.validate() {
                        return Err(e);
                    }
                    actuators += 1;
                }
            }
            let mut j = 0;
            while j < i {
                if !distinct(chains[j].platform_point, c.platform_point) {
                    return Err(GeometryError::CoincidentPoints);
                }
                j += 1;
            }
            stored[i] = c;
            i += 1;
        }
        if actuators != 6 {
            return Err(GeometryError::ChainCount);
        }
        let l = limits;
        // Written as "all in range" so that NaN, which compares false, fails.
        let limits_ok = valid_interval(l.stroke[0], l.stroke[1])
            && valid_interval(l.carriage_spacing[0], l.carriage_spacing[1])
            && l.carriage_spacing[1] <= 2.0 * core::f64::consts::PI
            && in_range(l.base_cone, 0.0, core::f64::consts::FRAC_PI_2)
            && in_range(l.platform_cone, 0.0, core::f64::consts::FRAC_PI_2)
            && in_range(l.min_singularity_index, 0.0, 1.0);
        if !limits_ok {
            return Err(GeometryError::BadLimits);
        }
        if !finite3(l.centre_of_mass) {
            return Err(GeometryError::NonFinite);
        }
        Ok(Self {
            name,
            ring_radius,
            rod_length,
            chains: stored,
            chain_count: n,
            limits,
        })
    }

    /// The chains, in counter-clockwise order around the ring.
    pub fn chains(&self) -> &[Chain] {
        self.chains.get(..self.chain_count).unwrap_or(&[])
    }

    /// What each actuator drives, in actuator order: a carriage per chain, then a length per radial chain, then a
    /// shoulder angle per elbow chain, six in all in a valid geometry (what [`super::Mechanism::axes`] of its platform returns, without building
    /// the platform).
    pub fn axes(&self) -> [super::AxisKind; 6] {
        let chains = self.chains();
        let radial = chains.iter().filter(|c| c.kind == ChainKind::Radial).count();
        let mut axes = [super::AxisKind::Ring; 6];
        for (a, axis) in axes.iter_mut().enumerate().skip(chains.len()) {
            *axis = if a < chains.len() + radial {
                super::AxisKind::Linear
            } else {
                super::AxisKind::Angle
            };
        }
        axes
    }

    /// The arm of the elbow chain whose shoulder angle is actuator `axis` (0-based), if it is one.
    pub fn arm_of_axis(&self, axis: usize) -> Option<Elbow> {
        let chains = self.chains();
        let radial = chains.iter().filter(|c| c.kind == ChainKind::Radial).count();
        let k = axis.checked_sub(chains.len() + radial)?;
        chains
            .iter()
            .filter_map(|c| match c.kind {
                ChainKind::Elbow(e) => Some(e),
                _ => None,
            })
            .nth(k)
    }
}

/// The five-DOF parallel-serial tool carrier of KINEMATICS.md 2.3 (all lengths in metres).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ToolGeometry {
    /// Preset name, for reports.
    pub name: &'static str,
    /// Tool offset below the frame centre `L1`.
    pub l1: f64,
    /// Link from the base pivot `L2`.
    pub l2: f64,
    /// Link to the frame pivot `L3`.
    pub l3: f64,
    /// Frame side along X, `a` (kept for drawings; the position problem does not use it).
    pub a: f64,
    /// Frame side along Y, `b`: distance between the frame pivots.
    pub b: f64,
    /// Base pivot `B` of the dyad on the +Y side.
    pub pivot_b: [f64; 3],
    /// Base pivot `D` of the dyad on the -Y side.
    pub pivot_d: [f64; 3],
    /// Assembly of the B-side dyad: `q2 = theta - kappa` (Minus) or `theta + kappa` (Plus).
    pub branch_b: Branch,
    /// Assembly of the D-side dyad, for `q4`.
    pub branch_d: Branch,
    /// The X carriage's travel `[min, max]` for `q1` (m): the reach check keeps `q1` inside.
    pub stroke: [f64; 2],
    /// Minimum scale-free singularity index (sine of the transmission angles).
    pub min_singularity_index: f64,
}

impl ToolGeometry {
    /// Builds and validates a tool-carrier geometry.
    #[allow(clippy::too_many_arguments)]
    pub const fn new(
        name: &'static str,
        l1: f64,
        l2: f64,
        l3: f64,
        a: f64,
        b: f64,
        pivot_b: [f64; 3],
        pivot_d: [f64; 3],
        branches: [Branch; 2],
        stroke: [f64; 2],
        min_singularity_index: f64,
    ) -> Result<Self, GeometryError> {
        let finite = l1.is_finite()
            && stroke[0].is_finite()
            && stroke[1].is_finite()
            && l2.is_finite()
            && l3.is_finite()
            && a.is_finite()
            && b.is_finite()
            && finite3(pivot_b)
            && finite3(pivot_d);
        if !finite {
            return Err(GeometryError::NonFinite);
        }
        if l1 < 0.0 || l2 <= 0.0 || l3 <= 0.0 || a <= 0.0 || b <= 0.0 {
            return Err(GeometryError::NonPositiveLength);
        }
        if !distinct(pivot_b, pivot_d) {
            return Err(GeometryError::CoincidentPoints);
        }
        if !in_range(min_singularity_index, 0.0, 1.0) || stroke[0] >= stroke[1] {
            return Err(GeometryError::BadLimits);
        }
        Ok(Self {
            name,
            l1,
            l2,
            l3,
            a,
            b,
            pivot_b,
            pivot_d,
            branch_b: branches[0],
            branch_d: branches[1],
            stroke,
            min_singularity_index,
        })
    }

    /// The same geometry with other dyad assemblies.
    pub const fn with_branches(mut self, b: Branch, d: Branch) -> Self {
        self.branch_b = b;
        self.branch_d = d;
        self
    }
}

impl core::error::Error for GeometryError {}

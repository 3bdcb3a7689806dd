//! Structural analysis of a mechanism (the dissertation's chapters 2 and 5.1): its mobility by the structural
//! formula, the unit screws of the joints of every chain, the wrenches each chain transmits to the platform, each
//! chain's workability determinant and the whole mechanism's wrench determinant.
//!
//! - Mobility (Somov-Malyshev, as chapter 2 uses it): `W = 6 n - 5 p5 - 4 p4 - 3 p3 - 2 p2 - p1`, `n` the moving
//!   links, `p_k` the pairs of class `k` (`6 - k` freedoms). A rod chain's platform joint is a spherical pair with a
//!   pin (class 4, two rotations): chapter 2 puts the pins there to take away the rods' idle spin about their own
//!   axes, which turns the trainer's `W = 8` into 6; [`Mobility::without_pins`] gives the count with plain spherical
//!   pairs.
//! - Unit screws: a revolute pair `[u; p x u]` about the base origin, a prismatic pair `[0; u]`, a spherical pair
//!   three revolutes along the base axes X, Y, Z through its centre, a pin-spherical pair two revolutes along the
//!   platform's axes X', Y' (the source's chain of fig. 5.1 takes X and Y through A: the platform is level there).
//! - A chain's workability determinant: the determinant of the 6x6 matrix whose rows are its joints' unit screws
//!   (chains of six joints). Zero means the joints' screws are dependent: a type 1 singularity (the chain loses a
//!   freedom). The source writes a prismatic pair's screw with the member's vector `B -> A` instead of its unit
//!   direction (fig. 5.3: `E3 = (0, 0, 0, -0.5, 0, 1)`); [`ChainAnalysis::determinant_source`] does the same, so it
//!   is the unit determinant times the member's length.
//! - Transmitted wrenches: the wrenches reciprocal to every unactuated joint of the chain. First the chain's
//!   constraint wrenches (reciprocal to all its joints), then one actuation wrench per actuated joint: reciprocal to
//!   all the chain's other joints and Euclid-orthogonal to its constraints (paper 003's choice). Each is unit (its
//!   force part, or its moment part for a couple) and oriented from the chain's base towards its platform joint
//!   (positive along `B -> A`); one across that line takes the sense that does negative work on the chain's first
//!   joint, as the source's tangent forces of the radial chains do. With these senses and the chains in order,
//!   the trainer's wrench determinant has the source's sign.
//! - Whole mechanism: the 6x6 matrix of all chains' transmitted wrenches (rows), chain by chain; zero is a type 2
//!   singularity.

use nalgebra::{Matrix6, Vector3, Vector6};

use super::chains::{null_space, swap, Joint};
use super::reciprocal;

/// A kinematic pair, by the freedoms it allows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pair {
    /// One rotation (class 5).
    Revolute,
    /// One translation (class 5).
    Prismatic,
    /// A spherical pair with a pin: two rotations (class 4).
    PinSpherical,
    /// Three rotations (class 3).
    Spherical,
}

impl Pair {
    /// The freedoms the pair allows (its joint screws).
    pub const fn freedoms(self) -> usize {
        match self {
            Pair::Revolute | Pair::Prismatic => 1,
            Pair::PinSpherical => 2,
            Pair::Spherical => 3,
        }
    }

    /// The pair's class: the freedoms it takes away, `6 - freedoms`.
    pub const fn class(self) -> usize {
        6 - self.freedoms()
    }
}

/// Why a chain cannot be built or analysed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StructureError {
    /// More than [`MAX_JOINTS`] joint screws in one chain.
    TooManyJoints,
    /// A point, direction or length is not finite, or a direction is zero.
    NotFinite,
    /// The decomposition did not converge.
    NoDecomposition,
}

/// Most joint screws in one chain (a serial chain with more could not transmit a wrench).
pub const MAX_JOINTS: usize = 6;

/// One serial chain from the base to the platform: its pairs in order, expanded into joint screws (unit twists
/// about the base origin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chain {
    joints: [Joint; MAX_JOINTS],
    /// The factor the source writes each joint's screw with (a prismatic member's length; 1 otherwise).
    scales: [f64; MAX_JOINTS],
    /// The pair each joint belongs to (index into `pairs`).
    owners: [usize; MAX_JOINTS],
    pairs: [Pair; MAX_JOINTS],
    joint_count: usize,
    pair_count: usize,
    base: Vector3<f64>,
    platform: Vector3<f64>,
}

fn unit(u: &Vector3<f64>) -> Result<Vector3<f64>, StructureError> {
    let n = u.norm();
    if !n.is_finite() || n <= 0.0 {
        return Err(StructureError::NotFinite);
    }
    Ok(u / n)
}

fn finite(v: &Vector3<f64>) -> Result<Vector3<f64>, StructureError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(*v)
    } else {
        Err(StructureError::NotFinite)
    }
}

/// The unit twist of a revolute pair along `u` through `at`.
fn revolute_twist(u: &Vector3<f64>, at: &Vector3<f64>) -> Vector6<f64> {
    let m = at.cross(u);
    Vector6::new(u.x, u.y, u.z, m.x, m.y, m.z)
}

impl Chain {
    /// An empty chain whose base joint is at `base` (the carriage's joint `B`) and whose platform joint is at
    /// `platform` (`A`): the two points orient the transmitted wrenches.
    pub fn new(base: Vector3<f64>, platform: Vector3<f64>) -> Result<Self, StructureError> {
        Ok(Self {
            joints: [Joint {
                twist: Vector6::zeros(),
                actuated: false,
            }; MAX_JOINTS],
            scales: [1.0; MAX_JOINTS],
            owners: [0; MAX_JOINTS],
            pairs: [Pair::Revolute; MAX_JOINTS],
            joint_count: 0,
            pair_count: 0,
            base: finite(&base)?,
            platform: finite(&platform)?,
        })
    }

    /// Appends a pair given by its joint screws (unit twists about the base origin).
    pub fn pair(
        mut self,
        pair: Pair,
        twists: &[Vector6<f64>],
        actuated: bool,
        scale: f64,
    ) -> Result<Self, StructureError> {
        if twists.iter().flat_map(|t| t.iter()).any(|c| !c.is_finite()) || !scale.is_finite() {
            return Err(StructureError::NotFinite);
        }
        if self.joint_count + twists.len() > MAX_JOINTS || self.pair_count >= MAX_JOINTS {
            return Err(StructureError::TooManyJoints);
        }
        for t in twists {
            let k = self.joint_count;
            self.joints[k] = Joint { twist: *t, actuated };
            self.scales[k] = scale;
            self.owners[k] = self.pair_count;
            self.joint_count += 1;
        }
        self.pairs[self.pair_count] = pair;
        self.pair_count += 1;
        Ok(self)
    }

    /// Appends a revolute pair along `u` through `at`.
    pub fn revolute(self, u: Vector3<f64>, at: Vector3<f64>, actuated: bool) -> Result<Self, StructureError> {
        let twist = revolute_twist(&unit(&u)?, &finite(&at)?);
        self.pair(Pair::Revolute, &[twist], actuated, 1.0)
    }

    /// Appends a prismatic pair along `u`; `length` is the member's length the source writes its screw with.
    pub fn prismatic(self, u: Vector3<f64>, length: f64, actuated: bool) -> Result<Self, StructureError> {
        let u = unit(&u)?;
        self.pair(
            Pair::Prismatic,
            &[Vector6::new(0.0, 0.0, 0.0, u.x, u.y, u.z)],
            actuated,
            length,
        )
    }

    /// Appends an unactuated spherical pair centred at `at`: revolutes along the base axes X, Y, Z.
    pub fn spherical(self, at: Vector3<f64>) -> Result<Self, StructureError> {
        let at = finite(&at)?;
        let twists = [Vector3::x(), Vector3::y(), Vector3::z()].map(|u| revolute_twist(&u, &at));
        self.pair(Pair::Spherical, &twists, false, 1.0)
    }

    /// Appends an unactuated spherical pair with a pin centred at `at`: revolutes along the two `axes`.
    pub fn pin_spherical(self, at: Vector3<f64>, axes: [Vector3<f64>; 2]) -> Result<Self, StructureError> {
        let at = finite(&at)?;
        let twists = [
            revolute_twist(&unit(&axes[0])?, &at),
            revolute_twist(&unit(&axes[1])?, &at),
        ];
        self.pair(Pair::PinSpherical, &twists, false, 1.0)
    }

    /// The joint screws in order.
    pub fn joints(&self) -> &[Joint] {
        &self.joints[..self.joint_count]
    }

    /// The pairs in order.
    pub fn pairs(&self) -> &[Pair] {
        &self.pairs[..self.pair_count]
    }

    /// The pair joint `i` belongs to (an index into [`Chain::pairs`]); `None` past the last joint.
    pub fn owner(&self, i: usize) -> Option<usize> {
        (i < self.joint_count).then(|| self.owners[i])
    }

    /// The chain's base joint `B` and platform joint `A`.
    pub fn ends(&self) -> (Vector3<f64>, Vector3<f64>) {
        (self.base, self.platform)
    }
}

/// A chain's transmitted wrenches and its workability determinant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainAnalysis {
    /// The wrenches reciprocal to every unactuated joint, `[force; moment about the origin]`, unit and oriented:
    /// the constraint wrenches first, then one per actuated joint in order. `count` of them are used.
    pub wrenches: [Vector6<f64>; 6],
    /// How many wrenches.
    pub count: usize,
    /// How many of them are constraint wrenches (reciprocal to every joint: the chain forbids these motions).
    pub constraints: usize,
    /// Each actuated joint has its own wrench (false at a singular chain: then the wrenches after the
    /// constraints are a basis of what the chain transmits, not one per drive).
    pub per_drive: bool,
    /// The determinant of the joints' unit screws (rows); `None` unless the chain has six joints.
    pub determinant: Option<f64>,
    /// The same with each prismatic pair's screw written with its member's vector, as the source does.
    pub determinant_source: Option<f64>,
}

/// Scales `w` to unit force (or unit moment for a couple) and orients it: positive along `along`; across it,
/// negative work on `first`.
fn oriented(w: &Vector6<f64>, along: &Vector3<f64>, first: Option<&Joint>) -> Vector6<f64> {
    let f = Vector3::new(w[0], w[1], w[2]);
    let m = Vector3::new(w[3], w[4], w[5]);
    let part = if f.norm() > 1e-9 * w.norm() { f } else { m };
    let n = part.norm();
    if n <= 0.0 || !n.is_finite() {
        return *w;
    }
    let (w, part) = (w / n, part / n);
    let d = along.norm();
    let component = if d > 0.0 { part.dot(along) / d } else { 0.0 };
    let flip = if component.abs() > 1e-9 {
        component < 0.0
    } else {
        first.is_some_and(|j| reciprocal(&j.twist, &w) > 1e-12)
    };
    if flip {
        -w
    } else {
        w
    }
}

fn determinant(rows: &[Vector6<f64>], scales: &[f64]) -> Option<f64> {
    (rows.len() == 6).then(|| Matrix6::from_fn(|r, c| rows[r][c] * scales[r]).determinant())
}

/// Analyses one chain.
pub fn analyse(chain: &Chain) -> Result<ChainAnalysis, StructureError> {
    let joints = chain.joints();
    let n = joints.len();
    let rows: [Vector6<f64>; MAX_JOINTS] =
        core::array::from_fn(|i| joints.get(i).map_or(Vector6::zeros(), |j| swap(&j.twist)));
    let (constraints, k) = null_space(&rows[..n]).ok_or(StructureError::NoDecomposition)?;
    let mut out = ChainAnalysis {
        wrenches: [Vector6::zeros(); 6],
        count: 0,
        constraints: k,
        per_drive: true,
        determinant: None,
        determinant_source: None,
    };
    let (b, a) = chain.ends();
    let along = a - b;
    let first = joints.first();
    for (slot, w) in out.wrenches.iter_mut().zip(&constraints[..k]) {
        *slot = oriented(w, &along, first);
    }
    out.count = k;
    // One wrench per actuated joint: reciprocal to the chain's other joints, orthogonal to its constraints.
    let mut per_drive = [Vector6::zeros(); 6];
    let mut drives = 0;
    for (j, _) in joints.iter().enumerate().filter(|(_, j)| j.actuated) {
        let mut others = [Vector6::zeros(); 6];
        let mut m = 0;
        for r in rows[..n]
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != j)
            .map(|(_, r)| r)
            .chain(&constraints[..k])
        {
            *others.get_mut(m).ok_or(StructureError::TooManyJoints)? = *r;
            m += 1;
        }
        let (w, found) = null_space(&others[..m]).ok_or(StructureError::NoDecomposition)?;
        if found != 1 {
            out.per_drive = false;
            break;
        }
        per_drive[drives] = w[0];
        drives += 1;
    }
    if !out.per_drive {
        // A singular chain: a basis of the wrenches reciprocal to its unactuated joints, beyond its constraints.
        let mut free = [Vector6::zeros(); 6];
        let mut m = 0;
        for (r, _) in rows[..n].iter().zip(joints).filter(|(_, j)| !j.actuated) {
            free[m] = *r;
            m += 1;
        }
        for c in &constraints[..k] {
            *free.get_mut(m).ok_or(StructureError::TooManyJoints)? = *c;
            m += 1;
        }
        let (basis, found) = null_space(&free[..m]).ok_or(StructureError::NoDecomposition)?;
        per_drive = basis;
        drives = found;
    }
    for w in &per_drive[..drives] {
        *out.wrenches.get_mut(out.count).ok_or(StructureError::TooManyJoints)? = oriented(w, &along, first);
        out.count += 1;
    }
    let twists: [Vector6<f64>; MAX_JOINTS] =
        core::array::from_fn(|i| joints.get(i).map_or(Vector6::zeros(), |j| j.twist));
    out.determinant = determinant(&twists[..n], &[1.0; 6]);
    out.determinant_source = determinant(&twists[..n], &chain.scales);
    Ok(out)
}

/// The structural formula's count for a mechanism of chains in parallel between the base and the platform.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mobility {
    /// Moving links `n`: the platform and every chain's intermediate links.
    pub moving_links: usize,
    /// Pairs by class: `pairs[k - 1]` is `p_k`, for classes 1 to 5.
    pub pairs: [usize; 5],
    /// `W = 6 n - 5 p5 - 4 p4 - 3 p3 - 2 p2 - p1`.
    pub w: i64,
}

impl Mobility {
    /// The count of `chains` as they are.
    pub fn of(chains: &[Chain]) -> Self {
        Self::count(chains, false)
    }

    /// The count with every pin-spherical pair a plain spherical one (chapter 2's first count: the rods spin).
    pub fn without_pins(chains: &[Chain]) -> Self {
        Self::count(chains, true)
    }

    fn count(chains: &[Chain], plain: bool) -> Self {
        let mut pairs = [0usize; 5];
        let mut moving_links = 1;
        for chain in chains {
            moving_links += chain.pairs().len().saturating_sub(1);
            for p in chain.pairs() {
                let p = if plain && *p == Pair::PinSpherical {
                    Pair::Spherical
                } else {
                    *p
                };
                if let Some(slot) = pairs.get_mut(p.class() - 1) {
                    *slot += 1;
                }
            }
        }
        let constrained: usize = pairs.iter().enumerate().map(|(i, p)| (i + 1) * p).sum();
        Self {
            moving_links,
            pairs,
            w: 6 * moving_links as i64 - constrained as i64,
        }
    }
}

/// The whole mechanism's wrench determinant: the transmitted wrenches of all chains in order as rows; `None`
/// unless they are six.
pub fn wrench_determinant(analyses: &[ChainAnalysis]) -> Option<f64> {
    let mut rows = [Vector6::zeros(); 6];
    let mut n = 0;
    for w in analyses.iter().flat_map(|a| &a.wrenches[..a.count]) {
        *rows.get_mut(n)? = *w;
        n += 1;
    }
    determinant(&rows[..n], &[1.0; 6])
}

//! Paper 003's method for a whole mechanism (SCREWS.md 2b): chains of joint twists, some actuated, and the wrench
//! the chains exert on the platform. Each chain's constraint wrenches are found from its twists, each actuated
//! joint's actuation wrench (no work on the chain's other joints, Euclid-orthogonal to its constraints, unit work
//! on its own joint), and [`super::reactions::reactions`] solves and projects.
//!
//! A chain may hold several actuated joints (each gets its own actuation wrench: the other actuated joints count
//! as locked). The mechanism must be statically determinate: its actuation and constraint wrenches together are
//! six; a redundantly constrained one is refused (`None`), since its reactions depend on compliance.

use nalgebra::{Matrix6, Vector6};

use super::reactions::heapless_rows::Rows;
use super::reactions::{reactions, Reactions};
use super::reciprocal;

/// One joint of a chain: its unit twist about the common origin, and whether a drive moves it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joint {
    /// `[direction; moment]` about the origin: a revolute `[u; p x u]`, a prismatic `[0; u]`.
    pub twist: Vector6<f64>,
    /// A drive moves (and holds) this joint.
    pub actuated: bool,
}

/// Most joints in one chain.
pub const MAX_JOINTS: usize = 6;

/// The reactions of a mechanism and the wrench each chain carries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainReactions {
    /// Actuator reactions in the order the actuated joints appear, chain by chain (torque or force of the drive).
    pub actuators: [f64; 6],
    /// How many of `actuators` are used.
    pub actuated: usize,
    /// Each constraint's wrench times its reaction (the load it carries; the sign of a null-space basis is
    /// arbitrary, the product is not), chain by chain, `6 - actuated` of them.
    pub constraint_loads: [Vector6<f64>; 6],
    /// The same with the projection (paper 003): `W_C^+ P` times the constraint wrenches, bounded near
    /// actuation singularities.
    pub constraint_loads_projected: [Vector6<f64>; 6],
    /// The wrench each chain exerts on the platform (about the origin); they sum to the platform wrench.
    pub chain_wrenches: [Vector6<f64>; 6],
    /// The reactions as solved.
    pub solution: Reactions,
}

/// `[a; b] -> [b; a]`: a row whose Euclidean product with a wrench is the reciprocal product with the twist.
pub(crate) fn swap(t: &Vector6<f64>) -> Vector6<f64> {
    Vector6::new(t[3], t[4], t[5], t[0], t[1], t[2])
}

/// An orthonormal basis of the vectors orthogonal to every row (at most six rows), by SVD: the right singular
/// vectors whose singular values are below `1e-9` of the largest.
pub(crate) fn null_space(rows: &[Vector6<f64>]) -> Option<([Vector6<f64>; 6], usize)> {
    if rows.len() > 6 || !rows.iter().flat_map(|r| r.iter()).all(|v| v.is_finite()) {
        return None;
    }
    let mut basis = [Vector6::zeros(); 6];
    if rows.is_empty() {
        for (i, b) in basis.iter_mut().enumerate() {
            b[i] = 1.0;
        }
        return Some((basis, 6));
    }
    let m = Matrix6::from_fn(|r, c| rows.get(r).map_or(0.0, |row| row[c]));
    let svd = m.try_svd(false, true, f64::EPSILON, 500)?;
    let v_t = svd.v_t?;
    let largest = svd.singular_values.max();
    let mut n = 0;
    for (i, s) in svd.singular_values.iter().enumerate() {
        if *s <= 1e-9 * largest {
            basis[n] = v_t.row(i).transpose();
            n += 1;
        }
    }
    Some((basis, n))
}

/// Solves the mechanism of `chains` for the platform wrench `p` (the wrench the chains exert on the platform,
/// about the origin: minus the applied load). `None` when a chain has more than [`MAX_JOINTS`] joints, the
/// wrenches are not six, or the system is singular.
pub fn solve(chains: &[&[Joint]], p: &Vector6<f64>) -> Option<ChainReactions> {
    let mut actuation = [Vector6::zeros(); 6];
    let mut constraints = [Vector6::zeros(); 6];
    // Which chain each wrench belongs to.
    let (mut owner_a, mut owner_c) = ([0usize; 6], [0usize; 6]);
    let (mut n, mut k) = (0, 0);
    for (c, chain) in chains.iter().enumerate() {
        if chain.len() > MAX_JOINTS {
            return None;
        }
        let rows: Rows = chain.iter().map(|j| swap(&j.twist)).collect();
        let (basis, dim) = null_space(rows.as_slice())?;
        for w in &basis[..dim] {
            *constraints.get_mut(k)? = *w;
            owner_c[k] = c;
            k += 1;
        }
        for (j, joint) in chain.iter().enumerate().filter(|(_, j)| j.actuated) {
            let mut rows = Rows::default();
            for (i, other) in chain.iter().enumerate() {
                if i != j {
                    rows.push(swap(&other.twist))?;
                }
            }
            for w in &basis[..dim] {
                rows.push(*w)?;
            }
            let (w, found) = null_space(rows.as_slice())?;
            if found != 1 {
                return None;
            }
            let work = reciprocal(&joint.twist, &w[0]);
            if work.abs() <= 1e-12 {
                return None;
            }
            *actuation.get_mut(n)? = w[0] / work;
            owner_a[n] = c;
            n += 1;
        }
    }
    if n + k != 6 || k == 0 {
        return None;
    }
    let solution = reactions(&actuation[..n], &constraints[..k], p)?;
    let mut out = ChainReactions {
        actuators: solution.actuators,
        actuated: n,
        constraint_loads: [Vector6::zeros(); 6],
        constraint_loads_projected: [Vector6::zeros(); 6],
        chain_wrenches: [Vector6::zeros(); 6],
        solution,
    };
    for i in 0..n {
        out.chain_wrenches[owner_a[i]] += actuation[i] * solution.actuators[i];
    }
    for i in 0..k {
        out.constraint_loads[i] = constraints[i] * solution.constraints[i];
        out.constraint_loads_projected[i] = constraints[i] * solution.constraints_projected[i];
        out.chain_wrenches[owner_c[i]] += out.constraint_loads[i];
    }
    Some(out)
}

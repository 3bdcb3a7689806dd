//! Paper 002's equation of motion for a [`Mechanism`]: the kinetic energy `1/2 sum tr(C_i J_i C_i^T) q_s'^2` (eq. 7)
//! with each link's pseudo-inertia `J_i = integral of r r^T dm`, the potential energy of springs in pairs and of
//! gravity `-sum G A_0i J_i e`, viscous friction and external forces in pairs.
//!
//! With several drives `u` (the generalised coordinates), `C_i^a = W_i(q' = dq/du_a) A_0i` and the mass matrix is
//! `M_ab = sum tr(C_i^a J_i C_i^bT)` (the paper's one-drive sum, extended). Lagrange's equation for `u_a` is, with
//! `d/dt dT/du_a' - dT/du_a = sum tr(C_i^a J_i A_0i''^T)`, the generalised force the drive must give:
//! `tau_a = sum tr(C_i^a J_i A_0i''^T) - sum G C_i^a J_i e + sum_j (c_j (q_j - q_j0) + d_j q_j' - f_j) dq_j/du_a`.
//! Inverse dynamics evaluates it; forward dynamics solves `M u'' = tau - tau(u'' = 0)` and integrates by RK4.

use nalgebra::{Matrix4, Vector3, Vector4};

use super::mechanism::{Frames, Mechanism, MAX_DRIVES, MAX_VARIABLES};
use super::LoopError;

/// Bodies, springs, dampers and external forces a model may have.
pub const MAX_ELEMENTS: usize = 24;

/// A link's mass: its pseudo-inertia about the link's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// The link (1 + the pair that moves it).
    pub link: usize,
    /// `J = [[m, m c^T], [m c, S]]`, `S = integral of r r^T dm` (see [`pseudo_inertia`]).
    pub inertia: Matrix4<f64>,
}

/// A spring, a viscous damper and a constant external force acting in one pair variable.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Element {
    /// The variable.
    pub variable: usize,
    /// Spring stiffness `c` (N/m or N m/rad).
    pub stiffness: f64,
    /// The variable's value where the spring is free.
    pub rest: f64,
    /// Viscous friction `d` (N s/m or N m s/rad): the force `-d q'`.
    pub damping: f64,
    /// External force (N or N m) doing work on the variable.
    pub force: f64,
}

/// A mechanism with its masses, its pair elements and gravity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Model {
    /// The kinematics.
    pub mechanism: Mechanism,
    bodies: [Option<Body>; MAX_ELEMENTS],
    elements: [Option<Element>; MAX_ELEMENTS],
    /// Gravity's acceleration in the base frame (m/s^2), the paper's `G` without its leading 0.
    pub gravity: Vector3<f64>,
}

/// The state of a motion in the drives, and the closed variables it was found at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// Every variable, closed.
    pub q: [f64; MAX_VARIABLES],
    /// Every variable's rate.
    pub qd: [f64; MAX_VARIABLES],
}

/// The pseudo-inertia of a body of mass `m`, centre of mass `c` and inertia tensor `i` about the centre (both in
/// the link's frame; `i` with the products as `-integral of x y dm`): `S = m c c^T + tr(i)/2 E - i`, which is the
/// paper's `S_xx = (-I_xx + I_yy + I_zz) / 2` about the centre.
pub fn pseudo_inertia(m: f64, c: &Vector3<f64>, i: &nalgebra::Matrix3<f64>) -> Matrix4<f64> {
    let s = c * c.transpose() * m + nalgebra::Matrix3::identity() * (i.trace() / 2.0) - i;
    let mut j = Matrix4::zeros();
    j[(0, 0)] = m;
    j.fixed_view_mut::<3, 1>(1, 0).copy_from(&(c * m));
    j.fixed_view_mut::<1, 3>(0, 1).copy_from(&(c * m).transpose());
    j.fixed_view_mut::<3, 3>(1, 1).copy_from(&s);
    j
}

/// The energies of a state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    /// Kinetic, `1/2 sum tr(W A J A^T W^T)` (J).
    pub kinetic: f64,
    /// Gravity's, `-sum G A_0i J_i e` (J).
    pub gravity: f64,
    /// The springs', `1/2 sum c (q - q0)^2` (J).
    pub springs: f64,
}

impl Model {
    /// A model of `mechanism` with `bodies` and pair `elements` under `gravity`; `Shape` past the capacities or for
    /// a link or variable that does not exist, `NonFinite` for a non-finite number.
    pub fn new(
        mechanism: Mechanism,
        bodies: &[Body],
        elements: &[Element],
        gravity: Vector3<f64>,
    ) -> Result<Self, LoopError> {
        if bodies.len() > MAX_ELEMENTS || elements.len() > MAX_ELEMENTS {
            return Err(LoopError::Shape);
        }
        let finite = bodies.iter().all(|b| b.inertia.iter().all(|v| v.is_finite()))
            && elements
                .iter()
                .all(|e| [e.stiffness, e.rest, e.damping, e.force].iter().all(|v| v.is_finite()))
            && gravity.iter().all(|v| v.is_finite());
        if !finite {
            return Err(LoopError::NonFinite);
        }
        let fits = bodies.iter().all(|b| b.link < mechanism.links())
            && elements.iter().all(|e| e.variable < mechanism.variables());
        if !fits {
            return Err(LoopError::Shape);
        }
        Ok(Model {
            mechanism,
            bodies: core::array::from_fn(|k| bodies.get(k).copied()),
            elements: core::array::from_fn(|k| elements.get(k).copied()),
            gravity,
        })
    }

    fn bodies(&self) -> impl Iterator<Item = &Body> {
        self.bodies.iter().flatten()
    }

    fn elements(&self) -> impl Iterator<Item = &Element> {
        self.elements.iter().flatten()
    }

    /// `dq/du_a` for each drive `a`: the variables' rates for a unit rate of that drive alone.
    pub fn sensitivities(&self, f: &Frames) -> Result<[[f64; MAX_VARIABLES]; MAX_DRIVES], LoopError> {
        let d = self.mechanism.drives().len();
        let mut out = [[0.0; MAX_VARIABLES]; MAX_DRIVES];
        for (a, column) in out.iter_mut().enumerate().take(d) {
            let unit: [f64; MAX_DRIVES] = core::array::from_fn(|k| if k == a { 1.0 } else { 0.0 });
            *column = self.mechanism.rates(f, &unit[..d])?;
        }
        Ok(out)
    }

    /// The mass matrix `M_ab = sum tr(C_i^a J_i C_i^bT)` over the drives (unused rows and columns zero).
    pub fn mass(&self, f: &Frames) -> Result<[[f64; MAX_DRIVES]; MAX_DRIVES], LoopError> {
        let s = self.sensitivities(f)?;
        let d = self.mechanism.drives().len();
        let mut m = [[0.0; MAX_DRIVES]; MAX_DRIVES];
        for body in self.bodies() {
            let frame = f.links[body.link];
            let c: [Matrix4<f64>; MAX_DRIVES] =
                core::array::from_fn(|a| self.mechanism.link_twist(f, &s[a], body.link) * frame);
            for a in 0..d {
                for b in 0..d {
                    m[a][b] += (c[a] * body.inertia * c[b].transpose()).trace();
                }
            }
        }
        Ok(m)
    }

    /// The drives' generalised forces along a motion (inverse dynamics) at a closed state with the variables'
    /// accelerations `qdd`: what the drives must give for the motion, against inertia, gravity, springs, friction
    /// and the external forces.
    pub fn drive_forces(
        &self,
        f: &Frames,
        state: &State,
        qdd: &[f64; MAX_VARIABLES],
    ) -> Result<[f64; MAX_DRIVES], LoopError> {
        let s = self.sensitivities(f)?;
        let d = self.mechanism.drives().len();
        let mut tau = [0.0; MAX_DRIVES];
        let g = Vector4::new(0.0, self.gravity.x, self.gravity.y, self.gravity.z);
        let e = Vector4::new(1.0, 0.0, 0.0, 0.0);
        for body in self.bodies() {
            let frame = f.links[body.link];
            let w = self.mechanism.link_twist(f, &state.qd, body.link);
            let wd = self.mechanism.link_twist_rate(f, &state.qd, qdd, body.link);
            let acceleration = (wd + w * w) * frame;
            for (a, t) in tau.iter_mut().enumerate().take(d) {
                let c = self.mechanism.link_twist(f, &s[a], body.link) * frame;
                *t += (c * body.inertia * acceleration.transpose()).trace() - g.dot(&(c * body.inertia * e));
            }
        }
        for el in self.elements() {
            let v = el.variable;
            let pull = el.stiffness * (state.q[v] - el.rest) + el.damping * state.qd[v] - el.force;
            for (a, t) in tau.iter_mut().enumerate().take(d) {
                *t += pull * s[a][v];
            }
        }
        Ok(tau)
    }

    /// The energies at a closed state.
    pub fn energy(&self, f: &Frames, state: &State) -> Energy {
        let g = Vector4::new(0.0, self.gravity.x, self.gravity.y, self.gravity.z);
        let e = Vector4::new(1.0, 0.0, 0.0, 0.0);
        let mut out = Energy {
            kinetic: 0.0,
            gravity: 0.0,
            springs: 0.0,
        };
        for body in self.bodies() {
            let frame = f.links[body.link];
            let rate = self.mechanism.link_twist(f, &state.qd, body.link) * frame;
            out.kinetic += 0.5 * (rate * body.inertia * rate.transpose()).trace();
            out.gravity -= g.dot(&(frame * body.inertia * e));
        }
        for el in self.elements() {
            let x = state.q[el.variable] - el.rest;
            out.springs += 0.5 * el.stiffness * x * x;
        }
        out
    }

    /// The power of the friction and the external forces on the variables at a state (W; friction's is negative).
    pub fn element_power(&self, state: &State) -> f64 {
        self.elements()
            .map(|el| (el.force - el.damping * state.qd[el.variable]) * state.qd[el.variable])
            .sum()
    }
}

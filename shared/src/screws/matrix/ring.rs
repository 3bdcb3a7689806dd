//! A ring platform (the trainer, the rotopod) in paper 002's terms, sketched at a pose: every pair's frame placed
//! in the base at that pose (its origin, its +X and +Z directions), the constant link matrices read between them.
//!
//! - a rod chain: the carriage's revolute pair about the ring axis, a Hooke's joint at the carriage's ball (both
//!   axes across the rod) and a spherical pair at the platform joint;
//! - a radial chain: the carriage's revolute pair, a revolute pair about the ring's tangent at the carriage, the
//!   linear actuator's prismatic pair along the rod and a spherical pair at the platform joint.
//!
//! Each chain closes on the platform, whose frame is the pose's; the first chain carries it, every other chain is
//! one loop welded to it. The Hooke's joint is sketched at `(0, 0)` and the spherical pair at `(0, pi/2, 0)`, away
//! from the Euler angles' gimbal lock at `theta = 0`. The chains are massless; the platform carries the payload.

use nalgebra::{Matrix3, Matrix4, Matrix6, Vector3, Vector6};

use super::lagrange::{pseudo_inertia, Body, Model};
use super::mechanism::{Closure, Frames, Mechanism, Pair, GROUND, MAX_PAIRS, MAX_VARIABLES};
use super::pairs::{inverse, Joint};
use super::LoopError;
use crate::kinematics::{geometry::ChainKind, Mechanism as _, MotionState, Pose, RingGeometry, RingPlatform};
use crate::screws::twist_of;

/// Standard gravity (m/s^2), as the ring platform's statics use.
pub const GRAVITY: f64 = 9.80665;

/// A ring platform as a model, with the closed variables of the pose it was sketched at.
#[derive(Debug, Clone, Copy)]
pub struct RingModel {
    /// The model: drives in the platform's actuator order.
    pub model: Model,
    /// The variables at the sketched pose.
    pub q: [f64; MAX_VARIABLES],
    /// The platform's link.
    pub platform: usize,
    /// The platform's frame in its link's frame.
    pub platform_offset: Matrix4<f64>,
}

/// The frame `[[1, 0], [o, R]]`.
pub fn frame_of(origin: &Vector3<f64>, rotation: &Matrix3<f64>) -> Matrix4<f64> {
    let mut a = Matrix4::identity();
    a.fixed_view_mut::<3, 1>(1, 0).copy_from(origin);
    a.fixed_view_mut::<3, 3>(1, 1).copy_from(rotation);
    a
}

/// The rotation whose +Z is `z` and whose +X is `x` made perpendicular to it; `NonFinite` when they are parallel.
fn axes(x: &Vector3<f64>, z: &Vector3<f64>) -> Result<Matrix3<f64>, LoopError> {
    let ez = z.try_normalize(1e-12).ok_or(LoopError::NonFinite)?;
    let ex = (x - ez * x.dot(&ez)).try_normalize(1e-12).ok_or(LoopError::NonFinite)?;
    Ok(Matrix3::from_columns(&[ex, ez.cross(&ex), ez]))
}

/// A chain being sketched: its pairs' frames in the base, the frame of the last link, the variables at the sketch.
struct Sketch {
    pairs: [Pair; MAX_PAIRS],
    count: usize,
    q: [f64; MAX_VARIABLES],
    variables: usize,
    /// The base frame of each link at the sketch (index 0 the ground).
    links: [Matrix4<f64>; MAX_PAIRS + 1],
}

impl Sketch {
    /// Adds `joint` at the base frame `at`, hanging from `parent`, with its variables `values` at the sketch.
    fn add(&mut self, joint: Joint, parent: usize, at: Matrix4<f64>, values: &[f64]) -> Result<usize, LoopError> {
        if self.count >= MAX_PAIRS || self.variables + joint.variables() > MAX_VARIABLES {
            return Err(LoopError::Shape);
        }
        self.pairs[self.count] = Pair {
            joint,
            parent,
            place: inverse(&self.links[parent]) * at,
        };
        self.q[self.variables..self.variables + joint.variables()].copy_from_slice(values);
        self.variables += joint.variables();
        self.count += 1;
        self.links[self.count] = at * joint.transform(values);
        Ok(self.count)
    }
}

/// The model of `geometry` sketched at `pose` (which must be reachable), the platform carrying `mass` (kg) with
/// `inertia` about its centre of mass (the geometry's) in the platform frame. Elbow chains are not modelled
/// (`Shape`); an unreachable pose is `Singular`.
pub fn ring_model(
    geometry: &RingGeometry,
    pose: &Pose<f64>,
    mass: f64,
    inertia: &Matrix3<f64>,
) -> Result<RingModel, LoopError> {
    let platform = RingPlatform::<f64>::new(geometry);
    let actuators = platform.inverse(pose).map_err(|_| LoopError::Singular)?.0;
    let home = frame_of(&pose.position(), &pose.rotation());
    let joints = platform.joints(pose);
    let mut s = Sketch {
        pairs: [Pair {
            joint: Joint::Revolute,
            parent: GROUND,
            place: Matrix4::identity(),
        }; MAX_PAIRS],
        count: 0,
        q: [0.0; MAX_VARIABLES],
        variables: 0,
        links: [Matrix4::identity(); MAX_PAIRS + 1],
    };
    let (mut ends, mut carriage_vars, mut lengths) = ([0usize; 6], [0usize; 6], [0usize; 6]);
    let mut length_count = 0;
    let z = Vector3::z();
    for (i, chain) in geometry.chains().iter().enumerate() {
        let q = actuators[i];
        carriage_vars[i] = s.variables;
        let carriage = s.add(Joint::Revolute, GROUND, Matrix4::identity(), &[q])?;
        let radial = Vector3::new(libm::cos(q), libm::sin(q), 0.0);
        let ball = radial * geometry.ring_radius;
        let rod = joints[i] - ball;
        let last = match chain.kind {
            ChainKind::Rod(_) => {
                let across = rod.cross(&z).cross(&rod);
                s.add(
                    Joint::Hooke,
                    carriage,
                    frame_of(&ball, &axes(&rod, &across)?),
                    &[0.0, 0.0],
                )?
            }
            ChainKind::Radial => {
                let tangent = z.cross(&radial);
                let tilt = s.add(
                    Joint::Revolute,
                    carriage,
                    frame_of(&ball, &axes(&radial, &tangent)?),
                    &[0.0],
                )?;
                lengths[length_count] = s.variables;
                length_count += 1;
                let slide = frame_of(&ball, &axes(&tangent, &rod)?);
                s.add(Joint::Prismatic, tilt, slide, &[rod.norm()])?
            }
            ChainKind::Elbow(_) => return Err(LoopError::Shape),
        };
        let at = frame_of(&joints[i], &pose.rotation());
        ends[i] = s.add(Joint::Spherical, last, at, &[0.0, core::f64::consts::FRAC_PI_2, 0.0])?;
    }
    let n = geometry.chains().len();
    let offsets: [Matrix4<f64>; 6] = core::array::from_fn(|i| inverse(&s.links[ends[i]]) * home);
    let closures: [Closure; 6] = core::array::from_fn(|k| Closure {
        a: ends[0],
        b: ends[k.min(n - 1)],
        offset: offsets[0] * inverse(&offsets[k.min(n - 1)]),
    });
    let mut drives = [0usize; 6];
    drives[..n].copy_from_slice(&carriage_vars[..n]);
    drives[n..n + length_count].copy_from_slice(&lengths[..length_count]);
    let mechanism = Mechanism::new(&s.pairs[..s.count], &closures[1..n], &drives[..n + length_count])?;
    let com = Vector3::from(geometry.limits.centre_of_mass);
    let payload = pseudo_inertia(mass, &com, inertia);
    let body = Body {
        link: ends[0],
        inertia: offsets[0] * payload * offsets[0].transpose(),
    };
    let model = Model::new(mechanism, &[body], &[], Vector3::new(0.0, 0.0, -GRAVITY))?;
    Ok(RingModel {
        model,
        q: s.q,
        platform: ends[0],
        platform_offset: offsets[0],
    })
}

impl RingModel {
    /// The drives' rates and accelerations that give the platform a motion's twist and its rate, at closed frames
    /// `f`: `K u' = xi`, `K u'' = xi' - (the platform twist's rate at u'' = 0)`, `K` the platform's twist per unit
    /// drive rate and `xi = [w; p' - w x p]` the twist about the base origin (the velocity of the platform point at
    /// the origin). `Singular` where the drives do not determine the platform.
    pub fn drive_motion(
        &self,
        f: &Frames,
        ring: &RingPlatform<f64>,
        s: &MotionState<f64>,
    ) -> Result<([f64; 6], [f64; 6]), LoopError> {
        let m = &self.model.mechanism;
        let sens = self.model.sensitivities(f)?;
        let k = Matrix6::from_fn(|r, c| twist_of(&m.link_twist(f, &sens[c], self.platform))[r]);
        let body = ring.body_motion(s);
        let p = s.pose.position();
        let pd = Vector3::new(s.rates[0], s.rates[1], s.rates[2]);
        let pdd = Vector3::new(s.accelerations[0], s.accelerations[1], s.accelerations[2]);
        let join = |a: Vector3<f64>, b: Vector3<f64>| Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z);
        let xi = join(body.omega, pd - body.omega.cross(&p));
        let xi_rate = join(body.omega_dot, pdd - body.omega_dot.cross(&p) - body.omega.cross(&pd));
        let lu = k.lu();
        let ud = lu.solve(&xi).ok_or(LoopError::Singular)?;
        let qd = m.rates(f, ud.as_slice())?;
        let qdd = m.accelerations(f, &qd, &[0.0; 6])?;
        let bias = twist_of(&m.link_twist_rate(f, &qd, &qdd, self.platform));
        let udd = lu.solve(&(xi_rate - bias)).ok_or(LoopError::Singular)?;
        Ok((core::array::from_fn(|i| ud[i]), core::array::from_fn(|i| udd[i])))
    }
}

//! Linear filters of the washout, discretised by the bilinear (Tustin) transform at each step's own interval.
//!
//! A section `H(s) = (b2 s^2 + b1 s + b0) / (s^2 + a1 s + a0)` runs as its state-space form (controllable
//! canonical) integrated by the trapezoidal rule, which is the bilinear transform exactly: a stable filter stays
//! stable at any interval, and nothing but `+ - * /` is needed, so every machine computes the same bits. The state
//! is kept as such and moved by its increment each sample; the direct-form difference equation (`y = 2 y1 - y2 +
//! ...` for a slow filter at a fast rate) would cancel most of its digits, which in `f32` at 1 kHz costs a tenth of
//! a degree of tilt. Each sample brings its own interval, so a jittery source is filtered exactly as sampled.

use crate::Real;

/// A second-order section in `s`: numerator `b2 s^2 + b1 s + b0` over `s^2 + a1 s + a0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section<T> {
    /// Numerator, `[b2, b1, b0]`.
    pub b: [T; 3],
    /// Denominator `[a1, a0]` (the `s^2` coefficient is 1).
    pub a: [T; 2],
}

impl<T: Real> Section<T> {
    /// `omega^2 / (s^2 + 2 zeta omega s + omega^2)`: second-order low-pass, unit gain at rest.
    pub fn low_pass(omega: T, zeta: T) -> Self {
        Self {
            b: [T::zero(), T::zero(), omega * omega],
            a: [T::of(2.0) * zeta * omega, omega * omega],
        }
    }

    /// `s^2 / (s^2 + 2 zeta omega s + omega^2)`: second-order high-pass.
    pub fn high_pass(omega: T, zeta: T) -> Self {
        Self {
            b: [T::one(), T::zero(), T::zero()],
            a: [T::of(2.0) * zeta * omega, omega * omega],
        }
    }

    /// `1 / (s^2 + 2 zeta omega s + omega^2)`: the second-order high-pass followed by a double integration, which
    /// turns an acceleration into a position in one section.
    pub fn high_pass_position(omega: T, zeta: T) -> Self {
        Self {
            b: [T::zero(), T::zero(), T::one()],
            a: [T::of(2.0) * zeta * omega, omega * omega],
        }
    }

    /// `s / (s^2 + 2 zeta omega s + omega^2)`: the second-order high-pass followed by one integration (a rate into
    /// an angle that returns to zero).
    pub fn high_pass_angle(omega: T, zeta: T) -> Self {
        Self {
            b: [T::zero(), T::one(), T::zero()],
            a: [T::of(2.0) * zeta * omega, omega * omega],
        }
    }

    /// `omega / (s + omega)`: first-order low-pass, unit gain at rest (run it with [`Biquad::first_order`]).
    pub fn first_order_low_pass(omega: T) -> Self {
        Self {
            b: [T::zero(), T::zero(), omega],
            a: [omega, T::zero()],
        }
    }

    /// `s / (s + omega)`: first-order high-pass (the third order of the translational washout). A first-order
    /// section: run it with [`Biquad::first_order`], which reads `b[1] s + b[2]` over `s + a[0]`.
    pub fn first_order_high_pass(omega: T) -> Self {
        Self {
            b: [T::zero(), T::one(), T::zero()],
            a: [omega, T::zero()],
        }
    }
}

/// A discretised section and its state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad<T> {
    section: Section<T>,
    /// First order (`b1 s + b0` over `s + a1`) rather than second.
    first_order: bool,
    /// State: position and velocity of the canonical form (first order: the first only).
    x: [T; 2],
    /// The last input.
    u: T,
}

impl<T: Real> Biquad<T> {
    /// A second-order filter at rest.
    pub fn new(section: Section<T>) -> Self {
        Self {
            section,
            first_order: false,
            x: [T::zero(); 2],
            u: T::zero(),
        }
    }

    /// A first-order filter at rest: `(b1 s + b0) / (s + a1)` from the section's `b[1]`, `b[2]` and `a[0]`.
    pub fn first_order(section: Section<T>) -> Self {
        Self {
            first_order: true,
            ..Self::new(section)
        }
    }

    /// One sample `u` at the end of an interval of `dt` seconds (positive); returns the output.
    pub fn step(&mut self, u: T, dt: T) -> T {
        let [b2, b1, b0] = self.section.b;
        let [a1, a0] = self.section.a;
        let half = dt * T::of(0.5);
        // The input over the interval, as the trapezoidal rule takes it.
        let mean = (self.u + u) * T::of(0.5);
        self.u = u;
        let [x1, x2] = self.x;
        if self.first_order {
            // x' = -a1 x + u, y = (b0 - b1 a1) x + b1 u.
            let dx = dt * (mean - a1 * x1) / (T::one() + a1 * half);
            self.x[0] = x1 + dx;
            return (b0 - b1 * a1) * self.x[0] + b1 * u;
        }
        // x1' = x2, x2' = -a0 x1 - a1 x2 + u, y = (b0 - b2 a0) x1 + (b1 - b2 a1) x2 + b2 u. Trapezoidal:
        // (I - A dt/2) dx = dt (A x + B mean), solved by Cramer's rule.
        let r1 = dt * x2;
        let r2 = dt * (mean - a0 * x1 - a1 * x2);
        let det = T::one() + a1 * half + a0 * half * half;
        let dx1 = (r1 * (T::one() + a1 * half) + r2 * half) / det;
        let dx2 = (r2 - a0 * half * r1) / det;
        self.x = [x1 + dx1, x2 + dx2];
        (b0 - b2 * a0) * self.x[0] + (b1 - b2 * a1) * self.x[1] + b2 * u
    }

    /// The section it runs.
    pub fn section(&self) -> &Section<T> {
        &self.section
    }

    /// The output for the state and the last input, and its rate of change for a steady input: `(y, dy/dt)`.
    pub fn output(&self) -> (T, T) {
        let [b2, b1, b0] = self.section.b;
        let [a1, a0] = self.section.a;
        let [x1, x2] = self.x;
        if self.first_order {
            let c = b0 - b1 * a1;
            return (c * x1 + b1 * self.u, c * (self.u - a1 * x1));
        }
        let (c1, c2) = (b0 - b2 * a0, b1 - b2 * a1);
        let dx2 = self.u - a0 * x1 - a1 * x2;
        (c1 * x1 + c2 * x2 + b2 * self.u, c1 * x2 + c2 * dx2)
    }

    /// Sets the state so that the output is `y` and (second order) changes at `dy` per second, with the last input
    /// kept; where the section cannot reach that output from its state (no state in its output), nothing changes.
    pub fn set_output(&mut self, y: T, dy: T) {
        let [b2, b1, b0] = self.section.b;
        let [a1, a0] = self.section.a;
        let u = self.u;
        if self.first_order {
            let c = b0 - b1 * a1;
            if c != T::zero() {
                self.x[0] = (y - b1 * u) / c;
            }
            return;
        }
        // y = c1 x1 + c2 x2 + b2 u, dy = c1 x2 + c2 (u - a0 x1 - a1 x2): two equations in x1, x2.
        let (c1, c2) = (b0 - b2 * a0, b1 - b2 * a1);
        let (r1, r2) = (y - b2 * u, dy - c2 * u);
        let (m11, m12, m21, m22) = (c1, c2, -c2 * a0, c1 - c2 * a1);
        let det = m11 * m22 - m12 * m21;
        if det != T::zero() && det.finite() {
            let x1 = (r1 * m22 - m12 * r2) / det;
            let x2 = (m11 * r2 - m21 * r1) / det;
            if x1.finite() && x2.finite() {
                self.x = [x1, x2];
            }
        }
    }

    /// Runs `section` from here on, its output and the output's rate carried over (bumpless transfer): a change
    /// of corner or damping does not make the output jump.
    pub fn retune(&mut self, section: Section<T>) {
        let (y, dy) = self.output();
        self.section = section;
        self.set_output(y, dy);
    }

    /// Holds `u` as the last input, the state at rest: the first sample of a stream, which has no interval
    /// before it, so that the next interval's input is taken from this sample rather than from zero.
    pub fn begin(&mut self, u: T) {
        self.x = [T::zero(); 2];
        self.u = u;
    }

    /// The steady state of a constant input `u` (a low-pass then outputs `u`).
    pub fn settle(&mut self, u: T) {
        self.u = u;
        let [a1, a0] = self.section.a;
        let x1 = if self.first_order { u / a1 } else { u / a0 };
        self.x = if x1.finite() { [x1, T::zero()] } else { [T::zero(); 2] };
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.x = [T::zero(); 2];
        self.u = T::zero();
    }
}

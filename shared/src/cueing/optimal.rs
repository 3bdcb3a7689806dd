//! The optimal (model-predictive) cueing's parameters: the horizon, the weights of its cost and the rig's
//! motion limits, as a cueing file's `[optimal]` table. The solver runs on the host (`ringpod cue`, `stream`);
//! the core holds what a file says and checks it, as it does the washout's.

/// Which cueing algorithm a file asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Algorithm {
    /// The classical washout (default).
    #[default]
    Classical,
    /// The optimal cueing: a quadratic programme over a horizon at each sample, on the rig's envelope.
    Optimal,
}

/// The optimal cueing's parameters. Per-axis keys are `[x, y, z]` (surge, sway, heave) or `[x, y]` (the pitch
/// that cues x, the roll that cues y), as the washout's; the tilt's angle and rate limits are the washout's
/// `tilt_limit_deg` and `tilt_rate_deg`, shared.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OptimalConfig {
    /// Steps of the horizon (default 8).
    pub horizon: u32,
    /// Length of one step (s; default 0.15): the horizon looks `horizon * step_s` ahead.
    pub step_s: f64,
    /// Weight of the perceived specific-force error, per axis (per (m/s^2)^2; default 1).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub force_weight: [f64; 3],
    /// Weight of the perceived roll and pitch rate error (per (rad/s)^2; default 10).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub rotation_weight: [f64; 2],
    /// Return to neutral: weight of the position offset, per axis (per m^2; default 10).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub position_weight: [f64; 3],
    /// Weight of the velocity, per axis (per (m/s)^2; default 1).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub velocity_weight: [f64; 3],
    /// Return to neutral: weight of the tilt, x (pitch) and y (roll) (per rad^2; default 0.1).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub tilt_weight: [f64; 2],
    /// Weight of the tilts' loss of vertical specific force, `g (1 - cos theta_x cos theta_y)`, in their own
    /// programmes (per (m/s^2)^2; default 0, unpriced): a tilt's perceived vertical error the per-axis linear
    /// programmes do not otherwise see.
    pub tilt_loss_weight: f64,
    /// Plan consistency: weight of each step's planned angle's departure from the last sample's plan, shifted on
    /// by the sample, in the x and y programmes (per rad^2; default 0, none): a plan that turns over from one
    /// sample to the next moves the tilt one way for a sample and back the next, a rotation the canals feel.
    pub plan_weight: f64,
    /// Effort: weight of the platform's acceleration, per axis (per (m/s^2)^2; default 0.001).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub acceleration_weight: [f64; 3],
    /// Effort: weight of the angular rate, x (pitch) and y (roll) (per (rad/s)^2; default 0.01).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub rate_weight: [f64; 2],
    /// The rig's velocity limit, per axis (m/s; default 0.5).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub max_velocity: [f64; 3],
    /// The rig's acceleration limit, per axis (m/s^2; default 5).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub max_acceleration: [f64; 3],
    /// The rig's angular rate limit, x (pitch) and y (roll) (deg/s; default 60).
    #[serde(deserialize_with = "super::axes::one_or_each")]
    pub max_rate_deg: [f64; 2],
    /// The share of each translation's range about home (from the workspace scan) the optimiser may use (default
    /// 0.5): the ranges are found one axis at a time, and a pose that uses several axes at once needs a margin.
    pub envelope_share: f64,
    /// The share of the roll and pitch ranges about home the optimiser may tilt in (default 0.5). Apart from the
    /// translations' share: on a small rig sustained force is mostly tilt, and the best cueing uses nearly all of
    /// the tilt range and little translation, a mix whose poses stay inside the coupled envelope.
    pub tilt_share: f64,
    /// The time a solve may take (ms; default 2, a 100 Hz sample's share): a longer one is counted as late. Counted
    /// only: the solver is bounded by [`OptimalConfig::iterations`], work and not a clock, so that the same drive
    /// gives the same motion on any machine under any load.
    pub budget_ms: f64,
    /// The solver's work per solve: interior-point iterations (default 60). A solve that has not converged within
    /// them falls back to its last plan, then to the classical washout.
    pub iterations: u32,
}

impl Default for OptimalConfig {
    fn default() -> Self {
        Self {
            horizon: 8,
            step_s: 0.15,
            force_weight: [1.0; 3],
            rotation_weight: [10.0; 2],
            position_weight: [10.0; 3],
            velocity_weight: [1.0; 3],
            tilt_weight: [0.1; 2],
            tilt_loss_weight: 0.0,
            plan_weight: 0.0,
            acceleration_weight: [0.001; 3],
            rate_weight: [0.01; 2],
            max_velocity: [0.5; 3],
            max_acceleration: [5.0; 3],
            max_rate_deg: [60.0; 2],
            envelope_share: 0.5,
            tilt_share: 0.5,
            budget_ms: 2.0,
            iterations: 60,
        }
    }
}

impl OptimalConfig {
    /// Checks every parameter; the error is the first key out of range, as `optimal.KEY`, and what it must be
    /// (the configuration's check turns it into its error).
    pub fn validate(&self) -> Result<(), (&'static str, &'static str)> {
        let ok = |v: f64, lo: f64, hi: f64| v.is_finite() && v >= lo && v <= hi;
        let err = |key, must| Err((key, must));
        if !(2..=60).contains(&self.horizon) {
            return err("optimal.horizon", "2 to 60 steps");
        }
        if !ok(self.step_s, 0.005, 0.5) {
            return err("optimal.step_s", "0.005 to 0.5 s");
        }
        let weights: [(&'static str, &[f64]); 9] = [
            ("optimal.force_weight", &self.force_weight),
            ("optimal.rotation_weight", &self.rotation_weight),
            ("optimal.position_weight", &self.position_weight),
            ("optimal.velocity_weight", &self.velocity_weight),
            ("optimal.tilt_weight", &self.tilt_weight),
            (
                "optimal.tilt_loss_weight",
                core::slice::from_ref(&self.tilt_loss_weight),
            ),
            ("optimal.plan_weight", core::slice::from_ref(&self.plan_weight)),
            ("optimal.acceleration_weight", &self.acceleration_weight),
            ("optimal.rate_weight", &self.rate_weight),
        ];
        for (key, w) in weights {
            if !w.iter().all(|&w| ok(w, 0.0, 1e6)) {
                return err(key, "0 to 1e6");
            }
        }
        // Effort weights keep the programme strictly convex: zero would leave an input free where nothing else
        // weighs it. Each key named on its own, so that the message points at the value that is wrong.
        for (key, w) in [
            ("optimal.acceleration_weight", &self.acceleration_weight[..]),
            ("optimal.rate_weight", &self.rate_weight[..]),
        ] {
            if !w.iter().all(|&w| w >= 1e-9) {
                return err(key, "above 0: it keeps the solve unique");
            }
        }
        let limits: [(&'static str, &[f64], f64, &'static str); 3] = [
            (
                "optimal.max_velocity",
                &self.max_velocity,
                10.0,
                "above 0, at most 10 m/s",
            ),
            (
                "optimal.max_acceleration",
                &self.max_acceleration,
                100.0,
                "above 0, at most 100 m/s^2",
            ),
            (
                "optimal.max_rate_deg",
                &self.max_rate_deg,
                720.0,
                "above 0, at most 720 deg/s",
            ),
        ];
        for (key, v, hi, must) in limits {
            if !v.iter().all(|&v| ok(v, 1e-6, hi)) {
                return err(key, must);
            }
        }
        if !ok(self.envelope_share, 0.05, 1.0) {
            return err("optimal.envelope_share", "0.05 to 1");
        }
        if !ok(self.tilt_share, 0.05, 1.0) {
            return err("optimal.tilt_share", "0.05 to 1");
        }
        if !ok(self.budget_ms, 0.01, 1000.0) {
            return err("optimal.budget_ms", "0.01 to 1000 ms");
        }
        if !(1..=200).contains(&self.iterations) {
            return err("optimal.iterations", "1 to 200 iterations");
        }
        Ok(())
    }
}

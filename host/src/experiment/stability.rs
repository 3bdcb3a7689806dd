//! `ringpod stability`: the vehicle stability tests of the dissertation's chapter 5.2 (the tip-over angle on a
//! longitudinal incline and on a lateral slope, the body's roll, the critical rollover speed in a turn) computed for a
//! vehicle model by the core's [`ringpod_core::vehicle`], and with `--experiment DIR` each run on the simulated
//! trainer model as the source's stand runs it: the platform tilts at a set rate toward the computed angle and a
//! little past it, the run record gives the followed tilt row by row, the vehicle's margin is evaluated at each, and
//! where it first goes negative is the measured tip-over, compared with the computed one.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ringpod_core::kinematics::presets::Preset;
use ringpod_core::vehicle::{gravity_in_platform, Roll, Stability, Vehicle, GRAVITY};
use serde::Serialize;

use crate::error::CliError;
use crate::out::{Outcome, EXIT_CHECK_FAILED};

/// What `ringpod stability` is asked.
pub struct Options<'a> {
    pub track: f64,
    pub wheelbase: f64,
    pub cg_height: f64,
    /// Default: half the wheelbase.
    pub cg_from_rear: Option<f64>,
    /// Roll stiffness (N m/rad), sprung mass (kg), roll centre height (m): all three or none.
    pub roll: Option<(f64, f64, f64)>,
    /// The turn's radius (m).
    pub radius: f64,
    /// Run the experiments, writing their motions and records here.
    pub experiment: Option<&'a Path>,
    /// The platform's tilt rate in the experiments (deg/s).
    pub rate_deg_s: f64,
    pub json: bool,
    /// Ends an experiment early (a signal).
    pub stopped: &'a dyn Fn() -> bool,
}

/// How far past the computed angle the platform tilts (rad): 2 deg.
const PAST: f64 = 2.0 * std::f64::consts::PI / 180.0;
/// The measured tip-over agrees with the computed one within this (rad): 0.05 deg, the followed pose being the
/// counted steps' (25,600 a carriage turn), read at 250 Hz and interpolated.
const AGREE: f64 = 0.05 * std::f64::consts::PI / 180.0;
/// The motion's rows (s).
const ROW_S: f64 = 0.02;

/// One experiment's setting: which way the platform tilts, and to what.
#[derive(Clone, Copy)]
enum Test {
    /// Nose up (a negative pitch): over the rear axle.
    Incline,
    /// Rolled: over the downhill wheels.
    Slope,
    /// A level turn by tilt coordination: the lateral load as the slope's, read as a speed.
    Turn,
}

impl Test {
    fn name(self) -> &'static str {
        match self {
            Self::Incline => "incline",
            Self::Slope => "slope",
            Self::Turn => "turn",
        }
    }

    /// The pose's tilt `(alpha, beta)` at a tilt angle of `a`.
    fn tilt(self, a: f64) -> (f64, f64) {
        match self {
            Self::Incline => (0.0, -a),
            Self::Slope | Self::Turn => (a, 0.0),
        }
    }

    /// The tilt angle of a pose.
    fn angle(self, pose: &[f64; 6]) -> f64 {
        match self {
            Self::Incline => -pose[4],
            Self::Slope | Self::Turn => pose[3],
        }
    }

    /// The computed angle the platform tilts toward, and the one it should show the tip at: the turn's level
    /// threshold `atan(a_y / g)` is approached, but on a tilted platform the normal load is `g cos theta`, so a
    /// sprung vehicle tips there at the slope's angle (the same for a rigid one).
    fn angles(self, s: &Stability) -> (f64, f64) {
        match self {
            Self::Incline => (s.incline, s.incline),
            Self::Slope => (s.slope, s.slope),
            Self::Turn => (s.rollover_g.atan(), s.slope),
        }
    }
}

#[derive(Serialize)]
struct Measured {
    test: &'static str,
    /// The angle computed (deg).
    computed_deg: f64,
    /// The angle the platform should show it at (deg).
    expected_on_platform_deg: f64,
    /// Where the record shows the tip-over (deg), if it does.
    measured_deg: Option<f64>,
    /// When (device time, s).
    at_s: Option<f64>,
    /// The largest tilt the platform followed (deg).
    largest_tilt_deg: f64,
    /// The turn: the critical speed read from the measured angle by tilt coordination (m/s).
    speed_m_s: Option<f64>,
    /// The slope: the body's roll at the measured tip-over (deg).
    roll_deg: Option<f64>,
    agrees: bool,
    motion: PathBuf,
    record: PathBuf,
}

#[derive(Serialize)]
struct StabilityJson {
    track: f64,
    wheelbase: f64,
    cg_height: f64,
    cg_from_rear: f64,
    static_stability_factor: f64,
    incline_deg: f64,
    decline_deg: f64,
    slope_deg: f64,
    roll_at_slope_deg: f64,
    roll_gradient_deg_per_g: f64,
    rollover_g: f64,
    turn_radius: f64,
    critical_speed_m_s: f64,
    experiments: Vec<Measured>,
    agree: bool,
}

/// Answers `ringpod stability`: 0 when computed (and every experiment shows the tip-over where computed), 3 when
/// an experiment does not.
pub fn run(o: &Options) -> Result<Outcome, CliError> {
    let roll = o.roll.map(|(stiffness, mass, centre_height)| Roll {
        stiffness,
        mass,
        centre_height,
    });
    let cg_from_rear = o.cg_from_rear.unwrap_or(0.5 * o.wheelbase);
    let v = Vehicle::with_roll(o.track, o.wheelbase, o.cg_height, cg_from_rear, roll)?;
    let s = v.stability();
    let speed = v.critical_speed(o.radius)?;
    let mut experiments = Vec::new();
    if let Some(dir) = o.experiment {
        if !(o.rate_deg_s.is_finite() && o.rate_deg_s > 0.0 && o.rate_deg_s <= 60.0) {
            return Err(CliError::bad(
                "rate",
                format!("{}: must be above 0 and at most 60 deg/s", o.rate_deg_s),
            ));
        }
        std::fs::create_dir_all(dir).map_err(|e| CliError::file(dir, e))?;
        for test in [Test::Incline, Test::Slope, Test::Turn] {
            experiments.push(experiment(&v, &s, test, o, dir)?);
        }
    }
    let agree = experiments.iter().all(|m| m.agrees);
    let json = StabilityJson {
        track: v.track,
        wheelbase: v.wheelbase,
        cg_height: v.cg_height,
        cg_from_rear,
        static_stability_factor: v.stability_factor(),
        incline_deg: s.incline.to_degrees(),
        decline_deg: s.decline.to_degrees(),
        slope_deg: s.slope.to_degrees(),
        roll_at_slope_deg: s.roll_at_slope.to_degrees(),
        roll_gradient_deg_per_g: s.roll_rate.to_degrees(),
        rollover_g: s.rollover_g,
        turn_radius: o.radius,
        critical_speed_m_s: speed,
        experiments,
        agree,
    };
    let code = if agree { 0 } else { EXIT_CHECK_FAILED };
    let text = if o.json {
        serde_json::to_string_pretty(&json)? + "\n"
    } else {
        text(&json)
    };
    Ok(Outcome { text, code })
}

/// The motion: home held 0.5 s, the tilt at `rate` to `peak`, held 0.5 s, back at the same rate, home held 0.3 s.
fn motion(test: Test, peak: f64, rate: f64) -> String {
    let home = Preset::TrainerModel.home();
    let ramp = peak / rate;
    let total = 0.5 + ramp + 0.5 + ramp + 0.3;
    let tilt_at = |t: f64| {
        if t < 0.5 {
            0.0
        } else if t < 0.5 + ramp {
            (t - 0.5) * rate
        } else if t < 1.0 + ramp {
            peak
        } else {
            (peak - (t - 1.0 - ramp) * rate).max(0.0)
        }
    };
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    let rows = (total / ROW_S).ceil() as usize;
    for i in 0..=rows {
        let t = i as f64 * ROW_S;
        let (alpha, beta) = test.tilt(tilt_at(t));
        let _ = writeln!(
            csv,
            "{t:.3},{},{},{},{alpha:.9},{beta:.9},{}",
            home[0], home[1], home[2], home[5]
        );
    }
    csv
}

/// Runs one test on the simulated platform and reads the record.
fn experiment(v: &Vehicle, s: &Stability, test: Test, o: &Options, dir: &Path) -> Result<Measured, CliError> {
    let (computed, expected) = test.angles(s);
    let rate = o.rate_deg_s.to_radians();
    let motion_path = dir.join(format!("stability-{}-motion.csv", test.name()));
    let record_path = dir.join(format!("stability-{}-record.csv", test.name()));
    let report = super::on_sim(
        &motion(test, computed.max(expected) + PAST, rate),
        &motion_path,
        &record_path,
        o.stopped,
    )?;
    if report.exit_code != crate::stream::exit::FOLLOWED {
        return Err(CliError::Experiment(format!(
            "{}: the stream ended {} ({})",
            test.name(),
            report.outcome,
            report.reason.unwrap_or_default()
        )));
    }
    let run = crate::stream::record::read(&record_path).map_err(|e| CliError::Experiment(e.to_string()))?;
    let (tip, largest) = tip_over(v, test, &run.t, &run.target);
    let measured = tip.map(|(_, angle)| angle);
    Ok(Measured {
        test: test.name(),
        computed_deg: computed.to_degrees(),
        expected_on_platform_deg: expected.to_degrees(),
        measured_deg: measured.map(f64::to_degrees),
        at_s: tip.map(|(t, _)| t),
        largest_tilt_deg: largest.to_degrees(),
        speed_m_s: match test {
            Test::Turn => measured.map(|a| (GRAVITY * a.tan() * o.radius).sqrt()),
            _ => None,
        },
        roll_deg: match test {
            Test::Slope => measured.map(|a| (v.roll_rate(GRAVITY * a.cos()) * a.tan()).to_degrees()),
            _ => None,
        },
        agrees: measured.is_some_and(|m| (m - expected).abs() <= AGREE),
        motion: motion_path,
        record: record_path,
    })
}

/// Where along a record the vehicle first tips (device time, tilt angle; interpolated between the rows around
/// its margin's zero), and the largest tilt followed.
fn tip_over(v: &Vehicle, test: Test, t: &[f64], followed: &[[f64; 6]]) -> (Option<(f64, f64)>, f64) {
    let margin = |p: &[f64; 6]| v.margin(gravity_in_platform(p[3], p[4]));
    let largest = followed.iter().map(|p| test.angle(p)).fold(0.0, f64::max);
    for i in 1..followed.len() {
        let (m0, m1) = (margin(&followed[i - 1]), margin(&followed[i]));
        if m0 >= 0.0 && m1 < 0.0 {
            let share = m0 / (m0 - m1);
            let (a0, a1) = (test.angle(&followed[i - 1]), test.angle(&followed[i]));
            return (
                Some((t[i - 1] + share * (t[i] - t[i - 1]), a0 + share * (a1 - a0))),
                largest,
            );
        }
    }
    (None, largest)
}

fn text(j: &StabilityJson) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "vehicle: track {} m, wheelbase {} m, centre of gravity {} m up and {} m ahead of the rear axle; T/2h = {:.4}",
        j.track, j.wheelbase, j.cg_height, j.cg_from_rear, j.static_stability_factor
    );
    let _ = writeln!(
        t,
        "tip-over climbing an incline (over the rear axle): {:.3} deg",
        j.incline_deg
    );
    let _ = writeln!(
        t,
        "tip-over descending (over the front axle):         {:.3} deg",
        j.decline_deg
    );
    let _ = writeln!(
        t,
        "tip-over on a lateral slope:                       {:.3} deg",
        j.slope_deg
    );
    let _ = writeln!(
        t,
        "body roll at the slope's tip-over: {:.3} deg; roll gradient {:.3} deg/g",
        j.roll_at_slope_deg, j.roll_gradient_deg_per_g
    );
    let _ = writeln!(
        t,
        "rollover in a level turn at {:.4} g: critical speed {:.3} m/s on a {} m radius",
        j.rollover_g, j.critical_speed_m_s, j.turn_radius
    );
    for m in &j.experiments {
        let _ = write!(t, "experiment {:<8} computed {:.3} deg", m.test, m.computed_deg);
        if (m.expected_on_platform_deg - m.computed_deg).abs() > 1e-9 {
            let _ = write!(t, " (on the tilted platform {:.3} deg)", m.expected_on_platform_deg);
        }
        match m.measured_deg {
            Some(a) => {
                let _ = write!(
                    t,
                    ", the record shows the tip at {a:.3} deg (t = {:.3} s), {:+.5} deg",
                    m.at_s.unwrap_or(f64::NAN),
                    a - m.expected_on_platform_deg
                );
            }
            None => {
                let _ = write!(
                    t,
                    ", NOT tipped: the platform followed up to {:.3} deg",
                    m.largest_tilt_deg
                );
            }
        }
        if let Some(v) = m.speed_m_s {
            let _ = write!(t, "; as a speed {v:.3} m/s");
        }
        if let Some(r) = m.roll_deg {
            let _ = write!(t, "; body roll {r:.3} deg");
        }
        let _ = writeln!(
            t,
            ": {}  [{}]",
            if m.agrees { "agrees" } else { "DIFFERS" },
            m.record.display()
        );
    }
    t
}

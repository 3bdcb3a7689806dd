//! `ringpod check --tip-over`: a payload's centre of mass over the carriages' support polygon under a
//! quasi-static lateral acceleration (the core's [`ringpod_core::kinematics::TipOver`]): the largest acceleration
//! in each direction before the projection of the centre of mass along `g - a` leaves the polygon, the weakest
//! over all directions, and for a given `--accel` whether it tips and by what margin.

use std::fmt::Write as _;

use nalgebra::Vector3;
use ringpod_core::kinematics::{Mechanism, GRAVITY};
use serde::Serialize;

use super::kinematics::{pose_arg, On};
use super::mechanism::{AnyMechanism, Selected};
use crate::error::CliError;
use crate::input::numbers;
use crate::out::Outcome;
use crate::out::EXIT_CHECK_FAILED;

/// Accelerations beyond this (m/s^2, about 1000 g) are a mistake, not a load.
const MAX_ACCEL: f64 = 1e4;

/// `check --tip-over`: the platform, the pose (the home pose when none), the payload's centre of mass in the
/// platform frame (the geometry's when none) and an acceleration to try.
pub struct Options<'a> {
    pub on: On<'a>,
    pub pose: Option<&'a str>,
    pub payload_com: Option<&'a str>,
    pub accel: Option<&'a str>,
}

/// The eight directions reported, with their names.
const DIRECTIONS: [(&str, f64); 8] = [
    ("+X", 0.0),
    ("+X+Y", 45.0),
    ("+Y", 90.0),
    ("-X+Y", 135.0),
    ("-X", 180.0),
    ("-X-Y", 225.0),
    ("-Y", 270.0),
    ("+X-Y", 315.0),
];

#[derive(Serialize)]
struct Direction {
    name: &'static str,
    /// Counter-clockwise from base X (rad, or deg with --degrees).
    direction: f64,
    /// The largest lateral acceleration that way before tipping (m/s^2).
    acceleration: f64,
}

#[derive(Serialize)]
struct Weakest {
    acceleration: f64,
    direction: f64,
}

#[derive(Serialize)]
struct Accel {
    accel: [f64; 2],
    /// Where the effective gravity through the centre of mass meets the ring plane.
    point: [f64; 2],
    /// That point's distance inside the polygon (m; negative outside).
    margin: f64,
    /// The largest acceleration in the same direction minus the one given (m/s^2).
    acceleration_margin: f64,
    tips: bool,
}

#[derive(Serialize)]
struct TipOverJson<'a> {
    mechanism: &'a str,
    pose: [f64; 6],
    /// The payload's centre of mass in the base frame (m).
    com: [f64; 3],
    /// Its height above the ring plane (m).
    height: f64,
    gravity: f64,
    /// The carriages, counter-clockwise around the ring.
    polygon: Vec<[f64; 2]>,
    /// The vertical projection's distance inside the polygon (m).
    static_margin: f64,
    weakest: Weakest,
    directions: Vec<Direction>,
    under: Option<Accel>,
    tips: bool,
}

/// Parses `what` as `N` comma-separated finite numbers.
fn list<const N: usize>(what: &'static str, text: &str) -> Result<[f64; N], numbers::BadNumber> {
    let bad = |reason: String| numbers::BadNumber::new(what, reason);
    let values: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>().map_err(|e| bad(format!("`{}`: {e}", s.trim()))))
        .collect::<Result<_, _>>()?;
    let values: [f64; N] = values
        .try_into()
        .map_err(|v: Vec<f64>| bad(format!("expected {N} numbers, got {}", v.len())))?;
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!("value {} is not a finite number", i + 1)));
    }
    Ok(values)
}

/// Answers `check --tip-over`. Exits 0 when the payload stands (under `--accel` if given), 3 when it tips.
pub fn run(o: &Options) -> Result<Outcome, CliError> {
    let Selected {
        name, home, mechanism, ..
    } = Selected::of(o.on.mechanism, o.on.geometry)?;
    let AnyMechanism::Ring(ring) = &mechanism else {
        return Err(CliError::bad(
            "tip-over",
            "the support polygon is the carriages' on the ring: ring platforms only".into(),
        ));
    };
    let length = mechanism.characteristic_length();
    let pose = pose_arg(&o.on, home, length, o.pose, "pose")?;
    let com = match o.payload_com {
        Some(text) => {
            let c = list::<3>("payload-com", text)?;
            for v in c {
                numbers::length_in_range("payload-com", v, length)?;
            }
            c
        }
        None => ring.geometry().limits.centre_of_mass,
    };
    let accel = match o.accel {
        Some(text) => {
            let a = list::<2>("accel", text)?;
            if let Some(v) = a.iter().find(|v| v.abs() > MAX_ACCEL) {
                return Err(CliError::bad(
                    "accel",
                    format!(
                        "{} m/s^2 is out of range (at most {MAX_ACCEL:e} either way)",
                        numbers::readable(*v)
                    ),
                ));
            }
            Some(a)
        }
        None => None,
    };
    let t = ring.tip_over(&pose, Vector3::from(com))?;
    let under = accel.map(|a| t.under(a)).transpose()?;
    let angle = |rad: f64| if o.on.degrees { rad.to_degrees() } else { rad };
    let unit = if o.on.degrees { "deg" } else { "rad" };
    let tips = t.static_margin < 0.0 || under.as_ref().is_some_and(|u| u.tips);
    let json = TipOverJson {
        mechanism: &name,
        pose: {
            let v = pose.to_array();
            std::array::from_fn(|i| if i < 3 { v[i] } else { angle(v[i]) })
        },
        com: [t.com.x, t.com.y, t.com.z],
        height: t.com.z,
        gravity: GRAVITY,
        polygon: t.polygon[..t.corners].iter().map(|p| [p.x, p.y]).collect(),
        static_margin: t.static_margin,
        weakest: Weakest {
            acceleration: t.weakest,
            direction: angle(t.weakest_direction),
        },
        directions: DIRECTIONS
            .iter()
            .map(|&(name, deg)| Direction {
                name,
                direction: angle(deg.to_radians()),
                acceleration: t.limit(deg.to_radians()),
            })
            .collect(),
        under: accel.zip(under).map(|(a, u)| Accel {
            accel: a,
            point: u.point,
            margin: u.margin,
            acceleration_margin: u.acceleration_margin,
            tips: u.tips,
        }),
        tips,
    };
    let code = if tips { EXIT_CHECK_FAILED } else { 0 };
    if o.on.json {
        return Ok(Outcome {
            text: serde_json::to_string_pretty(&json)? + "\n",
            code,
        });
    }
    Ok(Outcome {
        text: text(&json, unit),
        code,
    })
}

fn text(j: &TipOverJson, unit: &str) -> String {
    let mut t = String::new();
    let pose: Vec<String> = j.pose.iter().map(|v| format!("{v:.6}")).collect();
    let _ = writeln!(
        t,
        "{} at pose x,y,z,alpha,beta,gamma = {} (m, {unit})",
        j.mechanism,
        pose.join(", ")
    );
    let _ = writeln!(
        t,
        "payload centre of mass at ({:.4}, {:.4}, {:.4}) m, {:.4} m above the ring plane; support polygon of {} carriages",
        j.com[0],
        j.com[1],
        j.com[2],
        j.height,
        j.polygon.len()
    );
    let _ = writeln!(
        t,
        "at rest its vertical projection is {:.4} m {}",
        j.static_margin.abs(),
        if j.static_margin >= 0.0 { "inside" } else { "OUTSIDE" }
    );
    let _ = writeln!(t, "largest lateral acceleration before tipping (m/s^2; g = {GRAVITY}):");
    for d in &j.directions {
        let _ = writeln!(
            t,
            "  {:<5} ({:>7.2} {unit}) {:>10.4}",
            d.name, d.direction, d.acceleration
        );
    }
    let _ = writeln!(
        t,
        "  weakest {:.4} m/s^2 ({:.3} g) towards {:.4} {unit}",
        j.weakest.acceleration,
        j.weakest.acceleration / GRAVITY,
        j.weakest.direction
    );
    if let Some(u) = &j.under {
        let _ = writeln!(
            t,
            "under ({}, {}) m/s^2 the effective gravity meets the ring plane at ({:.4}, {:.4}), {:.4} m {}: {} (acceleration margin {:.4} m/s^2)",
            u.accel[0],
            u.accel[1],
            u.point[0],
            u.point[1],
            u.margin.abs(),
            if u.margin >= 0.0 { "inside" } else { "OUTSIDE" },
            if u.tips { "TIPS" } else { "stands" },
            u.acceleration_margin
        );
    }
    t
}

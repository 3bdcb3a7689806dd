//! A mechanism file (TOML) in paper 002's terms: pairs sketched in the base by three points each (origin, a point
//! on +X, one on +Z) with their variables at the sketch, loops welding two links as sketched, bodies (mass, centre,
//! inertia in the base at the sketch), springs, dampers and forces in pair variables, gravity, and the drives,
//! each swung as `at + amplitude sin(2 pi frequency t)`. See `docs/book/src/dynamics.md` and `docs/dynamics/`.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Matrix3, Matrix4, Vector3};
use ringpod_core::screws::matrix::mechanism::{MAX_DRIVES, MAX_VARIABLES};
use ringpod_core::screws::matrix::{
    frame, inverse, pseudo_inertia, Body, Closure, Element, Joint, LoopError, Mechanism, Model, Pair, GROUND,
};
use serde::Deserialize;

use super::{describe, report, Row};
use crate::error::CliError;
use crate::out::Outcome;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    name: Option<String>,
    #[serde(default = "down")]
    gravity: [f64; 3],
    pair: Vec<PairFile>,
    #[serde(default, rename = "loop")]
    loops: Vec<LoopFile>,
    #[serde(default)]
    body: Vec<BodyFile>,
    #[serde(default)]
    element: Vec<ElementFile>,
    motion: MotionFile,
}

fn down() -> [f64; 3] {
    [0.0, 0.0, -9.80665]
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PairFile {
    name: String,
    joint: String,
    #[serde(default)]
    pitch: f64,
    #[serde(default = "ground")]
    parent: String,
    origin: [f64; 3],
    x: [f64; 3],
    z: [f64; 3],
    #[serde(default)]
    at: Vec<f64>,
}

fn ground() -> String {
    "ground".into()
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LoopFile {
    a: String,
    b: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyFile {
    link: String,
    mass: f64,
    centre: [f64; 3],
    /// `Ixx, Iyy, Izz, Ixy, Ixz, Iyz` about the centre, base axes at the sketch (products as tensor entries).
    #[serde(default)]
    inertia: [f64; 6],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ElementFile {
    pair: String,
    #[serde(default)]
    variable: usize,
    #[serde(default)]
    stiffness: f64,
    rest: Option<f64>,
    #[serde(default)]
    damping: f64,
    #[serde(default)]
    force: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotionFile {
    /// Driven pairs (their first variable), in drive order.
    drives: Vec<String>,
    amplitude: Vec<f64>,
    frequency: Vec<f64>,
    duration: f64,
    step: f64,
}

/// The heaviest body a mechanism file may give (kg), and the largest moment of inertia (kg m^2): a thousand
/// tonnes; beyond that the number is a mistake (1e308 kg came back as a 300-digit force), as `loads --mass` takes it.
const MOST_MASS: f64 = 1e6;

fn bad(what: String) -> CliError {
    CliError::Dynamics(shown(&what))
}

/// Text from the file as it may be printed: a control character (an escape sequence would drive the terminal) is
/// written as its escape, `\u{1b}`.
fn shown(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// Why a body's mass, centre or inertia cannot be a body's (a mass not positive, not finite or beyond
/// [`MOST_MASS`]), by its key and link.
fn body_refused(b: &BodyFile) -> Option<String> {
    use crate::input::numbers::readable;
    let said = |what: String| Some(format!("body on `{}`: {what}", b.link));
    if !(b.mass.is_finite() && b.mass > 0.0 && b.mass <= MOST_MASS) {
        return said(format!(
            "mass = {} kg: a body's mass is positive and at most {} kg",
            readable(b.mass),
            readable(MOST_MASS)
        ));
    }
    if let Some(v) = b.inertia.iter().find(|v| !(v.is_finite() && v.abs() <= MOST_MASS)) {
        return said(format!(
            "inertia {} kg m^2: each a finite number, at most {} either way",
            readable(*v),
            readable(MOST_MASS)
        ));
    }
    if let Some(v) = b.centre.iter().find(|v| !v.is_finite()) {
        return said(format!("centre {}: not a finite number", readable(*v)));
    }
    None
}

/// Why a file's mechanism or model is refused, in words.
fn refused(e: LoopError) -> &'static str {
    match e {
        LoopError::NonFinite => "a value is not finite",
        _ => "past the limits, or too few loops to determine the variables that are not driven (six conditions a loop)",
    }
}

fn joint(name: &str, pitch: f64) -> Result<Joint, CliError> {
    Ok(match name {
        "revolute" => Joint::Revolute,
        "prismatic" => Joint::Prismatic,
        "screw" => Joint::Screw { pitch },
        "cylindrical" => Joint::Cylindrical,
        "hooke" => Joint::Hooke,
        "spherical" => Joint::Spherical,
        other => {
            return Err(bad(format!(
                "pair joint `{other}`: one of revolute, prismatic, screw, cylindrical, hooke, spherical"
            )))
        }
    })
}

/// The model of a file, the variables at its sketch, its drives' swing and sampling.
struct Built {
    model: Model,
    q: [f64; MAX_VARIABLES],
    swing: Vec<(f64, f64, f64)>,
    duration: f64,
    step: f64,
    name: String,
}

/// The pairs sketched: each placed on its parent link, the links by name, every link's frame at the sketch, each
/// pair's first variable by name and the variables at the sketch.
struct Sketched<'a> {
    pairs: Vec<Pair>,
    links: HashMap<&'a str, usize>,
    frames: Vec<Matrix4<f64>>,
    first: HashMap<&'a str, usize>,
    q: [f64; MAX_VARIABLES],
}

fn v3(a: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

fn sketch(f: &File) -> Result<Sketched<'_>, CliError> {
    let mut links: HashMap<&str, usize> = HashMap::from([("ground", GROUND)]);
    let mut frames = vec![Matrix4::identity()];
    let (mut pairs, mut q, mut first) = (Vec::new(), [0.0; MAX_VARIABLES], HashMap::new());
    let mut count = 0;
    for (p, pf) in f.pair.iter().enumerate() {
        let j = joint(&pf.joint, pf.pitch)?;
        let parent = *links.get(pf.parent.as_str()).ok_or_else(|| {
            bad(format!(
                "pair `{}`: parent `{}` is not an earlier pair or ground",
                pf.name, pf.parent
            ))
        })?;
        let at = frame(&v3(&pf.origin), &v3(&pf.x), &v3(&pf.z))
            .map_err(|_| bad(format!("pair `{}`: origin, x and z do not make a frame", pf.name)))?;
        let mut values = [0.0; 3];
        if pf.at.len() > j.variables() || !pf.at.iter().all(|v| v.is_finite()) {
            return Err(bad(format!(
                "pair `{}`: `at` takes {} finite values",
                pf.name,
                j.variables()
            )));
        }
        values[..pf.at.len()].copy_from_slice(&pf.at);
        if count + j.variables() > MAX_VARIABLES || links.insert(&pf.name, p + 1).is_some() {
            return Err(bad(format!(
                "pair `{}`: a repeated name, or past {MAX_VARIABLES} variables",
                pf.name
            )));
        }
        pairs.push(Pair {
            joint: j,
            parent,
            place: inverse(&frames[parent]) * at,
        });
        first.insert(pf.name.as_str(), count);
        q[count..count + j.variables()].copy_from_slice(&values[..j.variables()]);
        count += j.variables();
        frames.push(at * j.transform(&values));
    }
    Ok(Sketched {
        pairs,
        links,
        frames,
        first,
        q,
    })
}

/// The springs, dampers and forces, each in its pair's variable (a spring's rest defaults to the sketch's value).
fn elements(f: &File, first: &HashMap<&str, usize>, q: &[f64; MAX_VARIABLES]) -> Result<Vec<Element>, CliError> {
    f.element
        .iter()
        .map(|e| {
            let v = first
                .get(e.pair.as_str())
                .copied()
                .ok_or_else(|| bad(format!("element: `{}` names no pair", e.pair)))?
                + e.variable;
            Ok(Element {
                variable: v,
                stiffness: e.stiffness,
                rest: e.rest.unwrap_or(q[v.min(MAX_VARIABLES - 1)]),
                damping: e.damping,
                force: e.force,
            })
        })
        .collect::<Result<Vec<_>, CliError>>()
}

fn build(f: &File) -> Result<Built, CliError> {
    let Sketched {
        pairs,
        links,
        frames,
        first,
        q,
    } = sketch(f)?;
    let link = |name: &str| {
        links
            .get(name)
            .copied()
            .ok_or_else(|| bad(format!("`{name}` names no pair")))
    };
    let closures = f
        .loops
        .iter()
        .map(|l| {
            let (a, b) = (link(&l.a)?, link(&l.b)?);
            Ok(Closure {
                a,
                b,
                offset: inverse(&frames[a]) * frames[b],
            })
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    let m = &f.motion;
    if m.drives.len() > MAX_DRIVES || m.amplitude.len() != m.drives.len() || m.frequency.len() != m.drives.len() {
        return Err(bad(format!(
            "motion: one amplitude and one frequency per drive, at most {MAX_DRIVES} drives"
        )));
    }
    let drives = m
        .drives
        .iter()
        .map(|d| {
            first
                .get(d.as_str())
                .copied()
                .ok_or_else(|| bad(format!("drive `{d}` names no pair")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let positive =
        m.duration.is_finite() && m.duration > 0.0 && m.step.is_finite() && m.step > 0.0 && m.duration / m.step <= 1e6;
    if !positive || !m.amplitude.iter().chain(&m.frequency).all(|v| v.is_finite()) {
        return Err(bad(
            "motion: a positive duration and step (at most a million samples), finite amplitudes and frequencies"
                .into(),
        ));
    }
    let mechanism =
        Mechanism::new(&pairs, &closures, &drives).map_err(|e| bad(format!("the mechanism: {}", refused(e))))?;
    let bodies = f
        .body
        .iter()
        .map(|b| {
            if let Some(why) = body_refused(b) {
                return Err(bad(why));
            }
            let i = link(&b.link)?;
            let [xx, yy, zz, xy, xz, yz] = b.inertia;
            let tensor = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
            let back = inverse(&frames[i]);
            Ok(Body {
                link: i,
                inertia: back * pseudo_inertia(b.mass, &v3(&b.centre), &tensor) * back.transpose(),
            })
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    let elements = elements(f, &first, &q)?;
    let model = Model::new(mechanism, &bodies, &elements, v3(&f.gravity))
        .map_err(|e| bad(format!("the model: {}", refused(e))))?;
    let swing = drives
        .iter()
        .zip(m.amplitude.iter().zip(&m.frequency))
        .map(|(d, (a, w))| (q[*d], *a, *w))
        .collect();
    let name = f.name.as_deref().map_or_else(|| "mechanism".into(), shown);
    Ok(Built {
        model,
        q,
        swing,
        duration: m.duration,
        step: m.step,
        name,
    })
}

/// `dynamics --file`: the file's mechanism along its drives' swing, its inverse dynamics, table, plot and energy.
pub fn run_file(path: &Path, table: Option<&Path>, plot: Option<&Path>) -> Result<Outcome, CliError> {
    // Bounded, and never waiting in open() for a FIFO's writer, as every settings file is read.
    let text = crate::input::files::read_text(path, crate::input::files::CONFIG_LIMIT)
        .map_err(|e| bad(format!("{}: {e}", path.display())))?;
    // TOML's message spans lines (the line quoted, a caret under the fault): kept as it is.
    let file: File = toml::from_str(&text).map_err(|e| CliError::Dynamics(format!("{}: {e}", path.display())))?;
    let b = build(&file)?;
    let d = b.swing.len();
    let at = |t: f64, k: usize| -> [f64; MAX_DRIVES] {
        std::array::from_fn(|i| match b.swing.get(i) {
            Some((u0, a, f)) => {
                let w = 2.0 * std::f64::consts::PI * f;
                let s = (w * t).sin();
                let c = (w * t).cos();
                [u0 + a * s, a * w * c, -a * w * w * s][k]
            }
            None => 0.0,
        })
    };
    let mut guess = b.q;
    let mut rows = Vec::new();
    for k in 0..=(b.duration / b.step).floor() as usize {
        let t = k as f64 * b.step;
        let (u, ud, udd) = (at(t, 0), at(t, 1), at(t, 2));
        let fail = |e: LoopError| bad(format!("at t = {t} s: {}", describe(e)));
        let s = b
            .model
            .solve_point(&guess, &u[..d], &ud[..d], &udd[..d])
            .map_err(fail)?;
        let e = b.model.energy(&s.frames, &s.state);
        let power = s.forces.iter().zip(&ud).map(|(f, v)| f * v).sum::<f64>() + b.model.element_power(&s.state);
        rows.push(Row {
            t,
            u,
            ud,
            udd,
            forces: s.forces,
            kinetic: e.kinetic,
            potential: e.gravity + e.springs,
            power,
        });
        guess = s.state.q;
    }
    report(&b.name, &rows, d, table, plot)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FOUR_BAR: &str = include_str!("../../../../docs/dynamics/four-bar.toml");

    fn built(text: &str) -> Result<Built, CliError> {
        let file: File = toml::from_str(text).map_err(|e| bad(e.to_string()))?;
        build(&file)
    }

    /// The example file's four-bar, sketched at the crank's 60 deg, has SCREWS.md T3's mass: the three-point frames,
    /// the link matrices and the bodies given in the base all read as the hand-built four-bar's.
    #[test]
    fn the_example_four_bar_has_the_specifications_mass() {
        let b = built(FOUR_BAR).unwrap();
        let q = b.model.closed(&b.q, &[b.q[0]]).unwrap();
        assert!(
            q.iter().zip(&b.q).all(|(a, c)| (a - c).abs() < 1e-8),
            "the sketch is closed"
        );
        let m = b.model.mass(&b.model.mechanism.frames(&q).unwrap()).unwrap()[0][0];
        assert!((m - 0.0263978).abs() < 1e-7, "{m}");
    }

    #[test]
    fn every_bad_file_is_refused_with_what_is_wrong() {
        let cases = [
            (
                "joint = \"revolute\"\nparent = \"ground\"",
                "joint = \"wheel\"\nparent = \"ground\"",
                "pair joint",
            ),
            ("parent = \"crank\"", "parent = \"rocker\"", "not an earlier pair"),
            (
                "x = [0.050000000, 0.086602540, 0.0]",
                "x = [0.0, 0.0, 0.0]",
                "do not make a frame",
            ),
            ("name = \"pin\"", "name = \"crank\"", "repeated name"),
            ("a = \"pin\"", "a = \"nowhere\"", "names no pair"),
            ("amplitude = [0.3]", "amplitude = [0.3, 0.1]", "one amplitude"),
            ("drives = [\"crank\"]", "drives = [\"wheel\"]", "names no pair"),
            ("step = 0.01", "step = -0.01", "positive duration"),
            ("pair = \"coupler\"", "pair = \"wheel\"", "names no pair"),
            ("link = \"rocker\"", "link = \"wheel\"", "names no pair"),
            ("[[loop]]\na = \"pin\"\nb = \"ground\"", "", "the mechanism"),
            ("stiffness = 3.0", "stiffness = 3.0\nspring = 1.0", "unknown field"),
            ("gravity = [0.0, -9.81, 0.0]", "gravity = [0.0, nan, 0.0]", "the model"),
            ("mass = 1.0", "mass = -1.0", "mass = -1 kg: a body's mass is positive"),
            ("mass = 1.0", "mass = 0.0", "mass = 0 kg"),
            ("mass = 1.0", "mass = 1e308", "mass = 1e308 kg"),
            ("mass = 1.0", "mass = nan", "mass = NaN kg"),
            ("mass = 1.0", "mass = 2e6", "at most 1e6 kg"),
            ("inertia = [6.250000000e-04", "inertia = [1e300", "inertia 1e300 kg m^2"),
            // A control character from the file is printed as its escape.
            ("a = \"pin\"", "a = \"pin\\u001b[2J\"", "`pin\\u{1b}[2J` names no pair"),
        ];
        for (from, to, says) in cases {
            assert!(FOUR_BAR.contains(from), "{from}");
            let text = FOUR_BAR.replacen(from, to, 1);
            let e = built(&text).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(e.contains(says), "{from} -> {to}: {e}");
            assert!(!e.contains('\u{1b}'), "{e:?}");
        }
        let named = FOUR_BAR.replacen("name = \"four-bar\"", "name = \"four\\u001b]0;x\\u0007bar\"", 1);
        assert_eq!(built(&named).unwrap().name, "four\\u{1b}]0;x\\u{7}bar");
    }
}

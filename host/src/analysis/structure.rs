//! `ringpod structure`: the structural analysis of the source's chapters 2 and 5.1 (the math in
//! `ringpod_core::screws::structure`): the mobility by the structural formula, the unit screws of every joint of
//! every chain at a pose, the wrenches each chain transmits, each chain's workability determinant and the
//! mechanism's wrench determinant; or, with `--chain`, one of the source's single-chain examples (figs. 5.1-5.3) at
//! its coordinates.

use std::fmt::Write as _;

use ringpod_core::screws::layouts::{ring_chains, tool_chains, Chains, Figure, LayoutError};
use ringpod_core::screws::structure::{analyse, wrench_determinant, Chain, ChainAnalysis, Mobility, Pair};
use serde::Serialize;

use super::kinematics::{pose_arg, On};
use super::mechanism::{AnyMechanism, Selected};
use crate::error::CliError;
use crate::out::Outcome;

/// The source's single-chain examples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SourceChain {
    /// Fig. 5.1, A = (0.5, 0.2, 1): the rotopod's chain in its working position (the source: -0.2).
    #[value(name = "fig5.1")]
    Fig51,
    /// Fig. 5.1 as the source shows it first, A = (0.5, 0, 1): singular (0).
    #[value(name = "fig5.1-singular")]
    Fig51Singular,
    /// Fig. 5.2: three revolutes and a spherical pair (the source: -0.25).
    #[value(name = "fig5.2")]
    Fig52,
    /// Fig. 5.3: two revolutes, a prismatic and a spherical pair (the source: 0.625).
    #[value(name = "fig5.3")]
    Fig53,
}

impl SourceChain {
    fn figure(self) -> Figure {
        match self {
            SourceChain::Fig51 => Figure::Fig5_1,
            SourceChain::Fig51Singular => Figure::Fig5_1Singular,
            SourceChain::Fig52 => Figure::Fig5_2,
            SourceChain::Fig53 => Figure::Fig5_3,
        }
    }

    fn name(self) -> &'static str {
        match self {
            SourceChain::Fig51 => "fig5.1",
            SourceChain::Fig51Singular => "fig5.1-singular",
            SourceChain::Fig52 => "fig5.2",
            SourceChain::Fig53 => "fig5.3",
        }
    }
}

/// `structure`: a mechanism at a pose, or one of the source's chains.
pub struct Options<'a> {
    pub on: On<'a>,
    pub pose: Option<&'a str>,
    pub chain: Option<SourceChain>,
}

#[derive(Serialize)]
struct MobilityJson {
    /// `W = 6 n - 5 p5 - 4 p4 - 3 p3 - 2 p2 - p1`.
    w: i64,
    moving_links: usize,
    p5: usize,
    p4: usize,
    p3: usize,
    p2: usize,
    p1: usize,
    /// W with every pin-spherical pair a plain spherical one.
    without_pins: i64,
}

#[derive(Serialize)]
struct ChainJson {
    /// The chain's pairs from the base: R, P, S (spherical), PS (spherical with a pin).
    pairs: Vec<&'static str>,
    /// Each joint: its pair and axis, `*` when driven.
    joints: Vec<String>,
    /// Each joint's unit screw `[direction; moment about the base origin]`.
    unit_screws: Vec<[f64; 6]>,
    /// The wrenches reciprocal to the unactuated joints: the constraints first, then one per drive.
    wrenches: Vec<[f64; 6]>,
    constraints: usize,
    /// The joints' screws' determinant as the source forms it (a prismatic screw written as its member's vector).
    determinant: Option<f64>,
    /// The determinant of the unit screws.
    determinant_unit: Option<f64>,
}

#[derive(Serialize)]
struct StructureJson {
    mechanism: String,
    /// The pose (m, rad or deg); none for a source chain.
    pose: Option<[f64; 6]>,
    mobility: MobilityJson,
    chains: Vec<ChainJson>,
    /// The determinant of all chains' transmitted wrenches (rows, chain by chain), when they are six.
    determinant: Option<f64>,
    /// For a source chain: the determinant the source prints.
    published: Option<f64>,
}

fn pair_name(p: Pair) -> &'static str {
    match p {
        Pair::Revolute => "R",
        Pair::Prismatic => "P",
        Pair::Spherical => "S",
        Pair::PinSpherical => "PS",
    }
}

/// `R*`, `S.x`, `PS.1`: a joint by its pair and its place in the pair.
fn joint_labels(chain: &Chain) -> Vec<String> {
    let mut seen = [0usize; 6];
    (0..chain.joints().len())
        .map(|i| {
            let owner = chain.owner(i).unwrap_or(0);
            let pair = chain.pairs().get(owner).copied().unwrap_or(Pair::Revolute);
            let k = seen.get(owner).copied().unwrap_or(0);
            if let Some(s) = seen.get_mut(owner) {
                *s += 1;
            }
            let driven = if chain.joints()[i].actuated { "*" } else { "" };
            match pair {
                Pair::Spherical => format!("S.{}", ["x", "y", "z"].get(k).unwrap_or(&"?")),
                Pair::PinSpherical => format!("PS.{}", k + 1),
                p => format!("{}{driven}", pair_name(p)),
            }
        })
        .collect()
}

fn chain_json(chain: &Chain, a: &ChainAnalysis) -> ChainJson {
    ChainJson {
        pairs: chain.pairs().iter().map(|p| pair_name(*p)).collect(),
        joints: joint_labels(chain),
        unit_screws: chain.joints().iter().map(|j| j.twist.into()).collect(),
        wrenches: a.wrenches[..a.count].iter().map(|w| (*w).into()).collect(),
        constraints: a.constraints,
        determinant: a.determinant_source,
        determinant_unit: a.determinant,
    }
}

fn layout_error(e: LayoutError) -> CliError {
    match e {
        LayoutError::Kinematics(k) => CliError::Kinematics(k),
        LayoutError::Structure(s) => CliError::Structure(format!("{s:?}")),
    }
}

/// Runs the analysis.
pub fn run(o: &Options) -> Result<Outcome, CliError> {
    let (name, pose, chains, published) = match o.chain {
        Some(c) => {
            let chain = c.figure().chain().map_err(|e| CliError::Structure(format!("{e:?}")))?;
            (c.name().to_owned(), None, vec![chain], Some(c.figure().published()))
        }
        None => {
            let selected = Selected::of(o.on.mechanism, o.on.geometry)?;
            let length = ringpod_core::kinematics::Mechanism::characteristic_length(&selected.mechanism);
            let pose = pose_arg(&o.on, selected.home, length, o.pose, "pose")?;
            let chains: Chains = match &selected.mechanism {
                AnyMechanism::Ring(r) => ring_chains(r, &pose),
                AnyMechanism::Tool(t) => tool_chains(t, &pose),
            }
            .map_err(layout_error)?;
            let angle = if o.on.degrees { 1f64.to_degrees() } else { 1.0 };
            let p = pose.to_array();
            let shown = std::array::from_fn(|i| if i < 3 { p[i] } else { p[i] * angle });
            (selected.name, Some(shown), chains.iter().copied().collect(), None)
        }
    };
    let analyses = chains
        .iter()
        .map(analyse)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| CliError::Structure(format!("{e:?}")))?;
    let (m, plain) = (Mobility::of(&chains), Mobility::without_pins(&chains));
    let json = StructureJson {
        mechanism: name,
        pose,
        mobility: MobilityJson {
            w: m.w,
            moving_links: m.moving_links,
            p5: m.pairs[4],
            p4: m.pairs[3],
            p3: m.pairs[2],
            p2: m.pairs[1],
            p1: m.pairs[0],
            without_pins: plain.w,
        },
        chains: chains.iter().zip(&analyses).map(|(c, a)| chain_json(c, a)).collect(),
        determinant: if chains.len() > 1 {
            wrench_determinant(&analyses)
        } else {
            None
        },
        published,
    };
    if o.on.json {
        return Ok(Outcome::ok(serde_json::to_string_pretty(&json)? + "\n"));
    }
    Ok(Outcome::ok(text(&json, o.on.degrees)))
}

fn row(v: &[f64; 6]) -> String {
    // No "-0.00000" for a rounding residue.
    let clean = |x: f64| if x.abs() < 5e-6 { 0.0 } else { x };
    v.iter()
        .map(|x| format!("{:>10.5}", clean(*x)))
        .collect::<Vec<_>>()
        .join("")
}

fn text(j: &StructureJson, degrees: bool) -> String {
    let mut t = String::new();
    match j.pose {
        Some(p) => {
            let unit = if degrees { "deg" } else { "rad" };
            let list: Vec<String> = p.iter().map(|x| format!("{x}")).collect();
            let _ = writeln!(t, "{} at pose {} (m, {unit})", j.mechanism, list.join(", "));
        }
        None => {
            let _ = writeln!(
                t,
                "{}: the source's chain at its coordinates, B = (1, 0, 0)",
                j.mechanism
            );
        }
    }
    let m = &j.mobility;
    let mut terms = format!("W = 6*{}", m.moving_links);
    for (k, p) in [(5, m.p5), (4, m.p4), (3, m.p3), (2, m.p2), (1, m.p1)] {
        if p > 0 {
            let _ = write!(terms, " - {k}*{p}");
        }
    }
    let _ = writeln!(t, "mobility {terms} = {}", m.w);
    if m.without_pins != m.w {
        let _ = writeln!(
            t,
            "  (with plain spherical pairs instead of the pinned ones: W = {}, the rods' idle spins)",
            m.without_pins
        );
    }
    for (i, c) in j.chains.iter().enumerate() {
        let _ = writeln!(
            t,
            "chain {} ({}): unit screws [direction; moment about O], * driven",
            i + 1,
            c.pairs.join("-")
        );
        for (label, s) in c.joints.iter().zip(&c.unit_screws) {
            let _ = writeln!(t, "  {label:<6}{}", row(s));
        }
        match (c.determinant, c.determinant_unit) {
            (Some(d), Some(u)) => {
                let verdict = if u.abs() < 1e-9 {
                    "singular: the joints' screws are dependent, the chain loses a freedom (type 1)"
                } else {
                    "not zero: workable"
                };
                let _ = write!(t, "  determinant {:.6} ({verdict})", d + 0.0);
                if (d - u).abs() > 1e-12 {
                    let _ = write!(
                        t,
                        "; the source's form (the prismatic screw written as B -> A); {:.6} with unit screws",
                        u + 0.0
                    );
                }
                let _ = writeln!(t);
            }
            _ => {
                let _ = writeln!(t, "  no determinant: {} joints, not six", c.unit_screws.len());
            }
        }
        let _ = writeln!(
            t,
            "  transmits {} wrench(es) reciprocal to its unactuated joints ({} constraint(s) first):",
            c.wrenches.len(),
            c.constraints
        );
        for w in &c.wrenches {
            let _ = writeln!(t, "  {:<6}{}", "", row(w));
        }
    }
    if let Some(p) = j.published {
        let _ = writeln!(t, "the source prints {p}");
    }
    match j.determinant {
        Some(d) => {
            let verdict = if d.abs() < 1e-9 {
                "singular: the platform has an uncontrolled freedom (type 2)"
            } else {
                "not zero: workable"
            };
            let _ = writeln!(t, "wrench determinant of the mechanism {:.6} ({verdict})", d + 0.0);
        }
        None if j.chains.len() > 1 => {
            let _ = writeln!(t, "no wrench determinant: the chains do not transmit six wrenches");
        }
        None => {}
    }
    t
}

//! `ringpod cue --compare A.toml B.toml --input DRIVE...`: two cueing files on the same drives and the same
//! platform, scored by what the rider perceives ([`score`]), printed as a table and written as JSON, with a
//! picture of the perceived forces. `--tune` first searches the first file's classical washout for the best score
//! on the same drives and envelope ([`tune`]), so that a comparison is against the best classical tuning.
//! `--floor` adds the least error any motion inside the envelope's ranges can give ([`super::optimal::floor`]),
//! so that both are measured against what the rig allows, not only against each other.

mod floors;
#[cfg(test)]
pub mod laps;
mod picture;
pub mod score;
pub mod tune;

use std::path::{Path, PathBuf};

use ringpod_core::cueing::{Algorithm, CueConfig};
use ringpod_core::kinematics::{Pose, RingPlatform};
use serde::Serialize;

use super::offline::{read_drive, replay, CueError, Preview};
use super::optimal::{Counts, Envelope, Ranges};
use crate::analysis::mechanism::{AnyMechanism, Selected};
use crate::error::CliError;
use crate::input::cueing::load_config;
use floors::{floor_of, FloorReport};
use score::{score_from, Score, Trace};

/// What the bench is asked to do.
pub struct Options<'a> {
    /// The two cueing files compared.
    pub configs: [&'a Path; 2],
    /// The drives (telemetry CSV or packet captures).
    pub inputs: &'a [PathBuf],
    /// The report (JSON).
    pub out: &'a Path,
    /// The picture of the perceived forces (SVG or PNG).
    pub plot: Option<&'a Path>,
    /// Tune the first file's classical washout first.
    pub tune: bool,
    /// Print the report as JSON rather than a table.
    pub json: bool,
    /// What the optimal cueing sees ahead: with [`Preview::Lap`] the second file is cued both live and with the
    /// lap preview.
    pub preview: Preview,
    /// Add the floor: the least error any motion inside the ranges can give, the whole drive known.
    pub floor: bool,
    /// With the floor: also the floor inside the outer polytope of the rig's whole envelope.
    pub envelope_floor: bool,
    /// The platform: a preset by name...
    pub mechanism: &'a str,
    /// ...or a rig file.
    pub geometry: Option<&'a Path>,
}

/// One algorithm on every drive.
#[derive(Debug, Clone, Serialize)]
pub struct Entry {
    /// The cueing file (and `tuned` for the tuned classical washout).
    pub name: String,
    /// Its algorithm.
    pub algorithm: Algorithm,
    /// Each drive's score, in the order of the drives.
    pub drives: Vec<Score>,
    /// All drives together: RMS over every sample, peaks and envelope shares the largest, false cues summed.
    pub total: Score,
    /// Poses the envelope limiter changed.
    pub limited: usize,
    /// The optimal cueing's fallbacks (none for the washout): samples where an axis fell back, axes that
    /// followed their last plan, axes that took the classical washout's change.
    pub fallbacks: Option<[usize; 3]>,
    /// The optimal cueing's solve time per sample, all axes: p50, p99, max (ms).
    pub solve_ms: Option<[f64; 3]>,
    /// The lap preview's counts, every drive together.
    pub lap: Option<LapCounts>,
}

/// The bench's report.
#[derive(Debug, Serialize)]
pub struct Report {
    /// The drives, as given.
    pub drives: Vec<String>,
    /// The platform.
    pub mechanism: String,
    /// The envelope about home the optimal cueing planned in: x, y, z (m), roll, pitch (rad).
    pub ranges: Ranges,
    /// The tuned classical washout's file, when `--tune` ran.
    pub tuned: Option<String>,
    /// The algorithms compared.
    pub entries: Vec<Entry>,
    /// With `--floor`: the least error any motion inside the ranges can give.
    pub floor: Option<FloorReport>,
    /// Each drive's first sample scored: a drive with a lap distance is scored from its second lap on (the
    /// first has no lap before it to preview from), every other from its start.
    pub scored_from: Vec<usize>,
}

/// A drive's rows.
pub type Rows = Vec<(usize, Vec<f64>)>;

/// The platform a bench runs on.
pub struct Rig {
    /// The mechanism.
    pub mechanism: RingPlatform<f64>,
    /// Its home (the neutral pose).
    pub neutral: Pose<f64>,
    /// Its envelope about home.
    pub envelope: Envelope,
}

/// The lap preview's counts of every drive.
pub type LapCounts = super::lap::Counts;

/// Cues every drive by `config` and scores it from its sample `from[i]` on; with each drive's perceived forces.
pub fn evaluate(
    name: &str,
    config: CueConfig,
    drives: &[Rows],
    from: &[usize],
    rig: &Rig,
    preview: Preview,
) -> Result<(Entry, Vec<Vec<Trace>>), CueError> {
    let mut scores = Vec::new();
    let mut traces = Vec::new();
    let (mut limited, mut counts) = (0, Counts::default());
    let mut lap: Option<LapCounts> = None;
    for (d, rows) in drives.iter().enumerate() {
        let r = replay(rows, config, &rig.mechanism, &rig.neutral, &rig.envelope, preview)?;
        let first = from.get(d).copied().unwrap_or(0);
        let (s, t) = score_from(&r.cued, first, &rig.neutral, &rig.envelope.ranges, config.forward);
        limited += r.limited;
        if let Some(c) = &r.counts {
            counts.add(c);
        }
        if let Some(c) = r.lap {
            let sum = lap.get_or_insert_with(LapCounts::default);
            sum.laps += c.laps;
            sum.kept += c.kept;
            sum.departures += c.departures;
            sum.bad_distance += c.bad_distance;
            sum.previewed_s += c.previewed_s;
            sum.departed_s += c.departed_s;
        }
        scores.push(s);
        traces.push(t);
    }
    let optimal = config.algorithm == Algorithm::Optimal;
    Ok((
        Entry {
            name: name.to_owned(),
            algorithm: config.algorithm,
            total: combined(&scores),
            drives: scores,
            limited,
            fallbacks: optimal.then_some([counts.fallbacks, counts.followed_plan, counts.took_classical]),
            solve_ms: optimal.then(|| counts.solve_ms()),
            lap,
        },
        traces,
    ))
}

/// The scores of several drives as one: RMS weighted by samples, the largest peaks and shares, the sums.
fn combined(scores: &[Score]) -> Score {
    let mut t = Score::default();
    let n: usize = scores.iter().map(|s| s.samples).sum();
    let rms = |f: &dyn Fn(&Score) -> f64| {
        (scores.iter().map(|s| f(s).powi(2) * s.samples as f64).sum::<f64>() / n.max(1) as f64).sqrt()
    };
    t.samples = n;
    for i in 0..3 {
        t.force_rms[i] = rms(&|s| s.force_rms[i]);
        t.rotation_rms[i] = rms(&|s| s.rotation_rms[i]);
        t.force_peak[i] = scores.iter().map(|s| s.force_peak[i]).fold(0.0, f64::max);
        for s in scores {
            t.false_force[i].count += s.false_force[i].count;
            t.false_force[i].seconds += s.false_force[i].seconds;
        }
    }
    for s in scores {
        for i in 0..2 {
            t.false_rotation[i].count += s.false_rotation[i].count;
            t.false_rotation[i].seconds += s.false_rotation[i].seconds;
        }
        for i in 0..5 {
            t.envelope_share[i] = t.envelope_share[i].max(s.envelope_share[i]);
        }
    }
    t
}

/// Runs the bench; returns the report as text (a table, or JSON) and the exit code.
pub fn run(args: &Options) -> Result<(String, u8), CueError> {
    let mut inputs: Vec<&Path> = args.inputs.iter().map(PathBuf::as_path).collect();
    inputs.extend(args.configs);
    inputs.extend(args.geometry);
    let outputs: Vec<&Path> = [Some(args.out), args.plot].into_iter().flatten().collect();
    crate::out::file::check_outputs(&outputs, &inputs).map_err(|(out, e)| CliError::file(out, e))?;
    let configs = [0, 1].map(|i| load_config(Some(args.configs[i]), None));
    let [a, b] = configs;
    let (a, b) = (a.map_err(CliError::from)?, b.map_err(CliError::from)?);
    let selected = Selected::of(args.mechanism, args.geometry)?;
    let AnyMechanism::Ring(mechanism) = selected.mechanism else {
        return Err(CliError::NotARing(selected.name).into());
    };
    let neutral = Pose::from_array(selected.home);
    let rig = Rig {
        envelope: super::engine::envelope(&mechanism, &neutral).map_err(|check| CliError::NeutralOutside {
            name: selected.name.clone(),
            check,
        })?,
        mechanism: *mechanism,
        neutral,
    };
    let drives: Vec<Rows> = args.inputs.iter().map(|p| read_drive(p)).collect::<Result<_, _>>()?;
    let from: Vec<usize> = drives.iter().map(second_lap).collect();
    let name = |p: &Path| {
        p.file_name()
            .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into())
    };
    let mut entries = Vec::new();
    let mut traces = Vec::new();
    let mut tuned = None;
    let first = if args.tune && a.algorithm == Algorithm::Classical {
        let best = tune::tune(a, &drives, &from, &rig)?;
        tuned = Some(toml::to_string(&best).map_err(|e| CueError::Input {
            path: args.configs[0].to_path_buf(),
            reason: e.to_string(),
        })?);
        (format!("{} (tuned)", name(args.configs[0])), best)
    } else {
        (name(args.configs[0]), a)
    };
    let second = name(args.configs[1]);
    let mut runs = vec![(first.0, first.1, Preview::None)];
    match args.preview {
        Preview::Lap => {
            runs.push((second.clone(), b, Preview::None));
            runs.push((format!("{second} (lap preview)"), b, Preview::Lap));
        }
        p => runs.push((second.clone(), b, p)),
    }
    for (n, c, p) in runs {
        let (e, t) = evaluate(&n, c, &drives, &from, &rig, p)?;
        entries.push(e);
        traces.push(t);
    }
    let mut floor = None;
    if args.floor {
        let optimal = (b.algorithm == Algorithm::Optimal).then_some(&b);
        let (report, motions) = floor_of(&drives, &from, &rig, a.forward, args.envelope_floor, optimal)?;
        floor = Some(report);
        for (what, m) in motions {
            entries.push(Entry {
                name: format!("floor within {second}'s {what} (its motion)"),
                algorithm: Algorithm::Optimal,
                total: combined(&m.drives),
                drives: m.drives,
                limited: m.limited,
                fallbacks: None,
                solve_ms: None,
                lap: None,
            });
            traces.push(m.traces);
        }
    }
    let report = Report {
        drives: args.inputs.iter().map(|p| p.display().to_string()).collect(),
        mechanism: selected.name,
        ranges: rig.envelope.ranges,
        tuned,
        entries,
        floor,
        scored_from: from,
    };
    let json = serde_json::to_string_pretty(&report).map_err(CliError::from)? + "\n";
    crate::out::file::write(args.out, json.as_bytes()).map_err(|reason| CueError::Output {
        path: args.out.to_path_buf(),
        reason,
    })?;
    if let Some(plot) = args.plot {
        picture::draw(plot, &report, &traces).map_err(CliError::from)?;
    }
    let text = if args.json { json } else { table(&report) };
    Ok((text, 0))
}

/// The index of a drive's second lap's first sample: where its lap distance (a row's eighth value) first wraps
/// (falls by more than half of the largest distance before it); 0 for a drive without one.
pub fn second_lap(rows: &Rows) -> usize {
    let mut top = f64::NEG_INFINITY;
    for (k, (_, v)) in rows.iter().enumerate() {
        let Some(&s) = v.get(7).filter(|s| s.is_finite()) else {
            continue;
        };
        if top > 0.0 && s < top - 0.5 * top {
            return k;
        }
        top = top.max(s);
    }
    0
}

/// The report as a table: one column per algorithm.
fn table(r: &Report) -> String {
    let mut s = format!(
        "{} drive(s) on {}: {}\n",
        r.drives.len(),
        r.mechanism,
        r.drives.join(", ")
    );
    if r.scored_from.iter().any(|&k| k > 0) {
        s += &format!(
            "scored from each drive's second lap (its first sample scored: {:?})\n",
            r.scored_from
        );
    }
    let row = |label: &str, f: &dyn Fn(&Entry) -> String| {
        let mut line = format!("{label:<44}");
        for e in &r.entries {
            line += &format!("{:>26}", f(e));
        }
        line + "\n"
    };
    s += &row("", &|e| e.name.clone());
    s += &row("algorithm", &|e| format!("{:?}", e.algorithm).to_lowercase());
    let v3 = |v: [f64; 3]| format!("{:.3} {:.3} {:.3}", v[0], v[1], v[2]);
    s += &row("perceived force error RMS x y z (m/s^2)", &|e| v3(e.total.force_rms));
    s += &row("  all axes (m/s^2)", &|e| format!("{:.3}", e.total.force_total()));
    s += &row("perceived force error peak x y z (m/s^2)", &|e| v3(e.total.force_peak));
    s += &row("perceived rotation error RMS r p y (rad/s)", &|e| {
        v3(e.total.rotation_rms)
    });
    s += &row("false cues x y z roll pitch (count)", &|e| {
        let f = &e.total;
        format!(
            "{} {} {} {} {}",
            f.false_force[0].count,
            f.false_force[1].count,
            f.false_force[2].count,
            f.false_rotation[0].count,
            f.false_rotation[1].count
        )
    });
    s += &row("false cues, time (s)", &|e| {
        let f = &e.total;
        let t: f64 = f.false_force.iter().chain(&f.false_rotation).map(|c| c.seconds).sum();
        format!("{t:.2}")
    });
    s += &row("envelope used x y z r p (share)", &|e| {
        let v = e.total.envelope_share;
        format!("{:.2} {:.2} {:.2} {:.2} {:.2}", v[0], v[1], v[2], v[3], v[4])
    });
    s += &row("envelope limiter interventions", &|e| e.limited.to_string());
    s += &row("fallbacks (axes: last plan, washout)", &|e| {
        e.fallbacks
            .map_or("-".into(), |[n, plan, washout]| format!("{n} ({plan}, {washout})"))
    });
    s += &row("solve time p50 p99 max (ms)", &|e| {
        e.solve_ms
            .map_or("-".into(), |t| format!("{:.3} {:.3} {:.3}", t[0], t[1], t[2]))
    });
    if r.entries.iter().any(|e| e.lap.is_some()) {
        s += &row("lap preview: laps (kept), departures", &|e| {
            e.lap
                .map_or("-".into(), |c| format!("{} ({}), {}", c.laps, c.kept, c.departures))
        });
        s += &row("lap preview: previewed, departed (s)", &|e| {
            e.lap
                .map_or("-".into(), |c| format!("{:.1}, {:.1}", c.previewed_s, c.departed_s))
        });
    }
    s + &floors_and_ratios(r)
}

/// The table's last lines: the floors, and each entry's force error against the first's and the floor's.
fn floors_and_ratios(r: &Report) -> String {
    let mut s = String::new();
    if let Some(f) = &r.floor {
        let [x, y, z] = f.figures.force_rms;
        s += &format!(
            "floor: the least perceived force error RMS x y z, all axes, of any motion inside the ranges \
             (the optimiser's model, the whole drive known): {x:.3} {y:.3} {z:.3}, {:.3} m/s^2\n",
            f.figures.force_total
        );
        if let Some(e) = &f.envelope {
            let [x, y, z] = e.figures.force_rms;
            s += &format!(
                "floor inside the envelope's outer polytope ({} faces, the axes coupled): {x:.3} {y:.3} {z:.3}, \
                 {:.3} m/s^2\n",
                e.faces, e.figures.force_total
            );
        }
        if let Some(l) = &f.limits {
            let [x, y, z] = l.force_rms;
            s += &format!(
                "floor within the optimal cueing's own limits (its shares, velocity, acceleration and rate \
                 limits, its rotation error priced): {x:.3} {y:.3} {z:.3}, {:.3} m/s^2\n",
                l.force_total
            );
        }
        if let Some(l) = &f.envelope_limits {
            let [x, y, z] = l.force_rms;
            s += &format!(
                "floor inside the envelope's outer polytope within the optimal cueing's velocity, acceleration \
                 and rate limits, its rotation error priced: {x:.3} {y:.3} {z:.3}, {:.3} m/s^2\n",
                l.force_total
            );
        }
    }
    if let [a, rest @ ..] = r.entries.as_slice() {
        for b in rest {
            let ratio = b.total.force_total() / a.total.force_total().max(1e-12);
            s += &format!(
                "{} / {} perceived force error (RMS, all axes): {ratio:.3}\n",
                b.name, a.name
            );
        }
        if let Some(f) = &r.floor {
            let ratio = f.figures.force_total / a.total.force_total().max(1e-12);
            s += &format!("floor / {} perceived force error (RMS, all axes): {ratio:.3}\n", a.name);
            for b in rest {
                let ratio = b.total.force_total() / f.figures.force_total.max(1e-12);
                s += &format!("{} / floor perceived force error (RMS, all axes): {ratio:.3}\n", b.name);
            }
            if let Some(l) = &f.limits {
                let ratio = l.force_total / a.total.force_total().max(1e-12);
                s += &format!(
                    "floor within the limits / {} perceived force error (RMS, all axes): {ratio:.3}\n",
                    a.name
                );
                let ratio = l.force_total / f.figures.force_total.max(1e-12);
                s += &format!("floor within the limits / floor perceived force error (RMS, all axes): {ratio:.3}\n");
            }
            if let Some(e) = &f.envelope {
                let ratio = e.figures.force_total / a.total.force_total().max(1e-12);
                s += &format!(
                    "envelope floor / {} perceived force error (RMS, all axes): {ratio:.3}\n",
                    a.name
                );
            }
        }
    }
    s
}

#[cfg(test)]
mod tests;

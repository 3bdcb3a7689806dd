//! `ringpod rig check` and `ringpod presets --export`.

use std::fmt::Write as _;
use std::path::Path;

use ringpod_core::kinematics::geometry::RingGeometry;
use ringpod_core::kinematics::presets::{Preset, PresetGeometry};
use ringpod_core::kinematics::RingPlatform;
use serde::Serialize;

use super::coverage::Coverage;
use super::design::{design, Free, Search, Target};
use super::RigError;
use super::{coverage, read, RigFile};
use crate::input::numbers::BadNumber;
use crate::out::{Outcome, EXIT_CHECK_FAILED};

/// A `--mechanism` (or `presets --export`) name that is no preset.
#[derive(Debug, thiserror::Error)]
#[error("unknown mechanism `{0}`; `ringpod presets` lists them")]
pub struct UnknownMechanism(pub String);

/// Why `rig check`, `rig design` or `presets --export` had no answer, or a preset has no rig; `CliError` says each
/// as its variant of the same name does.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// No preset of that name.
    #[error(transparent)]
    UnknownMechanism(#[from] UnknownMechanism),
    /// A preset that is no ring platform, or a rig file that cannot be written.
    #[error(transparent)]
    Number(#[from] BadNumber),
    /// The rig file is not valid.
    #[error(transparent)]
    Rig(#[from] RigError),
    /// JSON output failed.
    #[error("JSON output: {0}")]
    Json(#[from] serde_json::Error),
}

/// The axes of the spec ranges, in their order.
const AXES: [&str; 5] = ["surge", "sway", "heave", "roll", "pitch"];

/// `ringpod presets --export NAME`: the preset as a rig file, to start one's own from.
pub fn export(name: &str) -> Result<Outcome, CommandError> {
    let (preset, file) = preset_file(name, "export")?;
    let body = file.to_toml().map_err(|e| BadNumber::new("export", e.to_string()))?;
    let header = format!(
        "# {name}: {}\n# Lengths in metres, angles of [limits] and [spec] in degrees, home = [x, y, z, roll, pitch, yaw]\n\
         # (m, rad). Chains counter-clockwise around the ring; actuators: every carriage in chain order, then every\n\
         # radial length, then every elbow chain's shoulder angle. Check with `ringpod rig check FILE`, use with `--geometry FILE`.\n",
        preset.description()
    );
    Ok(Outcome::ok(header + &body))
}

/// A preset ring platform as the rig file `presets --export` writes.
fn preset_file(name: &str, what: &'static str) -> Result<(Preset, RigFile), CommandError> {
    let preset = Preset::from_name(name).ok_or_else(|| UnknownMechanism(name.to_owned()))?;
    let PresetGeometry::Ring(g) = preset.geometry() else {
        return Err(BadNumber::new(
            what,
            format!("{name} is not a ring platform; rig files describe ring platforms"),
        )
        .into());
    };
    let ranges = preset.spec_ranges();
    Ok((
        preset,
        RigFile::of(g, preset.home(), ranges, super::drives::of_preset(preset)),
    ))
}

/// The rig a simulated controller runs for a preset (`stream --sim --mechanism`, `simulate --mechanism`): none for
/// the trainer model, whose configuration is compiled in; for another ring platform, its rig file with the trainer
/// model's drives and switches, checked as `--geometry` checks a file.
pub fn preset(name: &str) -> Result<Option<super::Rig>, CommandError> {
    let (preset, file) = preset_file(name, "mechanism")?;
    if preset == Preset::TrainerModel {
        return Ok(None);
    }
    Ok(Some(file.check().map_err(|e| e.in_file(Path::new(name)))?))
}

#[derive(Serialize)]
struct AxisJson {
    axis: &'static str,
    range: f64,
    inside: usize,
    tried: usize,
}

#[derive(Serialize)]
struct CheckJson<'a> {
    name: &'a str,
    /// Kept for scripts that read it: a valid mechanism (analysable).
    valid: bool,
    analysable: bool,
    drivable: bool,
    not_drivable_because: Option<String>,
    spec_covered: Option<bool>,
    per_axis: Vec<AxisJson>,
    combined_inside: Option<usize>,
    combined_tried: Option<usize>,
}

/// `ringpod rig check FILE`: the verdict, and the spec coverage when the file gives spec ranges.
pub fn check_command(path: &Path, json: bool) -> Result<Outcome, CommandError> {
    let file = read(path)?;
    // Not a mechanism at all: an error, as for every command. A mechanism that cannot be driven is a verdict.
    let rig = file.platform().map_err(|e| e.in_file(path))?;
    // Drivable: the controller accepts the rig and homes it, in the simulated machine, within a bounded time.
    let drivable = file.drivable().map(|_| ()).map_err(|e| e.to_string());
    let m = RingPlatform::<f64>::new(&rig.geometry);
    let cover = rig.ranges.map(|r| (r, coverage(&m, &rig.home, &r)));
    let covered = cover
        .as_ref()
        .map(|(_, c)| c.per_axis.iter().all(|(inside, tried)| inside == tried));
    let code = if covered == Some(false) || drivable.is_err() {
        EXIT_CHECK_FAILED
    } else {
        0
    };
    let name = rig.geometry.name;
    if json {
        let out = CheckJson {
            name,
            valid: true,
            analysable: true,
            drivable: drivable.is_ok(),
            not_drivable_because: drivable.as_ref().err().cloned(),
            spec_covered: covered,
            per_axis: cover
                .iter()
                .flat_map(|(r, c)| {
                    (0..5).map(move |i| AxisJson {
                        axis: AXES[i],
                        range: r[i],
                        inside: c.per_axis[i].0,
                        tried: c.per_axis[i].1,
                    })
                })
                .collect(),
            combined_inside: cover.as_ref().map(|(_, c)| c.combined.0),
            combined_tried: cover.as_ref().map(|(_, c)| c.combined.1),
        };
        return Ok(Outcome {
            text: serde_json::to_string_pretty(&out)? + "\n",
            code,
        });
    }
    Ok(Outcome {
        text: check_text(&rig.geometry, &drivable, cover.as_ref(), covered),
        code,
    })
}

/// `rig check`'s verdict as text: analysable, drivable or why not, and the spec coverage axis by axis.
fn check_text(
    g: &RingGeometry,
    drivable: &Result<(), String>,
    cover: Option<&([f64; 5], Coverage)>,
    covered: Option<bool>,
) -> String {
    let name = g.name;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{name}: analysable: yes ({} chains, ring radius {} m, rod {} m)",
        g.chains().len(),
        crate::input::numbers::readable(g.ring_radius),
        crate::input::numbers::readable(g.rod_length)
    );
    let _ = match drivable {
        Ok(()) => writeln!(
            t,
            "drivable: yes (the home pose is inside every check; homing plan and step timing accepted; it homes in \
             the simulated machine)"
        ),
        Err(why) => writeln!(t, "drivable: no, because {why}"),
    };
    match cover {
        None => {
            let _ = writeln!(t, "no [spec] ranges: add them to measure the coverage");
        }
        Some((r, c)) => {
            let _ = writeln!(
                t,
                "spec coverage (each axis alone: 41 steps at 36 yaws; inside every check):"
            );
            for i in 0..5 {
                let (inside, tried) = c.per_axis[i];
                let range = if i < 3 {
                    format!("+-{:.4} m", r[i])
                } else {
                    format!("+-{:.2} deg", r[i].to_degrees())
                };
                let _ = writeln!(
                    t,
                    "  {:<6} {:<14} {inside:>5} of {tried} ({:.1} %)",
                    AXES[i],
                    range,
                    100.0 * inside as f64 / tried as f64
                );
            }
            let (inside, tried) = c.combined;
            let _ = writeln!(
                t,
                "  all axes at once (corners at 8 yaws, random poses at any yaw): {inside} of {tried} ({:.1} %)",
                100.0 * inside as f64 / tried as f64
            );
            let _ = writeln!(
                t,
                "{}",
                if covered == Some(true) {
                    "every axis is covered over its whole range"
                } else {
                    "NOT covered: some axis leaves the workspace within its range"
                }
            );
        }
    }
    t
}

/// `ringpod rig design TEMPLATE`: the best dimensions found, as a rig file, with its coverage in comments.
pub fn design_command(
    path: &Path,
    combined: bool,
    arms_only: bool,
    starts: u32,
    steps: u32,
    seed: u64,
) -> Result<Outcome, CommandError> {
    let template = read(path)?;
    // A template that is no mechanism (a length not a positive finite number, a chain without its keys) is refused
    // by its key, as `rig check` refuses it, before the search scales anything by it.
    template.platform().map_err(|e| e.in_file(path))?;
    let search = Search {
        target: if combined { Target::Combined } else { Target::EachAxis },
        free: if arms_only { Free::Arms } else { Free::All },
        starts,
        steps,
        seed,
    };
    let found = design(&template, &search)?;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Designed by `ringpod rig design` ({} starts x {} steps, seed {seed}, covering {}): score {:.3}",
        starts,
        steps,
        if combined {
            "all spec axes at once"
        } else {
            "each spec axis alone"
        },
        found.score
    );
    let _ = writeln!(
        out,
        "# (the smallest margin over the spec poses in units of 5 mm, 0.1 rad, 0.05 index; >= 0: inside)"
    );
    let covers = match found.file.check() {
        Ok(rig) => {
            let m = RingPlatform::<f64>::new(&rig.geometry);
            if let Some(r) = rig.ranges {
                let c = coverage(&m, &rig.home, &r);
                for (i, (inside, tried)) in c.per_axis.iter().enumerate() {
                    let _ = writeln!(out, "# {:<6} {inside} of {tried} spec poses inside", AXES[i]);
                }
                let _ = writeln!(out, "# all at once: {} of {} inside", c.combined.0, c.combined.1);
                let axes = c.per_axis.iter().all(|(a, b)| a == b);
                if combined {
                    axes && c.combined.0 == c.combined.1
                } else {
                    axes
                }
            } else {
                false
            }
        }
        // Only a rig that `rig check` would call drivable is printed.
        Err(e) => {
            return Err(RigError::new(
                e.key,
                format!(
                    "the best candidate found is not a drivable rig, so none is printed: {}",
                    e.why
                ),
            )
            .in_file(path)
            .into())
        }
    };
    let body = found
        .file
        .to_toml()
        .map_err(|e| BadNumber::new("design", e.to_string()))?;
    Ok(Outcome {
        text: out + &body,
        code: if covers { 0 } else { EXIT_CHECK_FAILED },
    })
}

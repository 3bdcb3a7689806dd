//! `ringpod cue`: vehicle telemetry to platform poses by the core's classical washout, every pose limited into the
//! envelope, written as the pose CSV that `ringpod stream --input` reads, with an optional plot of the cues.

use std::io::Write;
use std::path::Path;

use plotters::style::colors::{BLACK, BLUE, CYAN, GREEN, MAGENTA, RED};
use ringpod_core::cueing::{self, SampleError, Telemetry};
use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::{envelope, EnvelopeMargins};
use serde::Serialize;

use super::engine::Pause;
pub use super::error::CueError;
pub use super::lap::{Preview, LAP_DISTANCE};
use crate::analysis::mechanism::{AnyMechanism, Selected};
use crate::error::CliError;
use crate::input::cueing::load_config;
use crate::input::table::{self, InputError};
use crate::out::plot::PlotError;
use crate::out::plot::{self, Panel, Series, TimePlot};

/// The columns of a telemetry file.
pub const TELEMETRY_COLUMNS: [&str; 7] = ["t", "ax", "ay", "az", "wx", "wy", "wz"];

/// Exit code when input rows could not be used (the rest was cued).
pub const EXIT_INPUT_ERRORS: u8 = 3;

/// What `cue` did.
#[derive(Debug, Serialize)]
pub struct Summary {
    /// Telemetry rows read.
    pub rows: usize,
    /// Poses written (one per row read).
    pub poses: usize,
    /// Poses the envelope limited.
    pub limited: usize,
    /// Rows that could not be used: unreadable, not finite (the platform held), or not after the row before.
    pub input_errors: Vec<InputError>,
    /// Pauses of more than a second (the washout rested through them and started again at neutral): not errors.
    pub pauses: Vec<Pause>,
    /// A packet capture's input: what it held (its input errors are numbered by packet).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture: Option<super::capture::CaptureSummary>,
    /// The optimal cueing's samples planned and its fallbacks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub optimal: Option<super::optimal::Counts>,
    /// The lap preview's counts, with `--preview lap`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lap: Option<super::lap::Counts>,
}

/// One cued sample, for the output and the plot.
pub struct Cued {
    /// Its time (s).
    pub t: f64,
    /// The vehicle's specific force and rates.
    pub input: Telemetry<f64>,
    /// The platform's pose, limited into the envelope.
    pub pose: Pose<f64>,
}

/// A drive cued: every sample, how many the envelope limited, and the rows that could not be used.
pub struct Replay {
    /// Every row's sample.
    pub cued: Vec<Cued>,
    /// Poses the envelope limited.
    pub limited: usize,
    /// Rows that could not be used, by line.
    pub errors: Vec<InputError>,
    /// Pauses of more than a second, each ended by its line.
    pub pauses: Vec<Pause>,
    /// The optimal cueing's counts (solves, fallbacks, solve times); none for the classical washout.
    pub counts: Option<super::optimal::Counts>,
    /// The lap preview's counts, with [`Preview::Lap`].
    pub lap: Option<super::lap::Counts>,
}

/// What `cue` is asked to do.
pub struct Options<'a> {
    /// The telemetry CSV, or a packet capture (pcap, pcapng) of a game's telemetry.
    pub input: &'a Path,
    /// A capture's telemetry format (`auto` without).
    pub telemetry_format: Option<crate::games::TelemetryFormat>,
    /// A capture: its datagrams to this UDP port only.
    pub udp_port: Option<u16>,
    /// A capture: Live for Speed's `OutSim Opts`, when given.
    pub outsim_opts: Option<crate::games::outsim2::Opts>,
    /// The pose CSV to write.
    pub out: &'a Path,
    /// Washout parameters (TOML); the defaults without.
    pub config: Option<&'a Path>,
    /// A profile of the cueing file (`[profiles.NAME]`).
    pub profile: Option<&'a str>,
    /// A plot of the cues (SVG).
    pub plot: Option<&'a Path>,
    /// The summary as JSON.
    pub json: bool,
    /// What the optimal cueing sees ahead: the sample held, the drive's next samples, or the laps before.
    pub preview: Preview,
    /// The platform: a preset by name...
    pub mechanism: &'a str,
    /// ...or a rig file.
    pub geometry: Option<&'a Path>,
}

/// Runs the command; returns the summary as text and the exit code.
pub fn run(args: &Options) -> Result<(String, u8), CueError> {
    // An output that is the input (or the cueing file) would destroy it: refused before anything is read.
    let inputs: Vec<&Path> = [Some(args.input), args.config, args.geometry]
        .into_iter()
        .flatten()
        .collect();
    let outputs: Vec<&Path> = [Some(args.out), args.plot].into_iter().flatten().collect();
    crate::out::file::check_outputs(&outputs, &inputs).map_err(|(out, e)| CliError::file(out, e))?;
    let config = load_config(args.config, args.profile).map_err(CliError::from)?;
    let (rows, mut errors, capture) = read_input(args)?;
    let selected = Selected::of(args.mechanism, args.geometry)?;
    let AnyMechanism::Ring(mechanism) = selected.mechanism else {
        return Err(CliError::NotARing(selected.name).into());
    };
    let neutral = Pose::from_array(selected.home);
    let envelope = super::engine::envelope(&mechanism, &neutral).map_err(|check| CliError::NeutralOutside {
        name: selected.name.clone(),
        check,
    })?;
    let Replay {
        cued,
        limited,
        errors: mut cue_errors,
        counts,
        pauses,
        lap,
    } = replay(&rows, config, &mechanism, &neutral, &envelope, args.preview)?;
    errors.append(&mut cue_errors);
    errors.sort_by_key(|e| e.line);
    write_poses(args.out, &cued)?;
    if let Some(plot) = &args.plot {
        draw(plot, &cued, &neutral).map_err(CliError::from)?;
    }
    let summary = Summary {
        rows: rows.len(),
        poses: cued.len(),
        limited,
        input_errors: errors,
        pauses,
        capture,
        optimal: counts,
        lap,
    };
    let code = if summary.input_errors.is_empty() && summary.rows > 0 {
        0
    } else {
        EXIT_INPUT_ERRORS
    };
    let text = if args.json {
        serde_json::to_string_pretty(&summary).map_err(CliError::from)? + "\n"
    } else {
        let mut s = format!(
            "{} rows, {} poses written to {} ({} limited into the envelope)\n",
            summary.rows,
            summary.poses,
            args.out.display(),
            summary.limited
        );
        if let Some(o) = &summary.optimal {
            s += &format!(
                "optimal cueing: {} samples planned, {} fell back (axes that followed their last plan {}, that took \
                 the classical washout's change {}); {} took longer than the budget\n",
                o.samples, o.fallbacks, o.followed_plan, o.took_classical, o.late
            );
        }
        if let Some(c) = &summary.lap {
            s += &c.describe();
        }
        if let Some(c) = &summary.capture {
            s += &format!(
                "{}: {} packets, {} UDP datagrams read as {}; skipped: {:?}\n",
                c.file_format, c.packets, c.datagrams, c.telemetry_format, c.skipped
            );
        }
        let unit = if summary.capture.is_some() { "packet" } else { "line" };
        for p in &summary.pauses {
            s += &format!(
                "{unit} {}: after a pause of {:.1} s, cued again from neutral\n",
                p.line, p.seconds
            );
        }
        for e in &summary.input_errors {
            s += &format!("{unit} {}: {}\n", e.line, e.reason);
        }
        s
    };
    Ok((text, code))
}

/// Cues telemetry rows (`t, ax, ay, az, wx, wy, wz`) by the washout of `config` on `mechanism` around `neutral`
/// (whose envelope about home is `envelope`, [`super::engine::envelope`]: scanned once by the caller, however
/// many configurations it replays), every pose limited into the envelope; `preview` says what the optimal
/// cueing's reference over its horizon is made of (a row's lap distance is its eighth value, when it has one).
pub fn replay(
    rows: &[(usize, Vec<f64>)],
    config: cueing::CueConfig,
    mechanism: &RingPlatform<f64>,
    neutral: &Pose<f64>,
    envelope: &super::optimal::Envelope,
    preview: Preview,
) -> Result<Replay, CueError> {
    let margins = EnvelopeMargins::default();
    let mut washout = super::engine::Engine::new(config, envelope).map_err(CueError::Washout)?;
    // A recorded drive's next samples, or the laps before, for the optimal cueing's preview.
    let horizon = washout.horizon();
    let drive_preview = horizon.filter(|_| preview == Preview::Drive);
    let mut laps = horizon
        .filter(|_| preview == Preview::Lap)
        .map(|_| super::lap::LapPreview::new(super::lap::Settings::default()));
    let (mut errors, mut pauses) = (Vec::new(), Vec::new());
    let mut cued: Vec<Cued> = Vec::with_capacity(rows.len());
    let mut limited = 0;
    let mut last_t: Option<f64> = None;
    let mut held = *neutral;
    for (line, v) in rows {
        let t = v[0];
        let sample = super::engine::row_sample(v);
        if let Some(laps) = laps.as_mut() {
            laps.observe(t, v.get(7).copied().unwrap_or(f64::NAN), &sample);
        }
        let offset = match last_t {
            // The first row (and the first after a gap) starts the washout at neutral and is its first input.
            None => washout.begin(&sample),
            Some(l) => {
                let ahead = match (drive_preview, horizon, &laps) {
                    (Some((n, h)), _, _) => super::engine::ahead(rows, t, n, h),
                    (None, Some((n, h)), Some(laps)) => laps.ahead(&sample, n, h),
                    _ => Vec::new(),
                };
                washout.step(&sample, t - l, &ahead)
            }
        };
        let dt = last_t.map_or(0.0, |l| t - l);
        last_t = Some(t);
        let pose = match offset {
            Ok(offset) => {
                let wanted = cueing::pose(neutral, &offset);
                let l = envelope::limit(mechanism, neutral, &wanted, &margins, 16);
                limited += usize::from(l.is_limited());
                l.pose
            }
            Err(e @ (SampleError::NonFinite | SampleError::Implausible)) => {
                errors.push(InputError {
                    line: *line,
                    reason: format!("{e}: the platform holds"),
                });
                held
            }
            Err(SampleError::Interval) if dt <= 0.0 => {
                errors.push(InputError {
                    line: *line,
                    reason: "its time is not after the row before's: the platform holds".into(),
                });
                held
            }
            Err(SampleError::Interval) => {
                // A pause (a game's menu): the washout has rested to neutral through it, and starts again here.
                pauses.push(Pause {
                    line: *line,
                    seconds: dt,
                });
                washout.reset();
                // This row starts the washout again: its first input.
                let _ = washout.begin(&sample);
                cueing::pose(neutral, &washout.offset())
            }
        };
        held = pose;
        cued.push(Cued { t, input: sample, pose });
    }
    Ok(Replay {
        cued,
        limited,
        errors,
        pauses,
        counts: washout.counts().cloned(),
        lap: laps.map(|l| l.counts()),
    })
}

/// A drive's telemetry rows (CSV, or a packet capture in its own format), for the bench; a row that cannot be
/// read refuses the drive (a bench scores whole drives).
pub fn read_drive(path: &Path) -> Result<Vec<(usize, Vec<f64>)>, CueError> {
    let args = Options {
        input: path,
        telemetry_format: None,
        udp_port: None,
        outsim_opts: None,
        out: path,
        config: None,
        profile: None,
        plot: None,
        json: false,
        preview: Preview::None,
        mechanism: "",
        geometry: None,
    };
    let (rows, errors, _) = read_input(&args)?;
    // A row the cueing would refuse is no drive to score: the vehicle's own perceived force is scored from it.
    let refused = rows
        .iter()
        .find_map(|(line, v)| cueing::check(&super::engine::row_sample(v)).err().map(|e| (*line, e)));
    if let Some((line, e)) = refused {
        return Err(CueError::Input {
            path: path.to_path_buf(),
            reason: format!("line {line}: {e}"),
        });
    }
    match errors.first() {
        // A drive of one sample has no interval to perceive anything over: its scores would be zeros, as
        // if the cueing were perfect.
        None if rows.len() < 2 => Err(CueError::Input {
            path: path.to_path_buf(),
            reason: format!("a drive to score needs two rows or more; it has {}", rows.len()),
        }),
        None => Ok(rows),
        Some(e) => Err(CueError::Input {
            path: path.to_path_buf(),
            reason: format!("line {}: {}", e.line, e.reason),
        }),
    }
}

/// The telemetry rows of the input: a CSV, or a packet capture ([`super::capture`]).
#[allow(clippy::type_complexity)]
fn read_input(
    args: &Options,
) -> Result<
    (
        Vec<(usize, Vec<f64>)>,
        Vec<InputError>,
        Option<super::capture::CaptureSummary>,
    ),
    CueError,
> {
    let bad = |reason: String| CueError::Input {
        path: args.input.to_path_buf(),
        reason,
    };
    let bytes = crate::input::files::read_bytes(args.input, crate::input::files::DATA_LIMIT).map_err(bad)?;
    if crate::input::capture::is_capture(&bytes) {
        if args.outsim_opts.is_some() && args.telemetry_format.is_some_and(|f| !f.reads_outsim2()) {
            return Err(bad(
                "--outsim-opts describes Live for Speed's OutSimPack2 packets: it needs \
                 --telemetry-format outsim2 or auto"
                    .into(),
            ));
        }
        let format = args.telemetry_format.unwrap_or(crate::games::TelemetryFormat::Auto);
        let opts = crate::games::outsim2::Opts::chosen(format, args.outsim_opts, args.config, args.profile)
            .map_err(CliError::from)?;
        let (rows, errors, summary) =
            super::capture::rows(&bytes, format, args.udp_port, opts).map_err(|e| bad(e.to_string()))?;
        return Ok((rows, errors, Some(summary)));
    }
    if args.telemetry_format.is_some() || args.udp_port.is_some() || args.outsim_opts.is_some() {
        return Err(bad(
            "--telemetry-format, --udp-port and --outsim-opts are for a packet capture (pcap, pcapng); this is not one"
                .into(),
        ));
    }
    let text = crate::input::files::read_text(args.input, crate::input::files::DATA_LIMIT).map_err(bad)?;
    let (rows, errors, _) =
        table::read_with_optional(&text, &TELEMETRY_COLUMNS, &[LAP_DISTANCE]).map_err(|e| bad(e.to_string()))?;
    Ok((rows, errors, None))
}

fn write_poses(path: &Path, cued: &[Cued]) -> Result<(), CueError> {
    // Written whole beside the target and renamed over it: a failure leaves the target as it was.
    let write = || -> std::io::Result<()> {
        let mut pending = crate::out::file::Pending::beside(path)?;
        let mut out = std::io::BufWriter::new(pending.file());
        writeln!(out, "t,x,y,z,alpha,beta,gamma")?;
        for c in cued {
            let p = c.pose.to_array();
            writeln!(
                out,
                "{},{:.7},{:.7},{:.7},{:.7},{:.7},{:.7}",
                c.t, p[0], p[1], p[2], p[3], p[4], p[5]
            )?;
        }
        out.flush()?;
        drop(out);
        pending.commit()
    };
    write().map_err(|reason| CueError::Output {
        path: path.to_path_buf(),
        reason,
    })
}

/// The specific force the platform delivers at each sample (platform axes): its acceleration by central
/// differences of its positions, and gravity in its tilted frame.
pub fn delivered_forces(cued: &[Cued]) -> Vec<[f64; 3]> {
    (0..cued.len())
        .map(|k| {
            let accel = if k == 0 || k + 1 == cued.len() {
                [0.0; 3]
            } else {
                let (a, b, c) = (&cued[k - 1], &cued[k], &cued[k + 1]);
                let (h0, h1) = (b.t - a.t, c.t - b.t);
                let (pa, pb, pc) = (a.pose.to_array(), b.pose.to_array(), c.pose.to_array());
                std::array::from_fn(|i| 2.0 * ((pc[i] - pb[i]) / h1 - (pb[i] - pa[i]) / h0) / (h0 + h1))
            };
            cueing::delivered(accel, cued[k].pose.alpha, cued[k].pose.beta)
        })
        .collect()
}

/// Draws the cues: per axis the specific force asked (scaled as the washout scales it) and delivered, and the
/// angular rates asked and delivered (SVG or PNG).
fn draw(path: &Path, cued: &[Cued], neutral: &Pose<f64>) -> Result<(), PlotError> {
    let delivered = delivered_forces(cued);
    let rates: Vec<[f64; 3]> = (0..cued.len())
        .map(|k| {
            if k == 0 {
                return [0.0; 3];
            }
            let (a, b) = (cued[k - 1].pose.to_array(), cued[k].pose.to_array());
            let h = cued[k].t - cued[k - 1].t;
            [(b[3] - a[3]) / h, (b[4] - a[4]) / h, (b[5] - a[5]) / h]
        })
        .collect();
    let g = cueing::G;
    let asked = |f: &dyn Fn(&Cued) -> f64| cued.iter().map(|c| (c.t, f(c))).collect::<Vec<_>>();
    let got = |f: &dyn Fn(&[f64; 3]) -> f64, v: &[[f64; 3]]| cued.iter().zip(v).map(|(c, d)| (c.t, f(d))).collect();
    let panel = |title: &str, unit: &str, series: Vec<Series>| Panel {
        title: title.into(),
        unit: unit.into(),
        series,
        events: Vec::new(),
    };
    let plot = TimePlot {
        title: format!(
            "ringpod cue: telemetry in, platform cues out (neutral z = {:.3} m)",
            neutral.z
        ),
        panels: vec![
            panel(
                "longitudinal specific force",
                "m/s^2",
                vec![
                    Series::new("vehicle ax", asked(&|c| c.input.force[0]), BLUE),
                    Series::new("platform delivers", got(&|d| d[0], &delivered), RED),
                ],
            ),
            panel(
                "lateral specific force",
                "m/s^2",
                vec![
                    Series::new("vehicle ay", asked(&|c| c.input.force[1]), BLUE),
                    Series::new("platform delivers", got(&|d| d[1], &delivered), RED),
                ],
            ),
            panel(
                "vertical specific force minus g",
                "m/s^2",
                vec![
                    Series::new("vehicle az - g", asked(&|c| c.input.force[2] - g), BLUE),
                    Series::new("platform delivers - g", got(&|d| d[2] - g, &delivered), RED),
                ],
            ),
            panel(
                "angular rates",
                "rad/s",
                vec![
                    Series::new("vehicle roll rate", asked(&|c| c.input.rate[0]), BLUE),
                    Series::new("platform roll rate", got(&|r| r[0], &rates), RED),
                    Series::new("vehicle pitch rate", asked(&|c| c.input.rate[1]), CYAN),
                    Series::new("platform pitch rate", got(&|r| r[1], &rates), MAGENTA),
                    Series::new("vehicle yaw rate", asked(&|c| c.input.rate[2]), GREEN),
                    Series::new("platform yaw rate", got(&|r| r[2], &rates), BLACK),
                ],
            ),
        ],
    };
    plot::save(path, (1000, 1000), &plot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::cueing::parse_config;
    use ringpod_core::cueing::{Corner, CueConfig, Smoothing};

    #[test]
    fn a_file_with_one_corner_for_all_axes_reads_as_before() {
        let old = "translation_high_pass = { omega = 3, zeta = 0.8 }\ntilt_low_pass = { omega = 4, zeta = 1 }\n\
                   tilt_limit_deg = 12\ntranslation_break = 0.5\n";
        let new = "translation_high_pass = [{ omega = 3, zeta = 0.8 }, { omega = 3, zeta = 0.8 }, \
                   { omega = 3, zeta = 0.8 }]\ntilt_low_pass = [{ omega = 4, zeta = 1 }, { omega = 4, zeta = 1 }]\n\
                   tilt_limit_deg = [12, 12]\ntranslation_break = [0.5, 0.5, 0.5]\n";
        let want = CueConfig {
            translation_high_pass: [Corner { omega: 3.0, zeta: 0.8 }; 3],
            tilt_low_pass: [Corner { omega: 4.0, zeta: 1.0 }; 2],
            tilt_limit_deg: [12.0; 2],
            translation_break: [0.5; 3],
            ..CueConfig::default()
        };
        assert_eq!(parse_config(old, None).unwrap(), want);
        assert_eq!(parse_config(new, None).unwrap(), want);
        let e = parse_config(
            "translation_high_pass = [{ omega = 3, zeta = 0.8 }, { omega = 0, zeta = 1 }, \
                              { omega = 3, zeta = 0.8 }]",
            None,
        )
        .unwrap_err();
        assert!(e.starts_with("translation_high_pass (sway) must be"), "{e}");
        let s = parse_config("[smoothing]\nkind = \"median\"\nwindow = 5\n", None).unwrap();
        assert_eq!(s.smoothing, Smoothing::Median { window: 5 });
        let e = parse_config("[smoothing]\nkind = \"median\"\nwindow = 4\n", None).unwrap_err();
        assert!(e.starts_with("smoothing.window must be"), "{e}");
        assert!(parse_config("[smoothing]\nkind = \"boxcar\"\n", None).is_err());
    }

    const PROFILES: &str = "translation_scale = [0.1, 0.1, 0.1]\ntilt_limit_deg = 12\n\
                            [smoothing]\nkind = \"median\"\nwindow = 5\n\
                            [profiles.rally]\ntilt_limit_deg = [10, 6]\n\
                            [profiles.rally.smoothing]\nkind = \"low_pass\"\ncorner_hz = 6\n\
                            [profiles.f1]\ntranslation_scale = 0.2\nforward = \"+y\"\n\
                            [profiles.broken]\ntilt_rate_deg = 500\n";

    #[test]
    fn a_profile_overrides_the_base_and_an_unknown_one_is_refused() {
        let base = parse_config(PROFILES, None).unwrap();
        assert_eq!(base.tilt_limit_deg, [12.0; 2]);
        assert_eq!(base.smoothing, Smoothing::Median { window: 5 });
        let rally = parse_config(PROFILES, Some("rally")).unwrap();
        assert_eq!(rally.tilt_limit_deg, [10.0, 6.0]);
        assert_eq!(
            rally.smoothing,
            Smoothing::LowPass {
                corner_hz: 6.0,
                order: 2
            }
        );
        let f1 = parse_config(PROFILES, Some("f1")).unwrap();
        assert_eq!(f1.translation_scale, [0.2; 3]);
        assert_eq!(
            f1.tilt_limit_deg, [12.0; 2],
            "what a profile does not name stays the base's"
        );
        assert_eq!(f1.smoothing, base.smoothing);
        let e = parse_config(PROFILES, Some("gt3")).unwrap_err();
        assert_eq!(e, "no profile `gt3`; the file's profiles: rally, f1, broken");
        let e = parse_config(PROFILES, Some("broken")).unwrap_err();
        assert!(e.starts_with("profile `broken`: tilt_rate_deg (x) must be"), "{e}");
        let e = parse_config("tilt_limit_deg = 12\n", Some("rally")).unwrap_err();
        assert!(e.contains("no [profiles.NAME]"), "{e}");
        assert!(parse_config("profiles = 3\n", None).is_err());
        assert!(load_config(None, Some("rally")).is_err());
    }

    /// Cues `rows` of telemetry (`t, ax`) on the trainer model and returns the poses' x.
    fn cue_x(name: &str, rows: &[(f64, f64)]) -> Vec<f64> {
        cue_rows(name, rows).2
    }

    /// Cues `rows` of telemetry (`t, ax`) on the trainer model: its JSON summary, exit code and the poses' x.
    fn cue_rows(name: &str, rows: &[(f64, f64)]) -> (serde_json::Value, u8, Vec<f64>) {
        let dir = std::env::temp_dir().join(format!("ringpod-cue-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (input, out) = (dir.join("in.csv"), dir.join("out.csv"));
        let mut text = "t,ax,ay,az,wx,wy,wz\n".to_string();
        for (t, ax) in rows {
            text += &format!("{t},{ax},0,{},0,0,0\n", cueing::G);
        }
        std::fs::write(&input, text).unwrap();
        let options = Options {
            input: &input,
            telemetry_format: None,
            outsim_opts: None,
            udp_port: None,
            out: &out,
            config: None,
            profile: None,
            plot: None,
            json: true,
            preview: Preview::None,
            mechanism: "trainer-model",
            geometry: None,
        };
        let (summary, code) = run(&options).unwrap();
        let poses = std::fs::read_to_string(&out).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        let x = poses
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
            .collect();
        (serde_json::from_str(&summary).unwrap(), code, x)
    }

    /// A drive with a 20 s pause (a game's menu): both parts cued, the pause reported, no input error, exit 0; the
    /// row after it starts again at neutral. A row whose time is not after the one before's is an input error.
    #[test]
    fn a_pause_is_a_pause_not_an_input_error() {
        let braking = |from: f64| (0..100).map(move |k| (from + f64::from(k) * 0.01, -6.0));
        let rows: Vec<(f64, f64)> = braking(0.0).chain(braking(21.0)).collect();
        let (summary, code, x) = cue_rows("pause", &rows);
        assert_eq!(code, 0, "{summary}");
        assert_eq!(summary["input_errors"], serde_json::json!([]), "{summary}");
        let pauses = summary["pauses"].as_array().unwrap();
        assert_eq!(pauses.len(), 1, "{summary}");
        assert_eq!(
            pauses[0]["line"], 102,
            "the row after it (line 1 is the header): {summary}"
        );
        assert!(
            (pauses[0]["seconds"].as_f64().unwrap() - 20.01).abs() < 1e-6,
            "{summary}"
        );
        assert_eq!(x.len(), 200);
        // Braking moves the platform back; the row after the pause is at neutral, and braking moves it again.
        assert!(
            x[99] < -1e-3 && x[100].abs() < 1e-9 && x[199] < -1e-3,
            "{} {} {}",
            x[99],
            x[100],
            x[199]
        );

        let mut repeated = rows.clone();
        repeated[50].0 = repeated[49].0;
        let (summary, code, _) = cue_rows("repeated", &repeated);
        assert_eq!(code, EXIT_INPUT_ERRORS, "{summary}");
        assert_eq!(summary["input_errors"][0]["line"], 52, "{summary}");
    }

    #[test]
    fn the_first_row_reaches_the_filters() {
        // Braking from the first row on, and the same but at rest on the first row: the first row's force is
        // the input of the first interval, so the two drives differ from the second pose on (when the first row
        // only set the time, they were the same).
        let braking: Vec<(f64, f64)> = (0..50).map(|k| (f64::from(k) * 0.01, -6.0)).collect();
        let mut at_rest_first = braking.clone();
        at_rest_first[0].1 = 0.0;
        let (a, b) = (cue_x("braking", &braking), cue_x("rest-first", &at_rest_first));
        assert_eq!(a[0], b[0], "the first pose is neutral either way");
        assert!(a[1] < b[1] && a[1] < 0.0, "{} vs {}", a[1], b[1]);
        assert!(a.iter().zip(&b).skip(1).all(|(a, b)| a < b));
    }
}

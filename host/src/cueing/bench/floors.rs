//! The bench's floors ([`floor`]): the least perceived force error any motion inside the envelope's ranges, or
//! inside an outer polytope of the rig's whole envelope, can give on the drives, every sample known.

use ringpod_core::cueing::{CueConfig, Forward, Telemetry};
use serde::Serialize;

use ringpod_core::motion::{envelope, EnvelopeMargins};

use super::super::engine::row_sample;
use super::super::offline::{CueError, Cued};
use super::super::optimal::floor::{self, Room};
use super::super::optimal::polytope::{self, Polytope};
use super::score::{Score, Trace};
use super::{combined, score, Rig, Rows};

/// The floor ([`floor`]) of every drive together.
#[derive(Debug, Serialize)]
pub struct FloorReport {
    /// Inside the ranges.
    #[serde(flatten)]
    pub figures: FloorFigures,
    /// The largest share of each range the floor's motion used: x, y, z, roll, pitch.
    pub envelope_share: [f64; 5],
    /// With `--envelope-floor`: the floor inside an outer polytope of the rig's whole envelope, the axes coupled
    /// as the rig couples them.
    pub envelope: Option<EnvelopeFloor>,
    /// With an optimal cueing as the second file: the floor within that cueing's own limits (its shares of
    /// the ranges, its velocity, acceleration and rate limits, its perceived rotation's error priced), what it
    /// could reach with the whole drive known and no horizon.
    pub limits: Option<FloorFigures>,
    /// With both: the floor inside the envelope's outer polytope within that cueing's limits (not its shares).
    pub envelope_limits: Option<FloorFigures>,
}

/// A floor within an optimal cueing's limits as a motion, every pose through the envelope limiter, scored by
/// the bench like a cueing's: each drive's score and traces, and the poses the limiter changed.
#[derive(Default)]
pub(super) struct LimitsMotion {
    pub drives: Vec<Score>,
    pub traces: Vec<Vec<Trace>>,
    pub limited: usize,
}

impl LimitsMotion {
    /// Adds a piece's floor motion, every pose through the limiter, to the drive's `scores` and `traces`.
    fn add(&mut self, f: &floor::Floor, piece: Piece, rig: &Rig, forward: Forward, scored: &mut Scored) {
        let margins = EnvelopeMargins::default();
        let cued: Vec<Cued> = (piece.t.iter().zip(piece.samples).zip(&f.offsets))
            .map(|((&t, &input), offset)| {
                let wanted = ringpod_core::cueing::pose(&rig.neutral, offset);
                let l = envelope::limit(&rig.mechanism, &rig.neutral, &wanted, &margins, 16);
                self.limited += usize::from(l.is_limited());
                Cued { t, input, pose: l.pose }
            })
            .collect();
        let (s, trace) = score::score_from(&cued, piece.from, &rig.neutral, &rig.envelope.ranges, forward);
        scored.0.push(s);
        scored.1.extend(trace);
    }

    /// Ends a drive: its pieces' scores as one.
    fn end_drive(&mut self, scored: &mut Scored) {
        let (scores, traces) = std::mem::take(scored);
        self.drives.push(combined(&scores));
        self.traces.push(traces);
    }
}

/// A floor's motion and what it is within.
pub(super) type NamedMotion = (&'static str, LimitsMotion);

/// A drive's pieces' scores and traces so far.
type Scored = (Vec<Score>, Vec<Trace>);

/// One continuous piece of a drive: its times, samples, and its own index of the first sample scored.
#[derive(Clone, Copy)]
struct Piece<'a> {
    t: &'a [f64],
    samples: &'a [Telemetry<f64>],
    from: usize,
}

/// A floor's figures over every drive.
#[derive(Debug, Serialize)]
pub struct FloorFigures {
    /// The least RMS perceived specific-force error on the optimiser's model, x, y, z (m/s^2).
    pub force_rms: [f64; 3],
    /// The three axes together (m/s^2).
    pub force_total: f64,
    /// Each drive's, x, y, z (m/s^2), in the order of the drives.
    pub drives: Vec<[f64; 3]>,
}

/// The floor inside the envelope's outer polytope ([`polytope`]).
#[derive(Debug, Serialize)]
pub struct EnvelopeFloor {
    /// Its figures.
    #[serde(flatten)]
    pub figures: FloorFigures,
    /// The polytope's faces.
    pub faces: usize,
    /// How far from settled its support search ended (a share of a face's support), before its slack.
    pub last_gain: f64,
    /// The slack added to every face's support (in the ranges' scale).
    pub slack: f64,
}

/// The floor of the drives on the optimiser's model, every drive's samples together; a drive with gaps by its
/// continuous pieces, each from neutral, as the cueing starts again at a gap. Its motion is not scored:
/// bounded by the ranges alone, it swings the tilt at any rate and reaches corners of the ranges' box outside the
/// coupled envelope, so the bench would score the limiter and the finite differences of a motion no cueing
/// makes, not the floor. With an `optimal` cueing, also the floors within its limits (in its shares, and with
/// `coupled` in the polytope), and their motions, which keep its rates, as the bench scores any cueing's.
pub(super) fn floor_of(
    drives: &[Rows],
    from: &[usize],
    rig: &Rig,
    forward: Forward,
    coupled: bool,
    optimal: Option<&CueConfig>,
) -> Result<(FloorReport, Vec<NamedMotion>), CueError> {
    let ranges = &rig.envelope.ranges;
    let outer = coupled.then(|| Polytope::of(&rig.mechanism, &rig.neutral, ranges, &polytope::directions(3), RAYS));
    let (mut within_ranges, mut within_envelope) = (Sums::default(), Sums::default());
    let (mut within_limits, mut envelope_limits) = (Sums::default(), Sums::default());
    let mut envelope_share = [0.0f64; 5];
    let (mut motion, mut envelope_motion) = (LimitsMotion::default(), LimitsMotion::default());
    for (d, rows) in drives.iter().enumerate() {
        let (mut scored, mut envelope_scored) = (Scored::default(), Scored::default());
        for piece in pieces(rows) {
            let t: Vec<f64> = piece.iter().map(|(_, v)| v[0]).collect();
            let samples: Vec<Telemetry<f64>> = piece.iter().map(|(_, v)| row_sample(v)).collect();
            // The piece's own index of the drive's first sample scored (lines are unique).
            let start = rows.iter().position(|r| r.0 == piece[0].0).unwrap_or(0);
            let from = from.get(d).map_or(0, |f| f.saturating_sub(start));
            let floor_in =
                |room, limits| floor::floor_from(&t, &samples, room, limits, forward, from).map_err(CueError::Floor);
            let f = floor_in(Room::Ranges(ranges), None)?;
            within_ranges.add(&f);
            for offset in &f.offsets {
                score::widen_shares(&mut envelope_share, offset, ranges);
            }
            if let Some(outer) = &outer {
                within_envelope.add(&floor_in(Room::Envelope(outer), None)?);
            }
            let piece = Piece {
                t: &t,
                samples: &samples,
                from,
            };
            if let Some(config) = optimal {
                let f = floor_in(Room::Shares(ranges, config), Some(config))?;
                within_limits.add(&f);
                motion.add(&f, piece, rig, forward, &mut scored);
                if let Some(outer) = &outer {
                    let f = floor_in(Room::Envelope(outer), Some(config))?;
                    envelope_limits.add(&f);
                    envelope_motion.add(&f, piece, rig, forward, &mut envelope_scored);
                }
            }
        }
        within_ranges.end_drive();
        within_envelope.end_drive();
        within_limits.end_drive();
        envelope_limits.end_drive();
        if optimal.is_some() {
            motion.end_drive(&mut scored);
            if outer.is_some() {
                envelope_motion.end_drive(&mut envelope_scored);
            }
        }
    }
    let report = FloorReport {
        figures: within_ranges.figures(),
        envelope_share,
        envelope: outer.map(|outer| EnvelopeFloor {
            figures: within_envelope.figures(),
            faces: outer.faces.len(),
            last_gain: outer.last_gain,
            slack: polytope::SLACK,
        }),
        limits: optimal.map(|_| within_limits.figures()),
        envelope_limits: optimal.filter(|_| coupled).map(|_| envelope_limits.figures()),
    };
    let mut motions = Vec::new();
    if optimal.is_some() {
        motions.push(("limits", motion));
        if coupled {
            motions.push(("limits in the envelope", envelope_motion));
        }
    }
    Ok((report, motions))
}

/// Rays spread through the envelope to find the polytope's supports from: with every face's own direction and
/// the climb, enough that the supports no longer grow (the search's last gain, reported).
const RAYS: usize = 2000;

/// A drive's continuous pieces of two rows or more: a row more than a second after the one before starts the
/// next (the bench's drives have no other gaps: a row not after the one before refuses the drive).
fn pieces(rows: &Rows) -> impl Iterator<Item = &[(usize, Vec<f64>)]> {
    rows.chunk_by(|(_, a), (_, b)| b[0] - a[0] > 0.0 && b[0] - a[0] <= 1.0)
        .filter(|piece| piece.len() >= 2)
}

/// Floors of several drives, each of one or more pieces, added up: squares weighted by intervals.
#[derive(Default)]
struct Sums {
    sum: [f64; 3],
    n: usize,
    /// The drive being added: its sums and intervals.
    drive: ([f64; 3], usize),
    each: Vec<[f64; 3]>,
}

impl Sums {
    /// Adds a piece of the present drive.
    fn add(&mut self, f: &floor::Floor) {
        let m = f.scored;
        for i in 0..3 {
            let square = f.force_rms[i].powi(2) * m as f64;
            self.sum[i] += square;
            self.drive.0[i] += square;
        }
        self.n += m;
        self.drive.1 += m;
    }

    /// Ends the present drive: its figures are its pieces' together.
    fn end_drive(&mut self) {
        let (sum, n) = std::mem::take(&mut self.drive);
        self.each.push(sum.map(|v| (v / n.max(1) as f64).sqrt()));
    }

    fn figures(self) -> FloorFigures {
        let force_rms = self.sum.map(|v| (v / self.n.max(1) as f64).sqrt());
        FloorFigures {
            force_rms,
            force_total: force_rms.iter().map(|r| r * r).sum::<f64>().sqrt(),
            drives: self.each,
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::super::{run, Options};

    /// Runs the bench with the floor on `inputs` (trainer model, no tuning): its table and its report.
    fn bench(
        configs: [&Path; 2],
        inputs: &[std::path::PathBuf],
        out: &Path,
        envelope: bool,
    ) -> (String, serde_json::Value) {
        let options = Options {
            configs,
            inputs,
            out,
            plot: None,
            tune: false,
            json: false,
            preview: crate::cueing::offline::Preview::None,
            floor: true,
            envelope_floor: envelope,
            mechanism: "trainer-model",
            geometry: None,
        };
        let (table, code) = run(&options).unwrap();
        assert_eq!(code, 0, "{table}");
        let report = serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
        (table, report)
    }

    /// On the shipped example drive, neither the classical washout nor the optimal cueing (nor the floors'
    /// motions within its limits) perceives less force error than the floor, which keeps to the ranges; the
    /// table says it and its ratio.
    #[test]
    fn no_cueing_on_the_bench_beats_the_floor() {
        let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
        let out = std::env::temp_dir().join(format!("ringpod-floor-{}.json", std::process::id()));
        let (classical, optimal) = (docs.join("drives/classical.toml"), docs.join("drives/optimal.toml"));
        let inputs = [docs.join("drive-telemetry.csv")];
        let (table, report) = bench([&classical, &optimal], &inputs, &out, true);
        std::fs::remove_file(&out).unwrap();
        let floor = report["floor"]["force_total"].as_f64().unwrap();
        assert!(floor > 0.1, "{report}");
        let coupled = report["floor"]["envelope"]["force_total"].as_f64().unwrap();
        assert!(coupled > 0.1, "{report}");
        // Within the optimal cueing's limits, a room no larger: no less error on the model.
        let limits = report["floor"]["limits"]["force_total"].as_f64().unwrap();
        let coupled_limits = report["floor"]["envelope_limits"]["force_total"].as_f64().unwrap();
        assert!(limits > floor && coupled_limits > coupled, "{report}");
        for e in report["entries"].as_array().unwrap() {
            let rms: Vec<f64> = e["total"]["force_rms"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let total = rms.iter().map(|r| r * r).sum::<f64>().sqrt();
            assert!(floor < total, "floor {floor} against {}: {total}", e["name"]);
            assert!(
                coupled < total,
                "envelope floor {coupled} against {}: {total}",
                e["name"]
            );
        }
        for share in report["floor"]["envelope_share"].as_array().unwrap() {
            assert!(share.as_f64().unwrap() <= 1.0 + 1e-4, "{report}");
        }
        assert!(
            table.contains("floor / classical.toml perceived force error")
                && table.contains("envelope floor / classical.toml perceived force error"),
            "{table}"
        );
    }

    /// A drive with a gap is floored by its pieces, each from neutral as the cueing starts again there: the
    /// same figures as the two pieces given as drives of their own.
    #[test]
    fn a_drive_with_a_gap_is_floored_by_its_pieces() {
        let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
        let text = std::fs::read_to_string(docs.join("drive-telemetry.csv")).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap();
        let (mut whole, mut first, mut second) = ([header].join("\n"), header.to_owned(), header.to_owned());
        for line in lines {
            let (t, rest) = line.split_once(',').unwrap();
            let t: f64 = t.parse().unwrap();
            let row = if t < 10.0 {
                format!("{t},{rest}")
            } else {
                format!("{},{rest}", t + 3.0)
            };
            whole += &format!("\n{row}");
            let piece = if t < 10.0 { &mut first } else { &mut second };
            *piece += &format!("\n{row}");
        }
        let dir = std::env::temp_dir().join(format!("ringpod-floor-gap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let files = [("whole.csv", &whole), ("first.csv", &first), ("second.csv", &second)].map(|(name, text)| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            path
        });
        let classical = docs.join("drives/classical.toml");
        let floor_of = |inputs: &[std::path::PathBuf]| {
            let out = dir.join("report.json");
            bench([&classical, &classical], inputs, &out, false).1["floor"]["force_rms"].clone()
        };
        let gapped = floor_of(&files[..1]);
        let apart = floor_of(&files[1..]);
        std::fs::remove_dir_all(&dir).unwrap();
        for i in 0..3 {
            let (a, b) = (gapped[i].as_f64().unwrap(), apart[i].as_f64().unwrap());
            assert!((a - b).abs() <= 1e-9 * b.max(1.0), "{i}: {gapped} against {apart}");
        }
        assert!(gapped[0].as_f64().unwrap() > 0.1, "{gapped}");
    }
}

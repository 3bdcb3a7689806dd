//! Run records: `stream --record run.csv` writes a row per telemetry sample (100 Hz by default: a row every 10 ms of
//! device time; `--record-hz 1000` a row every tick), and `ringpod plot run.csv --out run.png` draws what was commanded against what the platform
//! followed, the actuators, and the events (limits, refusals, state changes).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::time::Instant;

use plotters::style::colors::{BLACK, BLUE, CYAN, GREEN, MAGENTA, RED};
use plotters::style::RGBColor;
use ringpod_core::kinematics::Pose;
use ringpod_core::protocol::{Telemetry, TelemetryFlags};

use crate::device::state_name;

use crate::out::plot::{self, Event, Panel, Series, TimePlot};

/// The record's columns after [`COLUMNS`]: the auxiliary outputs (0 off, 1 on). A record is read without them, so
/// records written before they existed still read.
pub const AUX_COLUMNS: [&str; 2] = ["aux1", "aux2"];

/// The record's columns (the ones [`parse`] needs).
pub const COLUMNS: [&str; 28] = [
    "host_s",
    "device_s",
    "cmd_x",
    "cmd_y",
    "cmd_z",
    "cmd_alpha",
    "cmd_beta",
    "cmd_gamma",
    "x",
    "y",
    "z",
    "alpha",
    "beta",
    "gamma",
    "steps_1",
    "steps_2",
    "steps_3",
    "steps_4",
    "steps_5",
    "steps_6",
    "state",
    "limited",
    "refused",
    "held",
    "applied",
    "limited_total",
    "refused_total",
    "tick_cost",
];

/// Writes a run record: to a file beside the target, renamed to it when the run ends ([`Recorder::finish`]), so
/// that a run that never starts leaves an existing file as it was.
pub struct Recorder {
    out: BufWriter<File>,
    pending: crate::out::file::Pending,
    started: Instant,
    /// Rows written to the file (flushed).
    pub rows: u64,
    /// Rows formatted but still in the buffer.
    buffered: u64,
}

impl Recorder {
    /// Opens the file beside `path` and writes the header.
    pub fn create(path: &Path) -> std::io::Result<Self> {
        let mut pending = crate::out::file::Pending::beside(path)?;
        let mut out = BufWriter::new(pending.file().try_clone()?);
        writeln!(out, "{},{}", COLUMNS.join(","), AUX_COLUMNS.join(","))?;
        Ok(Self {
            out,
            pending,
            started: Instant::now(),
            rows: 0,
            buffered: 0,
        })
    }

    /// One row: the pose the host commanded last, and the device's sample (counted once flushed).
    pub fn write(&mut self, commanded: &Pose<f64>, t: &Telemetry) -> std::io::Result<()> {
        let mut row = format!(
            "{:.6},{:.6}",
            self.started.elapsed().as_secs_f64(),
            t.time_us as f64 * 1e-6
        );
        for v in commanded.to_array() {
            row += &format!(",{v}");
        }
        // The pose followed: where the counted steps put the platform (`link::followed`), not where it was sent.
        for v in t.pose.to_array() {
            row += &format!(",{v}");
        }
        for s in t.steps {
            row += &format!(",{s}");
        }
        let flag = |bit: u8| u8::from(t.flags & bit != 0);
        row += &format!(
            ",{},{},{},{},{},{},{},{}",
            state_name(t.state),
            flag(TelemetryFlags::LIMITED),
            flag(TelemetryFlags::REFUSED),
            flag(TelemetryFlags::HELD),
            t.applied,
            t.limited,
            t.refused,
            t.tick_cost
        );
        // Telemetry output bits 3 and 4.
        row += &format!(",{},{}", (t.outputs >> 3) & 1, (t.outputs >> 4) & 1);
        writeln!(self.out, "{row}")?;
        self.buffered += 1;
        Ok(())
    }

    /// Writes the buffered rows to the file: then they count as written.
    pub fn flush(&mut self) -> std::io::Result<()> {
        if self.buffered > 0 {
            self.out.flush()?;
            self.rows += std::mem::take(&mut self.buffered);
        }
        Ok(())
    }

    /// Flushes the file and puts it in place under its name: the rows written.
    pub fn finish(mut self) -> std::io::Result<u64> {
        self.flush()?;
        self.out.flush()?;
        drop(self.out);
        self.pending.commit()?;
        Ok(self.rows)
    }
}

/// A record read back (device time, each angle made continuous).
#[derive(Debug, serde::Serialize)]
pub struct Run {
    /// Device time (s).
    pub t: Vec<f64>,
    /// The pose the host commanded last (the record's `cmd_*`).
    pub commanded: Vec<[f64; 6]>,
    /// The pose followed: where the counted steps put the platform, angles unwrapped.
    pub target: Vec<[f64; 6]>,
    pub steps: Vec<[f64; 6]>,
    pub state: Vec<String>,
    pub limited: Vec<bool>,
    pub refused: Vec<bool>,
}

/// Why a run record could not be read.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The file could not be read.
    #[error("{}: {reason}", path.display())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
    /// What is wrong with the text, in the file.
    #[error("{}: {error}", path.display())]
    In {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong.
        error: Box<RecordError>,
    },
    /// A column of a run record is missing.
    #[error("no column {0:?} (is it a run record?)")]
    NoColumn(&'static str),
    /// A row ends early.
    #[error("line {0}: too few fields")]
    TooFewFields(usize),
    /// A field is not a number.
    #[error("line {line}: {column}: not a number: {text:?}")]
    NotANumber {
        /// The line, from 1.
        line: usize,
        /// The column.
        column: &'static str,
        /// What it holds.
        text: String,
    },
    /// There are no rows.
    #[error("no rows")]
    NoRows,
}

/// Why `ringpod plot` (and `plot --derivatives`) drew nothing.
#[derive(Debug, thiserror::Error)]
pub enum PlotCommandError {
    /// The record could not be read.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// A window or span that cannot be used.
    #[error(transparent)]
    Number(#[from] crate::input::numbers::BadNumber),
    /// The picture was not written.
    #[error(transparent)]
    Plot(#[from] plot::PlotError),
    /// A record too short to take a derivative of.
    #[error(
        "{}: {samples} sample{}: a derivative needs at least 2",
        path.display(),
        if *samples == 1 { "" } else { "s" }
    )]
    TooShort {
        /// The record.
        path: std::path::PathBuf,
        /// How many samples it holds.
        samples: usize,
    },
}

/// Reads a run record (`stream --record`).
pub(crate) fn read(path: &Path) -> Result<Run, RecordError> {
    let text =
        crate::input::files::read_text(path, crate::input::files::DATA_LIMIT).map_err(|reason| RecordError::File {
            path: path.to_path_buf(),
            reason,
        })?;
    parse(&text).map_err(|e| RecordError::In {
        path: path.to_path_buf(),
        error: Box::new(e),
    })
}

/// A run record's columns, found by name in its header line.
pub struct Columns {
    index: Vec<usize>,
}

/// One row of a run record, as read (angles as written, not made continuous).
pub struct Row {
    pub t: f64,
    pub commanded: [f64; 6],
    pub target: [f64; 6],
    pub steps: [f64; 6],
    pub state: String,
    pub limited: bool,
    pub refused: bool,
}

impl Columns {
    /// The columns of a record whose first line is `header`.
    pub fn of(header: &str) -> Result<Self, RecordError> {
        let header: Vec<&str> = header.split(',').collect();
        let col = |name: &'static str| {
            header
                .iter()
                .position(|h| h.trim() == name)
                .ok_or(RecordError::NoColumn(name))
        };
        Ok(Self {
            index: COLUMNS.iter().map(|c| col(c)).collect::<Result<_, _>>()?,
        })
    }

    /// The row on line `line` (from 1), `None` for a blank line.
    pub fn row(&self, line: usize, text: &str) -> Result<Option<Row>, RecordError> {
        if text.trim().is_empty() {
            return Ok(None);
        }
        let fields: Vec<&str> = text.split(',').collect();
        let number = |k: usize| -> Result<f64, RecordError> {
            let f = fields.get(self.index[k]).ok_or(RecordError::TooFewFields(line))?;
            f.trim().parse::<f64>().map_err(|_| RecordError::NotANumber {
                line,
                column: COLUMNS[k],
                text: (*f).to_owned(),
            })
        };
        let six = |from: usize| -> Result<[f64; 6], RecordError> {
            let mut v = [0.0; 6];
            for (i, slot) in v.iter_mut().enumerate() {
                *slot = number(from + i)?;
            }
            Ok(v)
        };
        Ok(Some(Row {
            t: number(1)?,
            commanded: six(2)?,
            target: six(8)?,
            steps: six(14)?,
            state: fields.get(self.index[20]).unwrap_or(&"").trim().to_owned(),
            limited: number(21)? != 0.0,
            refused: number(22)? != 0.0,
        }))
    }
}

/// A run record's text.
pub fn parse(text: &str) -> Result<Run, RecordError> {
    let mut lines = text.lines();
    let columns = Columns::of(lines.next().unwrap_or(""))?;
    let mut run = Run {
        t: Vec::new(),
        commanded: Vec::new(),
        target: Vec::new(),
        steps: Vec::new(),
        state: Vec::new(),
        limited: Vec::new(),
        refused: Vec::new(),
    };
    for (n, line) in lines.enumerate() {
        let Some(row) = columns.row(n + 2, line)? else {
            continue;
        };
        run.t.push(row.t);
        run.commanded.push(row.commanded);
        run.target.push(row.target);
        run.steps.push(row.steps);
        run.state.push(row.state);
        run.limited.push(row.limited);
        run.refused.push(row.refused);
    }
    if run.t.is_empty() {
        return Err(RecordError::NoRows);
    }
    // The device keeps yaw within a turn and a source may wrap it too: draw each angle continuous.
    for series in [&mut run.commanded, &mut run.target] {
        for k in 3..6 {
            let mut angle: Vec<f64> = series.iter().map(|p| p[k]).collect();
            crate::analysis::demand::unwrap(&mut angle);
            for (p, a) in series.iter_mut().zip(angle) {
                p[k] = a;
            }
        }
    }
    Ok(run)
}

/// A paler shade of `c` (the commanded line under the followed one).
fn light(c: RGBColor) -> RGBColor {
    RGBColor(c.0 / 2 + 128, c.1 / 2 + 128, c.2 / 2 + 128)
}

/// The start of each run of `true` in `flags`, as events.
fn onsets(t: &[f64], flags: &[bool], kind: &str, colour: RGBColor) -> Vec<Event> {
    (0..flags.len())
        .filter(|&i| flags[i] && (i == 0 || !flags[i - 1]))
        .map(|i| Event {
            t: t[i],
            kind: kind.to_owned(),
            colour,
        })
        .collect()
}

/// `ringpod plot RUN.csv --out FILE`: returns the summary to print.
pub fn plot_command(input: &Path, out: &Path) -> Result<String, PlotCommandError> {
    let run = read(input)?;
    let mut events = onsets(
        &run.t,
        &run.limited,
        "limited into the envelope",
        RGBColor(240, 150, 40),
    );
    events.extend(onsets(&run.t, &run.refused, "setpoint refused", RED));
    let changes: Vec<usize> = (1..run.state.len())
        .filter(|&i| run.state[i] != run.state[i - 1])
        .collect();
    events.extend(changes.iter().map(|&i| Event {
        t: run.t[i],
        kind: "state change".into(),
        colour: RGBColor(120, 120, 120),
    }));
    let colours = [BLUE, RED, GREEN, CYAN, MAGENTA, BLACK];
    let pair = |axes: &[(usize, &str)]| -> Vec<Series> {
        axes.iter()
            .enumerate()
            .flat_map(|(n, &(k, name))| {
                let c = colours[n % colours.len()];
                [
                    Series::new(
                        format!("{name} commanded"),
                        run.t.iter().zip(&run.commanded).map(|(t, p)| (*t, p[k])).collect(),
                        light(c),
                    ),
                    Series::new(
                        format!("{name} followed"),
                        run.t.iter().zip(&run.target).map(|(t, p)| (*t, p[k])).collect(),
                        c,
                    ),
                ]
            })
            .collect()
    };
    let panel = |title: &str, unit: &str, series: Vec<Series>| Panel {
        title: title.into(),
        unit: unit.into(),
        series,
        events: events
            .iter()
            .map(|e| Event {
                t: e.t,
                kind: e.kind.clone(),
                colour: e.colour,
            })
            .collect(),
    };
    let steps = (0..6)
        .map(|k| {
            Series::new(
                format!("axis {}", k + 1),
                run.t.iter().zip(&run.steps).map(|(t, s)| (*t, s[k])).collect(),
                colours[k],
            )
        })
        .collect();
    let picture = TimePlot {
        title: format!(
            "ringpod run {}: commanded vs followed",
            input
                .file_name()
                .map_or(String::new(), |f| f.to_string_lossy().into_owned())
        ),
        panels: vec![
            panel(
                "translation",
                "m",
                pair(&[(0, "surge x"), (1, "sway y"), (2, "heave z")]),
            ),
            panel("roll and pitch", "rad", pair(&[(3, "roll alpha"), (4, "pitch beta")])),
            panel("yaw", "rad", pair(&[(5, "yaw gamma")])),
            panel("actuator positions", "steps", steps),
        ],
    };
    plot::save(out, (1100, 1200), &picture)?;
    let limited = events.iter().filter(|e| e.kind.starts_with("limited")).count();
    let refused = events.iter().filter(|e| e.kind.starts_with("setpoint")).count();
    Ok(format!(
        "{} rows over {:.3} s of device time: {limited} limited stretches, {refused} refusal stretches, {} state \
         changes; picture: {}\n",
        run.t.len(),
        run.t[run.t.len() - 1] - run.t[0],
        changes.len(),
        out.display()
    ))
}

//! What a UDP datagram from simulator software means: a pose, a motion front end's pose string ([`template`]), or
//! vehicle telemetry that the core's washout turns into a pose (a text line, or a game's own packet:
//! [`crate::games`]).

use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime};

use ringpod_core::cueing::{self, SampleError, Telemetry, G};
use ringpod_core::kinematics::Pose;

use crate::cueing::live::LiveCueing;
use crate::cueing::optimal::Envelope;
use crate::games::{self, numbers};
use crate::out::console;

pub mod template;

/// Turns datagrams into poses.
pub enum Decoder {
    /// Six numbers `x y z alpha beta gamma` (m; rad, or degrees).
    Poses {
        /// Angles in degrees.
        degrees: bool,
    },
    /// A motion front end's pose strings (FlyPT Mover, SimTools, SimHub): offsets from the platform's neutral.
    Template {
        /// The strings' template.
        template: Box<template::Template>,
        /// The platform's neutral pose: the home pose of the rig the device runs ([`Decoder::centre_on`]).
        neutral: Option<Pose<f64>>,
    },
    /// Vehicle telemetry through the washout.
    Telemetry {
        /// The datagrams' format, and `auto`'s lock.
        reader: Box<games::Reader>,
        /// The washout, retuned live when its file changes.
        washout: Box<LiveCueing>,
        /// The platform's neutral pose: the home pose of the rig the device runs, set by the stream once it knows it
        /// ([`Decoder::centre_on`]), before the first datagram is read.
        neutral: Option<Pose<f64>>,
        /// Time of the last sample: its own (s) or its arrival.
        last: Option<(Option<f64>, Instant)>,
        /// Gaps of more than a second after which the washout started again at neutral.
        gaps: u32,
        /// The cueing file, watched for changes.
        watch: Option<Box<Watch>>,
    },
}

/// A sample this much older than the last (s) is not out of order: the game's clock started again.
const RESTARTED_S: f64 = 1.0;

/// The newest telemetry sample a session cued and when it came: the workbench's Live view shows what the game
/// asks beside what the platform does. One process runs one stream at a time, so one slot.
static NEWEST_INPUT: std::sync::Mutex<Option<(Instant, Telemetry<f64>)>> = std::sync::Mutex::new(None);

/// The newest telemetry sample any session cued, and when it came.
pub fn newest_input() -> Option<(Instant, Telemetry<f64>)> {
    *NEWEST_INPUT.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The lap preview of the session that cued the newest sample (its counts and state), and when: the workbench's
/// Live view shows it.
static NEWEST_LAP: std::sync::Mutex<Option<(Instant, crate::cueing::lap::Counts)>> = std::sync::Mutex::new(None);

/// The newest lap preview's counts and state, and when they were taken.
pub fn newest_lap() -> Option<(Instant, crate::cueing::lap::Counts)> {
    *NEWEST_LAP.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// How often the cueing file is looked at while streaming.
pub const WATCH_EVERY: Duration = Duration::from_millis(500);

/// A cueing file watched while streaming: its modification time and length are polled every [`WATCH_EVERY`] from
/// the stream's loop (a `stat`, no thread; a file system watcher would add a thread and a dependency to save a
/// call that costs microseconds twice a second, and would not see files on network shares any better). A change
/// is read, checked and handed to the cueing ([`LiveCueing::retune`]: blended in over a second); an invalid file is
/// refused with its key on stderr and the running configuration stays.
pub struct Watch {
    path: PathBuf,
    profile: Option<String>,
    /// The file's modification time and length when last read.
    seen: Option<(SystemTime, u64)>,
    /// When it was last looked at.
    polled: Option<Instant>,
    /// Changes that took effect.
    pub reloads: u32,
    /// Changes refused (a key out of range, an unknown profile).
    pub refused: u32,
    /// Reads ignored as not yet whole: empty, unreadable or not TOML (an editor's truncate-then-write caught
    /// half-way); the running configuration stays and the file is read again at its next change.
    pub ignored: u32,
}

fn stamp(path: &std::path::Path) -> Option<(SystemTime, u64)> {
    let m = std::fs::metadata(path).ok()?;
    Some((m.modified().ok()?, m.len()))
}

impl Watch {
    /// Watches `path`, as read just now (with `profile`).
    pub fn new(path: PathBuf, profile: Option<String>) -> Self {
        Self {
            seen: stamp(&path),
            path,
            profile,
            polled: None,
            reloads: 0,
            refused: 0,
            ignored: 0,
        }
    }

    /// Looks at the file if [`WATCH_EVERY`] has passed, and retunes `washout` if it changed and is valid.
    pub fn poll(&mut self, now: Instant, washout: &mut LiveCueing) {
        if self.polled.is_some_and(|p| now.duration_since(p) < WATCH_EVERY) {
            return;
        }
        self.polled = Some(now);
        // A file being replaced (an editor's save) may be missing for a moment: looked at again next time.
        let Some(stamp) = stamp(&self.path) else {
            return;
        };
        if self.seen == Some(stamp) {
            return;
        }
        self.seen = Some(stamp);
        let shown = self.path.display();
        // A file caught half-way through a save (empty, cut short: not TOML) is not a configuration of all
        // defaults: ignored until it is whole.
        let text = crate::input::files::read_text(&self.path, crate::input::files::CONFIG_LIMIT)
            .and_then(|text| crate::input::cueing::whole(&text).map(|()| text));
        let text = match text {
            Ok(text) => text,
            Err(e) => {
                self.ignored += 1;
                console::err(&format!(
                    "{shown}: changed but not whole ({e}): the running cueing stays, read again at its next change"
                ));
                return;
            }
        };
        let config = crate::input::cueing::parse_config(&text, self.profile.as_deref())
            .and_then(|config| washout.retune(config).map_err(|e| e.to_string()));
        match config {
            Ok(true) => {
                self.reloads += 1;
                console::err(&format!("{shown}: changed, the new cueing blends in over a second"));
            }
            // The same parameters (a save without a change): nothing to do.
            Ok(false) => {}
            Err(e) => {
                self.refused += 1;
                console::err(&format!("{shown}: changed but refused, the running cueing stays: {e}"));
            }
        }
    }
}

/// Parses one pose datagram: six numbers.
pub fn parse_pose(bytes: &[u8], degrees: bool) -> Result<Pose<f64>, String> {
    let v = numbers(bytes)?;
    if v.len() != 6 {
        return Err(format!("expected 6 numbers, got {}", v.len()));
    }
    let a = |x: f64| if degrees { x.to_radians() } else { x };
    let pose = [v[0], v[1], v[2], a(v[3]), a(v[4]), a(v[5])];
    // Garbage is not sent: a live source's datagram that no device could follow is unreadable, like a wrong one,
    // and the session goes on (a file's bad row is the device's to refuse, with its reason).
    if let Some(i) = pose.iter().position(|x| !(*x as f32).is_finite()) {
        return Err(format!("value {} is not a finite number (in single precision)", i + 1));
    }
    if pose[5].abs() > crate::input::numbers::MAX_TURNING {
        return Err(format!(
            "a yaw of {} rad is beyond {} rad either way",
            crate::input::numbers::readable(pose[5]),
            crate::input::numbers::readable(crate::input::numbers::MAX_TURNING)
        ));
    }
    Ok(Pose::from_array(pose))
}

impl Decoder {
    /// The pose a datagram asks for, arriving at `now`; `None` for another of the game's packets, which carries no
    /// motion (skipped: neither a pose nor an error).
    pub fn decode(&mut self, bytes: &[u8], now: Instant) -> Result<Option<Pose<f64>>, String> {
        match self {
            Decoder::Poses { degrees } => parse_pose(bytes, *degrees).map(Some),
            Decoder::Template { template, neutral } => {
                let neutral = neutral.ok_or("the platform's neutral pose is not known yet")?;
                Ok(Some(cueing::pose(&neutral, &template.read(bytes)?)))
            }
            Decoder::Telemetry { reader, .. } => {
                let read = reader.read(bytes);
                // `auto`'s lock, or its lock dropped: said once.
                if let Some(news) = reader.news() {
                    console::err(&format!("telemetry: {news}"));
                }
                match read {
                    Ok(None) => Ok(None),
                    Ok(Some(sample)) => self.cue(Ok(sample), now).map(Some),
                    Err(e) => self.cue(Err(e), now).map(Some),
                }
            }
        }
    }

    /// The pose a telemetry sample (read from a datagram, or a game's shared memory) asks for, arriving at `now`,
    /// through the washout; a sample that could not be read stays refused with its reason.
    pub fn cue(&mut self, read: Result<games::Sample, String>, now: Instant) -> Result<Pose<f64>, String> {
        let Decoder::Telemetry {
            washout,
            neutral,
            last,
            gaps,
            ..
        } = self
        else {
            return Err("a pose source reads no telemetry".into());
        };
        let neutral = neutral.ok_or("the platform's neutral pose is not known yet")?;
        let games::Sample {
            time: t,
            telemetry: sample,
            lap,
        } = read?;
        *NEWEST_INPUT.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some((now, sample));
        let dt = match *last {
            None => None,
            Some((Some(t0), _)) if t.is_some() => t.map(|t| t - t0),
            Some((_, arrived)) => Some(now.duration_since(arrived).as_secs_f64()),
        };
        let offset = match dt.map(|dt| washout.step_at(&sample, dt, lap)) {
            // The first sample: the washout's first input, at neutral.
            None => washout.begin_at(&sample, lap).map_err(|e| e.to_string()),
            Some(Ok(offset)) => Ok(offset),
            Some(Err(e @ (SampleError::NonFinite | SampleError::Implausible))) => Err(e.to_string()),
            Some(Err(SampleError::Interval)) if dt.is_some_and(|dt| !(-RESTARTED_S..=0.0).contains(&dt)) => {
                // A pause of more than a second, or the game's clock started again (a restarted game or session,
                // a replay): wash out to neutral and start again from here, this sample the first input.
                *gaps += 1;
                washout.reset();
                washout.begin_at(&sample, lap).map_err(|e| e.to_string())
            }
            Some(Err(SampleError::Interval)) => Err("its time is not after the last one's".to_string()),
        };
        let offset = offset?;
        *last = Some((t, now));
        *NEWEST_LAP.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = washout.lap_counts().map(|c| (now, c));
        Ok(cueing::pose(&neutral, &offset))
    }

    /// A telemetry source paused for `dt` more seconds (until `now`): the pose of the vehicle at rest through the
    /// washout (washing out to neutral), or `None` for a pose source (the platform holds).
    pub fn idle(&mut self, dt: f64, now: Instant) -> Option<Pose<f64>> {
        match self {
            Decoder::Poses { .. } | Decoder::Template { .. } => None,
            Decoder::Telemetry {
                washout, neutral, last, ..
            } => {
                // The next sample's interval runs from here, by arrival: the washout has covered the pause.
                *last = Some((None, now));
                let rest = Telemetry {
                    force: [0.0, 0.0, G],
                    rate: [0.0; 3],
                };
                let offset = washout.step(&rest, dt).ok()?;
                Some(cueing::pose(&(*neutral)?, &offset))
            }
        }
    }

    /// Cues around `home` (the home pose of the rig the device runs), within `envelope` about it (the optimal
    /// cueing plans in them: given when [`Decoder::cues`]); front-end strings are offsets from it; a pose source
    /// has no neutral.
    pub fn centre_on(&mut self, home: Pose<f64>, envelope: Option<Envelope>) {
        match self {
            Decoder::Telemetry { neutral, washout, .. } => {
                *neutral = Some(home);
                if let Some(envelope) = envelope {
                    washout.place(envelope);
                }
            }
            Decoder::Template { neutral, .. } => *neutral = Some(home),
            Decoder::Poses { .. } => {}
        }
    }

    /// Whether this decoder cues telemetry (and so wants the envelope [`Decoder::centre_on`] takes).
    pub fn cues(&self) -> bool {
        matches!(self, Decoder::Telemetry { .. })
    }

    /// Looks at the cueing file (every [`WATCH_EVERY`]) and retunes the washout if it changed: call it from the
    /// stream's loop.
    pub fn poll_config(&mut self, now: Instant) {
        if let Decoder::Telemetry {
            washout,
            watch: Some(watch),
            ..
        } = self
        {
            watch.poll(now, washout);
        }
    }

    /// Cueing-file changes that took effect, that were refused, and reads ignored as not yet whole.
    pub fn reloads(&self) -> (u32, u32, u32) {
        match self {
            Decoder::Telemetry { watch: Some(w), .. } => (w.reloads, w.refused, w.ignored),
            _ => (0, 0, 0),
        }
    }

    /// `auto`'s changes of format (telemetry only).
    pub fn locks(&self) -> Vec<games::Lock> {
        match self {
            Decoder::Poses { .. } | Decoder::Template { .. } => Vec::new(),
            Decoder::Telemetry { reader, .. } => reader.locks().to_vec(),
        }
    }

    /// Gaps after which the washout started again (telemetry only).
    pub fn gaps(&self) -> u32 {
        match self {
            Decoder::Poses { .. } | Decoder::Template { .. } => 0,
            Decoder::Telemetry { gaps, .. } => *gaps,
        }
    }

    /// What the lap preview did (telemetry with the preview on only).
    pub fn lap_counts(&self) -> Option<crate::cueing::lap::Counts> {
        match self {
            Decoder::Telemetry { washout, .. } => washout.lap_counts(),
            _ => None,
        }
    }

    /// What the optimal cueing did (telemetry cued by it only).
    pub fn optimal_counts(&self) -> Option<crate::cueing::optimal::Counts> {
        match self {
            Decoder::Telemetry { washout, .. } => washout.optimal_counts(),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests;

//! Reading a source's datagrams in one telemetry format, or in whichever game's format they turn out to be
//! (`auto`), with the `OutSim Opts` when the user gave them: the one reader of `stream --telemetry-udp` and of
//! `cue --input CAPTURE`.
//!
//! `auto` locks onto a format only after [`LOCK_AFTER`] datagrams in a row that one format recognises and decodes,
//! so that a stray datagram (another program's, a game's stale packet) does not choose it. Until then each
//! datagram is read in the format that recognises it; the first of a format after another format's is read
//! without its time (its arrival time stands in, so that no interval is taken across two formats' clocks). A locked format that refuses [`UNLOCK_AFTER`] datagrams
//! in a row (the game was changed, or the lock was wrong) is dropped, and the format is recognised again.
//!
//! Another of the game's packet types ([`Unreadable::Skipped`]: F1's session, lap data, ... between its motion
//! packets) is read as nothing (`Ok(None)`): neither an error nor a sample, and it neither breaks nor extends
//! `auto`'s run, nor counts against a lock.

use super::outsim2::Opts;
use super::{decode_with, parse_telemetry, recognise, Format, LapPosition, Sample, TelemetryFormat, Unreadable};

/// Datagrams in a row of one format before `auto` locks onto it: at a game's 60 Hz or more, under a tenth of a
/// second; more than a stray or two.
pub const LOCK_AFTER: u32 = 5;
/// Refusals in a row after which a locked format is dropped: half a second of a 100 Hz game.
pub const UNLOCK_AFTER: u32 = 50;

/// A change of `auto`'s format, to say on stderr and in the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Lock {
    /// The format locked onto, or `None` when a locked format was dropped.
    pub format: Option<&'static str>,
    /// The datagram (1-based, of those read) at which it happened.
    pub datagram: u64,
}

/// Changes of format kept for the report; a source that keeps changing is counted past them.
const LOCKS_KEPT: usize = 16;

/// Reads datagrams of one source.
#[derive(Debug, Clone)]
pub struct Reader {
    asked: TelemetryFormat,
    outsim_opts: Option<Opts>,
    locked: Option<Format>,
    /// `auto` before a lock: the format of the current run and its length.
    run: Option<(Format, u32)>,
    /// The format of the last datagram `auto` read, whose clock the next one's time is compared with.
    previous: Option<Format>,
    refused_in_row: u32,
    datagrams: u64,
    locks: Vec<Lock>,
    /// Changes of format past the kept ones.
    pub locks_dropped: u64,
    news: Option<String>,
    /// F1's last lap distance of the player's car: its lap data packet, given with the next motion samples.
    f1_lap: Option<LapPosition>,
}

impl Reader {
    /// A reader of `format`, `OutSimPack2` packets with `outsim_opts` when given.
    pub fn new(format: TelemetryFormat, outsim_opts: Option<Opts>) -> Self {
        Self {
            asked: format,
            outsim_opts,
            locked: None,
            run: None,
            previous: None,
            refused_in_row: 0,
            datagrams: 0,
            locks: Vec::new(),
            locks_dropped: 0,
            news: None,
            f1_lap: None,
        }
    }

    /// The format the datagrams are read in now: the one asked for, or `auto`'s lock.
    #[cfg(test)]
    pub fn format(&self) -> TelemetryFormat {
        match (self.asked, self.locked) {
            (TelemetryFormat::Auto, Some(f)) => TelemetryFormat::Game(f),
            (asked, _) => asked,
        }
    }

    /// `auto`'s changes of format (the first [`LOCKS_KEPT`]).
    pub fn locks(&self) -> &[Lock] {
        &self.locks
    }

    /// What changed since last asked (a lock, or a lock dropped), once, to say on stderr.
    pub fn news(&mut self) -> Option<String> {
        self.news.take()
    }

    fn note(&mut self, format: Option<Format>, news: String) {
        if self.locks.len() < LOCKS_KEPT {
            self.locks.push(Lock {
                format: format.map(Format::name),
                datagram: self.datagrams,
            });
        } else {
            self.locks_dropped += 1;
        }
        self.news = Some(news);
    }

    /// One datagram: its sample, `None` for another of the game's packets (skipped), or why it is not used.
    pub fn read(&mut self, bytes: &[u8]) -> Result<Option<Sample>, String> {
        self.datagrams += 1;
        let f1 = matches!(self.asked, TelemetryFormat::Game(Format::F1) | TelemetryFormat::Auto);
        if f1 {
            if let Some(lap) = super::f1::lap(bytes) {
                self.f1_lap = Some(lap);
            }
        }
        let mut read = self.read_one(bytes);
        // F1's motion packet has no lap distance: the lap data packet's, at most a frame old.
        if let Ok(Some(sample)) = &mut read {
            if f1 && sample.lap.is_none() && super::f1::header_fits(bytes) {
                sample.lap = self.f1_lap;
            }
        }
        read
    }

    fn read_one(&mut self, bytes: &[u8]) -> Result<Option<Sample>, String> {
        match self.asked {
            TelemetryFormat::Text => parse_telemetry(bytes).map(Some),
            TelemetryFormat::Game(f) => skipping(decode_with(f, bytes, self.outsim_opts)),
            TelemetryFormat::Auto => match self.locked {
                Some(f) => self.locked_read(f, bytes),
                None => self.seek(bytes),
            },
        }
    }

    fn locked_read(&mut self, f: Format, bytes: &[u8]) -> Result<Option<Sample>, String> {
        let read = skipping(decode_with(f, bytes, self.outsim_opts));
        if let Ok(sample) = read {
            if sample.is_some() {
                self.refused_in_row = 0;
                self.previous = Some(f);
            }
            return read;
        }
        self.refused_in_row += 1;
        if self.refused_in_row >= UNLOCK_AFTER {
            self.locked = None;
            self.run = None;
            self.refused_in_row = 0;
            let n = self.datagrams;
            self.note(
                None,
                format!(
                    "datagrams {}-{n} were not {f}: recognising the format again",
                    n + 1 - u64::from(UNLOCK_AFTER)
                ),
            );
        }
        read
    }

    fn seek(&mut self, bytes: &[u8]) -> Result<Option<Sample>, String> {
        let Some(f) = recognise(bytes) else {
            self.run = None;
            return Err(Unreadable::Unrecognised(bytes.len()).to_string());
        };
        let sample = match decode_with(f, bytes, self.outsim_opts) {
            Ok(sample) => sample,
            Err(Unreadable::Skipped { .. }) => return Ok(None),
            Err(e) => {
                self.run = None;
                return Err(e.to_string());
            }
        };
        let run = match self.run {
            Some((g, n)) if g == f => n + 1,
            _ => 1,
        };
        self.run = Some((f, run));
        if run >= LOCK_AFTER {
            self.locked = Some(f);
            let n = self.datagrams;
            self.note(
                Some(f),
                format!(
                    "the datagrams are {f} ({}): {LOCK_AFTER} in a row, datagrams {}-{n}",
                    f.games(),
                    n + 1 - u64::from(LOCK_AFTER)
                ),
            );
        }
        // After another format's datagram, the arrival time: the two clocks are not one.
        let switched = self.previous.is_some_and(|p| p != f);
        self.previous = Some(f);
        Ok(Some(if switched {
            Sample { time: None, ..sample }
        } else {
            sample
        }))
    }
}

/// A decoded datagram as the reader gives it: another of the game's packets is nothing, not an error.
fn skipping(decoded: Result<Sample, Unreadable>) -> Result<Option<Sample>, String> {
    match decoded {
        Ok(sample) => Ok(Some(sample)),
        Err(Unreadable::Skipped { .. }) => Ok(None),
        Err(e) => Err(e.to_string()),
    }
}

/// The format `auto` reads a whole capture in: the first run of [`LOCK_AFTER`] datagrams of one format (the
/// game's other packets between them passed over), else
/// the longest run (a capture shorter than that), with the index of the run's first datagram; `None` when no
/// datagram is any game's.
pub fn detect<'a>(payloads: impl IntoIterator<Item = &'a [u8]>, outsim_opts: Option<Opts>) -> Option<(Format, usize)> {
    let mut best: Option<(Format, usize, u32)> = None;
    let mut run: Option<(Format, usize, u32)> = None;
    for (i, bytes) in payloads.into_iter().enumerate() {
        let decoded = recognise(bytes).map(|f| (f, decode_with(f, bytes, outsim_opts)));
        // Another of the game's packets between its motion packets: the run goes on.
        if matches!(decoded, Some((_, Err(Unreadable::Skipped { .. })))) {
            continue;
        }
        let f = decoded.and_then(|(f, d)| d.is_ok().then_some(f));
        run = match (f, run) {
            (Some(f), Some((g, start, n))) if g == f => Some((f, start, n + 1)),
            (Some(f), _) => Some((f, i, 1)),
            (None, _) => None,
        };
        if let Some((f, start, n)) = run {
            if n >= LOCK_AFTER {
                return Some((f, start));
            }
            if best.is_none_or(|(_, _, m)| n > m) {
                best = Some((f, start, n));
            }
        }
    }
    best.map(|(f, start, _)| (f, start))
}

#[cfg(test)]
mod tests;

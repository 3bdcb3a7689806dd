//! Taking a game's samples from its live memory: a sample is new only when the game's own counter moved; a copy
//! the game wrote into while it was taken (its counter moved during the copy, or the game's own guard says so) is
//! torn, taken again up to [`TRIES`] times, and counted; a game whose counter stands still, or whose mapping is not
//! there, is a stall, counted once per pause and said on stderr.

use std::time::{Duration, Instant};

use super::take::{self, Now};
use super::{decode, Game, Guard, Memory, Read, Unreadable};

/// Copies taken of one sample before giving up until the next poll.
pub const TRIES: u32 = 3;
/// A pause of this many of the game's periods (and at least [`MIN_STALL`]) is a stall.
pub const STALL_PERIODS: f64 = 10.0;
/// The shortest pause counted as a stall.
pub const MIN_STALL: Duration = Duration::from_millis(100);

/// What a game's memory gave: counted in the stream's report.
#[derive(Debug, Default, Clone, PartialEq, serde::Serialize)]
pub struct Counts {
    /// New samples (the counter moved, the copy whole, the decoder content).
    pub samples: u64,
    /// Polls that found the counter where it was (no new sample yet).
    pub repeats: u64,
    /// Polls that found a new counter of a game without a write guard (AC, ACC, ETS2) and left it to stand for a
    /// poll before copying, so that the values it counts are written.
    pub settling: u64,
    /// Copies found torn (the game wrote while they were taken), each taken again.
    pub torn: u64,
    /// Polls that gave up after [`TRIES`] torn copies (the next poll tries again).
    pub torn_given_up: u64,
    /// New counters whose snapshot the decoder refused (no player's car, a layout it does not know).
    pub refused: u64,
    /// Polls that found no mapping (the game not running, or the plugin not installed).
    pub absent: u64,
    /// Polls at which the game said nobody is there (iRacing not connected, the SCS plugin inactive).
    pub idle: u64,
    /// Pauses of the game's counter longer than [`STALL_PERIODS`] periods (the game paused, in its menus, closed, or
    /// not yet started), each counted once.
    pub stalls: u64,
    /// Seconds spent in those pauses.
    pub stalled_s: f64,
    /// Samples whose game time went back (a new session, a restart): each passed on without its time, so that the
    /// stream times it by its arrival and takes the new clock from the next sample on.
    pub clock_restarts: u64,
}

/// What one poll gave.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// A new sample.
    New(Read),
    /// A new counter, but the snapshot was refused (with why).
    Refused(Unreadable),
    /// Nothing new (a repeat, a stall, a copy torn too often).
    Nothing,
}

/// Polls one game's memory.
#[derive(Debug)]
pub struct Poller {
    game: Game,
    last: Option<u64>,
    /// An unguarded game's counter as the last poll found it.
    seen: Option<u64>,
    /// The game time of the last new sample that had one.
    last_time: Option<f64>,
    /// When the last new sample came (or the poller started), and whether the pause since is counted as a stall.
    since: Instant,
    stalled: bool,
    /// The counts for the report.
    pub counts: Counts,
    news: Option<String>,
}

impl Poller {
    /// Polls `game`, its wait for a first sample starting at `start`.
    pub fn new(game: Game, start: Instant) -> Self {
        Self {
            game,
            last: None,
            seen: None,
            last_time: None,
            since: start,
            stalled: false,
            counts: Counts::default(),
            news: None,
        }
    }

    /// The game.
    pub fn game(&self) -> Game {
        self.game
    }

    /// The pause after which the game counts as stalled.
    pub fn stall_after(&self) -> Duration {
        Duration::from_secs_f64(STALL_PERIODS / self.game.rate_hz()).max(MIN_STALL)
    }

    /// How often to poll: a quarter of the game's period, between 1 and 5 ms (the counter alone is read, a few bytes;
    /// a sample waits at most that long).
    pub fn interval(&self) -> Duration {
        Duration::from_secs_f64(0.25 / self.game.rate_hz()).clamp(Duration::from_millis(1), Duration::from_millis(5))
    }

    /// A stall begun or ended since last asked, once, to say on stderr.
    pub fn news(&mut self) -> Option<String> {
        self.news.take()
    }

    /// Polls once at `now`.
    pub fn poll(&mut self, mem: &mut dyn Memory, now: Instant) -> Outcome {
        let mut outcome = self.take(mem);
        let paused = now.saturating_duration_since(self.since);
        if let Outcome::New(read) = &mut outcome {
            self.clock(read);
            if self.stalled {
                self.counts.stalled_s += paused.as_secs_f64();
                self.news = Some(format!(
                    "{}: samples again after {:.1} s",
                    self.game.title(),
                    paused.as_secs_f64()
                ));
            }
            self.stalled = false;
            self.since = now;
        } else if !self.stalled && paused > self.stall_after() {
            self.stalled = true;
            self.counts.stalls += 1;
            self.news = Some(format!(
                "{}: no new sample for {:.2} s (paused, in the menus, closed, or not started): waiting",
                self.game.title(),
                paused.as_secs_f64()
            ));
        }
        outcome
    }

    /// A game time before the last one (the game's clock started again): the sample goes on without it, once.
    fn clock(&mut self, read: &mut Read) {
        let Some(t) = read.sample.time else {
            return;
        };
        if self.last_time.is_some_and(|last| t < last) {
            self.counts.clock_restarts += 1;
            self.news = Some(format!(
                "{}: the game's clock went back from {:.3} s to {t:.3} s (a new session): timed by arrival once",
                self.game.title(),
                self.last_time.unwrap_or_default()
            ));
            read.sample.time = None;
        }
        self.last_time = Some(t);
    }

    /// The end of the run: a stall still going on counts its seconds.
    pub fn finish(&mut self, now: Instant) {
        if self.stalled {
            self.counts.stalled_s += now.saturating_duration_since(self.since).as_secs_f64();
            self.stalled = false;
        }
    }

    fn take(&mut self, mem: &mut dyn Memory) -> Outcome {
        let c = &mut self.counts;
        for _ in 0..TRIES {
            let before = match take::now(self.game, mem) {
                Err(_) => {
                    c.absent += 1;
                    return Outcome::Nothing;
                }
                Ok(Now::Idle) => {
                    c.idle += 1;
                    return Outcome::Nothing;
                }
                Ok(Now::Writing) => {
                    c.torn += 1;
                    continue;
                }
                Ok(Now::Tick(t)) if Some(t) == self.last => {
                    c.repeats += 1;
                    return Outcome::Nothing;
                }
                // A layout without a write guard: its counter may move before the values it counts (the SCS
                // plugin stamps the frame first), so a new counter is taken only once it has stood for a poll.
                Ok(Now::Tick(t)) if !self.game.guarded() && self.seen != Some(t) => {
                    self.seen = Some(t);
                    c.settling += 1;
                    return Outcome::Nothing;
                }
                Ok(Now::Tick(t)) => t,
            };
            let Ok(snapshot) = take::copy(self.game, mem) else {
                c.absent += 1;
                return Outcome::Nothing;
            };
            match decode(self.game, &snapshot) {
                Err(Unreadable::Torn { .. }) => c.torn += 1,
                Err(e) => {
                    // Refused once per counter value: the next poll finds it a repeat.
                    self.last = Some(before);
                    c.refused += 1;
                    return Outcome::Refused(e);
                }
                Ok(read) if read.tick == before && unmoved(mem, &read.guard) => {
                    self.last = Some(read.tick);
                    c.samples += 1;
                    return Outcome::New(read);
                }
                Ok(_) => c.torn += 1,
            }
        }
        c.torn_given_up += 1;
        Outcome::Nothing
    }
}

/// Whether the counter in the live memory is still what the copy holds.
fn unmoved(mem: &mut dyn Memory, guard: &Guard) -> bool {
    let mut now = [0; 8];
    mem.read(guard.page, guard.at, &mut now[..guard.len]).is_ok() && now[..guard.len] == guard.bytes[..guard.len]
}

#[cfg(test)]
mod tests;

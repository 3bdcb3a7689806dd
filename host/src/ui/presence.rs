//! Who is watching: the pages connected now, and what happens when the last one goes.
//!
//! A stream is never left running without a page: when the page that started it goes, it ends at once (as STOP
//! ends it) and the platform comes to rest where it is. When no page is left for [`GRACE`], the operator has gone:
//! the workbench does what STOP does, bringing whatever moves to rest and powering down. The grace lets a reload
//! or a second tab taking over keep the platform powered; a page counts as gone when its socket closes or when it
//! has answered none of [`UNANSWERED`] pings in a row (a killed browser, a machine that went to sleep): see
//! [`Heartbeat`].

use std::collections::BTreeSet;
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

/// How long the workbench waits with no page before it powers down.
pub const GRACE: Duration = Duration::from_secs(2);
/// How often a page is pinged (a browser answers by itself, also for a tab in the background).
pub const PING_EVERY: Duration = Duration::from_secs(1);
/// A page that has answered none of this many pings in a row (a message or a pong answers) is taken as gone.
pub const UNANSWERED: u32 = 5;
/// How long a page that answers nothing lasts: [`UNANSWERED`] pings.
pub const HEARD_WITHIN: Duration = Duration::from_secs(PING_EVERY.as_secs() * UNANSWERED as u64);

/// One page's liveness, counted in the pings the workbench sent rather than in time: a workbench that could not
/// send its pings (its machine busy with a game, its threads held up) has not asked the page anything, and does
/// not take the page's silence over that time as its going away.
#[derive(Debug, Default)]
pub struct Heartbeat {
    /// Pings sent since the page was last heard.
    unanswered: u32,
}

impl Heartbeat {
    /// The page said something (a message or a pong).
    pub fn heard(&mut self) {
        self.unanswered = 0;
    }

    /// Time for a ping: whether to send it, or `false` when the page has answered none of [`UNANSWERED`].
    pub fn ping(&mut self) -> bool {
        if self.unanswered >= UNANSWERED {
            return false;
        }
        self.unanswered += 1;
        true
    }
}

/// The pages connected now.
#[derive(Default)]
pub struct Presence {
    inner: Mutex<Inner>,
}

#[derive(Default)]
struct Inner {
    open: BTreeSet<u64>,
    /// Since when no page is open, after one left (not before the first came: the device is as the command
    /// found it).
    deserted: Option<Instant>,
}

impl Presence {
    fn inner(&self) -> std::sync::MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// A page connected.
    pub fn arrive(&self, page: u64) {
        let mut i = self.inner();
        i.open.insert(page);
        i.deserted = None;
    }

    /// A page went away.
    pub fn leave(&self, page: u64, now: Instant) {
        let mut i = self.inner();
        i.open.remove(&page);
        if i.open.is_empty() {
            i.deserted = Some(now);
        }
    }

    /// Whether the page is connected.
    pub fn is_open(&self, page: u64) -> bool {
        self.inner().open.contains(&page)
    }

    /// Whether the last page left [`GRACE`] ago and none came since: said once per departure.
    pub fn deserted(&self, now: Instant) -> bool {
        let mut i = self.inner();
        let gone = i.deserted.is_some_and(|since| now.duration_since(since) >= GRACE);
        if gone {
            i.deserted = None;
        }
        gone
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_page_is_gone_after_the_pings_it_left_unanswered_however_long_they_took() {
        let mut h = Heartbeat::default();
        for _ in 0..UNANSWERED {
            assert!(h.ping());
        }
        h.heard();
        for _ in 0..UNANSWERED {
            assert!(h.ping(), "an answer starts the count again");
        }
        assert!(!h.ping(), "none of {UNANSWERED} answered");
        assert!(!h.ping(), "and it stays gone");
    }

    #[test]
    fn the_last_page_gone_for_the_grace_is_said_once_and_a_return_within_it_is_not() {
        let p = Presence::default();
        let t0 = Instant::now();
        assert!(!p.deserted(t0 + GRACE * 10), "no page has come yet");
        p.arrive(1);
        p.arrive(2);
        p.leave(1, t0);
        assert!(!p.deserted(t0 + GRACE * 2), "page 2 is still there");
        assert!(p.is_open(2) && !p.is_open(1));
        p.leave(2, t0);
        assert!(!p.deserted(t0 + GRACE / 2));
        assert!(p.deserted(t0 + GRACE));
        assert!(!p.deserted(t0 + GRACE * 2), "once");
        // A reload: gone, back within the grace.
        p.arrive(3);
        p.leave(3, t0);
        p.arrive(4);
        assert!(!p.deserted(t0 + GRACE * 3));
    }
}

//! The rule for a host gone long. A stream whose setpoints stop for the stream timeout is lost: the platform brakes
//! to rest and holds there, homed and powered, so that a host that is only late (a busy PC, a cable bumped and
//! plugged again, a link stalled for a moment) carries on without homing again. A host that stays silent after that
//! is gone (its PC hung, its program killed, the link cut): the device then powers down as the host's STOP would
//! have (drivers disabled, motor power off, logic off, each after the supervisor's delay), so that a board whose PC
//! hung does not hold the platform with its drivers energised for as long as nobody comes.
//!
//! - The silence counts from the loss and starts again at every request a host sends (on any link): a host that
//!   asks for the status is there.
//! - The rule holds while the platform brakes or holds after the loss (`Stopping`, `Ready`) and ends with anything
//!   else (a new stream, a command, a fault), which the host that gave it is there to watch.
//! - Only a lost stream arms it: between two commands of a command line (`device home`, and `stream` minutes later)
//!   the device is idle, not abandoned.
//! - It moves nothing. The loss brought the platform to rest; a machine that starts a move nobody commanded, with
//!   nobody watching, is the unexpected start-up a machine must not make (ISO 14118), and parking it is
//!   the returning host's decision. Powered down where it rests, the trainer model stays there: its carriages run on
//!   a level ring, and its linear actuators are (as FIRMWARE.md assumes) 2 mm-lead screws, which the platform's
//!   weight does not turn back when they are trapezoidal. A rig whose axes sag without current needs brakes that
//!   close when the drivers' enable goes off.
//!
//! The time ([`HOST_GONE_MS`], the stream section's `host_gone_ms`): longer than every wait of a host that is still
//! there (5 s for an answer, a flash erase's 2 s hold-up, a USB port found again after a replug within a few
//! seconds), short enough that a board left with a hung PC is powered down before anyone is likely to come near it.

use super::supervisor::State;

/// How long, after a lost stream, the device waits for any host before it powers down (ms): twice the 5 s a host
/// waits for an answer before it gives the link up, and twice the longest hold-up a device recovers from
/// ([`crate::motion::pipeline::HOLD_UP_LIMIT_US`]).
pub const HOST_GONE_MS: u16 = 10_000;

/// Time since a lost stream with no request from a host; `None` when no lost stream is being watched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HostWatch {
    silent_ms: Option<u32>,
}

impl HostWatch {
    /// The stream was lost: the silence starts.
    pub fn lost(&mut self) {
        self.silent_ms = Some(0);
    }

    /// A host sent a request: the silence starts again.
    pub fn heard(&mut self) {
        if let Some(t) = &mut self.silent_ms {
            *t = 0;
        }
    }

    /// Milliseconds of silence so far, while a lost stream is watched.
    pub fn silent_ms(&self) -> Option<u32> {
        self.silent_ms
    }

    /// `ms` more passed with the supervisor in `state`: true once, when the device must power down now.
    pub fn elapse(&mut self, ms: u32, state: State, gone_ms: u16) -> bool {
        let Some(t) = self.silent_ms else {
            return false;
        };
        let t = t.saturating_add(ms);
        let (next, now) = match state {
            // braking counts toward the time; the power-down waits for rest
            State::Stopping => (Some(t), false),
            State::Ready if t < u32::from(gone_ms) => (Some(t), false),
            State::Ready => (None, true),
            // a new stream, a command or a fault: the host is there, or the supervisor has taken over
            _ => (None, false),
        };
        self.silent_ms = next;
        now
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn unarmed_it_never_fires() {
        let mut w = HostWatch::default();
        for _ in 0..100_000 {
            assert!(!w.elapse(1, State::Ready, 1_000));
        }
        w.heard();
        assert_eq!(w.silent_ms(), None);
    }

    #[test]
    fn it_fires_once_at_the_time_and_a_request_starts_it_again() {
        let mut w = HostWatch::default();
        w.lost();
        assert!(!w.elapse(150, State::Stopping, 1_000), "braking counts, never fires");
        assert!(!w.elapse(849, State::Ready, 1_000));
        w.heard();
        assert_eq!(w.silent_ms(), Some(0));
        let fired: Vec<u32> = (1..=3_000).filter(|_| w.elapse(1, State::Ready, 1_000)).collect();
        assert_eq!(fired.len(), 1);
        assert_eq!(w.silent_ms(), None, "fired: no longer armed");
    }

    #[test]
    fn any_other_state_ends_it() {
        for state in [
            State::Running,
            State::Homing,
            State::Jogging,
            State::Off,
            State::PowerOn { settled: true },
            State::ShuttingDown(crate::safety::supervisor::Shutdown::Drivers),
            State::Fault(crate::safety::FaultReason::EStop, crate::safety::Supplies::Logic),
        ] {
            let mut w = HostWatch::default();
            w.lost();
            assert!(!w.elapse(1, state, 1_000));
            assert_eq!(w.silent_ms(), None, "{state:?}");
            assert!(!w.elapse(100_000, State::Ready, 1_000), "{state:?}");
        }
    }

    proptest! {
        /// With requests at any times after the loss (some while braking), it fires once, at the first moment the
        /// silence since the loss or the latest request reaches the time.
        #[test]
        fn it_fires_when_the_silence_since_the_last_request_reaches_the_time(
            gone in 1_000u16..=60_000,
            braking in 0u32..400,
            gaps in prop::collection::vec(1u32..70_000, 0..6),
        ) {
            let requests: Vec<u32> = gaps.iter().scan(0u32, |t, g| { *t += g; Some(*t) }).collect();
            let mut expected = None;
            let mut since = 0u32;
            for r in &requests {
                if since + u32::from(gone) <= *r {
                    expected = Some(since + u32::from(gone));
                    break;
                }
                since = *r;
            }
            let expected = expected.unwrap_or(since + u32::from(gone));
            let mut w = HostWatch::default();
            w.lost();
            let mut fired = Vec::new();
            for now in 1..=expected + 70_000 {
                let state = if now <= braking { State::Stopping } else { State::Ready };
                if w.elapse(1, state, gone) {
                    fired.push(now);
                }
                if requests.contains(&now) {
                    w.heard();
                }
            }
            prop_assert_eq!(fired, vec![expected]);
        }
    }
}

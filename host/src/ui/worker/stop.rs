//! A STOP the device did not confirm: kept, shown to every page as pending, and given again until the device
//! confirms it. A link that stalls must not swallow the operator's STOP (the device comes to rest on its own when
//! the stream stops, but stays powered until it hears the STOP).

use std::time::{Duration, Instant};

use serde_json::json;

use super::{Device, WorkerError};
use crate::link::client::ClientError;

/// A STOP given while the device did not answer.
pub(super) struct PendingStop {
    /// When it was given, and when it was last sent.
    pub(super) given: Instant,
    pub(super) sent: Instant,
    /// Times it was sent again.
    pub(super) resent: u32,
}

/// How often a pending STOP is sent again.
const RESEND_STOP: Duration = Duration::from_secs(1);

impl Device {
    /// A STOP the link lost: kept as pending, said to every page, sent again every [`RESEND_STOP`].
    pub(super) fn keep_stop(&mut self, e: &ClientError) {
        let now = Instant::now();
        let pending = self.pending_stop.get_or_insert(PendingStop {
            given: now,
            sent: now,
            resent: 0,
        });
        pending.sent = now;
        let text = format!(
            "STOP pending: not confirmed by the device ({e}); sent again every second until it is, nothing else runs meanwhile"
        );
        self.hub
            .publish(&json!({ "type": "stop_pending", "pending": true, "text": text }));
    }

    /// Sends a pending STOP again when it is due; once the device confirms (at rest, powering down), says so.
    pub(super) fn resend_stop(&mut self) {
        let Some(pending) = &mut self.pending_stop else {
            return;
        };
        if pending.sent.elapsed() < RESEND_STOP {
            return;
        }
        pending.resent += 1;
        let (given, resent) = (pending.given, pending.resent);
        match self.halt() {
            Ok(text) => {
                self.pending_stop = None;
                let text = format!(
                    "STOP confirmed {:.1} s after it was given (sent again {resent} times): {text}",
                    given.elapsed().as_secs_f64()
                );
                self.hub
                    .publish(&json!({ "type": "stop_pending", "pending": false, "text": text.clone() }));
                self.hub
                    .publish(&json!({ "type": "halted", "page": 0, "id": 0, "text": text }));
            }
            Err(WorkerError::Client(e @ (ClientError::Timeout(_) | ClientError::Io(_)))) => self.keep_stop(&e),
            // The device answered and refused: the STOP is not lost, it is answered; the pages see why.
            Err(e) => {
                self.pending_stop = None;
                let text = format!("STOP: the device answered but did not power down: {e:#}");
                self.hub
                    .publish(&json!({ "type": "stop_pending", "pending": false, "text": text }));
            }
        }
    }
}

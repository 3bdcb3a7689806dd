//! A STOP the device did not confirm: kept, shown to every page as pending, and given again until the device
//! confirms it. A link that stalls must not swallow the operator's STOP (the device comes to rest on its own when
//! the stream stops, but stays powered until it hears the STOP).

use std::time::{Duration, Instant};

use serde_json::json;

use super::{Device, Job, WorkerError};
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

    /// A page's STOP: brought to rest and powered down, confirmed to the pages; kept pending when the device does not
    /// answer.
    pub(super) fn stop(&mut self, job: &Job) -> Result<String, WorkerError> {
        match self.halt() {
            Ok(text) => {
                // The STOP was answered when it arrived; this says the platform is at rest.
                self.pending_stop = None;
                self.confirm_stop(job.page, job.id, &text);
                Ok(text)
            }
            Err(WorkerError::Client(e @ (ClientError::Timeout(_) | ClientError::Io(_)))) => {
                self.keep_stop(&e);
                Err(WorkerError::Client(e))
            }
            Err(e) => {
                self.pending_stop = None;
                self.refused_stop(&e);
                Err(e)
            }
        }
    }

    /// The device answered the STOP and did not power down: it is not lost, it is answered; the pages see why.
    fn refused_stop(&self, e: &WorkerError) {
        let text = format!("STOP: the device answered but did not power down: {e:#}");
        self.hub
            .publish(&json!({ "type": "stop_pending", "pending": false, "text": text }));
        // Also for a page that opens later (a STOP the workbench gave for a page that went away).
        self.hub.keep(text);
    }

    /// The device confirmed the STOP (`page`'s request `id`, 0 for one given again): the pages are told.
    pub(super) fn confirm_stop(&self, page: u64, id: u64, text: &str) {
        let confirmed = format!("STOP confirmed: {text}");
        self.hub
            .publish(&json!({ "type": "stop_pending", "pending": false, "text": confirmed }));
        self.hub.keep(confirmed);
        self.hub
            .publish(&json!({ "type": "halted", "page": page, "id": id, "text": text }));
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
                    "{text}, {:.1} s after it was given (sent again {resent} times)",
                    given.elapsed().as_secs_f64()
                );
                self.confirm_stop(0, 0, &text);
            }
            Err(WorkerError::Client(e @ (ClientError::Timeout(_) | ClientError::Io(_)))) => self.keep_stop(&e),
            Err(e) => {
                self.pending_stop = None;
                self.refused_stop(&e);
            }
        }
    }
}

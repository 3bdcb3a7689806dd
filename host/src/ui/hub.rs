//! What the pages and the device thread share, and STOP.
//!
//! STOP never waits behind the device thread's queue: it is taken where the page's message arrives. It advances
//! the STOP generation, which every queued request carries from when it was sent, so that a request sent before
//! a STOP is answered as cancelled instead of run; and it raises the cancel flag of whatever the device thread
//! runs now (a stream, its powering up and homing), which ends it at once. The device thread then brings the
//! platform to rest and powers down.

use std::collections::{BTreeMap, VecDeque};
use std::net::IpAddr;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use ringpod_core::protocol::RigRecord;
use serde_json::json;

use super::outbox::Outbox;
use super::presence::Presence;
use super::request::Job;

/// What the pages and the device thread share.
pub struct Hub {
    /// What waits to be sent to each connected page.
    outboxes: Mutex<BTreeMap<u64, Arc<Outbox>>>,
    /// The STOP generation: how many STOPs were pressed.
    epoch: AtomicU64,
    /// The cancel flag of what the device thread runs now (a fresh one per request).
    cancel: Mutex<Arc<AtomicBool>>,
    /// The page whose stream runs (0: none).
    pub streaming: AtomicU64,
    /// A stream is queued or runs: set when a page's stream request is taken, cleared when the device thread is
    /// done with it, so that two pages asking at the same moment do not both run, one after the other.
    pub stream_claimed: AtomicBool,
    /// The newest rig message, for a page that connects later.
    pub rig: Mutex<Option<String>>,
    /// The rig the device runs, for the computations and the Rig panel.
    pub record: Mutex<Option<RigRecord>>,
    /// The cueing file a telemetry session reloads when it changes (the Cueing panel's "apply live").
    pub cue_file: PathBuf,
    /// Set when the server ends: the device thread powers down and returns.
    pub closing: AtomicBool,
    /// The pages connected now.
    pub presence: Presence,
    /// The address the workbench listens on: a UDP session of a page binds it too (loopback stays loopback).
    pub bind: IpAddr,
    /// The directory whose files a page may stream by name (`ringpod ui --files`).
    pub files: Option<PathBuf>,
    /// What the workbench did on its own (a stream stopped because its page went, a STOP's outcome), newest
    /// last, at most [`KEPT_NOTICES`]: a page that opens later (a reload) is told in its log.
    notices: Mutex<VecDeque<serde_json::Value>>,
}

/// Notices kept for pages that open later.
pub const KEPT_NOTICES: usize = 16;

impl Hub {
    /// A hub with no page and no STOP yet.
    pub fn new(cue_file: PathBuf, bind: IpAddr, files: Option<PathBuf>) -> Self {
        Self {
            outboxes: Mutex::new(BTreeMap::new()),
            epoch: AtomicU64::new(0),
            cancel: Mutex::new(Arc::new(AtomicBool::new(false))),
            streaming: AtomicU64::new(0),
            stream_claimed: AtomicBool::new(false),
            rig: Mutex::new(None),
            record: Mutex::new(None),
            cue_file,
            closing: AtomicBool::new(false),
            presence: Presence::default(),
            bind,
            files,
            notices: Mutex::new(VecDeque::new()),
        }
    }

    /// Keeps a notice for the pages that open later (the pages open now were told otherwise).
    pub fn keep(&self, text: impl Into<String>) -> serde_json::Value {
        let at_ms = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_millis() as u64);
        let notice = json!({ "type": "notice", "text": text.into(), "at_ms": at_ms });
        let mut kept = self.notices.lock().unwrap_or_else(PoisonError::into_inner);
        if kept.len() >= KEPT_NOTICES {
            kept.pop_front();
        }
        kept.push_back(notice.clone());
        notice
    }

    /// Says a notice to every page now and keeps it for the pages that open later.
    pub fn notice(&self, text: impl Into<String>) {
        let notice = self.keep(text);
        self.publish(&notice);
    }

    /// The notices kept, for a page that opens now: each marked as from before it.
    pub fn earlier_notices(&self) -> Vec<String> {
        let kept = self.notices.lock().unwrap_or_else(PoisonError::into_inner);
        kept.iter()
            .map(|n| {
                let mut n = n.clone();
                n["earlier"] = json!(true);
                n.to_string()
            })
            .collect()
    }

    fn outboxes(&self) -> Vec<Arc<Outbox>> {
        let o = self.outboxes.lock().unwrap_or_else(PoisonError::into_inner);
        o.values().cloned().collect()
    }

    /// A page's outbox, from when it connects.
    pub fn open_outbox(&self, page: u64) -> Arc<Outbox> {
        let outbox = Arc::new(Outbox::default());
        let mut o = self.outboxes.lock().unwrap_or_else(PoisonError::into_inner);
        o.insert(page, outbox.clone());
        outbox
    }

    /// The page has gone.
    pub fn close_outbox(&self, page: u64) {
        let mut o = self.outboxes.lock().unwrap_or_else(PoisonError::into_inner);
        o.remove(&page);
    }

    /// Sends a message to every page, never dropped (none listening is not an error).
    pub fn publish(&self, message: &serde_json::Value) {
        let text = message.to_string();
        for o in self.outboxes() {
            o.push(text.clone());
        }
    }

    /// Sends a telemetry frame to every page: a page that has not taken the last one gets this one instead.
    pub fn publish_frame(&self, frame: &serde_json::Value) {
        for o in self.outboxes() {
            o.frame(frame);
        }
    }

    /// A reply to a page's request, seen by every page.
    pub fn reply(&self, page: u64, id: u64, ok: bool, text: impl Into<String>) {
        self.publish(&json!({ "type": "reply", "page": page, "id": id, "ok": ok, "text": text.into() }));
    }

    /// The STOP generation a request sent now belongs to.
    pub fn epoch(&self) -> u64 {
        self.epoch.load(Ordering::SeqCst)
    }

    /// STOP: every request sent before now is cancelled and what runs now ends. Gives the new generation.
    pub fn stop_everything(&self) -> u64 {
        let epoch = self.epoch.fetch_add(1, Ordering::SeqCst) + 1;
        // After the generation: a request the device thread began before it sees this flag, one it begins after
        // it sees the new generation (see `begin`).
        self.cancel_current();
        epoch
    }

    /// Ends what the device thread runs now (a stream whose page went away, the server's end), sparing the queue.
    pub fn cancel_current(&self) {
        self.cancel
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .store(true, Ordering::SeqCst);
    }

    /// The device thread begins `job`: its cancel flag, or why it is not run: a STOP came after it was sent, or
    /// its page has gone (nobody would watch what it does). A STOP is begun only when no later STOP supersedes it.
    pub fn begin(&self, job: &Job) -> Result<Arc<AtomicBool>, &'static str> {
        let flag = Arc::new(AtomicBool::new(false));
        *self.cancel.lock().unwrap_or_else(PoisonError::into_inner) = flag.clone();
        // Read after the flag is in place: a STOP that this read misses raises the flag.
        if self.epoch() != job.epoch {
            return Err(if job.request.is_halt() {
                "STOP: taken over by a later STOP"
            } else {
                "cancelled: STOP was pressed after it was sent"
            });
        }
        if !job.request.is_halt() && !self.presence.is_open(job.page) {
            return Err("cancelled: its page has gone");
        }
        Ok(flag)
    }
}

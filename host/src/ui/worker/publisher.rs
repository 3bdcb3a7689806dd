//! The telemetry tap's side of the pages: frames of what the client sees, at a rate a browser draws.

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use ringpod_core::kinematics::RingPlatform;
use ringpod_core::protocol::Telemetry;
use serde_json::json;

use super::super::frame::{self, LinkCounts};
use super::super::hub::Hub;
use super::FRAME_HZ;

/// Makes frames of the telemetry the client sees, at most [`FRAME_HZ`] a second.
pub(super) struct Publisher {
    pub(super) hub: Arc<Hub>,
    pub(super) mechanism: Arc<Mutex<RingPlatform<f64>>>,
    pub(super) counts: LinkCounts,
    pub(super) last_sent: Option<Instant>,
    pub(super) window: (Instant, u64),
}

impl Publisher {
    pub(super) fn see(&mut self, sample: &Telemetry) {
        self.counts.received += 1;
        let now = Instant::now();
        let (since, n) = self.window;
        if now.duration_since(since) >= Duration::from_secs(1) {
            self.counts.rate_hz = (self.counts.received - n) as f64 / now.duration_since(since).as_secs_f64();
            self.window = (now, self.counts.received);
        }
        if self
            .last_sent
            .is_some_and(|t| now.duration_since(t) < Duration::from_secs_f64(1.0 / FRAME_HZ))
        {
            return;
        }
        self.last_sent = Some(now);
        let streaming = self.hub.streaming.load(Ordering::SeqCst) != 0;
        let Ok(m) = self.mechanism.lock() else { return };
        let frame = frame::frame(&m, sample, self.counts, streaming);
        let mut message = serde_json::to_value(frame).unwrap_or_default();
        message["type"] = json!("frame");
        self.hub.publish_frame(&message);
    }
}

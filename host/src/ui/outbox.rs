//! What waits to be sent to one page. Replies, reports and rig messages are kept in order and never dropped;
//! telemetry frames are coalesced (a page that lags gets the newest, and the count of those it missed). A page
//! that falls [`MOST_WAITING`] messages behind cannot keep up: it is closed with a reason, never fed silently less.

use std::collections::VecDeque;
use std::sync::{Mutex, MutexGuard, PoisonError};

use serde_json::Value;
use tokio::sync::Notify;

/// Messages (not frames) that may wait for one page before it is taken as unable to keep up.
pub const MOST_WAITING: usize = 4096;

/// One page's waiting messages.
#[derive(Default)]
pub struct Outbox {
    queue: Mutex<Queue>,
    ready: Notify,
}

#[derive(Default)]
struct Queue {
    messages: VecDeque<String>,
    frame: Option<Value>,
    /// Frames replaced by a newer one before they were sent, since the page connected.
    coalesced: u64,
    overrun: bool,
}

/// What the page is sent next.
#[derive(Debug, PartialEq)]
pub enum Next {
    /// The messages in order, then the newest frame with the count of frames coalesced so far.
    Send(Vec<String>, Option<Value>),
    /// The page fell too far behind.
    Overrun,
}

impl Outbox {
    fn queue(&self) -> MutexGuard<'_, Queue> {
        self.queue.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// A message that must arrive.
    pub fn push(&self, text: String) {
        let mut q = self.queue();
        if q.messages.len() >= MOST_WAITING {
            q.overrun = true;
        } else {
            q.messages.push_back(text);
        }
        drop(q);
        self.ready.notify_one();
    }

    /// The newest frame; one not sent yet is replaced and counted.
    pub fn frame(&self, frame: &Value) {
        let mut q = self.queue();
        if q.frame.replace(frame.clone()).is_some() {
            q.coalesced += 1;
        }
        drop(q);
        self.ready.notify_one();
    }

    /// Waits for something to send and takes it all (cancel-safe: nothing is taken before it is returned).
    pub async fn next(&self) -> Next {
        loop {
            {
                let mut q = self.queue();
                if q.overrun {
                    return Next::Overrun;
                }
                if !q.messages.is_empty() || q.frame.is_some() {
                    let messages = q.messages.drain(..).collect();
                    let coalesced = q.coalesced;
                    let frame = q.frame.take().map(|mut f| {
                        f["coalesced"] = coalesced.into();
                        f
                    });
                    return Next::Send(messages, frame);
                }
            }
            // A notification sent between the look above and this wait is kept for it (`Notify` stores a permit).
            self.ready.notified().await;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn now(o: &Outbox) -> Next {
        let waker = std::task::Waker::noop();
        let mut cx = std::task::Context::from_waker(waker);
        let mut next = std::pin::pin!(o.next());
        match next.as_mut().poll(&mut cx) {
            std::task::Poll::Ready(n) => n,
            std::task::Poll::Pending => Next::Send(Vec::new(), None),
        }
    }

    use std::future::Future;

    #[test]
    fn messages_all_arrive_in_order_and_frames_are_coalesced_and_counted() {
        let o = Outbox::default();
        for i in 0..1000 {
            o.frame(&json!({ "t": i }));
            o.push(format!("reply {i}"));
        }
        let Next::Send(messages, frame) = now(&o) else {
            panic!("not overrun")
        };
        assert_eq!(messages.len(), 1000);
        assert!(messages.iter().enumerate().all(|(i, m)| *m == format!("reply {i}")));
        assert_eq!(frame, Some(json!({ "t": 999, "coalesced": 999 })));
        assert_eq!(now(&o), Next::Send(Vec::new(), None), "nothing left");
    }

    #[test]
    fn a_page_too_far_behind_is_told() {
        let o = Outbox::default();
        for i in 0..=MOST_WAITING {
            o.push(i.to_string());
        }
        assert_eq!(now(&o), Next::Overrun);
    }
}

//! The pages' WebSocket: every page's messages out, its requests in, its heartbeat, and what its going away means
//! (see [`presence`](super::presence)).

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

use axum::extract::ws::{CloseFrame, Message, WebSocket, WebSocketUpgrade};
use axum::extract::State;
use axum::response::Response;
use serde_json::{json, Value};

use super::outbox::{Next, Outbox, MOST_WAITING};
use super::presence::{Heartbeat, HEARD_WITHIN, PING_EVERY};
use super::request::{self, Job, Request};
use super::App;

/// The largest message a page may send: a pose file the user picks comes whole in one (larger files go under
/// `ringpod ui --files`). A larger one closes the connection with code 1009 and says so. A frame is read whole up
/// to twice this before it is refused, so that the page, done sending, reads the close frame; a frame larger
/// still is refused at its header (the close frame is sent, though a client still sending may see a reset).
pub const MOST_BYTES: usize = 16 << 20;

/// How long one message may take to reach a page before it is taken as unable to keep up.
const SEND_WITHIN: Duration = HEARD_WITHIN;

pub async fn socket(State(app): State<Arc<App>>, upgrade: WebSocketUpgrade) -> Response {
    let page = app.pages.fetch_add(1, Ordering::SeqCst) + 1;
    upgrade
        .max_message_size(MOST_BYTES)
        .max_frame_size(2 * MOST_BYTES)
        .on_upgrade(move |ws| serve_page(app, page, ws))
}

/// Why a page's connection ends.
enum End {
    /// The page closed it, or it broke.
    Gone,
    /// Closed by the workbench with a close code and a reason.
    Close(u16, String),
}

/// Sends one message within [`SEND_WITHIN`].
async fn send(ws: &mut WebSocket, message: Message) -> Result<(), End> {
    match tokio::time::timeout(SEND_WITHIN, ws.send(message)).await {
        Ok(Ok(())) => Ok(()),
        Ok(Err(_)) => Err(End::Gone),
        Err(_) => Err(End::Close(
            1013,
            "this page did not take its messages: reload it".into(),
        )),
    }
}

/// What the page's connection says: its close code for an error (a message too large, a broken frame).
fn close_for(error: axum::Error) -> End {
    match error.into_inner().downcast_ref::<tungstenite::Error>() {
        Some(tungstenite::Error::Capacity(e)) => {
            End::Close(1009, format!("{e}: a message is at most {MOST_BYTES} bytes"))
        }
        Some(tungstenite::Error::Protocol(e)) => End::Close(1002, e.to_string()),
        _ => End::Gone,
    }
}

/// One page: its outbox out, its requests in, pings. When it goes, a stream it started stops.
async fn serve_page(app: Arc<App>, page: u64, mut ws: WebSocket) {
    let outbox = app.hub.open_outbox(page);
    app.hub.presence.arrive(page);
    // Whether pose files may be named (`ui --files`): the page shows the field only then.
    let files = app.hub.files.is_some();
    outbox.push(json!({ "type": "hello", "page": page, "files": files }).to_string());
    if let Some(rig) = app.hub.rig.lock().ok().and_then(|r| r.clone()) {
        outbox.push(rig);
    }
    for notice in app.hub.earlier_notices() {
        outbox.push(notice);
    }
    let end = converse(&app, page, &outbox, &mut ws).await;
    app.hub.close_outbox(page);
    app.hub.presence.leave(page, Instant::now());
    if app.hub.streaming.load(Ordering::SeqCst) == page {
        // The page that started the stream is gone: closed, reloaded, or killed; the workbench cannot tell which,
        // and a page being loaded has no STOP yet. What STOP does, at once, whatever other pages are open.
        stop_for_the_operator(
            &app,
            format!(
                "page {page}, which started the stream, went away (closed, reloaded or not answering): the stream \
                 is stopped and the platform comes to rest and powers down, as STOP does"
            ),
        );
    }
    if let End::Close(code, reason) = end {
        let frame = CloseFrame {
            code,
            reason: reason.into(),
        };
        let _ = tokio::time::timeout(PING_EVERY, ws.send(Message::Close(Some(frame)))).await;
    }
}

async fn converse(app: &App, page: u64, outbox: &Outbox, ws: &mut WebSocket) -> End {
    let mut ping = tokio::time::interval(PING_EVERY);
    // After a stall, one ping at once and the next a period later (not a burst of the missed ones, which would
    // count as unanswered before the page could answer).
    ping.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut heartbeat = Heartbeat::default();
    loop {
        tokio::select! {
            next = outbox.next() => match next {
                Next::Send(messages, frame) => {
                    for text in messages {
                        if let Err(end) = send(ws, Message::Text(text.into())).await {
                            return end;
                        }
                    }
                    if let Some(frame) = frame {
                        if let Err(end) = send(ws, Message::Text(frame.to_string().into())).await {
                            return end;
                        }
                    }
                }
                Next::Overrun => {
                    return End::Close(1013, format!("this page fell {MOST_WAITING} messages behind: reload it"));
                }
            },
            _ = ping.tick() => {
                if !heartbeat.ping() {
                    return End::Close(1001, "no answer to the pings: taken as gone".into());
                }
                if let Err(end) = send(ws, Message::Ping(Default::default())).await {
                    return end;
                }
            },
            incoming = ws.recv() => {
                heartbeat.heard();
                match incoming {
                    Some(Ok(Message::Text(text))) => {
                        if let Some(answer) = take(app, page, &text) {
                            outbox.push(answer.to_string());
                        }
                    }
                    Some(Ok(Message::Binary(_))) => {
                        return End::Close(1003, "the workbench takes text messages (JSON) only".into());
                    }
                    Some(Ok(Message::Close(_))) | None => return End::Gone,
                    Some(Err(e)) => return close_for(e),
                    Some(Ok(_)) => {}
                }
            },
        }
    }
}

/// STOP, from a page (`page`, `id`) or from the workbench itself (page 0): ends what runs, cancels what is queued,
/// and queues the bringing to rest. Whether the device thread took it.
fn stop(app: &App, page: u64, id: u64) -> bool {
    let epoch = app.hub.stop_everything();
    queue(app, page, id, epoch, Request::Halt)
}

/// Queues a request for the device thread, of the STOP generation `epoch`: whether the thread took it.
fn queue(app: &App, page: u64, id: u64, epoch: u64, request: Request) -> bool {
    let job = Job {
        page,
        id,
        epoch,
        request,
    };
    app.jobs.lock().ok().is_some_and(|jobs| jobs.send(job).is_ok())
}

/// STOP given by the workbench itself (page 0) because its operator has gone: said on stderr, to every page now
/// and to the pages that open later. Whether the device thread took it.
fn stop_for_the_operator(app: &App, why: String) -> bool {
    eprintln!("ringpod ui: {why}");
    app.hub.notice(why);
    app.hub.publish(&json!({
        "type": "stop_pending",
        "pending": true,
        "text": "STOP given by the workbench: pending until the device confirms it"
    }));
    stop(app, 0, 0)
}

/// When no page is left for the grace, the operator has gone: STOP.
pub async fn watch_presence(app: Arc<App>) {
    loop {
        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
        if app.hub.presence.deserted(Instant::now()) {
            let why = format!(
                "no page open for {} s: stopping and powering down",
                super::presence::GRACE.as_secs()
            );
            if !stop_for_the_operator(&app, why) {
                return;
            }
        }
    }
}

/// A page's request: queued for the device, or answered at once when it cannot be taken (unreadable, or not
/// STOP while a stream runs). STOP is answered here, never queued behind what the device thread does: it ends
/// what runs and cancels every request sent before it (see [`hub`](super::hub)); the device thread then brings
/// the platform to rest and says so.
fn take(app: &App, page: u64, text: &str) -> Option<Value> {
    let answer = |id: u64, ok: bool, text: &str| {
        Some(json!({ "type": "reply", "page": page, "id": id, "ok": ok, "text": text }))
    };
    let (id, request) = match request::parse(text) {
        Ok(r) => r,
        Err(e) => return answer(e.id, false, &e.why),
    };
    let taken = if request.is_halt() {
        // Pending until the device confirms it (the device thread says so, or keeps giving it).
        app.hub.publish(&json!({
            "type": "stop_pending",
            "pending": true,
            "text": "STOP given: pending until the device confirms it"
        }));
        let taken = stop(app, page, id);
        app.hub.reply(
            page,
            id,
            true,
            "STOP: what ran has ended and every request sent before is cancelled; coming to rest and powering down",
        );
        taken
    } else if app.hub.streaming.load(Ordering::SeqCst) != 0 {
        return answer(id, false, "a stream is running: STOP ends it");
    } else if request.is_stream() && app.hub.stream_claimed.swap(true, Ordering::SeqCst) {
        return answer(id, false, "another stream was asked first: STOP ends it");
    } else {
        queue(app, page, id, app.hub.epoch(), request)
    };
    if taken {
        None
    } else {
        answer(id, false, "the device thread has ended")
    }
}

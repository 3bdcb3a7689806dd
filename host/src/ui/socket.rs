//! The pages' WebSocket: every page's messages out, its requests in, its heartbeat, and what its going away means
//! (see [`presence`](super::presence)).

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Instant;

use axum::extract::ws::{CloseFrame, Message, WebSocket, WebSocketUpgrade};
use axum::extract::State;
use axum::response::Response;
use serde_json::{json, Value};

use super::presence::{HEARD_WITHIN, PING_EVERY};
use super::request::{self, Job, Request};
use super::App;

pub async fn socket(State(app): State<Arc<App>>, upgrade: WebSocketUpgrade) -> Response {
    let page = app.pages.fetch_add(1, Ordering::SeqCst) + 1;
    upgrade.on_upgrade(move |ws| serve_page(app, page, ws))
}

/// Closes a page's connection with a reason (`1001` going away: a page not heard from).
async fn close(ws: &mut WebSocket, code: u16, reason: &str) {
    let frame = CloseFrame {
        code,
        reason: reason.into(),
    };
    let _ = ws.send(Message::Close(Some(frame))).await;
}

/// One page: the pages' messages out, its requests in. When it goes, a stream it started stops.
async fn serve_page(app: Arc<App>, page: u64, mut ws: WebSocket) {
    let mut out = app.hub.out.subscribe();
    app.hub.presence.arrive(page);
    let hello = json!({ "type": "hello", "page": page });
    let rig = app.hub.rig.lock().ok().and_then(|r| r.clone());
    let mut greeted = true;
    for text in [Some(hello.to_string()), rig].into_iter().flatten() {
        greeted &= ws.send(Message::Text(text.into())).await.is_ok();
    }
    let mut ping = tokio::time::interval(PING_EVERY);
    let mut heard = Instant::now();
    while greeted {
        tokio::select! {
            message = out.recv() => match message {
                Ok(text) => {
                    if ws.send(Message::Text(text.into())).await.is_err() {
                        break;
                    }
                }
                // A slow page misses frames, never replies: frames are many, replies follow them.
                Err(tokio::sync::broadcast::error::RecvError::Lagged(_)) => continue,
                Err(tokio::sync::broadcast::error::RecvError::Closed) => break,
            },
            _ = ping.tick() => {
                if heard.elapsed() > HEARD_WITHIN {
                    close(&mut ws, 1001, "no answer to the pings: taken as gone").await;
                    break;
                }
                if ws.send(Message::Ping(Default::default())).await.is_err() {
                    break;
                }
            },
            incoming = ws.recv() => {
                heard = Instant::now();
                match incoming {
                    Some(Ok(Message::Text(text))) => {
                        if let Some(answer) = take(&app, page, &text) {
                            if ws.send(Message::Text(answer.to_string().into())).await.is_err() {
                                break;
                            }
                        }
                    }
                    Some(Ok(Message::Close(_))) | None | Some(Err(_)) => break,
                    Some(Ok(_)) => {}
                }
            },
        }
    }
    app.hub.presence.leave(page, Instant::now());
    if app.hub.streaming.load(Ordering::SeqCst) == page {
        // The page that started the stream is gone: nobody watches it any more.
        app.hub.cancel_current();
    }
}

/// STOP, from a page (`page`, `id`) or from the workbench itself (page 0): ends what runs, cancels what is queued,
/// and queues the bringing to rest. Whether the device thread took it.
fn stop(app: &App, page: u64, id: u64) -> bool {
    let epoch = app.hub.stop_everything();
    queue(
        app,
        Job {
            page,
            id,
            epoch,
            request: Request::Halt,
        },
    )
}

fn queue(app: &App, job: Job) -> bool {
    app.jobs.lock().ok().is_some_and(|jobs| jobs.send(job).is_ok())
}

/// When no page is left for the grace, the operator has gone: STOP.
pub async fn watch_presence(app: Arc<App>) {
    loop {
        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
        if app.hub.presence.deserted(Instant::now()) {
            eprintln!(
                "ringpod ui: no page open for {} s: stopping and powering down",
                super::presence::GRACE.as_secs()
            );
            if !stop(&app, 0, 0) {
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
    } else {
        let epoch = app.hub.epoch();
        queue(
            app,
            Job {
                page,
                id,
                epoch,
                request,
            },
        )
    };
    if taken {
        None
    } else {
        answer(id, false, "the device thread has ended")
    }
}

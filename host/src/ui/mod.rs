//! `ringpod ui`: the workbench in a browser. One local web application, embedded in the binary: the platform
//! live in 3D, the controls with the supervisor's gating, cueing on a replayed drive, the rig file checked as it is
//! typed, and run records. The page and its one WebSocket (`/ws`) carry the per-run token; see [`guard`].

mod api;
mod cue_fields;
mod error;
mod files;
mod frame;
pub mod guard;
mod hub;
mod outbox;
mod presence;
pub(crate) mod profiles;
mod request;
mod rig_edit;
mod rig_form;
mod runs;
mod socket;
mod worker;

use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};

use axum::extract::{Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::{json, Value};

use crate::device::Platform;
use crate::link::Target;
use crate::signals::Signals;
pub use error::UiError;
use guard::Token;
use hub::Hub;
use request::Job;

/// What `ringpod ui` is asked to do.
pub struct Options {
    /// The controller.
    pub target: Target,
    /// A simulated controller of this platform instead of the trainer model.
    pub platform: Option<Platform>,
    /// Where to listen.
    pub listen: SocketAddr,
    /// The directory whose pose files a page may stream by name (otherwise only the files the user picks).
    pub files: Option<std::path::PathBuf>,
    /// Write the followed pose for VR motion compensation.
    pub motion_compensation: Option<crate::vr::Tracker>,
    /// The cueing file whose `[profiles.NAME]` the page chooses, loads and saves (made by the first save).
    pub cue_config: Option<std::path::PathBuf>,
}

/// The page, its scripts and its style, compiled in.
const PAGE: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/app.js");
const CHART: &str = include_str!("page/chart.js");
const CUEING: &str = include_str!("page/cueing.js");
const VIEW3D: &str = include_str!("page/view3d.js");
const RIG: &str = include_str!("page/rig.js");
const STYLE: &str = include_str!("page/style.css");

struct App {
    listen: SocketAddr,
    token: Token,
    hub: Arc<Hub>,
    jobs: Mutex<mpsc::Sender<Job>>,
    pages: AtomicU64,
    profiles: profiles::Profiles,
    rig_target: rig_edit::RigTarget,
}

#[derive(Deserialize)]
struct Access {
    token: Option<String>,
}

impl App {
    fn admit(&self, access: &Access, headers: &HeaderMap) -> Result<(), guard::Refused> {
        let text = |name: header::HeaderName| headers.get(name).and_then(|v| v.to_str().ok());
        guard::check(
            self.listen,
            &self.token,
            access.token.as_deref(),
            text(header::ORIGIN),
            text(header::HOST),
        )
    }

    /// The platform the device runs and its home pose, for the computations.
    fn platform(&self) -> Option<(ringpod_core::kinematics::RingGeometry, [f64; 6])> {
        let record = (*self.hub.record.lock().ok()?)?;
        Some((record.geometry().ok()?, record.home))
    }
}

/// Serves the workbench until a signal; exits with 128 + its number (0 when the device thread ended first).
pub fn run(options: Options) -> Result<u8, UiError> {
    let signals = Signals::install()?;
    let token = Token::random().map_err(UiError::Random)?;
    let rig = Platform::rig(options.platform.as_ref())?;
    // The Rig panel saves to the rig file the simulator was started with, and to no other.
    let rig_file = match &options.platform {
        Some(Platform::File(path)) => Some(path.clone()),
        _ => None,
    };
    // The mapping is opened before anything is served: a tracker that cannot be written is said at the start.
    let compensation = match options.motion_compensation {
        Some(tracker) => Some(crate::vr::tap(
            tracker,
            rig.as_ref().map(|r| (r.home, r.centre_of_rotation)),
        )?),
        None => None,
    };
    // The address first: a port in use is said before anything else starts.
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    let listener = runtime
        .block_on(tokio::net::TcpListener::bind(options.listen))
        .map_err(|reason| UiError::Listen {
            addr: options.listen,
            reason,
        })?;
    // The live cueing file lives in a directory of its own that only this user can enter (removed at the end).
    let private = files::private_dir()?;
    let cue_file = private.path().join("cueing.toml");
    files::write_whole(
        &cue_file,
        &toml::to_string(&ringpod_core::cueing::CueConfig::default())?,
    )
    .map_err(|e| crate::error::CliError::file(&cue_file, e))?;
    let hub = Arc::new(Hub::new(cue_file.clone(), listener.local_addr()?.ip(), options.files));
    let (jobs, inbox) = mpsc::channel();
    let device = {
        let hub = hub.clone();
        let target = options.target.clone();
        std::thread::spawn(move || worker::run(target, rig, hub, inbox, compensation))
    };
    let local = listener.local_addr()?;
    let app = Arc::new(App {
        listen: local,
        token,
        hub: hub.clone(),
        jobs: Mutex::new(jobs),
        pages: AtomicU64::new(0),
        // Without --cue-config the profiles live as long as the workbench, beside the live cueing file.
        profiles: match options.cue_config {
            Some(path) => profiles::Profiles::new(path, true),
            None => profiles::Profiles::new(private.path().join("profiles.toml"), false),
        },
        rig_target: rig_edit::RigTarget::new(rig_file),
    });
    let served = runtime.block_on(async {
        println!("ringpod ui: open http://{local}/?token={}", app.token.as_str());
        // Scripts and tests read the URL as soon as it is printed.
        let _ = std::io::Write::flush(&mut std::io::stdout());
        if !local.ip().is_loopback() {
            eprintln!(
                "note: listening on {local}, not only on this machine: anyone with the URL can move the platform"
            );
        }
        let router = routes(&app);
        tokio::spawn(socket::watch_presence(app.clone()));
        let stop = {
            let hub = hub.clone();
            async move {
                while !signals.received() && !device.is_finished() {
                    tokio::time::sleep(std::time::Duration::from_millis(100)).await;
                }
                hub.closing.store(true, Ordering::SeqCst);
                hub.stop_everything();
                (signals, device)
            }
        };
        let (tx, rx) = tokio::sync::oneshot::channel();
        let shutdown = async move {
            let ended = stop.await;
            let _ = tx.send(ended);
        };
        axum::serve(listener, router).with_graceful_shutdown(shutdown).await?;
        rx.await.map_err(|_| UiError::NoStop)
    });
    drop(private);
    let (signals, device) = served?;
    match device.join() {
        Ok(Err(e)) => Err(UiError::Device(e)),
        Err(_) => Err(UiError::DeviceThread),
        Ok(Ok(())) if signals.received() => {
            eprintln!("ringpod ui: stopped by {}", signals.name());
            Ok(signals.exit_code())
        }
        Ok(Ok(())) => Ok(0),
    }
}

/// The workbench's routes: every one but the static scripts and style passes the token, origin and host check.
fn routes(app: &Arc<App>) -> Router {
    // The check, once, here.
    let checked = Router::new()
        .route("/", get(page))
        .route("/ws", get(socket::socket))
        .route("/api/cue/defaults", get(cue_defaults))
        .route("/api/cue", post(cue))
        .route("/api/cue/apply", post(cue_apply))
        .route("/api/profiles", get(profiles::list))
        .route("/api/profile", get(profiles::get).post(profiles::put))
        .route("/api/rig/check", post(rig_edit::check_route))
        .route("/api/rig/current", get(rig_edit::current))
        .route("/api/rig/save", post(rig_edit::save_route))
        .route("/api/run", post(run_record))
        .route_layer(axum::middleware::from_fn_with_state(app.clone(), admitted));
    let asset =
        |kind: &'static str, body: &'static str| get(move || async move { ([(header::CONTENT_TYPE, kind)], body) });
    Router::new()
        .merge(checked)
        .route("/app.js", asset("text/javascript", SCRIPT))
        .route("/chart.js", asset("text/javascript", CHART))
        .route("/cueing.js", asset("text/javascript", CUEING))
        .route("/view3d.js", asset("text/javascript", VIEW3D))
        .route("/rig.js", asset("text/javascript", RIG))
        .route("/style.css", asset("text/css", STYLE))
        .with_state(app.clone())
}

async fn page() -> Response {
    ([(header::CONTENT_TYPE, "text/html; charset=utf-8")], PAGE).into_response()
}

async fn admitted(
    State(app): State<Arc<App>>,
    Query(access): Query<Access>,
    request: axum::extract::Request,
    next: axum::middleware::Next,
) -> Response {
    match app.admit(&access, request.headers()) {
        Ok(()) => next.run(request).await,
        Err(refused) => (StatusCode::FORBIDDEN, refused.to_string()).into_response(),
    }
}

fn answer(result: Result<Value, String>) -> Response {
    match result {
        Ok(v) => Json(v).into_response(),
        Err(e) => (StatusCode::UNPROCESSABLE_ENTITY, Json(json!({ "error": e }))).into_response(),
    }
}

async fn cue_defaults() -> Response {
    Json(api::cue_defaults()).into_response()
}

async fn cue(State(app): State<Arc<App>>, Json(request): Json<api::CueRequest>) -> Response {
    let Some((geometry, home)) = app.platform() else {
        return answer(Err("the device's rig is not known yet".into()));
    };
    answer(
        tokio::task::spawn_blocking(move || api::cue(&request, &geometry, home))
            .await
            .unwrap_or_else(|e| Err(e.to_string())),
    )
}

/// Writes the parameters to the cueing file a telemetry session of this workbench watches: it blends them in.
async fn cue_apply(State(app): State<Arc<App>>, Json(request): Json<api::CueRequest>) -> Response {
    let written = api::cue_config(&request.config).and_then(|config| {
        let text = toml::to_string(&config).map_err(|e| e.to_string())?;
        // Whole or not at all: a telemetry session never reads a half-written file.
        files::write_whole(&app.hub.cue_file, &text).map_err(|e| format!("{}: {e}", app.hub.cue_file.display()))
    });
    answer(written.map(|()| json!({ "applied": app.hub.cue_file.display().to_string() })))
}

/// A run record, sent as the file's bytes (the page never holds it as text), read as it arrives (see [`runs`]).
async fn run_record(mut body: axum::body::Body) -> Response {
    use axum::body::HttpBody;
    let mut reader = runs::Reader::default();
    let read = loop {
        match std::future::poll_fn(|cx| std::pin::Pin::new(&mut body).poll_frame(cx)).await {
            None => break reader.finish(),
            Some(Err(e)) => break Err(runs::RunError::Upload(e.to_string())),
            Some(Ok(frame)) => {
                if let Some(bytes) = frame.data_ref() {
                    if let Err(e) = reader.take(bytes) {
                        break Err(e);
                    }
                }
            }
        }
    };
    match read {
        Ok(v) => Json(v).into_response(),
        Err(e @ runs::RunError::TooLarge) => {
            (StatusCode::PAYLOAD_TOO_LARGE, Json(json!({ "error": e.to_string() }))).into_response()
        }
        Err(e) => answer(Err(e.to_string())),
    }
}

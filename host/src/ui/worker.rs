//! The device's side of the workbench: one thread owns the client (a board's port or the simulated controller),
//! as every other command does, and runs what the pages ask through the same client calls and the same
//! `stream::run` as the CLI. Its telemetry tap publishes frames to every page at [`FRAME_HZ`], also while a
//! stream runs; a stream ends when STOP is pressed or the page that started it goes away.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

use ringpod_core::kinematics::{Mechanism, Pose, RingPlatform};
use ringpod_core::safety::State;
use serde_json::json;

use super::files;
use super::frame::LinkCounts;
use super::hub::Hub;
use super::request::{Job, Request};
use crate::link::client::{Client, ClientError, Transport};
use crate::link::sim::SimDevice;
use crate::link::transport::AnyTransport;
use crate::link::{self, Target};
use crate::stream::command::{self as job, Datagrams, Input};
use crate::stream::{self, Motion, Source};

mod publisher;
mod rig;
mod spare;
mod stop;

use publisher::Publisher;

/// Why the device thread could not start, or a page's request was not done (sent back to the page in words).
#[derive(Debug, thiserror::Error)]
pub enum WorkerError {
    /// The device's answer.
    #[error(transparent)]
    Client(#[from] ClientError),
    /// No link to the device.
    #[error(transparent)]
    Link(#[from] crate::link::LinkError),
    /// A jog or buzz.
    #[error(transparent)]
    Commission(#[from] crate::device::commission::CommissionError),
    /// A stream's source.
    #[error(transparent)]
    Source(#[from] crate::stream::command::SourceError),
    /// A rig file from the page.
    #[error(transparent)]
    Rig(#[from] crate::rig::RigError),
    /// Loading the rig onto the device.
    #[error(transparent)]
    DeviceRig(#[from] crate::device::rig::DeviceRigError),
    /// A message for the pages.
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// The rig the device runs is not a valid geometry.
    #[error("the device's rig does not check: {0}")]
    DeviceGeometry(ringpod_core::kinematics::GeometryError),
    /// The stream could not be started.
    #[error("the stream did not start: {0}")]
    NotStarted(ClientError),
    /// The page named something there is not (a motion, a format, what a UDP session holds).
    #[error("{0}")]
    NoSuch(String),
    /// A rig is loaded only with the supplies off.
    #[error("a rig is loaded with the supplies off: Disable first")]
    NotOff,
    /// A pose file the page may not read, or that is not one.
    #[error("{0}")]
    File(String),
    /// A stream or a park that did not end at the pose asked: its report's words.
    #[error("{0}")]
    Ended(String),
}

/// The reply to a stream that STOP ended before it sent a setpoint.
const STOPPED_BEFORE_START: &str = "stopped by STOP before it started: nothing was sent";

/// Frames a page is sent per second at most (a browser draws at 60; telemetry may come at 1 kHz).
pub const FRAME_HZ: f64 = 50.0;

/// Opens the device and serves the pages' requests until the hub closes. Errors here mean no device.
pub fn run(
    target: Target,
    rig: Option<crate::rig::Rig>,
    hub: Arc<Hub>,
    jobs: mpsc::Receiver<Job>,
    mut compensation: Option<crate::vr::PoseTap>,
) -> Result<(), WorkerError> {
    let transport = match (&target, &rig) {
        (_, Some(r)) => AnyTransport::Sim(Box::new(SimDevice::for_rig(true, r)?)),
        _ => link::connect(&target, true)?,
    };
    let mut client = Client::new(transport);
    client.hello()?;
    let mechanism = Arc::new(Mutex::new(rig::announce_rig(&mut client, &hub)?));
    let publisher = Arc::new(Mutex::new(Publisher {
        hub: hub.clone(),
        mechanism: mechanism.clone(),
        counts: LinkCounts::default(),
        last_sent: None,
        window: (Instant::now(), 0),
    }));
    let tap = publisher.clone();
    client.tap = Some(Box::new(move |sample| {
        if let Ok(mut p) = tap.lock() {
            p.see(sample);
        }
        if let Some(write) = compensation.as_mut() {
            write(sample);
        }
    }));
    client.telemetry(true)?;
    // The spare axes' card waits for a section the device answers; the workbench runs without it.
    let fitted = spare::fitted(&mut client)
        .unwrap_or([ringpod_core::motion::SpareAxisSettings::NONE; ringpod_core::motion::SPARE_AXES]);
    let mut device = Device {
        client,
        hub: hub.clone(),
        mechanism,
        cancel: Arc::new(AtomicBool::new(false)),
        pending_stop: None,
        spare: fitted,
    };
    let mut last_sample = Instant::now();
    let mut last_spare = Instant::now();
    while !hub.closing.load(Ordering::SeqCst) {
        while let Ok(job) = jobs.try_recv() {
            device.serve(&job);
        }
        device.resend_stop();
        device.publish_spare(&mut last_spare);
        // The samples were published by the tap; none is kept. A device that stopped sending (a restart, a
        // hello by another program on a shared link) is asked again once a second.
        if device.client.take_telemetry().is_ok_and(|s| !s.is_empty()) {
            last_sample = Instant::now();
        } else if last_sample.elapsed() > Duration::from_secs(1) {
            let _ = device.client.telemetry(true);
            last_sample = Instant::now();
        }
        device.client.transport().elapse(Duration::from_millis(2));
    }
    // The workbench ends: nothing keeps moving without it.
    let _ = device.halt();
    Ok(())
}

struct Device {
    client: Client<AnyTransport>,
    hub: Arc<Hub>,
    mechanism: Arc<Mutex<RingPlatform<f64>>>,
    /// The cancel flag of the request being served.
    cancel: Arc<AtomicBool>,
    /// A STOP the device has not confirmed (its link stalled or cut): kept, and given again until it is.
    pending_stop: Option<stop::PendingStop>,
    /// The spare axes the device runs (their positions go to the pages while one is fitted).
    spare: [ringpod_core::motion::SpareAxisSettings; ringpod_core::motion::SPARE_AXES],
}

impl Device {
    /// Serves a page's request; a stream's claim ends with it (run, refused or cancelled).
    /// The claim ends before the reply goes out: a page that asks for the next stream as soon as it reads the
    /// reply is not refused for the one just answered.
    fn serve(&mut self, job: &Job) {
        let reply = self.serve_job(job);
        if job.request.is_stream() {
            self.hub.stream_claimed.store(false, Ordering::SeqCst);
        }
        if let Some((ok, text)) = reply {
            self.hub.reply(job.page, job.id, ok, text);
        }
    }

    /// Runs a request: its reply (none for a STOP run, which says its outcome itself).
    fn serve_job(&mut self, job: &Job) -> Option<(bool, String)> {
        let cancel = match self.hub.begin(job) {
            Ok(flag) => flag,
            Err(why) => return Some((job.request.is_halt(), why.to_owned())),
        };
        // Nothing moves before the STOP given last is confirmed.
        if self.pending_stop.is_some() && !job.request.is_halt() {
            return Some((
                false,
                "refused: a STOP is pending (the device has not confirmed it yet)".to_owned(),
            ));
        }
        self.cancel = cancel;
        let result = match &job.request {
            Request::Enable => self.client.enable().map(|()| "enabling".to_owned()).map_err(Into::into),
            Request::Disable => self
                .client
                .disable()
                .map(|()| "powering down".to_owned())
                .map_err(Into::into),
            Request::Home => self.client.home().map(|()| "homing".to_owned()).map_err(Into::into),
            Request::Start => self.client.start().map(|()| "running".to_owned()).map_err(Into::into),
            Request::Stop => self.client.stop().map(|()| "stopping".to_owned()).map_err(Into::into),
            Request::Clear => self
                .client
                .clear()
                .map(|()| "fault cleared".to_owned())
                .map_err(Into::into),
            Request::Halt => self.stop(job),
            Request::Jog { axis, distance } => self.commission(*axis, Some(*distance)),
            Request::Buzz { axis } => self.commission(*axis, None),
            Request::Park => self.park(job.page),
            Request::SpareJog { axis, distance } => self.spare(job.page, *axis, spare::Goal::By(*distance)),
            Request::SpareTo { axis, value } => self.spare(job.page, *axis, spare::Goal::To(*value)),
            Request::Motion {
                motion,
                seconds,
                rate_hz,
            } => clap::ValueEnum::from_str(motion, true)
                .map_err(|e| WorkerError::NoSuch(format!("motion {motion:?}: {e}")))
                .and_then(|motion: Motion| {
                    if motion == Motion::Sine {
                        return Err(WorkerError::NoSuch(
                            "the sine needs its axis, frequency and amplitude: `ringpod stream --motion sine`".into(),
                        ));
                    }
                    self.stream(
                        job.page,
                        &Input::Motion {
                            motion,
                            sine: None,
                            seconds: *seconds,
                            rate_hz: *rate_hz,
                        },
                    )
                }),
            Request::File { name, text, degrees } => self.file(job.page, name, text.as_deref(), *degrees),
            Request::Udp {
                port,
                holds,
                format,
                degrees,
                idle,
                from,
                outsim_opts,
                lap_preview,
            } => self.udp(
                job.page,
                *port,
                holds,
                format.as_deref(),
                (outsim_opts.as_deref(), *lap_preview),
                *degrees,
                *idle,
                *from,
            ),
            Request::LoadRig { text } => self.load_rig(text),
        };
        match result {
            Ok(_) if job.request.is_halt() => None,
            Ok(text) => Some((true, text)),
            Err(e) => Some((false, format!("{e:#}"))),
        }
    }

    /// STOP: the stream already ended (its cancel flag was raised when STOP arrived); ramps whatever moves to
    /// rest and powers down.
    fn halt(&mut self) -> Result<String, WorkerError> {
        let status = self.client.status()?;
        if matches!(status.state, State::Running | State::Homing | State::Jogging) {
            self.client.stop()?;
        }
        let status = self.client.wait_for(Duration::from_secs(10), |s| {
            !matches!(
                s.state,
                State::Stopping | State::Running | State::Homing | State::Jogging
            )
        })?;
        if matches!(status.state, State::LogicOn | State::PowerOn { .. } | State::Ready) {
            self.client.disable()?;
        }
        Ok("stopped and powering down".to_owned())
    }

    fn commission(&mut self, axis: u8, distance: Option<f64>) -> Result<String, WorkerError> {
        let index = crate::device::commission::axis_index(axis)?;
        let kind = self
            .mechanism
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .axes()[usize::from(index)];
        let what = crate::device::commission::begin_move(&mut self.client, index, kind, distance)?;
        Ok(format!("axis {axis} {what}; home again before streaming"))
    }

    /// To the home pose (powering up and homing first if needed), then powered down.
    fn park(&mut self, page: u64) -> Result<String, WorkerError> {
        let (record, _, _) = self.client.rig()?;
        let home = Pose::from_array(record.home);
        let poses = vec![
            (1, 0.0, home, crate::stream::NO_AUX),
            (2, 1.0, home, crate::stream::NO_AUX),
        ];
        let report = match self.run(page, Source::Poses(poses), Vec::new()) {
            Err(WorkerError::NotStarted(ClientError::Interrupted)) => {
                return Ok(format!("park: {STOPPED_BEFORE_START}"))
            }
            r => r?,
        };
        if report.exit_code != stream::exit::FOLLOWED {
            return Err(WorkerError::Ended(format!(
                "park: {}",
                report.reason.as_deref().unwrap_or(report.outcome)
            )));
        }
        self.client.disable()?;
        Ok("parked at home and powering down".to_owned())
    }

    /// A pose file: the text of one the user picked in the page, or one under `ringpod ui --files`. A refusal
    /// names the file and never quotes what it holds.
    fn file(&mut self, page: u64, name: &str, text: Option<&str>, degrees: bool) -> Result<String, WorkerError> {
        let refused = |reason: String| WorkerError::File(format!("{name}: {}", files::reason_without_content(&reason)));
        let text = match text {
            Some(t) => t.to_owned(),
            None => {
                let limit = crate::input::files::DATA_LIMIT;
                // Its reasons name the file already.
                files::read_under(self.hub.files.as_deref(), name, limit)
                    .map_err(|r| WorkerError::File(files::reason_without_content(&r).to_owned()))?
            }
        };
        let (poses, errors) = stream::read_csv(&text, degrees).map_err(refused)?;
        self.follow(page, Source::Poses(poses), errors)
    }

    /// A UDP session on the workbench's own address (loopback when it listens on loopback), taking datagrams
    /// only from `from` when given.
    #[allow(clippy::too_many_arguments)]
    fn udp(
        &mut self,
        page: u64,
        port: u16,
        holds: &str,
        format: Option<&str>,
        (outsim_opts, lap_preview): (Option<&str>, bool),
        degrees: bool,
        idle: f64,
        from: Option<std::net::IpAddr>,
    ) -> Result<String, WorkerError> {
        let holds = match holds {
            "poses" if outsim_opts.is_none() => Datagrams::Poses { degrees },
            "telemetry" => {
                let format: crate::games::TelemetryFormat =
                    clap::ValueEnum::from_str(format.unwrap_or("auto"), true)
                        .map_err(|e| WorkerError::NoSuch(format!("telemetry format: {e}")))?;
                let outsim_opts = match outsim_opts {
                    Some(_) if !format.reads_outsim2() => {
                        return Err(WorkerError::NoSuch(
                            "OutSim Opts describe outsim2 packets: choose the format outsim2 or auto".into(),
                        ))
                    }
                    Some(hex) => Some(crate::games::outsim2::Opts::parse_hex(hex).map_err(WorkerError::NoSuch)?),
                    None => None,
                };
                Datagrams::Telemetry {
                    format,
                    cue_config: Some(self.hub.cue_file.clone()),
                    profile: None,
                    outsim_opts,
                    lap_preview,
                }
            }
            "strings" if outsim_opts.is_none() => {
                // A front end's pose strings, at the default ranges (the command line's --pose-range).
                use crate::stream::datagram::template::{Template, DEFAULT_RANGES};
                let template = Template::parse(format.unwrap_or_default(), DEFAULT_RANGES)
                    .map_err(|e| WorkerError::NoSuch(e.to_string()))?;
                Datagrams::Strings(Box::new(template))
            }
            "poses" | "strings" => return Err(WorkerError::NoSuch("OutSim Opts are for telemetry, not poses".into())),
            other => {
                return Err(WorkerError::NoSuch(format!(
                    "a UDP session holds `poses`, `telemetry` or `strings`, not {other:?}"
                )))
            }
        };
        self.stream(
            page,
            &Input::Udp {
                addr: std::net::SocketAddr::new(self.hub.bind, port),
                holds,
                from,
                idle,
            },
        )
    }

    fn stream(&mut self, page: u64, input: &Input) -> Result<String, WorkerError> {
        let (source, errors) = job::open(input)?;
        self.follow(page, source, errors)
    }

    /// Runs a stream and tells the pages its report.
    fn follow(&mut self, page: u64, source: Source, errors: Vec<stream::InputError>) -> Result<String, WorkerError> {
        let report = match self.run(page, source, errors) {
            // STOP while it powered up, homed or waited for its first setpoint: what was asked, not a failure.
            Err(WorkerError::NotStarted(ClientError::Interrupted)) => return Ok(STOPPED_BEFORE_START.into()),
            r => r?,
        };
        let text = format!(
            "{}: {} setpoints sent, {} applied, {} limited, {} refused{}",
            report.outcome,
            report.setpoints_sent,
            report.setpoints_applied,
            report.limited.device + report.limited.host,
            report.rejected.values().sum::<u32>(),
            report.reason.as_deref().map(|r| format!(" ({r})")).unwrap_or_default()
        );
        let mut message = serde_json::to_value(&report)?;
        message["type"] = json!("report");
        self.hub.publish(&message);
        if !self.hub.presence.is_open(page) {
            // Its page has gone: the page that opens next is told how the stream ended.
            self.hub
                .keep(format!("the stream of page {page}, which went away: {text}"));
        }
        if report.exit_code == stream::exit::FOLLOWED || report.exit_code == stream::exit::INTERRUPTED {
            Ok(text)
        } else {
            Err(WorkerError::Ended(text))
        }
    }

    /// Runs a stream as `ringpod stream` does (powering up and homing first if needed), owned by `page`.
    fn run(
        &mut self,
        page: u64,
        source: Source,
        errors: Vec<stream::InputError>,
    ) -> Result<stream::Report, WorkerError> {
        self.hub.streaming.store(page, Ordering::SeqCst);
        // STOP, the loss of its page or the server's end raise the flag: the waits for powering up and homing end,
        // and the stream ends, as Ctrl-C ends `ringpod stream`.
        self.client.cancel = Some(self.cancel.clone());
        let halt = self.cancel.clone();
        let options = stream::Options {
            home: false,
            host_limits: true,
            telemetry: true,
            telemetry_hz: None,
            resend_stop: false,
            quiet: true,
        };
        let report = stream::run(
            &mut self.client,
            source,
            errors,
            &options,
            false,
            &|| halt.load(Ordering::SeqCst),
            None,
        );
        self.client.cancel = None;
        self.hub.streaming.store(0, Ordering::SeqCst);
        // Telemetry stays on for the pages whatever the stream did with it.
        self.client.telemetry(true)?;
        report.map_err(WorkerError::NotStarted)
    }
}

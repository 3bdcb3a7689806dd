//! `ringpod stream` as a job: where its poses come from, which device follows them, what is checked first and how
//! the end is reported. The command line builds a [`Job`]; [`run`] opens the source and the device, checks loads,
//! streams and prints the report, and its exit code is [`super::exit`]'s.

use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;

use super::live::{LiveSource, Receiver};
use super::{datagram, exit, Motion, Options, Report, Source};
use crate::cueing::live::LiveCueing;
use crate::error::CliError;
use crate::games::TelemetryFormat;
use crate::input::{files, numbers};
use crate::link::{self, client};
use crate::out::console;
use crate::signals::Signals;

/// Where a stream's poses come from.
pub enum Input {
    /// A built-in motion for `seconds` at `rate_hz` setpoints per second.
    Motion {
        motion: Motion,
        /// The sine's parameters, for `--motion sine`.
        sine: Option<super::Sine>,
        seconds: f64,
        rate_hz: f64,
    },
    /// A CSV pose file.
    File { path: PathBuf, degrees: bool },
    /// UDP datagrams: poses or vehicle telemetry.
    Udp {
        /// The address to listen on.
        addr: SocketAddr,
        /// What a datagram holds.
        holds: Datagrams,
        /// Only datagrams from this sender count.
        from: Option<IpAddr>,
        /// Seconds without a readable datagram after which the stream ends.
        idle: f64,
    },
    /// A game's shared memory (Windows), its telemetry cued by the washout (`lap_preview`: the lap preview on).
    Shm {
        /// The game.
        game: crate::games::shm::Game,
        /// The cueing file, and a profile of it.
        cue_config: Option<PathBuf>,
        profile: Option<String>,
        /// Seconds without a new sample after which the stream ends.
        idle: f64,
        lap_preview: bool,
    },
}

/// What the datagrams of a UDP source hold.
pub enum Datagrams {
    /// Six numbers, a pose.
    Poses { degrees: bool },
    /// A motion front end's pose strings.
    Strings(Box<datagram::template::Template>),
    /// Vehicle telemetry in a format, cued by the washout of a cueing file (or the defaults), with a lap preview.
    Telemetry {
        format: TelemetryFormat,
        cue_config: Option<PathBuf>,
        /// A profile of the cueing file.
        profile: Option<String>,
        /// Live for Speed's `OutSim Opts`, when given.
        outsim_opts: Option<crate::games::outsim2::Opts>,
        lap_preview: bool,
    },
}

/// The device that follows: a board, or the simulated controller (of the trainer model, or another platform).
pub enum Device {
    Port(String),
    Sim {
        fast: bool,
        platform: Option<crate::device::Platform>,
    },
}

/// The payload `--check-loads` predicts the drive demand for.
pub struct LoadsCheck {
    /// kg, as given (checked here).
    pub mass: f64,
    /// `Ixx,Iyy,Izz` as given, or none.
    pub inertia: Option<String>,
}

/// One `ringpod stream`.
pub struct Job {
    pub input: Input,
    pub device: Device,
    pub check_loads: Option<LoadsCheck>,
    pub options: Options,
    /// The run record to write.
    pub record: Option<PathBuf>,
    /// A live source: the pcap file its datagrams (or shared-memory samples) are captured to.
    pub capture: Option<PathBuf>,
    /// One JSON report instead of the summary line.
    pub report_json: bool,
    /// Write the followed pose for VR motion compensation.
    pub motion_compensation: Option<crate::vr::Tracker>,
}

/// Why a stream's source could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// A number of a stream option out of its range.
    #[error(transparent)]
    Option(#[from] numbers::BadNumber),
    /// The cueing file.
    #[error(transparent)]
    Cueing(#[from] crate::input::cueing::CueingFileError),
    /// The washout refused its configuration.
    #[error("cueing: {0}")]
    Washout(ringpod_core::cueing::ConfigError),
    /// The UDP address could not be bound.
    #[error("{addr}: {reason}")]
    Bind {
        /// The address.
        addr: std::net::SocketAddr,
        /// Why.
        reason: std::io::Error,
    },
    /// `--telemetry-shm` on a system without Windows' named file mappings (the command line refuses it first).
    #[cfg(not(windows))]
    #[error("--telemetry-shm reads a game's shared memory, a Windows named file mapping: not on this system")]
    NoSharedMemory,
    /// The pose file could not be read, or is not a pose file.
    #[error("{}: {reason}", path.display())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
}

/// Why a stream did not run (a stream that ran and ended badly says so in its report and exit code instead).
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The source.
    #[error(transparent)]
    Source(#[from] SourceError),
    /// No link to the device.
    #[error(transparent)]
    Link(#[from] link::LinkError),
    /// The platform to simulate, or a capture or record file that could not be created.
    #[error(transparent)]
    Cli(#[from] CliError),
    /// `--check-loads`.
    #[error(transparent)]
    Loads(#[from] super::loads::LoadsError),
    /// The signal handlers or the UDP socket.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The report as JSON.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// `--motion-compensation`.
    #[error(transparent)]
    Vr(#[from] crate::vr::VrError),
}

/// A number of a stream option: finite, above 0 and at most `max`.
fn positive(name: &'static str, v: f64, max: f64) -> Result<f64, SourceError> {
    if v.is_finite() && v > 0.0 && v <= max {
        Ok(v)
    } else {
        Err(numbers::BadNumber::given(name, v, format!("must be a number of at most {max:e}, above 0")).into())
    }
}

/// Opens the source: its poses, and the lines of a file that could not be read (already printed).
pub(crate) fn open(input: &Input) -> Result<(Source, Vec<super::InputError>), SourceError> {
    Ok(match input {
        Input::Udp {
            addr,
            holds,
            from,
            idle,
        } => {
            let decoder = match holds {
                Datagrams::Poses { degrees } => datagram::Decoder::Poses { degrees: *degrees },
                Datagrams::Strings(template) => datagram::Decoder::Template {
                    template: template.clone(),
                    neutral: None,
                },
                Datagrams::Telemetry {
                    format,
                    cue_config,
                    profile,
                    outsim_opts,
                    lap_preview,
                } => telemetry_decoder(*format, *outsim_opts, cue_config, profile, *lap_preview)?,
            };
            let idle = positive("udp-idle", *idle, 1e6)?;
            let socket = std::net::UdpSocket::bind(addr).map_err(|reason| SourceError::Bind { addr: *addr, reason })?;
            let source = LiveSource {
                receiver: Receiver::Udp(socket),
                decoder,
                idle: std::time::Duration::from_secs_f64(idle),
                from: *from,
                capture: None,
            };
            (Source::Live(source), Vec::new())
        }
        Input::Shm {
            game,
            cue_config,
            profile,
            idle,
            lap_preview,
        } => {
            let decoder = telemetry_decoder(TelemetryFormat::Text, None, cue_config, profile, *lap_preview)?;
            let idle = positive("udp-idle", *idle, 1e6)?;
            let source = LiveSource {
                receiver: shared_memory(*game)?,
                decoder,
                idle: std::time::Duration::from_secs_f64(idle),
                from: None,
                capture: None,
            };
            (Source::Live(source), Vec::new())
        }
        Input::File { path, degrees } => {
            let in_file = |reason| SourceError::File {
                path: path.clone(),
                reason,
            };
            let text = files::read_text(path, files::DATA_LIMIT).map_err(in_file)?;
            let (poses, errors) = super::read_csv(&text, *degrees).map_err(in_file)?;
            for e in &errors {
                console::err(&format!("{}: line {}: {}", path.display(), e.line, e.reason));
            }
            (Source::Poses(poses), errors)
        }
        Input::Motion {
            motion,
            sine,
            seconds,
            rate_hz,
        } => (
            Source::Motion {
                motion: *motion,
                sine: match sine {
                    Some(s) => Some(super::Sine {
                        frequency: positive("frequency", s.frequency, 1_000.0)?,
                        amplitude: match s.amplitude {
                            super::Amplitude::Velocity(v) => {
                                super::Amplitude::Velocity(positive("velocity-amplitude", v, 100.0)?)
                            }
                            super::Amplitude::Position(a) => {
                                super::Amplitude::Position(positive("amplitude", a, 10.0)?)
                            }
                        },
                        axis: s.axis,
                        seconds: s.seconds,
                    }),
                    None => None,
                },
                seconds: positive("duration", *seconds, 1e9)?,
                rate_hz: positive("rate", *rate_hz, 10_000.0)?,
            },
            Vec::new(),
        ),
    })
}

/// A decoder of vehicle telemetry through the washout of the cueing file (or the defaults), watched for changes.
pub(crate) fn telemetry_decoder(
    format: TelemetryFormat,
    outsim_opts: Option<crate::games::outsim2::Opts>,
    cue_config: &Option<PathBuf>,
    profile: &Option<String>,
    lap_preview: bool,
) -> Result<datagram::Decoder, SourceError> {
    let config = crate::input::cueing::load_config(cue_config.as_deref(), profile.as_deref())?;
    let washout = LiveCueing::new(config)
        .map_err(SourceError::Washout)?
        .with_lap_preview(lap_preview);
    let outsim_opts =
        crate::games::outsim2::Opts::chosen(format, outsim_opts, cue_config.as_deref(), profile.as_deref())?;
    Ok(datagram::Decoder::Telemetry {
        reader: Box::new(crate::games::Reader::new(format, outsim_opts)),
        washout: Box::new(washout),
        // The device's home pose, once the stream has asked for its rig.
        neutral: None,
        last: None,
        gaps: 0,
        watch: cue_config
            .as_ref()
            .map(|path| Box::new(datagram::Watch::new(path.clone(), profile.clone()))),
    })
}

/// `game`'s shared memory: its named mappings, opened read-only as they appear (Windows only).
fn shared_memory(game: crate::games::shm::Game) -> Result<Receiver, SourceError> {
    #[cfg(windows)]
    {
        let memory = crate::games::shm::windows::Mappings::new(game);
        Ok(Receiver::Shm(Box::new(super::live::ShmSource::new(
            game,
            Box::new(memory),
        ))))
    }
    #[cfg(not(windows))]
    {
        let _ = game;
        Err(SourceError::NoSharedMemory)
    }
}

/// Whether the motion's drive demand on the platform the device runs is within its drives (printed either way).
fn loads_keep_up<T: client::Transport>(
    check: &LoadsCheck,
    source: &Source,
    client: &mut client::Client<T>,
    rig: Option<&crate::rig::Rig>,
) -> Result<bool, super::loads::LoadsError> {
    let payload = ringpod_core::kinematics::Payload {
        mass: numbers::mass(check.mass)?,
        inertia: nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::from(numbers::inertia(
            check.inertia.as_deref(),
        )?)),
    };
    let platform = super::loads_platform(client, rig)?;
    let check = super::check_loads(source, &payload, &platform)?;
    console::err(check.text.trim_end());
    Ok(check.keeps_up)
}

/// The files a stream reads (a pose file, a cueing file): none may be written by it.
fn inputs(input: &Input) -> Vec<&std::path::Path> {
    match input {
        Input::File { path, .. } => vec![path.as_path()],
        Input::Udp {
            holds: Datagrams::Telemetry {
                cue_config: Some(path), ..
            },
            ..
        }
        | Input::Shm {
            cue_config: Some(path), ..
        } => vec![path.as_path()],
        _ => Vec::new(),
    }
}

/// Runs a stream: the exit codes of [`exit`].
pub fn run(job: &Job) -> Result<u8, JobError> {
    let signals = Signals::install()?;
    // A closed or full standard output or error ends the run as a stop does (and wakes any wait for the device).
    console::on_failure(signals.flag());
    let mut read = inputs(&job.input);
    if let Device::Sim {
        platform: Some(crate::device::Platform::File(rig)),
        ..
    } = &job.device
    {
        read.push(rig.as_path());
    }
    let outputs: Vec<&std::path::Path> = [&job.record, &job.capture]
        .into_iter()
        .flatten()
        .map(|p| p.as_path())
        .collect();
    crate::out::file::check_outputs(&outputs, &read).map_err(|(out, e)| CliError::file(out, e))?;
    let (mut source, input_errors) = open(&job.input)?;
    if let (Some(path), Source::Live(udp)) = (&job.capture, &mut source) {
        let local = udp.receiver.local_addr()?;
        let writer = crate::input::capture::CaptureWriter::create(path, local).map_err(|e| CliError::file(path, e))?;
        udp.capture = Some((Box::new(writer), path.display().to_string()));
    }
    let (rig, fast) = match &job.device {
        Device::Sim { platform, fast } => (crate::device::Platform::rig(platform.as_ref())?, *fast),
        Device::Port(_) => (None, false),
    };
    let transport = match (&job.device, &rig) {
        (_, Some(r)) => link::transport::AnyTransport::Sim(Box::new(link::sim::SimDevice::for_rig(!fast, r)?)),
        (Device::Port(port), None) => link::connect(&link::Target::Port(port.clone()), true)?,
        (Device::Sim { .. }, None) => link::connect(&link::Target::Sim, !fast)?,
    };
    let mut client = client::Client::new(transport);
    client.cancel = Some(signals.flag());
    if let Some(tracker) = job.motion_compensation {
        let rig = rig.as_ref().map(|r| (r.home, r.centre_of_rotation));
        client.tap = Some(crate::vr::tap(tracker, rig)?);
    }
    // Checked on the platform the device runs, before it powers up.
    if let Some(check) = &job.check_loads {
        if !loads_keep_up(check, &source, &mut client, rig.as_ref())? {
            console::err("ringpod: the motion asks more than the drives give (--check-loads): not streamed");
            return Ok(exit::NOT_STARTED);
        }
    }
    let recorder = match &job.record {
        Some(path) => Some((
            super::record::Recorder::create(path).map_err(|e| CliError::file(path, e))?,
            path.display().to_string(),
        )),
        None => None,
    };
    let stopped = || signals.received() || console::has_failed();
    let report = match super::run(
        &mut client,
        source,
        input_errors,
        &job.options,
        fast,
        &stopped,
        recorder,
    ) {
        Ok(report) => report,
        Err(client::ClientError::Interrupted) if console::has_failed() => return Ok(crate::out::EXIT_OUTPUT),
        Err(client::ClientError::Interrupted) => {
            console::err(&format!(
                "ringpod: interrupted by {} before the stream started",
                signals.name()
            ));
            return Ok(signals.exit_code());
        }
        Err(e) => {
            console::err(&format!("ringpod: the stream could not start: {e}"));
            return Ok(exit::NOT_STARTED);
        }
    };
    print(report, job.report_json, &signals)
}

/// Settles the report's exit code (a signal's, a closed output's, a record that failed), says on stderr what went
/// wrong, then prints the report on stdout: the report's `exit_code` is the process's.
fn print(mut report: Report, json: bool, signals: &Signals) -> Result<u8, JobError> {
    if report.exit_code == exit::INTERRUPTED {
        report.exit_code = signals.exit_code();
        report.reason = Some(format!("interrupted by {}", signals.name()));
    }
    let mut notes = Vec::new();
    if let Some(reason) = &report.reason {
        notes.push(format!("ringpod: {reason}"));
    }
    for (what, path, error) in [
        report.record.as_ref().map(|r| ("record", &r.path, &r.error)),
        report.capture.as_ref().map(|c| ("capture", &c.path, &c.error)),
    ]
    .into_iter()
    .flatten()
    {
        if let Some(e) = error {
            notes.push(format!("ringpod: the {what} {path} could not be written: {e}"));
            if report.exit_code == exit::FOLLOWED {
                report.exit_code = exit::RECORD_FAILED;
            }
        }
    }
    if !json {
        if let Some(r) = report.record.as_ref().filter(|r| r.error.is_none()) {
            let hz = r.telemetry_hz.map_or(String::new(), |hz| format!(" at {hz} Hz"));
            notes.push(format!(
                "recorded {} rows to {}{hz} ({} dropped)",
                r.rows, r.path, r.dropped
            ));
        }
        if let Some(c) = report.capture.as_ref().filter(|c| c.error.is_none()) {
            notes.push(format!("captured {} datagrams to {}", c.packets, c.path));
        }
    }
    for note in notes {
        console::err(&note);
    }
    // Standard error closed or full (during the run or just now): the run ended as a stop does, and says so.
    if let Some(failed) = console::failed() {
        report.outcome = "output_failed";
        report.reason = Some(format!("{failed}: the run ended as a stop does"));
        report.exit_code = crate::out::EXIT_OUTPUT;
    }
    let text = if json {
        format!("{}\n", serde_json::to_string_pretty(&report)?)
    } else {
        let rejected: u32 = report.rejected.values().sum();
        let mut text = format!(
            "{}: {} setpoints sent, {} applied ({} limited on the host, {} on the device), {} refused; final state {}; steps {:?}\n",
            report.outcome,
            report.setpoints_sent,
            report.setpoints_applied,
            report.limited.host,
            report.limited.device,
            rejected,
            report.state,
            report.final_steps
        );
        for (reason, n) in &report.rejected {
            text += &format!("  refused {reason}: {n}\n");
        }
        text
    };
    // A closed stdout loses the report; `main` then exits with the code for a lost output.
    console::out(&text);
    Ok(report.exit_code)
}

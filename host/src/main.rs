//! `ringpod`: the command line of the ringpod motion controller.

mod cli;
mod client;
mod commission;
mod cue;
mod datagram;
mod demand;
mod error;
mod files;
// Wired into `stream` in the next commit.
#[allow(dead_code)]
mod games;
mod kinematics;
mod mechanism;
mod monitor;
mod numbers;
mod out;
mod plot;
mod pty;
mod reactions;
mod record;
mod rig;
mod settings;
mod signals;
mod stream;
mod table;
mod transport;
mod workspace;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    use cli::Command as C;
    let cli = cli::Cli::parse();
    let result = match &cli.command {
        C::Presets { json, export } => answer(match export {
            Some(name) => rig::export(name),
            None => kinematics::presets(*json),
        }),
        C::Rig { action } => answer(match action {
            cli::RigAction::Check { file, json } => rig::check_command(file, *json),
            cli::RigAction::Design {
                file,
                combined,
                starts,
                steps,
                seed,
            } => rig::design_command(file, *combined, *starts, *steps, *seed),
        }),
        C::Ik(args) => answer(kinematics::ik(&args.common.on(), args.pose.as_deref(), false)),
        C::Check(args) => answer(kinematics::ik(&args.common.on(), args.pose.as_deref(), true)),
        C::Fk(args) => answer(kinematics::fk(&args.options())),
        C::Loads(args) => answer(kinematics::loads(&args.options())),
        C::Reactions(args) => answer(reactions::run(&args.common.on(), args.pose.as_deref(), &args.wrench)),
        C::Stream(args) => stream_command(args),
        C::Device(args) => device_command(args),
        C::Ports => ports_command(),
        C::Simulate { pty, geometry } => simulate_command(*pty, geometry.as_deref()),
        C::Cue(args) => cue::run(&args.options()).map(|(text, code)| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            code
        }),
        C::Monitor { port, sim, frames } => monitor_command(port.as_deref(), *sim, *frames),
        C::Plot { record, out } => record::plot_command(record, out).map(|text| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            0
        }),
        C::Workspace(args) => workspace::run(&args.options()).map(|text| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            0
        }),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("ringpod: {e:#}");
            ExitCode::from(error::EXIT_ERROR)
        }
    }
}

/// Prints a kinematics command's text and passes on its exit code.
fn answer(outcome: Result<kinematics::Outcome, error::CliError>) -> anyhow::Result<u8> {
    let outcome = outcome?;
    // A closed pipe (`| head`) is not an error of ours.
    let _ = std::io::stdout().write_all(outcome.text.as_bytes());
    Ok(outcome.code)
}

/// `ringpod stream`: the exit codes of [`stream::exit`].
fn stream_command(args: &cli::StreamArgs) -> anyhow::Result<u8> {
    let signals = signals::Signals::install()?;
    let positive = |name: &str, v: f64, max: f64| {
        if v.is_finite() && v > 0.0 && v <= max {
            Ok(v)
        } else {
            Err(anyhow::anyhow!(
                "--{name} {}: must be a number of at most {max:e}, above 0",
                numbers::readable(v)
            ))
        }
    };
    let (source, input_errors) = match (&args.input, args.motion) {
        _ if args.udp.is_some() || args.telemetry_udp.is_some() => {
            let (addr, decoder) = match (args.udp, args.telemetry_udp) {
                (Some(addr), _) => (addr, datagram::Decoder::Poses { degrees: args.degrees }),
                (None, Some(addr)) => {
                    let config = cue::load_config(args.cue_config.as_deref())?;
                    let washout = ringpod_core::cueing::Washout::new(config).map_err(|e| anyhow::anyhow!("{e}"))?;
                    let decoder = datagram::Decoder::Telemetry {
                        format: args.telemetry_format,
                        washout: Box::new(washout),
                        // The device's home pose, once the stream has asked for its rig.
                        neutral: None,
                        last: None,
                        gaps: 0,
                    };
                    (addr, decoder)
                }
                (None, None) => anyhow::bail!("--udp or --telemetry-udp"),
            };
            let idle = positive("udp-idle", args.udp_idle, 1e6)?;
            let socket = std::net::UdpSocket::bind(addr).map_err(|e| anyhow::anyhow!("{addr}: {e}"))?;
            let source = stream::UdpSource {
                socket,
                decoder,
                idle: std::time::Duration::from_secs_f64(idle),
                from: args.udp_from,
            };
            (stream::Source::Udp(source), Vec::new())
        }
        (Some(path), _) => {
            let text =
                files::read_text(path, files::DATA_LIMIT).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
            let (poses, errors) =
                stream::read_csv(&text, args.degrees).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
            for e in &errors {
                eprintln!("{}: line {}: {}", path.display(), e.line, e.reason);
            }
            (stream::Source::Poses(poses), errors)
        }
        (None, motion) => (
            stream::Source::Motion {
                motion: motion.unwrap_or(stream::Motion::Demo),
                seconds: positive("duration", args.duration, 1e9)?,
                rate_hz: positive("rate", args.rate, 10_000.0)?,
            },
            Vec::new(),
        ),
    };
    let rig = args.geometry.as_deref().map(rig::load).transpose()?;
    let transport = match &rig {
        Some(r) => transport::AnyTransport::Sim(Box::new(transport::SimDevice::for_rig(!args.fast, r)?)),
        None => connect(args.port.as_deref(), args.sim, !args.fast)?,
    };
    let mut client = client::Client::new(transport);
    client.cancel = Some(signals.flag());
    // Checked on the platform the device runs, before it powers up.
    if args.check_loads {
        let payload = ringpod_core::kinematics::Payload {
            mass: numbers::mass(args.mass.unwrap_or(f64::NAN))?,
            inertia: nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::from(numbers::inertia(
                args.inertia.as_deref(),
            )?)),
        };
        let platform = stream::loads_platform(&mut client, rig.as_ref())?;
        let check = stream::check_loads(&source, &payload, &platform)?;
        eprint!("{}", check.text);
        if !check.keeps_up {
            eprintln!("ringpod: the motion asks more than the drives give (--check-loads): not streamed");
            return Ok(stream::exit::NOT_STARTED);
        }
    }
    // The bar draws on stderr (and hides itself without a terminal), the report on stdout.
    let options = stream::Options {
        home: args.home,
        host_limits: !args.device_limits_only,
        quiet: args.quiet,
    };
    let recorder = match &args.record {
        Some(path) => Some((
            record::Recorder::create(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?,
            path.display().to_string(),
        )),
        None => None,
    };
    let report = match stream::run(
        &mut client,
        source,
        input_errors,
        &options,
        args.fast,
        &|| signals.received(),
        recorder,
    ) {
        Ok(mut report) => {
            if report.exit_code == stream::exit::INTERRUPTED {
                report.exit_code = signals.exit_code();
                report.reason = Some(format!("interrupted by {}", signals.name()));
            }
            report
        }
        Err(client::ClientError::Interrupted) => {
            eprintln!("ringpod: interrupted by {} before the stream started", signals.name());
            return Ok(signals.exit_code());
        }
        Err(e) => {
            eprintln!("ringpod: the stream could not start: {e}");
            return Ok(stream::exit::NOT_STARTED);
        }
    };
    if args.report_json {
        let _ = writeln!(std::io::stdout(), "{}", serde_json::to_string_pretty(&report)?);
    } else {
        let rejected: u32 = report.rejected.values().sum();
        // A closed stdout (`| head -c1`) loses the summary, not the run's exit code.
        let mut out = std::io::stdout();
        let _ = writeln!(
            out,
            "{}: {} setpoints sent, {} applied ({} limited on the host, {} on the device), {} refused; final state {}; steps {:?}",
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
            let _ = writeln!(out, "  refused {reason}: {n}");
        }
    }
    if let Some(reason) = &report.reason {
        eprintln!("ringpod: {reason}");
    }
    if let Some(record) = &report.record {
        match &record.error {
            Some(e) => {
                eprintln!("ringpod: the record {} could not be written: {e}", record.path);
                if report.exit_code == stream::exit::FOLLOWED {
                    return Ok(stream::exit::RECORD_FAILED);
                }
            }
            None if !args.report_json => {
                eprintln!(
                    "recorded {} rows to {} ({} dropped)",
                    record.rows, record.path, record.dropped
                )
            }
            None => {}
        }
    }
    Ok(report.exit_code)
}

/// `ringpod monitor`.
fn monitor_command(port: Option<&str>, sim: bool, frames: Option<u64>) -> anyhow::Result<u8> {
    let mut client = client::Client::new(connect(port, sim, true)?);
    let source = port.map_or_else(|| "the simulated controller".to_owned(), str::to_owned);
    let signals = signals::Signals::install()?;
    monitor::run(&mut client, &source, frames, &|| signals.received())?;
    Ok(if signals.received() { signals.exit_code() } else { 0 })
}

/// The transport named on the command line.
fn connect(port: Option<&str>, sim: bool, realtime: bool) -> anyhow::Result<transport::AnyTransport> {
    Ok(match (port, sim) {
        (Some(port), _) => transport::AnyTransport::Serial(transport::Serial::open(port)?),
        (None, true) => transport::AnyTransport::Sim(Box::new(transport::SimDevice::new(realtime))),
        (None, false) => anyhow::bail!("say where the controller is: --port PATH or --sim"),
    })
}

/// `ringpod device ACTION`.
fn device_command(args: &cli::DeviceArgs) -> anyhow::Result<u8> {
    use cli::DeviceAction as A;
    if !matches!(args.action, A::Config | A::Jog | A::Buzz | A::Rig) && !args.config.is_empty() {
        anyhow::bail!("only `device config`, `jog`, `buzz` and `rig` take further words");
    }
    if args.watch && args.action != A::Inputs {
        anyhow::bail!("--watch is for `device inputs`");
    }
    let mut client = client::Client::new(connect(args.port.as_deref(), args.sim, false)?);
    client.hello()?;
    match args.action {
        A::Status => {}
        A::Enable => client.enable()?,
        A::Disable => client.disable()?,
        A::Home => {
            // Right after `device enable` the supplies may still be coming up: wait for them, as `stream` does,
            // instead of being refused for the state.
            client.wait_for(std::time::Duration::from_secs(5), |s| {
                !matches!(
                    s.state,
                    ringpod_core::safety::State::LogicOn | ringpod_core::safety::State::PowerOn { settled: false }
                )
            })?;
            client.home()?;
            client.wait_for(std::time::Duration::from_secs(120), |s| {
                !matches!(s.state, ringpod_core::safety::State::Homing)
            })?;
        }
        A::Start => client.start()?,
        A::Stop => client.stop()?,
        A::Clear => client.clear()?,
        A::Jog | A::Buzz => {
            let line = commission::jog(&mut client, &args.config, args.action == A::Buzz)?;
            let _ = writeln!(std::io::stdout(), "{line}");
            return Ok(0);
        }
        A::Inputs if args.watch => {
            // Watched until a signal, which is its normal end: 128 + the signal, as a shell reports it.
            let signals = signals::Signals::install()?;
            commission::inputs(&mut client, true, &|| signals.received())?;
            return Ok(signals.exit_code());
        }
        A::Inputs => {
            commission::inputs(&mut client, false, &|| false)?;
            return Ok(0);
        }
        A::Rig => {
            let words: Vec<&str> = args.config.iter().map(String::as_str).collect();
            let text = match words.as_slice() {
                ["load", file] => rig::device::load(&mut client, std::path::Path::new(file))?,
                ["show"] => rig::device::show(&mut client)?,
                _ => anyhow::bail!("`device rig load RIG.toml` or `device rig show`"),
            };
            let _ = writeln!(std::io::stdout(), "{text}");
            return Ok(0);
        }
        A::Restart => {
            let line = rig::device::restart(&mut client)?;
            let _ = writeln!(std::io::stdout(), "{line}");
            return Ok(0);
        }
        A::Config => {
            let json = settings::run(&mut client, &args.config)?;
            let _ = writeln!(std::io::stdout(), "{}", serde_json::to_string_pretty(&json)?);
            return Ok(0);
        }
    }
    // The status, and the rig the board runs: where it came from and whether another waits for the next start.
    let status = client.status()?;
    let (rig, source, pending) = client.rig()?;
    if let ringpod_core::protocol::RigSource::Refused(_) | ringpod_core::protocol::RigSource::Unreadable = source {
        eprintln!("warning: {source}");
    }
    let mut json = serde_json::to_value(status)?;
    json["rig"] = serde_json::json!({ "name": rig.name(), "source": source.to_string(), "pending": pending });
    let _ = writeln!(std::io::stdout(), "{}", serde_json::to_string_pretty(&json)?);
    Ok(0)
}

/// `ringpod simulate --pty [--geometry RIG.toml]`.
fn simulate_command(pty: bool, geometry: Option<&std::path::Path>) -> anyhow::Result<u8> {
    if !pty {
        anyhow::bail!("say how to serve the simulator: --pty");
    }
    let device = match geometry {
        Some(path) => transport::SimDevice::for_rig(true, &rig::load(path)?)?,
        None => transport::SimDevice::new(true),
    };
    let signals = signals::Signals::install()?;
    pty::serve(device, &|| signals.received())?;
    eprintln!("ringpod: simulator stopped by {}", signals.name());
    Ok(signals.exit_code())
}

/// `ringpod ports`.
fn ports_command() -> anyhow::Result<u8> {
    let ports = serialport::available_ports()?;
    let mut out = std::io::stdout();
    if ports.is_empty() {
        let _ = writeln!(out, "no serial ports found");
    }
    for p in ports {
        let kind = match p.port_type {
            serialport::SerialPortType::UsbPort(u) => {
                format!("USB {:04x}:{:04x} {}", u.vid, u.pid, u.product.unwrap_or_default())
            }
            serialport::SerialPortType::PciPort => "PCI".into(),
            serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
            serialport::SerialPortType::Unknown => "unknown".into(),
        };
        let _ = writeln!(out, "{}  {kind}", p.port_name);
    }
    Ok(0)
}

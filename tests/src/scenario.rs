//! Data-driven scenarios (in the manner of rmk's and Klipper's test files): a TOML file lists timed commands,
//! input changes, pose streams and expectations; [`run`] plays it against the controller and the simulated plant.
//!
//! ```toml
//! description = "..."
//! start = [-500, -400, -300, -200, 8000, 9000]   # plant positions before homing (steps from each switch)
//! [[step]]
//! at_ms = 0
//! send = "enable"                # hello, enable, disable, home, start, stop, clear, status, jog A S, buzz A
//! expect_response = "Ack"        # optional: prefix of the response's Debug text
//! [[step]]
//! at_ms = 5
//! input = { estop = true }       # estop, supply_dead, limit_axis (drives that axis past its far limit)
//! [[step]]
//! at_ms = 10
//! stream = { kind = "sine", axis = 2, amplitude = 0.02, frequency_hz = 1.0, rate_hz = 60.0, duration_ms = 2000 }
//! [[step]]
//! at_ms = 50
//! setpoint = { pose = [0, 0, 0.5, 0, 0, 0], expect = "Nack(Rejected(GrossJump" }
//! [[step]]
//! at_ms = 3000
//! expect = { state = "Ready", logic = true, power = true, enable = true, homed = true, at_pose = [0, 0, 0.227, 0, 0, 0] }
//! ```

use std::fmt::Write;

use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::kinematics::{presets, Pose};
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{self, DeviceMessage, HostMessage, Request, Response, PROTOCOL_VERSION};
use ringpod_core::safety::Command;
use serde::Deserialize;

use crate::plant::{Plant, Rig};

/// A scenario file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// What it shows.
    pub description: String,
    /// Plant positions before homing (steps from each switch).
    #[serde(default = "default_start")]
    pub start: [i64; 6],
    /// The timed steps, in order.
    pub step: Vec<Step>,
}

fn default_start() -> [i64; 6] {
    ringpod_core::sim::TRAINER_MODEL_PARKED
}

/// One timed step.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// When (ms from the start).
    pub at_ms: u64,
    /// A command to send.
    pub send: Option<String>,
    /// Prefix of the expected response to `send`.
    pub expect_response: Option<String>,
    /// Input changes.
    pub input: Option<InputChange>,
    /// A pose stream to start.
    pub stream: Option<Stream>,
    /// One setpoint with its expected response.
    pub setpoint: Option<OneSetpoint>,
    /// Expectations at this time.
    pub expect: Option<Expect>,
}

/// Changes to the plant's inputs.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputChange {
    /// Open (true) or close the e-stop chain.
    pub estop: Option<bool>,
    /// Supplies stop coming up.
    pub supply_dead: Option<bool>,
    /// Push this linear axis past its far end-of-travel switch (a runaway).
    pub limit_axis: Option<usize>,
}

/// A stream of setpoints.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stream {
    /// `sine` (one pose axis), `yaw` (constant yaw rate), `demo` (all axes), `hold` (one pose, `pose`).
    pub kind: String,
    /// Pose axis for `sine` (0..6).
    #[serde(default)]
    pub axis: usize,
    /// Amplitude (m or rad), or yaw rate (rad/s) for `yaw`.
    #[serde(default)]
    pub amplitude: f64,
    /// Frequency (Hz).
    #[serde(default)]
    pub frequency_hz: f64,
    /// The pose of a `hold` stream.
    #[serde(default)]
    pub pose: [f64; 6],
    /// Setpoints per second.
    pub rate_hz: f64,
    /// How long (ms).
    pub duration_ms: u64,
}

/// One setpoint.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OneSetpoint {
    /// The pose (TOML allows nan and inf).
    pub pose: [f64; 6],
    /// Prefix of the expected response.
    pub expect: String,
}

/// Expectations.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// Prefix of the supervisor state's Debug text.
    pub state: Option<String>,
    /// Logic relay.
    pub logic: Option<bool>,
    /// Power relay.
    pub power: Option<bool>,
    /// Driver enable.
    pub enable: Option<bool>,
    /// Homed.
    pub homed: Option<bool>,
    /// The axes' step positions are those of this pose (within one step).
    pub at_pose: Option<[f64; 6]>,
    /// The axes' step positions are those of the last accepted setpoint (within one step).
    pub at_last_setpoint: Option<bool>,
    /// Total rejected setpoints.
    pub rejected: Option<u32>,
    /// Accepted setpoints.
    pub applied: Option<u32>,
    /// Every setpoint sent was either accepted or rejected (nothing lost).
    pub counts_add_up: Option<bool>,
    /// Setpoints limited into the envelope, at least this many.
    pub limited_at_least: Option<u32>,
    /// Setpoints limited into the envelope, exactly.
    pub limited: Option<u32>,
    /// The axes' step positions, exactly.
    pub steps: Option<[i64; 6]>,
}

/// What a run did, for assertions beyond the file.
#[derive(Debug, Default)]
pub struct Report {
    /// Setpoints sent.
    pub sent: u32,
    /// Largest step a ring axis made between two control periods.
    pub max_ring_steps_per_tick: i64,
    /// Steps received by the plant while its drivers were disabled.
    pub steps_while_disabled: u64,
    /// One line per expectation checked.
    pub log: String,
}

struct ActiveStream {
    stream: Stream,
    start_ms: u64,
    next_ms: f64,
}

struct Host {
    next_id: u32,
    seq: u32,
    last_accepted: Option<Pose<f32>>,
}

impl Host {
    /// Sends a request through the real framing, as the link task would.
    fn send(&mut self, c: &mut Controller, body: HostMessage) -> Response {
        self.next_id += 1;
        let mut frame = [0u8; protocol::MAX_FRAME];
        let n = protocol::encode(&Request { id: self.next_id, body }, &mut frame).expect("request fits a frame");
        let mut out = [0u8; protocol::MAX_FRAME];
        let m = c.handle_frame(&frame[..n - 1], &mut out);
        let response: Response = protocol::decode(&out[..m - 1]).expect("device response decodes");
        assert_eq!(response.id, self.next_id, "response to the request sent");
        response
    }

    /// Remembers where an accepted setpoint sends the platform: the pose itself, or the pose it was limited to.
    fn accepted(&mut self, c: &Controller, answer: &DeviceMessage, pose: Pose<f32>) {
        match answer {
            DeviceMessage::Ack => self.last_accepted = Some(pose),
            DeviceMessage::Limited(_) => self.last_accepted = Some(c.pipeline().target()),
            _ => {}
        }
    }
}

fn command(name: &str) -> Result<HostMessage, String> {
    Ok(match name {
        "hello" => HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
        "hello-v0" => HostMessage::Hello { version: 0 },
        "enable" => HostMessage::Command(Command::Enable),
        "disable" => HostMessage::Command(Command::Disable),
        "home" => HostMessage::Command(Command::Home),
        "start" => HostMessage::Command(Command::Start),
        "stop" => HostMessage::Command(Command::Stop),
        "clear" => HostMessage::Command(Command::ClearFault),
        "status" => HostMessage::GetStatus,
        other => {
            // `jog AXIS STEPS`, `buzz AXIS` (axis 0-5).
            let words: Vec<&str> = other.split_whitespace().collect();
            let number = |w: &str| w.parse::<i64>().map_err(|_| format!("`{other}`: {w} is not a number"));
            match words.as_slice() {
                ["jog", axis, steps] => HostMessage::Jog {
                    axis: u8::try_from(number(axis)?).map_err(|e| e.to_string())?,
                    steps: i32::try_from(number(steps)?).map_err(|e| e.to_string())?,
                },
                ["buzz", axis] => HostMessage::Buzz {
                    axis: u8::try_from(number(axis)?).map_err(|e| e.to_string())?,
                },
                _ => return Err(format!("unknown command `{other}`")),
            }
        }
    })
}

fn stream_pose(s: &Stream, t: f64) -> Pose<f64> {
    let mut p = presets::Preset::TrainerModel.home();
    let w = std::f64::consts::TAU * s.frequency_hz;
    match s.kind.as_str() {
        "sine" => p[s.axis.min(5)] += s.amplitude * (w * t).sin(),
        "yaw" => p[5] = (s.amplitude * t).rem_euclid(std::f64::consts::TAU),
        "hold" => p = s.pose,
        _ => {
            // demo: every axis at once, at half its range, different frequencies; starts at home
            let r = presets::TRAINER_MODEL_RANGES;
            for (i, f) in [0.31, 0.23, 0.37, 0.41, 0.29].iter().enumerate() {
                p[i] += 0.5 * r[i] * (std::f64::consts::TAU * f * t).sin();
            }
            p[5] = (0.5 * t).rem_euclid(std::f64::consts::TAU);
        }
    }
    Pose::from_array(p)
}

/// The steps the axes must be at for a pose, via the controller's own converter and the multi-turn branch
/// nearest to where the axes are.
fn steps_of(c: &Controller, pose: &Pose<f32>) -> [i64; 6] {
    let mut q = *c.pipeline().actuators();
    q.inverse_near(c.pipeline().mechanism(), pose)
        .expect("expected pose reachable");
    c.pipeline().converter().to_steps(&q)
}

/// Plays a scenario; Err describes the first expectation that failed.
pub fn run(scenario: &Scenario) -> Result<Report, String> {
    let controller = Controller::new(ControllerConfig::trainer_model()).map_err(|e| format!("{e:?}"))?;
    let mut rig = Rig {
        controller,
        plant: Plant::trainer_model(scenario.start),
        ticks: 0,
    };
    let mut host = Host {
        next_id: 0,
        seq: 0,
        last_accepted: None,
    };
    let mut report = Report::default();
    let mut streams: Vec<ActiveStream> = Vec::new();
    let end = scenario.step.iter().map(|s| s.at_ms).max().unwrap_or(0);
    let mut steps = scenario.step.iter().peekable();
    let mut last_steps = rig.controller.steps();
    for now in 0..=end {
        while let Some(step) = steps.next_if(|s| s.at_ms == now) {
            apply_step(step, now, &mut rig, &mut host, &mut report, &mut streams)?;
        }
        feed_streams(now, &mut streams, &mut rig, &mut host, &mut report);
        rig.tick();
        let now_steps = rig.controller.steps();
        for a in 0..4 {
            report.max_ring_steps_per_tick = report.max_ring_steps_per_tick.max((now_steps[a] - last_steps[a]).abs());
        }
        last_steps = now_steps;
    }
    report.steps_while_disabled = rig.plant.steps_while_disabled;
    if report.steps_while_disabled != 0 {
        return Err(format!(
            "{} steps reached the plant with its drivers disabled",
            report.steps_while_disabled
        ));
    }
    Ok(report)
}

/// One step of a scenario at `now` (ms): its command, inputs, setpoint, stream and expectations.
fn apply_step(
    step: &Step,
    now: u64,
    rig: &mut Rig,
    host: &mut Host,
    report: &mut Report,
    streams: &mut Vec<ActiveStream>,
) -> Result<(), String> {
    let at = format!("at {now} ms");
    if let Some(name) = &step.send {
        let response = host.send(&mut rig.controller, command(name)?);
        let text = format!("{:?}", response.body);
        if let Some(want) = &step.expect_response {
            if !text.starts_with(want.as_str()) {
                return Err(format!("{at}: `{name}` answered {text}, expected {want}"));
            }
        }
        let _ = writeln!(report.log, "{at}: {name} -> {text}");
    }
    if let Some(i) = &step.input {
        if let Some(v) = i.estop {
            rig.plant.estop_open = v;
        }
        if let Some(v) = i.supply_dead {
            rig.plant.supply_dead = v;
        }
        if let Some(a) = i.limit_axis {
            rig.plant.position[a] = rig.plant.switches[a].far_limit.ok_or("not a linear axis")?;
        }
    }
    if let Some(s) = &step.setpoint {
        host.seq += 1;
        report.sent += 1;
        let pose = Pose::from_array(s.pose.map(|v| v as f32));
        let sp = Setpoint {
            seq: host.seq,
            time_us: now * 1000,
            pose,
            aux: [None; 2],
            spare: [None; 2],
        };
        let response = host.send(&mut rig.controller, HostMessage::Setpoint(sp));
        let text = format!("{:?}", response.body);
        if !text.starts_with(s.expect.as_str()) {
            return Err(format!(
                "{at}: setpoint {:?} answered {text}, expected {}",
                s.pose, s.expect
            ));
        }
        host.accepted(&rig.controller, &response.body, pose);
    }
    if let Some(s) = &step.stream {
        streams.push(ActiveStream {
            stream: s.clone(),
            start_ms: now,
            next_ms: now as f64,
        });
    }
    if let Some(e) = &step.expect {
        check(rig, host, report, e).map_err(|m| format!("{at}: {m}"))?;
        let _ = writeln!(report.log, "{at}: expectations met");
    }
    Ok(())
}

/// The setpoints of the running streams due at `now` (ms).
fn feed_streams(now: u64, streams: &mut [ActiveStream], rig: &mut Rig, host: &mut Host, report: &mut Report) {
    for s in streams.iter_mut() {
        while s.next_ms <= now as f64 && now < s.start_ms + s.stream.duration_ms {
            let t = (s.next_ms - s.start_ms as f64) / 1000.0;
            let pose = stream_pose(&s.stream, t).cast::<f32>();
            host.seq += 1;
            report.sent += 1;
            let sp = Setpoint {
                seq: host.seq,
                time_us: (s.next_ms * 1000.0) as u64,
                pose,
                aux: [None; 2],
                spare: [None; 2],
            };
            let response = host.send(&mut rig.controller, HostMessage::Setpoint(sp));
            host.accepted(&rig.controller, &response.body, pose);
            s.next_ms += 1000.0 / s.stream.rate_hz;
        }
    }
}

fn check(rig: &Rig, host: &Host, report: &Report, e: &Expect) -> Result<(), String> {
    let c = &rig.controller;
    let s = c.supervisor();
    let o = s.outputs();
    let status = c.status();
    let state = format!("{:?}", s.state());
    if let Some(want) = &e.state {
        if !state.starts_with(want.as_str()) {
            return Err(format!("state {state}, expected {want}"));
        }
    }
    for (name, want, got) in [
        ("logic", e.logic, o.logic_relay),
        ("power", e.power, o.power_relay),
        ("enable", e.enable, o.driver_enable),
        ("homed", e.homed, s.homed()),
    ] {
        if want.is_some_and(|w| w != got) {
            return Err(format!("{name} is {got} in state {state}"));
        }
    }
    let near = |target: [i64; 6]| -> Result<(), String> {
        let steps = c.steps();
        if steps.iter().zip(target).all(|(a, b)| (a - b).abs() <= 1) {
            Ok(())
        } else {
            Err(format!("steps {steps:?}, expected {target:?}"))
        }
    };
    if let Some(p) = e.at_pose {
        near(steps_of(c, &Pose::from_array(p.map(|v| v as f32))))?;
    }
    if e.steps.is_some_and(|want| c.steps() != want) {
        return Err(format!("steps {:?}, expected {:?}", c.steps(), e.steps));
    }
    if e.at_last_setpoint == Some(true) {
        let pose = host.last_accepted.ok_or("no setpoint was accepted")?;
        near(steps_of(c, &pose))?;
    }
    if let Some(r) = e.rejected {
        if status.rejected.total() != r {
            return Err(format!(
                "{} rejected ({:?}), expected {r}",
                status.rejected.total(),
                status.rejected
            ));
        }
    }
    if let Some(a) = e.applied {
        if status.applied != a {
            return Err(format!("{} applied, expected {a}", status.applied));
        }
    }
    if e.limited.is_some_and(|n| status.limited.count != n)
        || e.limited_at_least.is_some_and(|n| status.limited.count < n)
    {
        return Err(format!("{} limited ({:?})", status.limited.count, status.limited));
    }
    if e.counts_add_up == Some(true) && status.applied + status.rejected.total() != report.sent {
        return Err(format!(
            "sent {} != applied {} + rejected {}",
            report.sent,
            status.applied,
            status.rejected.total()
        ));
    }
    Ok(())
}

/// Reads a scenario file.
pub fn load(path: &std::path::Path) -> Result<Scenario, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

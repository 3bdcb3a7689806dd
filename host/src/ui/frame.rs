//! What the page is sent: the rig once (to draw the ring and name the axes), then frames of telemetry with the
//! mechanism placed in 3D and, for every command, whether the device's supervisor would take it now and why not.

use ringpod_core::kinematics::{AxisKind, ChainKind, Mechanism, Pose, RingGeometry, RingPlatform};
use ringpod_core::protocol::Telemetry;
use ringpod_core::safety::{Command, Event, Inputs, Supervisor, SupervisorConfig};
use serde::Serialize;

use crate::analysis::placement::{place, Placed};
use crate::device::{commission, state_name};

/// The rig the device runs, as the page draws it.
#[derive(Debug, Clone, Serialize)]
pub struct RigView {
    pub name: String,
    /// m.
    pub ring_radius: f64,
    /// Each chain's kind, `rod` or `radial`.
    pub chains: Vec<&'static str>,
    /// Each actuator's kind and unit: `ring` (rad), `linear` (m), `angle` (rad).
    pub axes: Vec<&'static str>,
    /// m and rad.
    pub home: [f64; 6],
    /// The inputs in telemetry bit order: (bit mask, name).
    pub inputs: Vec<(u16, String)>,
    /// Where it came from, as the device says.
    pub source: String,
    /// The firmware the device runs and its protocol version (empty for a rig file shown on its own).
    pub firmware: String,
    /// Each axis's reach about home (surge, sway, heave m; roll, pitch rad), as the cueing's envelope scans it:
    /// the Live view's share of the envelope used. None when the home is outside the workspace.
    pub envelope: Option<[(f64, f64); 5]>,
    /// The unit of a frame's tick cost: `cycles` on a board's MCU, `ns` in the simulator.
    pub tick_unit: &'static str,
    /// The longest jog of each actuator the device takes (deg of ring or shoulder, mm of a linear actuator): a
    /// carriage its homing back-off, a linear actuator or a shoulder its homing search travel. Empty when unknown.
    pub jog_most: Vec<f64>,
}

impl RigView {
    /// The view of a geometry and its home pose.
    pub fn of(geometry: &RingGeometry, home: [f64; 6], source: String) -> Self {
        let m = RingPlatform::<f64>::new(geometry);
        Self {
            name: geometry.name.to_owned(),
            ring_radius: geometry.ring_radius,
            chains: geometry
                .chains()
                .iter()
                .map(|c| match c.kind {
                    ChainKind::Radial => "radial",
                    ChainKind::Elbow(_) => "elbow",
                    ChainKind::Rod(_) => "rod",
                })
                .collect(),
            axes: m
                .axes()
                .iter()
                .map(|a| match a {
                    AxisKind::Ring => "ring",
                    AxisKind::Linear => "linear",
                    AxisKind::Angle => "angle",
                })
                .collect(),
            home,
            inputs: commission::names()
                .into_iter()
                .map(|(bit, name)| (bit.mask(), name))
                .collect(),
            source,
            firmware: String::new(),
            envelope: crate::cueing::engine::envelope(&m, &Pose::from_array(home))
                .ok()
                .map(|e| e.ranges),
            tick_unit: "cycles",
            jog_most: Vec::new(),
        }
    }
}

impl RigView {
    /// The longest jog of each actuator, as the device checks it (`commission::begin_move`'s "further than a jog
    /// goes"): a carriage its homing back-off, a linear actuator or a shoulder its homing search travel.
    pub fn jog_the_device_takes(&mut self, homing: &[ringpod_core::protocol::SwitchSettings; 6]) {
        self.jog_most = self
            .axes
            .iter()
            .zip(homing)
            .map(|(kind, h)| match *kind {
                "ring" => f64::from(h.backoff).to_degrees(),
                "linear" => f64::from(h.search) * 1000.0,
                _ => f64::from(h.search).to_degrees(),
            })
            .collect();
    }
}

/// Whether each command would be taken now (`None`) or why not: the supervisor's own decision, asked of one
/// rebuilt from the reported state and inputs; while a stream runs from this workbench, only its STOP.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Gates {
    pub enable: Option<String>,
    pub disable: Option<String>,
    pub home: Option<String>,
    pub start: Option<String>,
    pub stop: Option<String>,
    pub clear: Option<String>,
    pub jog: Option<String>,
    /// A stream, park or session of this workbench.
    pub stream: Option<String>,
}

impl Gates {
    /// The gates of a telemetry sample.
    pub fn of(sample: &Telemetry, streaming: bool) -> Self {
        let s = Supervisor::as_reported(
            SupervisorConfig::default(),
            sample.state,
            Inputs::from_word(sample.inputs),
        );
        let busy = streaming.then(|| "a stream is running: STOP ends it".to_owned());
        let why = |e: Event| busy.clone().or_else(|| s.permits(e).err().map(|r| r.to_string()));
        // A stream powers up and homes by itself (as `ringpod stream` does): only a fault or the e-stop keep it
        // from starting.
        let stream = busy.clone().or_else(|| {
            if matches!(sample.state, ringpod_core::safety::State::Fault(..)) {
                Some("a fault is latched: clear it first".to_owned())
            } else {
                s.permits(Event::Command(Command::Enable))
                    .err()
                    .filter(|r| *r == ringpod_core::safety::Refusal::EStopOpen)
                    .map(|r| r.to_string())
            }
        });
        Self {
            enable: why(Event::Command(Command::Enable)),
            disable: why(Event::Command(Command::Disable)),
            home: why(Event::Command(Command::Home)),
            start: why(Event::Command(Command::Start)),
            stop: why(Event::Command(Command::Stop)),
            clear: why(Event::Command(Command::ClearFault)),
            jog: why(Event::Jog),
            stream,
        }
    }
}

/// One frame of the live view.
#[derive(Debug, Clone, Serialize)]
pub struct Frame {
    /// Device time (s).
    pub t: f64,
    pub state: String,
    /// Where the platform is driven now (the followed pose), m and rad.
    pub pose: [f64; 6],
    /// The last accepted setpoint as limited (the commanded pose, drawn as a ghost).
    pub target: [f64; 6],
    pub steps: [i64; 6],
    pub applied: u32,
    pub limited: u32,
    pub refused: u32,
    /// Telemetry samples that arrived.
    pub received: u64,
    /// Samples per second over the last second.
    pub rate_hz: f64,
    /// CPU cycles on the MCU, ns in the simulator.
    pub tick_cost: u32,
    pub inputs: u16,
    /// Bit 0 LOGIC_EN, 1 POWER_EN, 2 driver enable, 3 AUX1, 4 AUX2.
    pub outputs: u8,
    pub placed: Option<Placed>,
    pub ghost: Option<Placed>,
    pub gates: Gates,
    pub streaming: bool,
    /// What the game asked of the cueing in the last half second (a telemetry session's newest sample).
    pub cue_input: Option<CueInput>,
    /// The lap preview of a telemetry session that has it on, as of its newest sample in the last half second.
    pub lap_preview: Option<LapPreview>,
}

/// The lap preview's state as the Live view shows it: the lap being driven, the earlier lap it is matched to (1
/// the first), the preview's share of the reference, the alignment's error, and what it counted.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct LapPreview {
    pub lap: usize,
    pub matched: Option<usize>,
    pub confidence: f64,
    pub error: f64,
    pub laps: usize,
    pub kept: usize,
    pub departures: usize,
}

impl LapPreview {
    /// The newest session's lap preview, if its last sample came within the last half second.
    pub fn newest() -> Option<Self> {
        let (at, c) = crate::stream::datagram::newest_lap()?;
        let s = c.state?;
        (at.elapsed() < std::time::Duration::from_millis(500)).then_some(Self {
            lap: s.lap + 1,
            matched: s.matched.map(|m| m + 1),
            confidence: s.confidence,
            error: s.error,
            laps: c.laps,
            kept: c.kept,
            departures: c.departures,
        })
    }
}

/// A telemetry sample as the Live view shows it: specific force in g (x forward, y left, z up) and angular rate
/// in deg/s (roll, pitch, yaw).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct CueInput {
    pub force_g: [f64; 3],
    pub rate_deg_s: [f64; 3],
}

impl CueInput {
    /// The newest sample a telemetry session cued, if it came within the last half second.
    pub fn newest() -> Option<Self> {
        let (at, t) = crate::stream::datagram::newest_input()?;
        (at.elapsed() < std::time::Duration::from_millis(500)).then(|| Self {
            force_g: t.force.map(|f| f / ringpod_core::cueing::G),
            rate_deg_s: t.rate.map(f64::to_degrees),
        })
    }
}

/// Counts of the telemetry link, kept by whoever taps it.
#[derive(Debug, Clone, Copy, Default)]
pub struct LinkCounts {
    pub received: u64,
    pub rate_hz: f64,
}

/// The frame of a sample on the mechanism the device runs.
pub fn frame(m: &RingPlatform<f64>, t: &Telemetry, link: LinkCounts, streaming: bool) -> Frame {
    let pose: Pose<f64> = t.pose.cast();
    let target: Pose<f64> = t.target.cast();
    Frame {
        t: t.time_us as f64 * 1e-6,
        state: state_name(t.state),
        pose: pose.to_array(),
        target: target.to_array(),
        steps: t.steps,
        applied: t.applied,
        limited: t.limited,
        refused: t.refused,
        received: link.received,
        rate_hz: link.rate_hz,
        tick_cost: t.tick_cost,
        inputs: t.inputs,
        outputs: t.outputs,
        placed: place(m, &pose),
        ghost: place(m, &target),
        gates: Gates::of(t, streaming),
        streaming,
        cue_input: CueInput::newest(),
        lap_preview: LapPreview::newest(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::kinematics::presets::{Preset, PresetGeometry};
    use ringpod_core::safety::debounce::InputBit;
    use ringpod_core::safety::State;

    fn sample(state: State, inputs: u16) -> Telemetry {
        let home = Pose::from_array(Preset::TrainerModel.home()).cast::<f32>();
        Telemetry {
            time_us: 1_000_000,
            state,
            pose: home,
            target: home,
            steps: [0; 6],
            flags: 0,
            applied: 0,
            limited: 0,
            refused: 0,
            tick_cost: 0,
            inputs,
            outputs: 0,
        }
    }

    /// The jog the page says is the one the device takes: a carriage's homing back-off in degrees of ring, a
    /// linear actuator's search travel in mm; the trainer's simulator counts its tick in ns.
    #[test]
    fn the_longest_jog_is_the_homing_back_off_or_search() {
        use ringpod_core::protocol::{SwitchSettings, Toward};
        let PresetGeometry::Ring(g) = Preset::TrainerModel.geometry() else {
            unreachable!("the trainer model is a ring platform")
        };
        let mut view = RigView::of(g, Preset::TrainerModel.home(), "test".into());
        assert_eq!(view.tick_unit, "cycles", "a board's until the worker says it simulates");
        let envelope = view.envelope.expect("the trainer's home is inside its workspace");
        assert!(envelope.iter().all(|(lo, hi)| *lo < 0.0 && *hi > 0.0), "{envelope:?}");
        let switch = |backoff: f32, search: f32| SwitchSettings {
            toward: Toward::Plus,
            switch: 0.0,
            search,
            backoff,
            fast: 1.0,
            slow: 0.1,
        };
        view.axes = vec!["ring", "linear", "angle", "ring", "ring", "ring"];
        let homing = [
            switch(0.0349, 7.0),
            switch(0.01, 0.05),
            switch(0.01, 0.5),
            switch(0.1, 7.0),
            switch(0.1, 7.0),
            switch(0.1, 7.0),
        ];
        view.jog_the_device_takes(&homing);
        let most: Vec<f64> = view.jog_most.iter().map(|v| (v * 100.0).round() / 100.0).collect();
        assert_eq!(most, [2.0, 50.0, 28.65, 5.73, 5.73, 5.73]);
    }

    #[test]
    fn gates_say_what_the_supervisor_would_refuse() {
        let off = Gates::of(&sample(State::Off, 0), false);
        assert_eq!(off.enable, None);
        assert!(off.home.as_deref().unwrap().contains("not possible"), "{off:?}");
        assert_eq!(off.stream, None, "a stream powers up by itself");
        let estop = Gates::of(&sample(State::Off, InputBit::EStop.mask()), false);
        assert_eq!(estop.enable.as_deref(), Some("e-stop is open"));
        assert_eq!(estop.stream.as_deref(), Some("e-stop is open"));
        let ready = Gates::of(&sample(State::Ready, 0), false);
        assert_eq!(
            (ready.start.clone(), ready.home.clone(), ready.jog.clone()),
            (None, None, None)
        );
        let streaming = Gates::of(&sample(State::Running, 0), true);
        assert!(streaming.stop.as_deref().unwrap().contains("STOP"), "{streaming:?}");
        assert!(streaming.stream.is_some());
    }
}

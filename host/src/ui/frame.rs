//! What the page is sent: the rig once (to draw the ring and name the axes), then frames of telemetry with the
//! mechanism placed in 3D and, for every command, whether the device's supervisor would take it now and why not.

use ringpod_core::kinematics::{AxisKind, ChainKind, Mechanism, Pose, RingGeometry, RingPlatform};
use ringpod_core::protocol::Telemetry;
use ringpod_core::safety::{Command, Event, Inputs, Supervisor, SupervisorConfig};
use serde::Serialize;

use crate::device::commission;
use crate::stream::record::state_name;

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
        }
    }
}

/// The mechanism at one pose: each chain's carriage on the ring, an elbow chain's shoulder and elbow axes, and
/// its platform joint (m, base frame).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Placed {
    pub carriages: Vec<[f64; 3]>,
    /// Per chain: `[shoulder, elbow]` of an elbow chain, none for the others.
    pub arms: Vec<Option<[[f64; 3]; 2]>>,
    pub joints: Vec<[f64; 3]>,
}

/// Places the mechanism at `pose`: `None` where the pose has no inverse kinematics.
///
/// An elbow chain's shoulder angle `s` is the actuator after every carriage and every radial length, in chain
/// order; the upper arm points along `cos(s) u + sin(s) z`, with `u` the horizontal unit vector from the shoulder
/// toward the ring axis (KINEMATICS, the rig file's `elbow` chain).
pub fn place(m: &RingPlatform<f64>, pose: &Pose<f64>) -> Option<Placed> {
    let q = m.inverse(pose).ok()?;
    let chains = m.geometry().chains();
    let n = chains.len();
    let r = m.geometry().ring_radius;
    let joints = m.joints(pose);
    let radial = chains.iter().filter(|c| c.kind == ChainKind::Radial).count();
    let mut next_shoulder = n + radial;
    let arms = chains
        .iter()
        .enumerate()
        .map(|(i, c)| match c.kind {
            ChainKind::Elbow(e) => {
                let (s, (sq, cq)) = (q.0.get(next_shoulder).copied()?, q.0[i].sin_cos());
                next_shoulder += 1;
                let reach = e.shoulder_radius - e.upper_arm * s.cos();
                Some(Some([
                    [e.shoulder_radius * cq, e.shoulder_radius * sq, e.shoulder_height],
                    [reach * cq, reach * sq, e.shoulder_height + e.upper_arm * s.sin()],
                ]))
            }
            _ => Some(None),
        })
        .collect::<Option<Vec<_>>>()?;
    Some(Placed {
        carriages: (0..n)
            .map(|i| {
                let a = q.0[i];
                [r * a.cos(), r * a.sin(), 0.0]
            })
            .collect(),
        arms,
        joints: joints.iter().take(n).map(|j| [j.x, j.y, j.z]).collect(),
    })
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
    /// Bit 0 LOGIC_EN, 1 POWER_EN, 2 driver enable.
    pub outputs: u8,
    pub placed: Option<Placed>,
    pub ghost: Option<Placed>,
    pub gates: Gates,
    pub streaming: bool,
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

    #[test]
    fn the_mechanism_is_placed_on_its_ring_and_joints() {
        let PresetGeometry::Ring(g) = Preset::TrainerModel.geometry() else {
            unreachable!("the trainer model is a ring platform")
        };
        let m = RingPlatform::<f64>::new(g);
        let home = Pose::from_array(Preset::TrainerModel.home());
        let p = place(&m, &home).unwrap();
        assert_eq!(p.carriages.len(), g.chains().len());
        for c in &p.carriages {
            let r = (c[0] * c[0] + c[1] * c[1]).sqrt();
            assert!((r - g.ring_radius).abs() < 1e-12, "on the ring: {r}");
        }
        // Each rod chain's joint is a rod length from its carriage.
        for (i, c) in g.chains().iter().enumerate() {
            if c.kind != ChainKind::Radial {
                let (a, j) = (p.carriages[i], p.joints[i]);
                let d = ((a[0] - j[0]).powi(2) + (a[1] - j[1]).powi(2) + (a[2] - j[2]).powi(2)).sqrt();
                assert!((d - g.rod_length).abs() < 1e-9, "chain {i}: {d}");
            }
        }
        assert!(
            place(&m, &Pose::new(0.0, 0.0, 10.0, 0.0, 0.0, 0.0)).is_none(),
            "out of reach"
        );
    }

    #[test]
    fn an_elbow_chain_is_placed_with_its_arms_lengths() {
        let PresetGeometry::Ring(g) = Preset::TrainerElbow.geometry() else {
            unreachable!("the elbow trainer is a ring platform")
        };
        let m = RingPlatform::<f64>::new(g);
        let p = place(&m, &Pose::from_array(Preset::TrainerElbow.home())).unwrap();
        let d =
            |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        let mut elbows = 0;
        for (i, c) in g.chains().iter().enumerate() {
            if let ChainKind::Elbow(e) = c.kind {
                let [shoulder, elbow] = p.arms[i].expect("an elbow chain has arms");
                assert!(
                    (d(shoulder, elbow) - e.upper_arm).abs() < 1e-9,
                    "upper arm of chain {i}"
                );
                assert!((d(elbow, p.joints[i]) - e.forearm).abs() < 1e-9, "forearm of chain {i}");
                elbows += 1;
            } else {
                assert!(p.arms[i].is_none());
            }
        }
        assert_eq!(elbows, 2);
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

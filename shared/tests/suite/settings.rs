//! Input debouncing and the device settings: sections and their codes, live and next-start sections, every bad
//! value refused with its cause, the changes the firmware stores, and the restore at boot that replays them.

use crate::common::device;

use proptest::prelude::*;
use ringpod_core::controller::{Controller, ControllerConfig, Inputs};
use ringpod_core::protocol::{
    AxisSettings, ConfigRefusal, ControlSettings, DeviceMessage, HomingSettings, HostMessage, MotionSettings,
    NackReason, Request, Settings, SettingsKind, StreamSettings, PROTOCOL_VERSION,
};
use ringpod_core::safety::debounce::{Debouncer, InputBit, InputConfig};
use ringpod_core::safety::{Command, SupervisorConfig};

fn config(samples: u8) -> InputConfig {
    InputConfig {
        active_low: 0,
        debounce_samples: samples,
    }
}

/// The definition: a level is accepted on the sample that completes `n` equal samples in a row of a level other
/// than the accepted one.
fn reference(initial: bool, samples: &[bool], n: usize) -> Vec<bool> {
    let mut accepted = initial;
    let mut run = 0;
    let mut out = Vec::new();
    for (i, &s) in samples.iter().enumerate() {
        if s != accepted {
            run += 1;
            // The run counts only samples of the new level since the last sample of the accepted level.
            if run >= n && samples[i + 1 - n..=i].iter().all(|&x| x == s) {
                accepted = s;
                run = 0;
            }
        } else {
            run = 0;
        }
        out.push(accepted);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2_000))]

    #[test]
    fn debouncing_matches_its_definition(
        samples in prop::collection::vec(any::<bool>(), 0..200),
        n in 1u8..6,
        initial in any::<bool>(),
        bit in 0u32..15,
    ) {
        let mask = 1u16 << bit;
        let mut d = Debouncer::new(config(n), if initial { mask } else { 0 });
        let expected = reference(initial, &samples, usize::from(n));
        for (s, e) in samples.iter().zip(expected) {
            let accepted = d.sample(if *s { mask } else { 0 });
            prop_assert_eq!(accepted & mask != 0, e);
            prop_assert_eq!(accepted & !mask, 0, "other inputs stay where they are");
        }
    }

    #[test]
    fn inputs_round_trip_through_the_logical_word(
        estop in any::<bool>(), home in 0u16..64, limits in 0u16..64, logic_ok in any::<bool>(), power_ok in any::<bool>()
    ) {
        let inputs = Inputs { estop_open: estop, home, limits, logic_ok, power_ok };
        prop_assert_eq!(Inputs::from_word(inputs.word()), inputs);
    }
}

#[test]
fn a_bounce_shorter_than_the_window_changes_nothing() {
    let estop = InputBit::EStop.mask();
    let mut d = Debouncer::new(config(3), 0);
    for _ in 0..10 {
        assert_eq!(d.sample(estop), 0);
        assert_eq!(d.sample(estop), 0);
        assert_eq!(d.sample(0), 0);
    }
    assert!(!d.settling());
    assert_eq!(d.sample(estop), 0);
    assert!(d.settling());
    assert_eq!(d.sample(estop), 0);
    assert_eq!(d.sample(estop), estop, "accepted on the third equal sample");
    assert!(!d.settling());
}

#[test]
fn polarity_maps_electrical_levels() {
    let defaults = InputConfig::default();
    // At rest: switches with pull-ups read high (not pressed), the e-stop chain is closed (low), supplies down.
    let at_rest = defaults.active_low;
    let d = Debouncer::new(defaults, at_rest);
    assert_eq!(Inputs::from_word(d.stable()), Inputs::default());
    // A pressed home switch of axis 2 pulls its pin low.
    let mut d = Debouncer::new(
        InputConfig {
            debounce_samples: 1,
            ..defaults
        },
        at_rest,
    );
    let pressed = at_rest & !InputBit::Home(2).mask();
    assert_eq!(Inputs::from_word(d.sample(pressed)).home, 1 << 2);
    // The e-stop chain opening pulls its pin high.
    let open = pressed | InputBit::EStop.mask();
    assert!(Inputs::from_word(d.sample(open)).estop_open);
    assert_eq!(InputBit::Home(6).mask(), 0, "no seventh axis");
}

#[test]
fn every_section_has_a_unique_name_and_answers_with_its_kind() {
    let mut names: Vec<&str> = SettingsKind::ALL.iter().map(|k| k.name()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), SettingsKind::ALL.len());
    let defaults = ControllerConfig::trainer_model();
    for kind in SettingsKind::ALL {
        assert_eq!(defaults.settings(kind).kind(), kind);
        let mut again = defaults;
        again.apply(&defaults.settings(kind)).unwrap();
        assert_eq!(again, defaults, "{kind:?} read and written back changes nothing");
    }
}

/// The trainer model's homing, given in each axis's own units, is the step counts of FIRMWARE.md.
#[test]
fn the_trainer_models_homing_in_units_is_its_step_counts() {
    let h = ControllerConfig::trainer_model().homing().unwrap();
    // (toward, search, back-off, fast rate, slow rate, position at the switch) in steps.
    let carriage = (1, 1_422, 142, 4_000, 500, 0);
    let linear = (-1, 64_000, 3_200, 32_000, 4_000, -106_096);
    for (a, expected) in [carriage, carriage, carriage, carriage, linear, linear]
        .into_iter()
        .enumerate()
    {
        let c = h.axes[a];
        let got = (
            c.toward,
            c.search_steps,
            c.backoff_steps,
            c.fast_rate,
            c.slow_rate,
            c.home_position,
        );
        assert_eq!(got, expected, "axis {a}");
    }
    assert_eq!(h.order, [4, 5, 0, 2, 1, 3]);
}

fn set(c: &mut Controller, settings: Settings) -> DeviceMessage {
    c.handle(&Request {
        id: 7,
        body: HostMessage::SetSettings(settings),
    })
    .body
}

fn get(c: &mut Controller, kind: SettingsKind) -> DeviceMessage {
    c.handle(&Request {
        id: 8,
        body: HostMessage::GetSettings(kind),
    })
    .body
}

fn stream(c: &Controller) -> StreamSettings {
    match c.saved_config().settings(SettingsKind::Stream) {
        Settings::Stream(s) => s,
        other => panic!("{other:?}"),
    }
}

fn motion(c: &Controller) -> MotionSettings {
    match c.saved_config().settings(SettingsKind::Motion) {
        Settings::Motion(s) => s,
        other => panic!("{other:?}"),
    }
}

fn axes(c: &Controller) -> [AxisSettings; 6] {
    match c.saved_config().settings(SettingsKind::Axes) {
        Settings::Axes(s) => s,
        other => panic!("{other:?}"),
    }
}

#[test]
fn live_sections_apply_at_once_and_next_start_sections_are_stored() {
    let mut c = device::connected();
    let mut m = motion(&c);
    m.pose_velocity[2] = 0.02;
    // A faster lead screw's motor: 0.12 m/s is 192 k steps/s at 1.6 M steps/m, inside the step generator's 200 k.
    m.actuator_velocity[5] = 0.12;
    m.actuator_acceleration[0] = 50.0;
    assert_eq!(set(&mut c, Settings::Motion(m)), DeviceMessage::Ack);
    let limits = c.pipeline().config().limits;
    assert_eq!(limits.pose_velocity[2], 0.02);
    assert_eq!(
        (limits.actuator_velocity[5], limits.actuator_acceleration[0]),
        (0.12, 50.0)
    );
    assert_eq!(
        get(&mut c, SettingsKind::Motion),
        DeviceMessage::Settings {
            settings: Settings::Motion(m),
            pending: false
        }
    );

    let fast = Settings::Control(ControlSettings { tick_hz: 2_000 });
    assert_eq!(set(&mut c, fast), DeviceMessage::Ack);
    assert_eq!(
        c.pipeline().config().tick_us,
        1_000,
        "the running rate stays until the next start"
    );
    assert_eq!(c.saved_config().pipeline.tick_us, 500);
    assert_eq!(c.saved_config().scheduler.period_ns, 500_000);
    assert_eq!(
        get(&mut c, SettingsKind::Control),
        DeviceMessage::Settings {
            settings: fast,
            pending: true
        }
    );

    let inputs = InputConfig {
        active_low: 1,
        ..c.config().inputs
    };
    assert_eq!(set(&mut c, Settings::Inputs(inputs)), DeviceMessage::Ack);
    assert_eq!(c.config().inputs.active_low, 1);
}

#[test]
fn bad_sections_are_refused_and_nothing_is_stored() {
    let mut c = device::connected();
    let s = stream(&c);
    let m = motion(&c);
    let a = axes(&c);
    let inputs = c.config().inputs;
    let homing = c.config().switches;
    let supervisor = c.config().supervisor;
    // Each bad value with the field the refusal must name.
    let mut bad: Vec<(Settings, String)> = vec![
        (
            Settings::Control(ControlSettings { tick_hz: 1_500 }),
            "control.tick_hz".into(),
        ),
        (
            Settings::Control(ControlSettings { tick_hz: 4_000 }),
            "control.tick_hz".into(),
        ),
        (
            Settings::Stream(StreamSettings { timeout_ms: 0, ..s }),
            "stream.timeout_ms".into(),
        ),
        (
            Settings::Stream(StreamSettings {
                timeout_ms: 10_001,
                ..s
            }),
            "stream.timeout_ms".into(),
        ),
        (
            Settings::Stream(StreamSettings { gross_jump_ms: 5, ..s }),
            "stream.gross_jump_ms".into(),
        ),
        (
            Settings::Stream(StreamSettings {
                telemetry_hz: 2_001,
                ..s
            }),
            "stream.telemetry_hz".into(),
        ),
        (
            Settings::Inputs(InputConfig {
                debounce_samples: 0,
                ..inputs
            }),
            "inputs.debounce_ms".into(),
        ),
        (
            Settings::Inputs(InputConfig {
                debounce_samples: 51,
                ..inputs
            }),
            "inputs.debounce_ms".into(),
        ),
        (
            Settings::Supervisor(SupervisorConfig {
                discharge_ms: 600_000,
                ..supervisor
            }),
            "supervisor.discharge_ms".into(),
        ),
    ];
    for (i, v) in [0.2, -0.001, f32::NAN].into_iter().enumerate() {
        let mut margins = s.margins;
        margins[i] = v;
        bad.push((
            Settings::Stream(StreamSettings { margins, ..s }),
            format!("stream.margins[{i}]"),
        ));
    }
    for v in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let mut velocity = m;
        velocity.pose_velocity[0] = v;
        let mut acceleration = m;
        acceleration.pose_acceleration[5] = v;
        bad.push((Settings::Motion(velocity), "motion.pose_velocity[0]".into()));
        bad.push((Settings::Motion(acceleration), "motion.pose_acceleration[5]".into()));
        let mut velocity = m;
        velocity.actuator_velocity[2] = v;
        let mut acceleration = m;
        acceleration.actuator_acceleration[4] = v;
        bad.push((Settings::Motion(velocity), "motion.actuator_velocity[2]".into()));
        bad.push((Settings::Motion(acceleration), "motion.actuator_acceleration[4]".into()));
    }
    // A linear actuator at 0.13 m/s on the model's 1.6 M steps/m asks 208 k steps/s, beyond the step generator's
    // 200 k (one step per 5 us); 0.12 m/s (192 k) is taken.
    let mut fast = m;
    fast.actuator_velocity[5] = 0.13;
    bad.push((Settings::Motion(fast), "motion.actuator_velocity[5]".into()));
    for (axis, v) in [(0, 25_600.5), (4, -1.0), (4, 0.5), (1, 2e7), (2, f32::NAN)] {
        let mut x = a;
        x[axis].steps_per_unit = v;
        bad.push((Settings::Axes(x), format!("axes[{axis}].steps_per_unit")));
    }
    for order in [[0, 0, 1, 2, 3, 4], [0, 1, 2, 3, 4, 6]] {
        bad.push((
            Settings::Homing(HomingSettings { order, ..homing }),
            "homing.order".into(),
        ));
    }
    for v in [0.0, -0.1, f32::NAN] {
        let mut h = homing;
        h.axes[3].search = v;
        bad.push((Settings::Homing(h), "homing.axes[3].search".into()));
        let mut h = homing;
        h.axes[4].slow = v;
        bad.push((Settings::Homing(h), "homing.axes[4].slow".into()));
    }
    let mut h = homing;
    h.axes[0].switch = f32::INFINITY;
    bad.push((Settings::Homing(h), "homing.axes[0].switch".into()));
    let before = *c.saved_config();
    for (settings, field) in bad {
        match set(&mut c, settings) {
            DeviceMessage::Nack(NackReason::BadConfig(refusal @ ConfigRefusal::OutOfRange(named))) => {
                assert_eq!(named.to_string(), field, "{settings:?}");
                assert!(
                    refusal.to_string().starts_with(&format!("{field}: must be ")),
                    "{refusal}"
                );
            }
            other => panic!("{settings:?}: {other:?}"),
        }
    }
    assert_eq!(*c.saved_config(), before);
    assert!(!c.has_unsaved());
    assert_eq!(c.take_unsaved(), None);
}

#[test]
fn a_homing_section_that_breaks_the_spacing_proof_is_refused_with_its_cause() {
    // Carriages that back off 40 degrees before their slow approach would meet their neighbours.
    let mut c = device::connected();
    let mut h = c.config().switches;
    for a in 0..4 {
        h.axes[a].backoff = 40f32.to_radians();
        h.axes[a].search = 60f32.to_radians();
    }
    assert_eq!(
        set(&mut c, Settings::Homing(h)),
        DeviceMessage::Nack(NackReason::BadConfig(ConfigRefusal::Homing))
    );
    assert_eq!(*c.saved_config(), ControllerConfig::trainer_model());
}

#[test]
fn a_coarser_motor_that_breaks_the_homing_proof_is_refused() {
    // 400 steps per carriage turn: the homing search of 20 degrees becomes 22 steps, and the back-off 2; the plan
    // must still validate or be refused as a whole, never half-applied.
    let mut c = device::connected();
    let mut a = axes(&c);
    a[0].steps_per_unit = 400.0;
    let reply = set(&mut c, Settings::Axes(a));
    let config = *c.saved_config();
    match reply {
        DeviceMessage::Ack => assert_eq!(config.scales[0].steps_per_turn, 400),
        DeviceMessage::Nack(NackReason::BadConfig(why)) => {
            assert_eq!(why, ConfigRefusal::Homing, "the cause is named");
            assert_eq!(config, ControllerConfig::trainer_model());
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn steps_per_unit_keeps_homing_distances_physical() {
    let mut config = ControllerConfig::trainer_model();
    let before = config.homing().unwrap().axes[4];
    let Settings::Axes(mut a) = config.settings(SettingsKind::Axes) else {
        panic!()
    };
    a[4].steps_per_unit = 3.2e6;
    config.apply(&Settings::Axes(a)).unwrap();
    let after = config.homing().unwrap().axes[4];
    assert_eq!(after.search_steps, before.search_steps * 2);
    assert_eq!(after.home_position, before.home_position * 2);
    assert_eq!(after.fast_rate, before.fast_rate * 2);
    assert_eq!(config.settings(SettingsKind::Axes), Settings::Axes(a));
    assert_eq!(config.scales[0].steps_per_turn, 25_600);
    config.validate().unwrap();
}

#[test]
fn unsaved_changes_are_handed_out_once_with_their_last_value_and_restore_at_boot() {
    let mut c = device::connected();
    let s = stream(&c);
    let later = StreamSettings { timeout_ms: 300, ..s };
    assert_eq!(
        set(&mut c, Settings::Stream(StreamSettings { timeout_ms: 250, ..s })),
        DeviceMessage::Ack
    );
    assert_eq!(set(&mut c, Settings::Stream(later)), DeviceMessage::Ack);
    let slow = Settings::Control(ControlSettings { tick_hz: 500 });
    assert_eq!(set(&mut c, slow), DeviceMessage::Ack);
    let mut a = axes(&c);
    a[5].steps_per_unit = 3.2e6;
    assert_eq!(set(&mut c, Settings::Axes(a)), DeviceMessage::Ack);
    let inputs = InputConfig {
        debounce_samples: 5,
        ..c.config().inputs
    };
    assert_eq!(set(&mut c, Settings::Inputs(inputs)), DeviceMessage::Ack);
    // Everything changed is in the one configuration handed out, once, with its last values.
    let stored = c.take_unsaved().expect("the changed configuration");
    assert_eq!(c.take_unsaved(), None);
    assert!(!c.has_unsaved());
    assert_eq!(stored.stream(), later);
    assert_eq!(stored.settings(SettingsKind::Control), slow);
    let rig = stored.rig();
    assert_eq!(rig.machine.axes, a);
    assert_eq!(rig.machine.inputs, inputs);
    // Boot: the stored rig, then the stored sections through the same checks.
    let mut boot = ControllerConfig::from_record(&rig).unwrap();
    boot.apply(&Settings::Stream(stored.stream())).unwrap();
    boot.apply(&Settings::Control(stored.control())).unwrap();
    assert_eq!(boot, *c.saved_config());
    let restarted = Controller::new(boot).unwrap();
    assert_eq!(restarted.pipeline().config().tick_us, 2_000);
}

#[test]
fn settings_are_handed_out_for_storing_only_with_the_supplies_off() {
    use ringpod_core::safety::State;
    use ringpod_core::sim::{Plant, Rig};
    let mut rig = Rig {
        controller: device::connected(),
        plant: Plant::trainer_model([0; 6]),
        ticks: 0,
    };
    assert_eq!(
        rig.controller
            .handle(&Request {
                id: 2,
                body: HostMessage::Command(Command::Enable)
            })
            .body,
        DeviceMessage::Ack
    );
    for _ in 0..5_000 {
        if matches!(rig.controller.supervisor().state(), State::PowerOn { settled: true }) {
            break;
        }
        rig.tick();
    }
    assert!(rig.controller.supervisor().outputs().power_relay);
    // Nothing moves in PowerOn, so the section is taken, but it is not handed out for flash while power is on.
    let s = StreamSettings {
        gross_jump_ms: 700,
        ..stream(&rig.controller)
    };
    assert_eq!(set(&mut rig.controller, Settings::Stream(s)), DeviceMessage::Ack);
    let inputs = InputConfig {
        debounce_samples: 7,
        ..rig.controller.config().inputs
    };
    assert_eq!(set(&mut rig.controller, Settings::Inputs(inputs)), DeviceMessage::Ack);
    assert!(rig.controller.has_unsaved());
    assert_eq!(rig.controller.take_unsaved(), None);
    assert_eq!(
        rig.controller
            .handle(&Request {
                id: 3,
                body: HostMessage::Command(Command::Disable)
            })
            .body,
        DeviceMessage::Ack
    );
    for _ in 0..5_000 {
        if rig.controller.supervisor().state() == State::Off {
            break;
        }
        rig.tick();
    }
    assert_eq!(rig.controller.supervisor().state(), State::Off);
    let stored = rig.controller.take_unsaved().expect("handed out with the supplies off");
    assert_eq!((stored.stream(), stored.inputs), (s, inputs));
    assert_eq!(rig.controller.take_unsaved(), None);
}

/// `GetInputs`: the debounced state with the polarity, and the pins' levels as the board sampled them (derived
/// from the state and the polarity where nothing samples pins).
#[test]
fn get_inputs_reports_levels_and_states() {
    let mut c = device::connected();
    let ask = |c: &mut Controller| match c
        .handle(&Request {
            id: 5,
            body: HostMessage::GetInputs,
        })
        .body
    {
        DeviceMessage::Inputs(r) => r,
        other => panic!("{other:?}"),
    };
    c.set_inputs(Inputs {
        home: 0b100,
        logic_ok: true,
        ..Inputs::default()
    });
    let r = ask(&mut c);
    let home3 = InputBit::Home(2).mask();
    assert_eq!(r.active, home3 | InputBit::LogicOk.mask());
    assert!(!r.sampled);
    assert_eq!(r.raw, r.active ^ r.active_low, "derived through the polarity");
    c.set_raw_inputs(0x1234);
    let r = ask(&mut c);
    assert!(r.sampled);
    assert_eq!(r.raw, 0x1234);
    assert_eq!(r.debounce_ms, ControllerConfig::trainer_model().inputs.debounce_samples);
    // Before the handshake: refused like every other request.
    let mut fresh = Controller::new(ControllerConfig::trainer_model()).unwrap();
    let r = fresh.handle(&Request {
        id: 6,
        body: HostMessage::GetInputs,
    });
    assert_eq!(r.body, DeviceMessage::Nack(NackReason::NotConnected));
}

/// The controller drives any ring rig: restating the trainer model through `for_rig` gives exactly the model's
/// configuration (scales, homing distances and order, the linear switch 1 mm below the stroke), and another rig
/// gets its own home and geometry, with the preset named in Hello only when it is one.
#[test]
fn a_rig_restating_the_trainer_model_configures_the_controller_exactly() {
    use ringpod_core::kinematics::presets::{self, Preset};
    let model = ControllerConfig::trainer_model();
    let mut restated = ControllerConfig::for_rig(&presets::TRAINER_MODEL, Preset::TrainerModel.home()).unwrap();
    // The model's switch offset was written from the home length rounded to 0.01 mm (231.31 - 165 mm); computed,
    // it is 5 um (8 steps) less. Everything else is equal.
    for a in [4, 5] {
        let (got, written) = (
            restated.homing().unwrap().axes[a].home_position,
            model.homing().unwrap().axes[a].home_position,
        );
        assert!((got - written).abs() <= 10, "axis {a}: {got} vs {written}");
        restated.switches.axes[a].switch = model.switches.axes[a].switch;
    }
    assert_eq!(restated, model);
    let mut home = Preset::TrainerModel.home();
    home[2] += 0.005;
    let other = ControllerConfig::for_rig(&presets::TRAINER_MODEL, home).unwrap();
    assert_eq!(other.home, home);
    // The switch stays 1 mm below the stroke: a 5 mm higher home lengthens the actuators, so the switch is further
    // below the new home length.
    assert!(other.homing().unwrap().axes[4].home_position < restated.homing().unwrap().axes[4].home_position - 4_000);
    let mut c = Controller::new(other).unwrap();
    let hello = c.handle(&Request {
        id: 1,
        body: HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
    });
    match hello.body {
        DeviceMessage::Hello { preset, axes, .. } => {
            assert_eq!(preset, Some(Preset::TrainerModel), "same geometry: the preset is named");
            assert_eq!(axes, model_axes());
        }
        other => panic!("{other:?}"),
    }
    // A home pose without a solution is refused with its cause.
    assert!(matches!(
        ControllerConfig::for_rig(&presets::TRAINER_MODEL, [0.0, 0.0, 2.0, 0.0, 0.0, 0.0]),
        Err(ringpod_core::controller::ConfigError::HomePose(_))
    ));
}

fn model_axes() -> [ringpod_core::kinematics::AxisKind; 6] {
    use ringpod_core::kinematics::AxisKind::{Linear, Ring};
    [Ring, Ring, Ring, Ring, Linear, Linear]
}

/// Runs `rig` until it is Ready or faulted (at most 60 s of ticks) after a Home.
fn home(rig: &mut ringpod_core::sim::Rig) -> ringpod_core::safety::State {
    use ringpod_core::safety::State;
    for body in [
        HostMessage::Command(Command::Enable),
        HostMessage::Command(Command::Home),
    ] {
        for _ in 0..5_000 {
            if matches!(
                rig.controller.supervisor().state(),
                State::PowerOn { settled: true } | State::Ready
            ) {
                break;
            }
            rig.tick();
        }
        assert_eq!(rig.controller.handle(&Request { id: 9, body }).body, DeviceMessage::Ack);
    }
    for _ in 0..60_000 {
        match rig.controller.supervisor().state() {
            s @ (State::Ready | State::Fault(..)) => return s,
            _ => {
                rig.tick();
            }
        }
    }
    rig.controller.supervisor().state()
}

/// A motor wired the other way round: homing drives its axis away from the switch and fails; the axes section's `reverse` (taken at
/// the next start) mirrors its steps, homing direction and switch position, and the machine homes to the same
/// physical place as one wired right.
#[test]
fn an_axis_reversed_corrects_a_motor_wired_the_other_way_round() {
    use ringpod_core::safety::{FaultReason, State};
    use ringpod_core::sim::{Plant, Rig, TRAINER_MODEL_PARKED};
    let rig_with = |config: ControllerConfig, reversed: u8| {
        let mut plant = Plant::trainer_model(TRAINER_MODEL_PARKED);
        plant.reversed = reversed;
        let mut controller = Controller::new(config).unwrap();
        let hello = controller.handle(&Request {
            id: 1,
            body: HostMessage::Hello {
                version: PROTOCOL_VERSION,
            },
        });
        assert!(matches!(hello.body, DeviceMessage::Hello { .. }));
        Rig {
            controller,
            plant,
            ticks: 0,
        }
    };
    let model = ControllerConfig::trainer_model();
    let mut right = rig_with(model, 0);
    assert_eq!(home(&mut right), State::Ready);

    // Carriage 2 and linear actuator 5 wired the other way round.
    let reversed = 0b01_0010;
    let mut wrong = rig_with(model, reversed);
    assert!(matches!(home(&mut wrong), State::Fault(FaultReason::HomingFailed, _)));

    let mut config = model;
    let Settings::Axes(mut a) = config.settings(SettingsKind::Axes) else {
        panic!()
    };
    a[1].reverse = true;
    a[4].reverse = true;
    config.apply(&Settings::Axes(a)).unwrap();
    assert!(!SettingsKind::Axes.is_live());
    let mut fixed = rig_with(config, reversed);
    assert_eq!(home(&mut fixed), State::Ready);
    // The same physical place: every axis where the correctly wired machine's is; the reversed axes count their
    // motor steps the other way.
    assert_eq!(fixed.plant.position, right.plant.position);
    let (r, f) = (right.controller.steps(), fixed.controller.steps());
    for a in 0..6 {
        let sign = if reversed & (1 << a) != 0 { -1 } else { 1 };
        assert_eq!(f[a], sign * r[a], "axis {a}");
    }
}

/// A value for an `f32` field: near the defaults (mostly), anything at all, or not a number.
fn real() -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => 0.0f32..0.5,
        2 => -1.0e9f32..1.0e9,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => any::<f32>(),
    ]
}

/// A section of any kind with values in and out of every range.
fn any_settings() -> impl Strategy<Value = Settings> {
    use ringpod_core::motion::FollowMode;
    use ringpod_core::protocol::{SwitchSettings, Toward};
    let stream = (
        0u16..12_000,
        0u16..12_000,
        any::<bool>(),
        prop::array::uniform6(real()),
        0u16..3_000,
        0u16..=u16::MAX,
    )
        .prop_map(
            |(timeout_ms, gross_jump_ms, direct, margins, telemetry_hz, host_gone_ms)| {
                Settings::Stream(StreamSettings {
                    timeout_ms,
                    gross_jump_ms,
                    follow: if direct {
                        FollowMode::Direct
                    } else {
                        FollowMode::Interpolate
                    },
                    margins: margins.map(|m| m * 0.25),
                    telemetry_hz,
                    host_gone_ms,
                })
            },
        );
    let control = prop::sample::select(vec![0u16, 500, 999, 1_000, 1_500, 2_000, 4_000])
        .prop_map(|tick_hz| Settings::Control(ControlSettings { tick_hz }));
    // Actuator velocities up to 4 rad/s or m/s: a carriage takes any of them, a linear actuator only up to the
    // step generator's 0.125 m/s.
    let motion = (
        prop::array::uniform6(real()),
        prop::array::uniform6(real()),
        prop::array::uniform6(real()),
        prop::array::uniform6(real()),
    )
        .prop_map(|(v, a, av, aa)| {
            Settings::Motion(MotionSettings {
                pose_velocity: v,
                pose_acceleration: a.map(|x| x * 40.0),
                actuator_velocity: av.map(|x| x * 8.0),
                actuator_acceleration: aa.map(|x| x * 200.0),
            })
        });
    let inputs = (any::<u16>(), 0u8..60).prop_map(|(active_low, debounce_samples)| {
        Settings::Inputs(InputConfig {
            active_low,
            debounce_samples,
        })
    });
    let axes = prop::array::uniform6((
        prop::sample::select(vec![
            0.0f32,
            400.0,
            12_800.0,
            25_600.0,
            25_600.5,
            1.6e6,
            3.2e6,
            2e7,
            f32::NAN,
        ]),
        any::<bool>(),
    ))
    .prop_map(|a| {
        Settings::Axes(a.map(|(steps_per_unit, reverse)| AxisSettings {
            steps_per_unit,
            reverse,
        }))
    });
    let switch = (any::<bool>(), real(), real(), real(), real(), real()).prop_map(
        |(plus, switch, search, backoff, fast, slow)| SwitchSettings {
            toward: if plus { Toward::Plus } else { Toward::Minus },
            switch: switch * 0.2,
            search,
            backoff: backoff * 0.1,
            fast,
            slow: slow * 0.1,
        },
    );
    let homing = (prop::array::uniform6(0u8..7), prop::array::uniform6(switch))
        .prop_map(|(order, axes)| Settings::Homing(HomingSettings { order, axes }));
    let supervisor = (any::<bool>(), any::<bool>(), prop::array::uniform5(0u32..80_000)).prop_map(|(l, p, ms)| {
        Settings::Supervisor(SupervisorConfig {
            logic_sense: l,
            power_sense: p,
            logic_settle_ms: ms[0],
            power_settle_ms: ms[1],
            supply_timeout_ms: ms[2],
            driver_off_ms: ms[3],
            discharge_ms: ms[4],
        })
    });
    prop_oneof![stream, control, motion, inputs, axes, homing, supervisor]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3_000))]

    /// Any section, sensible or not: the controller never panics; what it takes it reports back exactly as sent,
    /// still runs (its stored configuration builds a controller) and hands out for storing; what it refuses
    /// changes nothing.
    #[test]
    fn any_section_is_taken_exactly_or_refused_with_nothing_changed(settings in any_settings()) {
        let mut c = device::connected();
        let before = *c.saved_config();
        let kind = settings.kind();
        match set(&mut c, settings) {
            DeviceMessage::Ack => {
                match get(&mut c, kind) {
                    DeviceMessage::Settings { settings: back, .. } => prop_assert_eq!(back, settings),
                    other => prop_assert!(false, "{:?}", other),
                }
                prop_assert!(c.saved_config().validate().is_ok());
                prop_assert!(c.has_unsaved());
            }
            DeviceMessage::Nack(NackReason::BadConfig(_)) => {
                prop_assert_eq!(*c.saved_config(), before);
                prop_assert!(!c.has_unsaved());
            }
            other => prop_assert!(false, "{:?}", other),
        }
    }
}

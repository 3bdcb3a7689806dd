//! Input debouncing and the device settings: keys and their flash codes, live and next-start settings, the set of
//! unsaved changes the firmware stores, and the restore at boot that replays them.

#[path = "common/device.rs"]
mod device;

use proptest::prelude::*;
use ringpod_core::controller::{Controller, ControllerConfig, Inputs};
use ringpod_core::protocol::{
    ConfigKey, ConfigRefusal, DeviceMessage, HostMessage, NackReason, Request, PROTOCOL_VERSION,
};
use ringpod_core::safety::debounce::{from_inputs, to_inputs, Debouncer, InputBit, InputConfig};

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
        prop_assert_eq!(to_inputs(from_inputs(&inputs)), inputs);
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
    assert_eq!(to_inputs(d.stable()), Inputs::default());
    // A pressed home switch of axis 2 pulls its pin low.
    let mut d = Debouncer::new(
        InputConfig {
            debounce_samples: 1,
            ..defaults
        },
        at_rest,
    );
    let pressed = at_rest & !InputBit::Home(2).mask();
    assert_eq!(to_inputs(d.sample(pressed)).home, 1 << 2);
    // The e-stop chain opening pulls its pin high.
    let open = pressed | InputBit::EStop.mask();
    assert!(to_inputs(d.sample(open)).estop_open);
    assert_eq!(InputBit::Home(6).mask(), 0, "no seventh axis");
}

#[test]
fn every_key_has_a_unique_code_that_round_trips() {
    let keys: Vec<ConfigKey> = ConfigKey::all().collect();
    // stream timeout, gross jump, follow mode, tick rate, polarity, debounce, telemetry rate; per axis four (pose
    // velocity and acceleration, steps per unit, reverse); per check one.
    assert_eq!(keys.len(), 7 + 4 * 6 + 6);
    let mut codes: Vec<u8> = keys.iter().map(|k| k.code()).collect();
    codes.sort_unstable();
    codes.dedup();
    assert_eq!(codes.len(), keys.len());
    for k in &keys {
        assert_eq!(ConfigKey::from_code(k.code()), Some(*k));
        assert!(k.code() < 64, "the unsaved set is a 64-bit mask");
    }
    let defaults = ControllerConfig::trainer_model();
    for k in &keys {
        assert!(defaults.get(*k).is_some(), "{k:?} has a value");
    }
}

fn set(c: &mut Controller, key: ConfigKey, value: f32) -> DeviceMessage {
    c.handle(&Request {
        id: 7,
        body: HostMessage::SetConfig(key, value),
    })
    .body
}

fn get(c: &mut Controller, key: ConfigKey) -> DeviceMessage {
    c.handle(&Request {
        id: 8,
        body: HostMessage::GetConfig(key),
    })
    .body
}

#[test]
fn live_settings_apply_at_once_and_next_start_settings_are_stored() {
    let mut c = device::connected();
    assert_eq!(set(&mut c, ConfigKey::PoseVelocity(2), 0.02), DeviceMessage::Ack);
    assert_eq!(c.pipeline().config().limits.pose_velocity[2], 0.02);
    assert_eq!(
        get(&mut c, ConfigKey::PoseVelocity(2)),
        DeviceMessage::Config(ConfigKey::PoseVelocity(2), 0.02)
    );

    assert_eq!(set(&mut c, ConfigKey::TickHz, 2_000.0), DeviceMessage::Ack);
    assert_eq!(
        c.pipeline().config().tick_us,
        1_000,
        "the running rate stays until the next start"
    );
    assert_eq!(c.saved_config().pipeline.tick_us, 500);
    assert_eq!(c.saved_config().scheduler.period_ns, 500_000);
    assert_eq!(
        get(&mut c, ConfigKey::TickHz),
        DeviceMessage::Config(ConfigKey::TickHz, 2_000.0)
    );

    assert_eq!(
        set(&mut c, ConfigKey::InputActiveLow, 0x0001 as f32),
        DeviceMessage::Ack
    );
    assert_eq!(c.config().inputs.active_low, 1);
}

#[test]
fn bad_values_are_refused_and_nothing_is_stored() {
    let mut c = device::connected();
    let bad = [
        (ConfigKey::TickHz, 1_500.0),
        (ConfigKey::TickHz, 4_000.0),
        (ConfigKey::PoseVelocity(6), 1.0),
        (ConfigKey::PoseVelocity(0), 0.0),
        (ConfigKey::PoseAcceleration(1), f32::NAN),
        (ConfigKey::StreamTimeoutMs, f32::INFINITY),
        (ConfigKey::StreamTimeoutMs, 0.5),
        (ConfigKey::StepsPerUnit(0), 25_600.5),
        (ConfigKey::StepsPerUnit(4), -1.0),
        (ConfigKey::StepsPerUnit(7), 1_000.0),
        (ConfigKey::InputActiveLow, 70_000.0),
        (ConfigKey::DebounceMs, 0.0),
        (ConfigKey::DebounceMs, 51.0),
        (ConfigKey::GrossJumpMs, 5.0),
        (ConfigKey::FollowDirect, 0.5),
        (ConfigKey::EnvelopeMargin(0), 0.2),
        (ConfigKey::EnvelopeMargin(6), 0.001),
    ];
    let before = *c.saved_config();
    for (key, value) in bad {
        assert_eq!(
            set(&mut c, key, value),
            DeviceMessage::Nack(NackReason::BadConfig(ConfigRefusal::OutOfRange)),
            "{key:?} = {value}"
        );
    }
    assert_eq!(*c.saved_config(), before);
    assert!(!c.has_unsaved());
    assert_eq!(c.take_unsaved(), None);
}

#[test]
fn a_coarser_motor_that_breaks_the_homing_proof_is_refused() {
    // 400 steps per carriage turn: the homing search of 20 degrees becomes 22 steps, and the scaled back-off
    // rounds to 2; the plan must still validate or be refused as a whole, never half-applied.
    let mut c = device::connected();
    let reply = set(&mut c, ConfigKey::StepsPerUnit(0), 400.0);
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
    let before = config.homing.axes[4];
    config.set(ConfigKey::StepsPerUnit(4), 3.2e6).unwrap();
    let after = config.homing.axes[4];
    assert_eq!(after.search_steps, before.search_steps * 2);
    assert_eq!(after.home_position, before.home_position * 2);
    assert_eq!(after.fast_rate, before.fast_rate * 2);
    assert_eq!(config.get(ConfigKey::StepsPerUnit(4)), Some(3.2e6));
    assert_eq!(config.get(ConfigKey::StepsPerUnit(0)), Some(25_600.0));
    config.validate().unwrap();
}

#[test]
fn unsaved_changes_are_handed_out_once_with_their_last_value_and_restore_at_boot() {
    let mut c = device::connected();
    assert_eq!(set(&mut c, ConfigKey::StreamTimeoutMs, 250.0), DeviceMessage::Ack);
    assert_eq!(set(&mut c, ConfigKey::StreamTimeoutMs, 300.0), DeviceMessage::Ack);
    assert_eq!(set(&mut c, ConfigKey::TickHz, 500.0), DeviceMessage::Ack);
    assert_eq!(set(&mut c, ConfigKey::StepsPerUnit(5), 3.2e6), DeviceMessage::Ack);
    assert_eq!(set(&mut c, ConfigKey::DebounceMs, 5.0), DeviceMessage::Ack);
    let mut stored = Vec::new();
    while let Some(kv) = c.take_unsaved() {
        stored.push(kv);
    }
    assert_eq!(
        stored,
        vec![
            (ConfigKey::StreamTimeoutMs, 300.0),
            (ConfigKey::TickHz, 500.0),
            (ConfigKey::DebounceMs, 5.0),
            (ConfigKey::StepsPerUnit(5), 3.2e6),
        ]
    );
    assert!(!c.has_unsaved());
    // Boot: the defaults, then every stored pair replayed through the same checks.
    let mut boot = ControllerConfig::trainer_model();
    for (k, v) in &stored {
        boot.set(*k, *v).unwrap();
    }
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
                body: HostMessage::Enable
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
    // Nothing moves in PowerOn, so the setting is taken, but it is not handed out for flash while power is on.
    assert_eq!(set(&mut rig.controller, ConfigKey::DebounceMs, 7.0), DeviceMessage::Ack);
    assert!(rig.controller.has_unsaved());
    assert_eq!(rig.controller.take_unsaved(), None);
    assert_eq!(
        rig.controller
            .handle(&Request {
                id: 3,
                body: HostMessage::Disable
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
    assert_eq!(rig.controller.take_unsaved(), Some((ConfigKey::DebounceMs, 7.0)));
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
            restated.homing.axes[a].home_position,
            model.homing.axes[a].home_position,
        );
        assert!((got - written).abs() <= 10, "axis {a}: {got} vs {written}");
        restated.homing.axes[a].home_position = written;
    }
    assert_eq!(restated, model);
    let mut home = Preset::TrainerModel.home();
    home[2] += 0.005;
    let other = ControllerConfig::for_rig(&presets::TRAINER_MODEL, home).unwrap();
    assert_eq!(other.home, home);
    // The switch stays 1 mm below the stroke: a 5 mm higher home lengthens the actuators, so the switch is further
    // below the new home length.
    assert!(other.homing.axes[4].home_position < restated.homing.axes[4].home_position - 4_000);
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
    for body in [HostMessage::Enable, HostMessage::Home] {
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

/// A motor wired the other way round: homing drives its axis away from the switch and fails; `reverse.N` (taken at
/// the next start) mirrors its steps, homing direction and switch position, and the machine homes to the same
/// physical place as one wired right.
#[test]
fn reverse_corrects_a_motor_wired_the_other_way_round() {
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
    for a in [1u8, 4] {
        config.set(ConfigKey::Reverse(a), 1.0).unwrap();
        assert_eq!(config.get(ConfigKey::Reverse(a)), Some(1.0));
    }
    assert!(!ConfigKey::Reverse(1).is_live());
    assert_eq!(
        config.set(ConfigKey::Reverse(1), 0.5),
        Err(ringpod_core::controller::ConfigError::Value)
    );
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

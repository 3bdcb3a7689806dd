//! The rule for a host gone long, through the controller and the simulated machine: a stream whose host falls
//! silent brakes to rest and holds, homed and powered, for `host_gone_ms`; a request from a host within that time
//! keeps it there, and a silence that long powers it down as STOP does (drivers off, then the motor supply after
//! `driver_off_ms`, then the logic supply after `discharge_ms`), with nothing moving after the brake.

use proptest::prelude::*;
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{DeviceMessage, HostMessage, Request, Settings, SettingsKind};
use ringpod_core::safety::{Outputs, State, HOST_GONE_MS};
use ringpod_core::selfcheck::{running_rig, Digest};
use ringpod_core::sim::Rig;

fn ask(rig: &mut Rig, body: HostMessage) -> DeviceMessage {
    rig.controller.handle(&Request { id: 9, body }).body
}

/// Setpoints at the pose the controller holds, every 10 ms, for `ms`.
fn stream(rig: &mut Rig, seq: &mut u32, ms: u32) {
    for t in 0..ms {
        if t % 10 == 0 {
            *seq += 1;
            let pose = rig.controller.pipeline().pose();
            let sp = Setpoint {
                seq: *seq,
                time_us: u64::from(*seq) * 10_000,
                pose,
                aux: [None; 2],
                spare: [None; 2],
            };
            assert!(matches!(
                ask(rig, HostMessage::Setpoint(sp)),
                DeviceMessage::Ack | DeviceMessage::Limited(_)
            ));
        }
        rig.tick();
    }
}

/// A running rig with `host_gone_ms` set, that has streamed for half a second and then heard nothing more.
fn silent_rig(gone_ms: u16) -> Rig {
    let mut rig = running_rig(&mut Digest::default()).expect("the trainer model homes and starts");
    let mut stream_settings = match rig.controller.config().settings(SettingsKind::Stream) {
        Settings::Stream(s) => s,
        other => panic!("{other:?}"),
    };
    stream_settings.host_gone_ms = gone_ms;
    // the section is live but refused while anything may move: set it before the stream starts again
    assert_eq!(
        ask(&mut rig, HostMessage::Command(ringpod_core::safety::Command::Stop)),
        DeviceMessage::Ack
    );
    for _ in 0..2_000 {
        rig.tick();
        if rig.controller.supervisor().state() == State::Ready {
            break;
        }
    }
    assert_eq!(
        ask(&mut rig, HostMessage::SetSettings(Settings::Stream(stream_settings))),
        DeviceMessage::Ack
    );
    assert_eq!(
        ask(&mut rig, HostMessage::Command(ringpod_core::safety::Command::Start)),
        DeviceMessage::Ack
    );
    let mut seq = 0;
    stream(&mut rig, &mut seq, 500);
    assert_eq!(rig.controller.supervisor().state(), State::Running);
    rig
}

/// Ticks until `done` or `limit` ticks; each tick's (state, outputs) when they changed, with the tick they changed in.
fn run(rig: &mut Rig, limit: u32, done: impl Fn(State) -> bool) -> Vec<(u32, State, Outputs)> {
    let mut seen: Vec<(u32, State, Outputs)> = Vec::new();
    for t in 1..=limit {
        let out = rig.tick();
        let state = rig.controller.supervisor().state();
        if seen.last().map(|s| (s.1, s.2)) != Some((state, out.outputs)) {
            seen.push((t, state, out.outputs));
        }
        if done(state) {
            break;
        }
    }
    seen
}

#[test]
fn the_default_is_ten_seconds_and_the_section_says_so() {
    let rig = running_rig(&mut Digest::default()).expect("runs");
    assert_eq!(HOST_GONE_MS, 10_000);
    match rig.controller.config().settings(SettingsKind::Stream) {
        Settings::Stream(s) => assert_eq!(s.host_gone_ms, HOST_GONE_MS),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_silent_host_is_braked_for_then_powered_down_in_order() {
    let gone = 1_000;
    let mut rig = silent_rig(gone);
    let config = *rig.controller.supervisor().config();
    let seen = run(&mut rig, 5_000, |s| s == State::Off);
    let at = |pred: &dyn Fn(State) -> bool| seen.iter().find(|s| pred(s.1)).map(|s| s.0);
    let stopping = at(&|s| s == State::Stopping).expect("the stream is lost");
    let ready = at(&|s| s == State::Ready).expect("at rest");
    let drivers_off = seen
        .iter()
        .find(|s| !s.2.driver_enable)
        .map(|s| s.0)
        .expect("drivers off");
    let power_off = seen.iter().find(|s| !s.2.power_relay).map(|s| s.0).expect("power off");
    let logic_off = seen.iter().find(|s| !s.2.logic_relay).map(|s| s.0).expect("logic off");
    // the stream timeout (100 ms) after the last setpoint, which came 10 ticks before the silence
    assert_eq!(stopping, 91, "{seen:?}");
    assert!(ready - stopping <= 200, "braked in {} ms: {seen:?}", ready - stopping);
    // powered and holding until the silence since the loss reaches host_gone_ms, then the supervisor's order
    assert_eq!(drivers_off - stopping, u32::from(gone), "{seen:?}");
    assert_eq!(power_off - drivers_off, config.driver_off_ms, "{seen:?}");
    assert_eq!(logic_off - power_off, config.discharge_ms, "{seen:?}");
    assert_eq!(rig.controller.supervisor().state(), State::Off);
    assert!(
        !rig.controller.supervisor().homed(),
        "without drive current the positions are not held"
    );
}

#[test]
fn nothing_moves_after_the_brake_and_the_host_back_finds_it_off() {
    let mut rig = silent_rig(2_000);
    run(&mut rig, 400, |s| s == State::Ready);
    let rest = rig.plant.position;
    let steps = rig.controller.steps();
    run(&mut rig, 4_000, |s| s == State::Off);
    assert_eq!(rig.plant.position, rest, "the rule moves nothing");
    assert_eq!(rig.plant.steps_while_disabled, 0);
    assert_eq!(rig.controller.steps(), steps);
    let DeviceMessage::Status(status) = ask(&mut rig, HostMessage::GetStatus) else {
        panic!("a status")
    };
    assert_eq!((status.state, status.homed), (State::Off, false));
    assert_eq!(
        rig.controller.host_silent_ms(),
        None,
        "done: a later silence is no loss"
    );
}

#[test]
fn a_request_within_the_time_keeps_it_homed_and_holding() {
    let gone = 1_000u32;
    let mut rig = silent_rig(gone as u16);
    run(&mut rig, 900, |_| false);
    assert_eq!(rig.controller.supervisor().state(), State::Ready);
    // a host back: its status request starts the silence again
    assert!(matches!(
        ask(&mut rig, HostMessage::GetStatus),
        DeviceMessage::Status(_)
    ));
    let seen = run(&mut rig, gone - 1, |_| false);
    assert!(
        seen.iter()
            .all(|s| s.1 == State::Ready && s.2.driver_enable && s.2.power_relay),
        "{seen:?}"
    );
    let seen = run(&mut rig, 2, |_| false);
    assert!(matches!(seen.last(), Some((_, State::ShuttingDown(_), _))), "{seen:?}");
}

#[test]
fn a_new_stream_ends_the_watch() {
    let mut rig = silent_rig(1_000);
    run(&mut rig, 500, |s| s == State::Ready);
    assert_eq!(rig.controller.supervisor().state(), State::Ready);
    assert_eq!(
        ask(&mut rig, HostMessage::Command(ringpod_core::safety::Command::Start)),
        DeviceMessage::Ack
    );
    let mut seq = 1_000;
    stream(&mut rig, &mut seq, 3_000);
    assert_eq!(rig.controller.supervisor().state(), State::Running);
    assert_eq!(rig.controller.host_silent_ms(), None);
}

#[test]
fn a_host_that_stops_its_stream_is_not_watched() {
    // a stream ended by the host's own stop: the host is there; the device idles powered until it is told
    let mut rig = silent_rig(1_000);
    assert_eq!(
        ask(&mut rig, HostMessage::Command(ringpod_core::safety::Command::Stop)),
        DeviceMessage::Ack
    );
    let seen = run(&mut rig, 5_000, |_| false);
    assert_eq!(rig.controller.supervisor().state(), State::Ready, "{seen:?}");
    assert_eq!(rig.controller.host_silent_ms(), None);
}

#[test]
fn the_setting_is_ranged() {
    let mut rig = running_rig(&mut Digest::default()).expect("runs");
    assert_eq!(
        ask(&mut rig, HostMessage::Command(ringpod_core::safety::Command::Stop)),
        DeviceMessage::Ack
    );
    run(&mut rig, 2_000, |s| s == State::Ready);
    let Settings::Stream(s) = rig.controller.config().settings(SettingsKind::Stream) else {
        panic!("the stream section")
    };
    for (value, taken) in [(999, false), (1_000, true), (60_000, true), (60_001, false), (0, false)] {
        let answer = ask(
            &mut rig,
            HostMessage::SetSettings(Settings::Stream(ringpod_core::protocol::StreamSettings {
                host_gone_ms: value,
                ..s
            })),
        );
        assert_eq!(answer == DeviceMessage::Ack, taken, "{value}: {answer:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// Whatever the time and wherever a host's requests fall, the power-down comes `host_gone_ms` after the loss
    /// or the latest request, and never while a request came within it.
    #[test]
    fn the_power_down_comes_the_time_after_the_last_request(
        gone in 1_000u16..=3_000,
        requests in prop::collection::vec(50u32..1_000, 0..3),
    ) {
        let mut rig = silent_rig(gone);
        run(&mut rig, 2_000, |s| s == State::Stopping);
        prop_assert_eq!(rig.controller.supervisor().state(), State::Stopping);
        // each request within the time (every gap is shorter than the shortest time)
        for gap in &requests {
            let seen = run(&mut rig, *gap, |_| false);
            prop_assert!(seen.iter().all(|s| s.2.driver_enable), "{:?}", seen);
            prop_assert!(matches!(ask(&mut rig, HostMessage::GetStatus), DeviceMessage::Status(_)));
        }
        let seen = run(&mut rig, u32::from(gone) + 600, |s| s == State::Off);
        let off = seen.iter().find(|s| !s.2.driver_enable).map(|s| s.0);
        prop_assert_eq!(off, Some(u32::from(gone)), "{:?}", seen);
        prop_assert_eq!(rig.controller.supervisor().state(), State::Off);
    }
}

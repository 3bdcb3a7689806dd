//! The safety supervisor: every event sequence up to depth 8 checked against the interlock invariants, longer
//! random sequences by proptest, and the normal sequences step by step.

use std::collections::{HashMap, HashSet};

use proptest::prelude::*;
use ringpod_core::safety::{
    Aux, Command, Event, FaultReason, Motion, Outputs, Refusal, State, Supervisor, SupervisorConfig,
};

/// Every event the supervisor knows, with the time steps that matter (1 ms and each configured delay).
fn alphabet(c: &SupervisorConfig) -> Vec<Event> {
    let mut events: Vec<Event> = Command::ALL.into_iter().map(Event::Command).collect();
    events.extend([
        Event::Jog,
        Event::JogDone,
        Event::LogicOk(true),
        Event::LogicOk(false),
        Event::PowerOk(true),
        Event::PowerOk(false),
        Event::EStop(true),
        Event::EStop(false),
        Event::Limit(4, true),
        Event::Limit(4, false),
        Event::HomingDone,
        Event::HomingFailed,
        Event::AtRest,
        Event::StreamLost,
        Event::MotionFault,
        Event::WatchdogReset,
        Event::Elapsed(1),
    ]);
    let mut delays = vec![
        c.logic_settle_ms,
        c.power_settle_ms,
        c.supply_timeout_ms,
        c.driver_off_ms,
        c.discharge_ms,
    ];
    delays.sort();
    delays.dedup();
    events.extend(delays.into_iter().map(Event::Elapsed));
    events
}

/// The invariants of one transition `before --event--> after`; Err names the violation.
fn check(before: &Supervisor, event: Event, after: &Supervisor, result: Result<(), Refusal>) -> Result<(), String> {
    let (b, a): (Outputs, Outputs) = (before.outputs(), after.outputs());
    if a.power_relay && !a.logic_relay {
        return Err("power without logic".into());
    }
    if a.power_relay && !b.power_relay && !(b.logic_relay && matches!(before.state(), State::LogicOn)) {
        return Err("power switched on without settled logic".into());
    }
    if b.logic_relay && !a.logic_relay && b.power_relay {
        return Err("logic switched off while power was on".into());
    }
    if a.driver_enable && (!a.power_relay || matches!(after.state(), State::Fault(..))) {
        return Err("drivers enabled without power or with a fault".into());
    }
    if b.power_relay && !b.driver_enable && a.driver_enable && !matches!(after.state(), State::Homing | State::Jogging)
    {
        return Err("drivers enabled by anything but homing or a jog".into());
    }
    if b.power_relay && !a.power_relay && b.driver_enable && !matches!(after.state(), State::Fault(..)) {
        return Err("power cut under enabled drivers outside a fault".into());
    }
    if let State::Fault(..) = before.state() {
        if !matches!(after.state(), State::Fault(..)) && event != Event::Command(Command::ClearFault) {
            return Err("fault left without ClearFault".into());
        }
        if a.driver_enable || a.motion != Motion::None {
            return Err("fault with enable or motion".into());
        }
    }
    let stop_input = matches!(event, Event::EStop(true) | Event::Limit(_, true));
    if stop_input && b.power_relay && !matches!(after.state(), State::Fault(..)) {
        return Err("e-stop or limit with power on did not latch a fault".into());
    }
    if stop_input && (a.driver_enable || a.motion != Motion::None) {
        return Err("e-stop or limit left motion enabled".into());
    }
    if a.motion == Motion::Stream && !after.homed() {
        return Err("stream motion before homing".into());
    }
    if a.motion == Motion::Homing && after.state() != State::Homing {
        return Err("homing motion outside homing".into());
    }
    if a.motion == Motion::Jog && (after.state() != State::Jogging || after.homed()) {
        return Err("jog motion outside a jog, or a jogged machine still counted homed".into());
    }
    if result.is_err() && before != after {
        return Err("a refused command changed the state".into());
    }
    if a.aux != after.aux() || a.aux & !3 != 0 {
        return Err("outputs report other auxiliary outputs than the supervisor keeps".into());
    }
    if a.aux != 0 && !matches!(after.state(), State::Ready | State::Running | State::Stopping) {
        return Err("an auxiliary output on outside Ready, Running and Stopping".into());
    }
    if a.aux != 0 && !a.driver_enable {
        return Err("an auxiliary output on without the drivers enabled".into());
    }
    let switched_on = a.aux & !b.aux;
    let asked = match event {
        Event::Command(Command::Aux { output, on: true }) => output.bit(),
        _ => 0,
    };
    if switched_on & !asked != 0 {
        return Err("an auxiliary output switched on by anything but its own command".into());
    }
    let taken = result.is_ok() && before != after;
    if (event == Event::StreamLost || event == Event::Command(Command::Disable)) && taken && a.aux != 0 {
        return Err("an auxiliary output left on by a stream loss or a disable".into());
    }
    Ok(())
}

/// Walks every event sequence up to `depth` from `Off`. The supervisor is deterministic and the invariants concern
/// single transitions, so checking each (reachable state, event) pair once per depth checks every sequence; the
/// number of sequences covered is counted alongside.
fn enumerate(config: SupervisorConfig, depth: usize) -> (u128, usize, usize) {
    let events = alphabet(&config);
    let mut frontier: HashMap<Supervisor, u128> = HashMap::from([(Supervisor::new(config), 1)]);
    let mut states: HashSet<Supervisor> = frontier.keys().copied().collect();
    let mut transitions: HashSet<(Supervisor, usize)> = HashSet::new();
    let mut sequences: u128 = 0;
    for _ in 0..depth {
        let mut next: HashMap<Supervisor, u128> = HashMap::new();
        for (s, paths) in &frontier {
            for (k, e) in events.iter().enumerate() {
                let mut t = *s;
                let r = t.handle(*e);
                if transitions.insert((*s, k)) {
                    if let Err(v) = check(s, *e, &t, r) {
                        panic!("{v}: {s:?} --{e:?}--> {t:?}");
                    }
                }
                *next.entry(t).or_default() += paths;
                sequences += paths;
                states.insert(t);
            }
        }
        frontier = next;
    }
    (sequences, states.len(), transitions.len())
}

#[test]
fn every_event_sequence_to_depth_8_keeps_the_interlocks() {
    for config in [
        SupervisorConfig::default(),
        SupervisorConfig {
            logic_sense: false,
            power_sense: false,
            ..SupervisorConfig::default()
        },
    ] {
        let (sequences, states, transitions) = enumerate(config, 8);
        let events = alphabet(&config).len() as u128;
        assert_eq!(
            sequences,
            (1..=8).map(|d| events.pow(d)).sum::<u128>(),
            "every sequence of length 1..=8 counted"
        );
        assert!(states > 40, "{states} states reached");
        println!(
            "sense {}: {sequences} event sequences of length <= 8 over {events} events; {states} distinct states, {transitions} distinct transitions checked, 0 violations",
            config.logic_sense
        );
    }
}

/// Cross-check of the state-based walk: explicit depth-first enumeration of every sequence to depth 5.
#[test]
fn explicit_sequences_to_depth_5() {
    let config = SupervisorConfig::default();
    let events = alphabet(&config);
    fn walk(s: Supervisor, events: &[Event], depth: usize, count: &mut u64) {
        if depth == 0 {
            return;
        }
        for e in events {
            let mut t = s;
            let r = t.handle(*e);
            check(&s, *e, &t, r).unwrap_or_else(|v| panic!("{v}: {s:?} --{e:?}--> {t:?}"));
            *count += 1;
            walk(t, events, depth - 1, count);
        }
    }
    let mut count = 0;
    walk(Supervisor::new(config), &events, 5, &mut count);
    let n = events.len() as u64;
    assert_eq!(count, (1..=5).map(|d| n.pow(d)).sum::<u64>());
}

fn event() -> impl Strategy<Value = Event> {
    let c = SupervisorConfig::default();
    prop_oneof![
        4 => prop::sample::select(alphabet(&c)),
        1 => (0u8..6, any::<bool>()).prop_map(|(a, on)| Event::Limit(a, on)),
        1 => (0u32..3000).prop_map(Event::Elapsed),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]
    #[test]
    fn long_random_sequences_keep_the_interlocks(events in prop::collection::vec(event(), 1..200)) {
        let mut s = Supervisor::new(SupervisorConfig::default());
        for e in events {
            let before = s;
            let r = s.handle(e);
            prop_assert!(check(&before, e, &s, r).is_ok(), "{:?}: {before:?} --{e:?}--> {s:?}", check(&before, e, &s, r));
        }
    }
}

fn run(s: &mut Supervisor, events: &[Event]) {
    for e in events {
        s.handle(*e)
            .unwrap_or_else(|r| panic!("{e:?} refused in {:?}: {r}", s.state()));
    }
}

#[test]
fn power_up_home_run_stop_shut_down() {
    let c = SupervisorConfig::default();
    let mut s = Supervisor::new(c);
    run(&mut s, &[Event::Command(Command::Enable)]);
    assert_eq!(s.state(), State::LogicOn);
    assert_eq!(
        s.outputs(),
        Outputs {
            logic_relay: true,
            power_relay: false,
            driver_enable: false,
            motion: Motion::None,
            aux: 0
        }
    );
    run(&mut s, &[Event::Elapsed(c.logic_settle_ms)]);
    assert_eq!(s.state(), State::LogicOn, "no power before LOGIC_OK");
    run(&mut s, &[Event::LogicOk(true), Event::Elapsed(1)]);
    assert_eq!(s.state(), State::PowerOn { settled: false });
    run(&mut s, &[Event::PowerOk(true), Event::Elapsed(c.power_settle_ms)]);
    assert_eq!(s.state(), State::PowerOn { settled: true });
    assert_eq!(
        s.handle(Event::Command(Command::Start)),
        Err(Refusal::WrongState),
        "no streaming before homing"
    );
    run(
        &mut s,
        &[
            Event::Command(Command::Home),
            Event::HomingDone,
            Event::Command(Command::Start),
        ],
    );
    assert_eq!(s.outputs().motion, Motion::Stream);
    run(&mut s, &[Event::StreamLost]);
    assert_eq!(s.state(), State::Stopping);
    run(&mut s, &[Event::AtRest, Event::Command(Command::Disable)]);
    assert!(
        s.outputs().power_relay && !s.outputs().driver_enable,
        "drivers off first"
    );
    run(&mut s, &[Event::Elapsed(c.driver_off_ms)]);
    assert!(
        !s.outputs().power_relay && s.outputs().logic_relay,
        "then power, logic stays for the discharge"
    );
    run(&mut s, &[Event::Elapsed(c.discharge_ms)]);
    assert_eq!(s.outputs(), Outputs::OFF);
}

#[test]
fn estop_latches_until_cleared_and_released() {
    let mut s = Supervisor::new(SupervisorConfig {
        logic_sense: false,
        power_sense: false,
        ..SupervisorConfig::default()
    });
    run(
        &mut s,
        &[
            Event::Command(Command::Enable),
            Event::Elapsed(1000),
            Event::Elapsed(1000),
            Event::Command(Command::Home),
            Event::HomingDone,
            Event::Command(Command::Start),
        ],
    );
    s.handle(Event::EStop(true)).unwrap();
    assert_eq!(
        s.state(),
        State::Fault(FaultReason::EStop, ringpod_core::safety::Supplies::Logic)
    );
    assert!(!s.outputs().power_relay && !s.outputs().driver_enable);
    assert_eq!(s.handle(Event::Command(Command::ClearFault)), Err(Refusal::EStopOpen));
    assert_eq!(s.handle(Event::Command(Command::Home)), Err(Refusal::Faulted));
    run(&mut s, &[Event::EStop(false), Event::Command(Command::ClearFault)]);
    assert_eq!(s.state(), State::Off);
    assert!(!s.homed(), "homing is lost with the drivers");
}

#[test]
fn supply_timeout_and_loss() {
    let c = SupervisorConfig::default();
    let mut s = Supervisor::new(c);
    run(
        &mut s,
        &[Event::Command(Command::Enable), Event::Elapsed(c.supply_timeout_ms)],
    );
    assert!(matches!(s.state(), State::Fault(FaultReason::SupplyTimeout, _)));
    let mut s = Supervisor::new(c);
    run(
        &mut s,
        &[
            Event::Command(Command::Enable),
            Event::LogicOk(true),
            Event::Elapsed(c.logic_settle_ms),
            Event::PowerOk(true),
            Event::Elapsed(c.power_settle_ms),
            Event::PowerOk(false),
        ],
    );
    assert!(matches!(s.state(), State::Fault(FaultReason::PowerLost, _)));
    assert!(!s.outputs().power_relay);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, ..ProptestConfig::default() })]
    /// What a host shows as allowed is what the supervisor then does: `permits` answers as `handle` would for
    /// every command in every state reached, never changes anything, and a supervisor rebuilt from its telemetry
    /// (state and input levels) answers the same.
    #[test]
    fn permits_is_what_handle_would_do(events in prop::collection::vec(event(), 0..60)) {
        let config = SupervisorConfig::default();
        let mut s = Supervisor::new(config);
        for e in events {
            let _ = s.handle(e);
        }
        let reported = Supervisor::as_reported(config, s.state(), s.inputs());
        // Every command of the alphabet the other tests use (the six commands and the jog).
        let commands = alphabet(&config)
            .into_iter()
            .filter(|e| matches!(e, Event::Command(_) | Event::Jog));
        for command in commands {
            let before = s;
            let asked = s.permits(command);
            prop_assert_eq!(s, before, "permits changed the supervisor");
            prop_assert_eq!(reported.permits(command), asked, "telemetry's view of {:?} in {:?}", command, s.state());
            let mut done = s;
            prop_assert_eq!(done.handle(command), asked, "{:?} in {:?}", command, s.state());
        }
    }
}

/// Every state reachable from `Off` with `config`: the walk runs to closure (time saturates, so the set is finite).
fn reachable(config: SupervisorConfig) -> HashSet<Supervisor> {
    let events = alphabet(&config);
    let mut seen: HashSet<Supervisor> = HashSet::from([Supervisor::new(config)]);
    let mut todo = vec![Supervisor::new(config)];
    while let Some(s) = todo.pop() {
        for e in &events {
            let mut t = s;
            let _ = t.handle(*e);
            if seen.insert(t) {
                todo.push(t);
            }
        }
    }
    seen
}

/// The auxiliary outputs are off in every fault path. Over every reachable state (no depth bound) and
/// every event, a transition into a fault, a shutdown or `Off` leaves both outputs off; and such transitions do
/// start from states with outputs on, for every fault an operator can meet while streaming (so the check bites).
#[test]
fn aux_outputs_off_in_every_fault_path() {
    for config in [
        SupervisorConfig::default(),
        SupervisorConfig {
            logic_sense: false,
            power_sense: false,
            ..SupervisorConfig::default()
        },
    ] {
        let states = reachable(config);
        let events = alphabet(&config);
        let mut from_on: HashSet<&'static str> = HashSet::new();
        let mut paths = 0u64;
        for s in &states {
            for e in &events {
                let mut t = *s;
                let r = t.handle(*e);
                check(s, *e, &t, r).unwrap_or_else(|v| panic!("{v}: {s:?} --{e:?}--> {t:?}"));
                let down = matches!(t.state(), State::Fault(..) | State::ShuttingDown(_) | State::Off);
                if down && t.state() != s.state() {
                    paths += 1;
                    assert_eq!(t.outputs().aux, 0, "{s:?} --{e:?}--> {t:?}");
                    if s.aux() != 0 {
                        from_on.insert(match t.state() {
                            State::Fault(FaultReason::EStop, _) => "e-stop",
                            State::Fault(FaultReason::Limit(_), _) => "limit",
                            State::Fault(FaultReason::LogicLost, _) => "logic lost",
                            State::Fault(FaultReason::PowerLost, _) => "power lost",
                            State::Fault(FaultReason::Watchdog, _) => "watchdog",
                            State::Fault(FaultReason::MotionFault, _) => "motion fault",
                            State::Fault(..) => "other fault",
                            _ => "disable",
                        });
                    }
                }
            }
        }
        let mut met: Vec<_> = from_on.into_iter().collect();
        met.sort();
        let mut expected = vec!["disable", "e-stop", "limit", "motion fault", "watchdog"];
        if config.logic_sense {
            expected.extend(["logic lost", "power lost"]);
        }
        expected.sort();
        assert_eq!(met, expected, "the fault paths taken with an output on");
        println!(
            "sense {}: {} reachable states, {paths} transitions into a fault, a shutdown or Off, every one with both auxiliary outputs off",
            config.logic_sense,
            states.len()
        );
    }
}

/// Refused where it does not apply, with the supervisor's reason; off always taken.
#[test]
fn aux_outputs_switch_only_where_allowed() {
    let c = SupervisorConfig {
        logic_sense: false,
        power_sense: false,
        ..SupervisorConfig::default()
    };
    let on = |output| Event::Command(Command::Aux { output, on: true });
    let off = |output| Event::Command(Command::Aux { output, on: false });
    let mut s = Supervisor::new(c);
    assert_eq!(s.handle(on(Aux::Aux1)), Err(Refusal::WrongState), "not in Off");
    run(
        &mut s,
        &[
            Event::Command(Command::Enable),
            Event::Elapsed(1000),
            Event::Elapsed(1000),
        ],
    );
    assert_eq!(s.state(), State::PowerOn { settled: true });
    assert_eq!(s.handle(on(Aux::Aux1)), Err(Refusal::WrongState), "not before homing");
    run(&mut s, &[Event::Command(Command::Home)]);
    assert_eq!(s.handle(on(Aux::Aux2)), Err(Refusal::WrongState), "not while homing");
    run(&mut s, &[Event::HomingDone, on(Aux::Aux1)]);
    assert_eq!((s.aux(), s.outputs().aux), (1, 1));
    run(&mut s, &[Event::Command(Command::Start), on(Aux::Aux2), off(Aux::Aux1)]);
    assert_eq!(s.outputs().aux, 2, "AUX2 on, AUX1 off, while running");
    run(&mut s, &[Event::Command(Command::Stop)]);
    assert_eq!((s.state(), s.aux()), (State::Stopping, 2), "a stop keeps them");
    assert_eq!(
        s.handle(on(Aux::Aux1)),
        Err(Refusal::WrongState),
        "none switched on while braking"
    );
    run(&mut s, &[Event::AtRest]);
    assert_eq!((s.state(), s.aux()), (State::Ready, 2));
    run(&mut s, &[Event::Command(Command::Start), Event::StreamLost]);
    assert_eq!(
        (s.state(), s.aux()),
        (State::Stopping, 0),
        "a stream loss switches them off"
    );
    run(&mut s, &[Event::AtRest, on(Aux::Aux1), Event::Command(Command::Home)]);
    assert_eq!(s.aux(), 0, "homing again switches them off");
    run(&mut s, &[Event::HomingDone, on(Aux::Aux2), Event::Limit(4, true)]);
    assert!(matches!(s.state(), State::Fault(FaultReason::Limit(4), _)));
    assert_eq!(s.outputs().aux, 0);
    assert_eq!(
        s.handle(on(Aux::Aux2)),
        Err(Refusal::Faulted),
        "not with a fault latched"
    );
    assert_eq!(s.handle(off(Aux::Aux2)), Ok(()), "off is always taken");
    assert!(matches!(s.state(), State::Fault(..)), "and changes nothing else");
}

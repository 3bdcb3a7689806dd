//! A pass (`Controller::pass`): the control period a firmware gives up after a hold-up, so that its step queue
//! drains back. Time goes on in it exactly as in a tick (supply sequencing, power-down, telemetry); motion does
//! not, and resumes from where it was.

use crate::common::device;

use ringpod_core::controller::Controller;
use ringpod_core::motion::AxisMove;
use ringpod_core::protocol::{DeviceMessage, HostMessage, Request, Response, Telemetry};
use ringpod_core::safety::{Command, Inputs, State};

/// The trainer model's controller, greeted, subscribed to telemetry, its supplies reporting good.
fn connected() -> Controller {
    let mut c = device::connected();
    let telemetry = c.handle(&Request {
        id: 2,
        body: HostMessage::Telemetry(true),
    });
    assert_eq!(telemetry.body, DeviceMessage::Ack);
    c.set_inputs(Inputs {
        logic_ok: true,
        power_ok: true,
        ..Inputs::default()
    });
    c
}

fn command(c: &mut Controller, command: Command) {
    let r = c.handle(&Request {
        id: 2,
        body: HostMessage::Command(command),
    });
    assert_eq!(r.body, DeviceMessage::Ack, "{command:?}");
}

fn telemetry(c: &mut Controller) -> Vec<Telemetry> {
    core::iter::from_fn(|| c.unsolicited())
        .filter_map(|r: Response| match r.body {
            DeviceMessage::Telemetry(t) => Some(t),
            _ => None,
        })
        .collect()
}

fn steps(moves: &[AxisMove; 6]) -> u32 {
    moves.iter().map(|m| m.count).sum()
}

#[test]
fn a_pass_keeps_the_supervisors_time_as_a_tick_does() {
    // Two controllers through enable and disable, one ticking and one passing: the same state in every period,
    // the same outputs and the same telemetry clock. A lost period would show as a sequence ending late.
    let (mut ticked, mut passed) = (connected(), connected());
    command(&mut ticked, Command::Enable);
    command(&mut passed, Command::Enable);
    let mut states = Vec::new();
    for period in 0..3_000 {
        if period == 1_500 {
            command(&mut ticked, Command::Disable);
            command(&mut passed, Command::Disable);
        }
        let out = ticked.tick();
        assert_eq!(passed.pass(), out.outputs, "period {period}");
        assert_eq!(
            passed.supervisor().state(),
            ticked.supervisor().state(),
            "period {period}"
        );
        let (a, b) = (telemetry(&mut ticked), telemetry(&mut passed));
        assert_eq!(
            a.iter().map(|t| t.time_us).collect::<Vec<_>>(),
            b.iter().map(|t| t.time_us).collect::<Vec<_>>()
        );
        if states.last() != Some(&out.outputs) {
            states.push(out.outputs);
        }
    }
    // The sequence really ran: logic, power, settled, then the shutdown back to off.
    assert!(states.len() >= 4, "{states:?}");
    assert_eq!(passed.supervisor().state(), State::Off);
}

#[test]
fn a_pass_moves_nothing_and_homing_resumes_where_it_was() {
    let mut c = connected();
    command(&mut c, Command::Enable);
    for _ in 0..1_000 {
        c.tick();
    }
    assert!(matches!(c.supervisor().state(), State::PowerOn { settled: true }));
    command(&mut c, Command::Home);
    let mut moved = 0;
    for _ in 0..50 {
        moved += steps(&c.tick().moves);
    }
    assert!(moved > 0, "homing moves the first axis");
    assert_eq!(c.supervisor().state(), State::Homing);
    let before = c.steps();
    for _ in 0..200 {
        c.pass();
    }
    assert_eq!(c.steps(), before, "passes plan no steps");
    assert_eq!(c.supervisor().state(), State::Homing);
    let next = c.tick();
    assert!(steps(&next.moves) > 0, "the next tick goes on homing");
    assert_ne!(c.steps(), before);
}

#[test]
fn the_status_carries_the_boards_step_counters() {
    // The firmware counts periods its step generator played empty and periods it passed; the status is where a
    // host sees them (`device status`), so they are not only in a log nobody reads.
    let mut c = connected();
    let s = c.status();
    assert_eq!((s.idle_periods, s.passed_periods), (0, 0));
    c.set_step_counters(3, 5);
    let s = c.status();
    assert_eq!((s.idle_periods, s.passed_periods), (3, 5));
}

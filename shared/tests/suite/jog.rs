//! A jog's end: the drivers stay enabled through the period that plays its last steps.

use crate::common::device;

use ringpod_core::controller::Controller;
use ringpod_core::protocol::{DeviceMessage, HostMessage, Request};
use ringpod_core::safety::{Command, Inputs, State};

fn powered() -> Controller {
    let mut c = device::connected();
    c.set_inputs(Inputs {
        logic_ok: true,
        power_ok: true,
        ..Inputs::default()
    });
    let r = c.handle(&Request {
        id: 2,
        body: HostMessage::Command(Command::Enable),
    });
    assert_eq!(r.body, DeviceMessage::Ack);
    for _ in 0..3_000 {
        c.tick();
        if c.supervisor().state() == (State::PowerOn { settled: true }) {
            return c;
        }
    }
    panic!("never powered: {:?}", c.supervisor().state());
}

#[test]
fn the_drivers_stay_enabled_for_the_periods_that_play_a_jogs_last_steps() {
    // A board takes a tick's moves at the next period boundary and plays them in the ring's half after it, and
    // ticks again before each boundary: the two ticks after the last steps must still enable the drivers, or the
    // last steps play into disabled drivers (`motion::jog::SETTLE_PERIODS`).
    for steps in [1, 36, -5] {
        let mut c = powered();
        let r = c.handle(&Request {
            id: 3,
            body: HostMessage::Jog { axis: 0, steps },
        });
        assert_eq!(r.body, DeviceMessage::Ack, "{steps}");
        let mut last_move = None;
        for period in 0..10_000 {
            let out = c.tick();
            if out.moves.iter().any(|m| m.count > 0) {
                last_move = Some(period);
            }
            if !out.outputs.driver_enable {
                let last = last_move.expect("the jog moved");
                assert!(
                    period >= last + 3,
                    "jog of {steps}: drivers off in period {period}, last steps planned in {last}"
                );
                assert_eq!(c.steps()[0], i64::from(steps));
                break;
            }
        }
        assert_eq!(c.supervisor().state(), State::PowerOn { settled: true }, "{steps}");
    }
}

/// A buzz of each axis at its homing's fast rate, rendered into port words and played into the drivers' model
/// period by period as the board's DMA plays them: the STEP edges, signed by DIR, end where the controller's count
/// does (a reversal inside a period must not lose or add a step at the pins).
#[test]
fn a_buzz_ends_at_the_pins_where_the_count_does() {
    use crate::pulse::MAP;
    use ringpod_core::motion::pulse::{PulseRenderer, MAX_STEP_SLOTS, STEP_SLOT_NS};
    use ringpod_core::sim::drivers::DriverInputs;
    for axis in 0..6u8 {
        let mut c = powered();
        let sched = ringpod_core::controller::ControllerConfig::trainer_model().scheduler;
        let timing = ringpod_core::motion::pulse::PulseTiming::new(&sched, STEP_SLOT_NS, MAX_STEP_SLOTS).unwrap();
        let mut renderer = PulseRenderer::new(MAP, timing).unwrap();
        let mut drivers = DriverInputs::new(MAP, timing.slot_ns, sched);
        let mut buf = vec![0u32; timing.slots];
        let r = c.handle(&Request {
            id: 3,
            body: HostMessage::Buzz { axis },
        });
        assert_eq!(r.body, DeviceMessage::Ack);
        let mut moved_before = false;
        for period in 0..20_000 {
            let out = c.tick();
            // A tick's moves play in the period after it: the drivers are enabled through both.
            let moves = out.moves.iter().any(|m| m.count > 0);
            assert!(
                out.outputs.driver_enable || !(moves || moved_before),
                "axis {axis}: drivers disabled in period {period} with steps to play"
            );
            moved_before = moves;
            let report = renderer.render(&out.moves, &mut buf).unwrap();
            assert_eq!(report.collisions, 0);
            assert_eq!(drivers.play_all(&buf), None);
        }
        assert_eq!(
            drivers.position(),
            c.steps(),
            "axis {axis}: edges {:?}",
            drivers.edges()
        );
    }
}

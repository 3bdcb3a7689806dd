//! Commissioning a board: `ringpod device inputs [--watch]` (every input's electrical level and debounced state,
//! to check the wiring switch by switch), `device jog AXIS DISTANCE` and `device buzz AXIS` (one motor at a time,
//! to check its direction and its steps per unit).

use std::fmt::Write as _;
use std::time::Duration;

use ringpod_core::protocol::InputReport;
use ringpod_core::safety::debounce::InputBit;

use ringpod_core::kinematics::AxisKind;
use ringpod_core::protocol::endpoints::{Buzz, Jog};
use ringpod_core::protocol::{NackReason, Settings, SettingsKind};
use ringpod_core::safety::{FaultReason, State};

use crate::input::numbers::readable;
use crate::link::client::{Client, ClientError, Transport};

/// Why a commissioning move was not made or did not end well.
#[derive(Debug, thiserror::Error)]
pub enum CommissionError {
    /// The words are not an axis (and a distance).
    #[error("{0}")]
    Usage(&'static str),
    /// The distance is not a number.
    #[error("{usage}: {text:?} is not a number")]
    NotANumber {
        /// How the command goes.
        usage: &'static str,
        /// What was given.
        text: String,
    },
    /// There is no such axis.
    #[error("axis {0} does not exist (1-6)")]
    NoAxis(u16),
    /// The distance is no number of steps.
    #[error("{} {unit} is out of range", readable(*.distance))]
    Unrepresentable {
        /// The distance asked.
        distance: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// The distance rounds to no step at all: a jog checks a motor's direction and its steps per unit, and a
    /// move of nothing checks neither (a "moved 0 steps" success would read as a motor that did not turn).
    #[error("{} {unit} is 0 steps: a jog moves at least one step ({} {unit} on this axis)", readable(*.distance), readable(*.step))]
    NoStep {
        /// The distance asked.
        distance: f64,
        /// Its unit.
        unit: &'static str,
        /// One motor step in that unit.
        step: f64,
    },
    /// The device refused the jog as too far.
    #[error(
        "{} {unit} ({steps} steps) is further than a jog goes: a carriage at most its homing back-off, a \
         linear actuator or a shoulder its homing search travel",
        readable(*.distance)
    )]
    TooFar {
        /// The distance asked.
        distance: f64,
        /// Its unit.
        unit: &'static str,
        /// In motor steps.
        steps: i32,
    },
    /// The move ended in a fault.
    #[error("axis {} {what} into a fault: {reason}", axis + 1)]
    Fault {
        /// The axis, from 0.
        axis: u8,
        /// What was done.
        what: String,
        /// The device's fault.
        reason: FaultReason,
    },
    /// The device's answer.
    #[error(transparent)]
    Client(#[from] ClientError),
}

/// The inputs in bit order, with their names.
pub fn names() -> Vec<(InputBit, String)> {
    let mut v = vec![(InputBit::EStop, "e-stop".to_owned())];
    v.extend((0..6u8).map(|a| (InputBit::Home(a), format!("home {}", a + 1))));
    v.extend((0..6u8).map(|a| (InputBit::Limit(a), format!("end {}", a + 1))));
    v.push((InputBit::LogicOk, "LOGIC_OK".into()));
    v.push((InputBit::PowerOk, "POWER_OK".into()));
    v
}

/// A table: one input a line, its pin level, polarity and state.
pub fn table(r: &InputReport) -> String {
    let mut t = format!(
        "{:<9} {:<5} {:<12} state   (debounce {} ms{})\n",
        "input",
        "pin",
        "active when",
        r.debounce_ms,
        if r.sampled {
            ""
        } else {
            "; levels derived: a simulated machine has no pins"
        }
    );
    for (bit, name) in names() {
        let m = bit.mask();
        let _ = writeln!(
            t,
            "{name:<9} {:<5} {:<12} {}",
            if r.raw & m != 0 { "high" } else { "low" },
            if r.active_low & m != 0 { "low" } else { "high" },
            if r.active & m != 0 { "ACTIVE" } else { "-" }
        );
    }
    t
}

/// The changes from `before` to `now`, one line each.
pub fn changes(before: &InputReport, now: &InputReport) -> Vec<String> {
    names()
        .into_iter()
        .filter_map(|(bit, name)| {
            let m = bit.mask();
            let (raw, active) = ((before.raw ^ now.raw) & m != 0, (before.active ^ now.active) & m != 0);
            (raw || active).then(|| {
                format!(
                    "{name}: pin {}, {}",
                    if now.raw & m != 0 { "high" } else { "low" },
                    if now.active & m != 0 { "ACTIVE" } else { "inactive" }
                )
            })
        })
        .collect()
}

/// Prints the table, then with `watch` every change until `stop` says so.
pub fn inputs<T: Transport>(client: &mut Client<T>, watch: bool, stop: &dyn Fn() -> bool) -> Result<(), ClientError> {
    use crate::out::console;
    let mut last = client.inputs()?;
    // A reader that went away (`| head`) ends the watch, as it ends any filter: found by a write that fails, or,
    // while nothing changes and nothing is written, by asking standard output each sweep. Either is kept as the
    // command's output failure (exit 141).
    if !console::out(&table(&last)) || !console::flush_stdout() {
        return Ok(());
    }
    while watch && !stop() && !console::stdout_closed() {
        client.transport().elapse(Duration::from_millis(20));
        let now = client.inputs()?;
        for line in changes(&last, &now) {
            if !console::out(&format!("{line}\n")) || !console::flush_stdout() {
                return Ok(());
            }
        }
        last = now;
    }
    Ok(())
}

/// `device jog AXIS DISTANCE` or `device buzz AXIS`: AXIS 1-6, DISTANCE in degrees of ring for a carriage and
/// millimetres for a linear actuator. Waits until the move is done; returns the step positions and a line to print.
pub fn jog<T: Transport>(client: &mut Client<T>, words: &[String], buzz: bool) -> Result<String, CommissionError> {
    let usage = if buzz {
        "usage: ringpod device buzz AXIS (1-6)"
    } else {
        "usage: ringpod device jog AXIS DISTANCE (1-6; degrees for a carriage or a shoulder, mm for a linear actuator)"
    };
    let axis: u8 = match words.first().map(|w| w.parse::<u8>()) {
        Some(Ok(a)) if (1..=6).contains(&a) => a - 1,
        _ => return Err(CommissionError::Usage(usage)),
    };
    let distance = match (buzz, words) {
        (true, [_]) => None,
        (false, [_, distance]) => Some(distance.parse::<f64>().map_err(|_| CommissionError::NotANumber {
            usage,
            text: distance.clone(),
        })?),
        _ => return Err(CommissionError::Usage(usage)),
    };
    let kind = client.hello()?.axes[usize::from(axis)];
    let before = client.status()?.steps;
    let what = begin_move(client, axis, kind, distance)?;
    let status = client.wait_for(Duration::from_secs(120), |s| s.state != State::Jogging)?;
    if let State::Fault(reason, _) = status.state {
        return Err(CommissionError::Fault { axis, what, reason });
    }
    let moved = status.steps[usize::from(axis)] - before[usize::from(axis)];
    Ok(format!(
        "axis {} {what}: moved {moved} steps, now at {} (state {:?}; home again before streaming)",
        axis + 1,
        status.steps[usize::from(axis)],
        status.state
    ))
}

/// An axis as people number it (1-6) to the index the device takes (0-5).
pub fn axis_index(axis: u8) -> Result<u8, CommissionError> {
    match axis {
        1..=6 => Ok(axis - 1),
        _ => Err(CommissionError::NoAxis(u16::from(axis))),
    }
}

/// Starts a commissioning move of `axis` (0-5) without waiting for its end: a jog by `distance` (degrees of ring
/// for a carriage, mm for a linear actuator), turned into steps with the device's own steps per unit, or a buzz
/// (`None`). `kind` is what the axis measures, as the device's hello said. Returns what was done ("jogged 5 deg
/// (120 steps)", "buzzed").
pub fn begin_move<T: Transport>(
    client: &mut Client<T>,
    axis: u8,
    kind: AxisKind,
    distance: Option<f64>,
) -> Result<String, CommissionError> {
    if axis > 5 {
        return Err(CommissionError::NoAxis(u16::from(axis) + 1));
    }
    let Some(d) = distance else {
        client.call(Buzz(axis))?;
        return Ok("buzzed".to_owned());
    };
    // Motor steps per unit, signed: a reversed motor steps the other way for the same distance.
    let (Settings::Axes(axes), _) = client.settings(SettingsKind::Axes)? else {
        return Err(ClientError::Unexpected("another section than the axes".into()).into());
    };
    let motor = axes[usize::from(axis)];
    let per_unit = f64::from(motor.steps_per_unit) * if motor.reverse { -1.0 } else { 1.0 };
    // Steps per carriage or shoulder turn, or per metre.
    let (per_turn_or_metre, unit) = match kind {
        AxisKind::Ring | AxisKind::Angle => (360.0, "deg"),
        AxisKind::Linear => (1000.0, "mm"),
    };
    let steps = d / per_turn_or_metre * per_unit;
    if !steps.is_finite() || steps.abs() > f64::from(i32::MAX) {
        return Err(CommissionError::Unrepresentable { distance: d, unit });
    }
    let steps = steps.round() as i32;
    if steps == 0 {
        return Err(CommissionError::NoStep {
            distance: d,
            unit,
            step: per_turn_or_metre / per_unit.abs(),
        });
    }
    match client.call(Jog { axis, steps }) {
        Err(ClientError::Device(NackReason::OutOfRange)) => {
            return Err(CommissionError::TooFar {
                distance: d,
                unit,
                steps,
            })
        }
        other => other?,
    }
    Ok(format!("jogged {} {unit} ({steps} steps)", readable(d)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_are_numbered_1_to_6_and_others_are_refused_by_number() {
        assert_eq!(
            (1..=6).map(|a| axis_index(a).ok()).collect::<Vec<_>>(),
            (0..6).map(Some).collect::<Vec<_>>()
        );
        for a in [0, 7, 255] {
            let e = axis_index(a).unwrap_err();
            assert!(matches!(e, CommissionError::NoAxis(n) if n == u16::from(a)), "{e:?}");
            assert_eq!(e.to_string(), format!("axis {a} does not exist (1-6)"));
        }
    }

    #[test]
    fn a_switch_change_is_one_line_and_the_table_names_every_input() {
        let off = InputReport {
            raw: 0,
            sampled: true,
            active: 0,
            active_low: InputBit::EStop.mask(),
            debounce_ms: 5,
        };
        let table = table(&off);
        assert_eq!(table.lines().count(), 16, "a header and 15 inputs");
        assert!(table.contains("e-stop    low   low          -"), "{table}");
        let home3 = InputBit::Home(2).mask();
        let on = InputReport {
            raw: home3,
            active: home3,
            ..off
        };
        assert_eq!(changes(&off, &on), vec!["home 3: pin high, ACTIVE".to_owned()]);
        assert!(changes(&on, &on).is_empty());
    }
}

//! `ringpod device inputs [--watch]`: every input's electrical level and debounced state, to check a new board's
//! wiring switch by switch.

use std::fmt::Write as _;
use std::time::Duration;

use ringpod_core::protocol::InputReport;
use ringpod_core::safety::debounce::InputBit;

use crate::client::{Client, Transport};

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
pub fn run<T: Transport>(client: &mut Client<T>, watch: bool, stop: &dyn Fn() -> bool) -> anyhow::Result<()> {
    let mut last = client.inputs()?;
    print!("{}", table(&last));
    while watch && !stop() {
        client.transport().elapse(Duration::from_millis(20));
        let now = client.inputs()?;
        for line in changes(&last, &now) {
            println!("{line}");
        }
        last = now;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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

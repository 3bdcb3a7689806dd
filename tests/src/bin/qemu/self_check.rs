//! The core's self-check on the emulated MCU (bit identity with this host) and the instruction counts of the control
//! path against their budgets.

use std::io::{BufRead, BufReader};

use ringpod_core::selfcheck;

use crate::emulator::{build, run_to_end};
use crate::Tally;

/// The self-check and the instruction counts.
pub(crate) fn core_on_m4f(t: &mut Tally) {
    println!("== ringpod-core on an emulated Cortex-M4F (mps2-an386)");
    let output = match build("ringpod-qemu").and_then(|elf| run_to_end(&elf)) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("{e}");
            t.check(false, "the self-check runs on the emulated Cortex-M4F");
            return;
        }
    };
    let host = selfcheck::run();
    let mut checks = 0;
    let mut digest = None;
    let mut costs = Vec::new();
    let mut iterations = None;
    for line in BufReader::new(output.as_bytes()).lines().map_while(Result::ok) {
        if let Some(rest) = line.strip_prefix("CHECK ") {
            checks += 1;
            let (verdict, name) = rest.split_once(' ').unwrap_or((rest, ""));
            t.check(verdict == "PASS", &format!("Cortex-M4F: {name}"));
        } else if let Some(d) = line.strip_prefix("DIGEST ") {
            digest = u64::from_str_radix(d.trim(), 16).ok();
        } else if let Some(rest) = line.strip_prefix("COST ") {
            let (n, name) = rest.split_once(' ').unwrap_or((rest, ""));
            costs.push((name.to_string(), n.parse::<u64>().unwrap_or(0)));
        } else if let Some(rest) = line.strip_prefix("FK_ITERATIONS ") {
            iterations = rest.split_whitespace().next().and_then(|n| n.parse::<u64>().ok());
        } else if let Some(e) = line.strip_prefix("ERROR ") {
            eprintln!("qemu: {e}");
        }
    }
    t.check(
        checks == selfcheck::CHECKS.len(),
        "every check of the self-check reported",
    );
    match digest {
        Some(d) => t.check(
            d == host.digest,
            &format!(
                "bit identity: digest {d:016x} on the M4F, {:016x} on this host",
                host.digest
            ),
        ),
        None => t.check(false, "bit identity: the M4F reported a digest"),
    }
    t.check(
        output.contains("DONE") && !costs.is_empty(),
        "instruction counts measured",
    );
    for (row, budget) in BUDGETS {
        match costs.iter().find(|(name, _)| name.contains(row)) {
            Some((_, n)) => t.check(
                *n <= budget,
                &format!("budget: {row} {n} instructions, at most {budget}"),
            ),
            None => t.check(false, &format!("budget: the row {row:?} was measured")),
        }
    }
    println!();
    println!("| operation (f32, trainer model) | instructions | at 96 MHz, 1 instruction a cycle | of its period |");
    println!("|---|---|---|---|");
    for (name, n) in &costs {
        // Rows at 2 kHz take a share of a 500 us period; everything else of the default 1 kHz.
        let period_us = if name.contains("2 kHz") { 500.0 } else { 1_000.0 };
        let us = *n as f64 / 96.0;
        println!("| {name} | {n} | {us:.1} us | {:.1} % |", us / period_us * 100.0);
    }
    if let Some(i) = iterations {
        println!("(FK: {:.2} Newton iterations per solve)", i as f64 / 100.0);
    }
    println!();
}

/// Instruction budgets of the control path on the M4F: a row whose name contains the key must not cost more. Each
/// is the measured figure plus about 5 %, the most that code placement under LTO moves the inlined rows between
/// builds of unchanged source (the renderer is never inlined, so its code is the same in every program). Counts
/// under `-icount` are exact and repeatable for a given build, so these hold or fail deterministically; they keep
/// the control path from growing back unnoticed.
pub(crate) const BUDGETS: [(&str, u64); 13] = [
    ("control tick: pipeline", 4_730),
    // The same tick with both spare axes fitted and following a stream: 4,950 measured, held at the goal (5,000)
    // rather than 5 % over it.
    ("control tick with the spare axes", 5_000),
    ("control tick at 2 kHz", 4_570),
    ("trainer IK (f32)", 815),
    ("IK + all", 2_080),
    ("setpoint frame", 4_540),
    ("FK", 11_460),
    ("limited into the envelope", 10_330),
    ("step buffers, idle", 900),
    // The step generator's second render while a spare axis is fitted (its words then split by port on the board).
    ("the spare axes' period", 1_410),
    ("step buffers, typical", 2_700),
    ("step buffers, the trainer's fastest", 6_100),
    ("step buffers (6 axes x 100 k", 13_500),
];

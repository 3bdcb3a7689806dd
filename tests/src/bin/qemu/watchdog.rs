//! The watchdog on the emulated MCU: a stalled control loop is reset and comes back safe.

use std::time::Duration;

use crate::emulator::start_or_fail;
use crate::host_cli::{ringpod_json, ringpod_text};
use crate::Tally;

/// The watchdog: the control loop hangs once the platform is homed (the program's `stall-when-homed`); the CMSDK
/// watchdog resets the emulated MCU, which comes back with its supplies off, the `Watchdog` fault latched, homing
/// lost and the setting stored before the reset restored from its flash; cleared, it powers and homes again.
pub(crate) fn watchdog_on_m4f(t: &mut Tally) {
    println!("== the watchdog on the emulated Cortex-M4F: a stalled control loop");
    let Some(emulated) = start_or_fail(t, &["stall-when-homed"]) else {
        return;
    };
    let pty = emulated.pty.as_str();
    let port = ["--port", pty];
    let stored = ringpod_text(&[&["device", "config", "set", "stream.telemetry_hz", "50"][..], &port].concat()).0;
    // The settings task stores a change within 100 ms while the supplies are off.
    std::thread::sleep(Duration::from_millis(500));
    let enabled = ringpod_text(&[&["device", "enable"][..], &port].concat()).0;
    // Homing ends in the stall: the command gets no answer and fails.
    let _ = ringpod_text(&[&["device", "home"][..], &port].concat());
    let reset = emulated.wait_for(Duration::from_secs(20), |l| l.trim() == "READY");
    println!("printed over the stall: {reset:?}");
    let lines = reset.unwrap_or_default();
    t.check(
        stored && enabled && lines.iter().any(|l| l == "STALL") && lines.iter().any(|l| l == "RESET watchdog"),
        "a control loop stalled with the platform homed is reset by the watchdog",
    );
    let status = ringpod_json(&[&["device", "status"][..], &port].concat());
    let (_, inputs) = ringpod_text(&[&["device", "inputs"][..], &port].concat());
    let sense_off = ["LOGIC_OK", "POWER_OK"].iter().all(|name| {
        inputs
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().last())
            == Some("-")
    });
    if let Ok(s) = &status {
        println!("after the reset: state {}, homed {}", s["state"], s["homed"]);
    }
    t.check(
        status
            .as_ref()
            .is_ok_and(|s| s["state"] == serde_json::json!({"Fault": ["Watchdog", "None"]}) && s["homed"] == false)
            && sense_off,
        "it comes back with the Watchdog fault reported, both supplies off (sensed), homing lost",
    );
    let setting = ringpod_json(&[&["device", "config", "get", "stream.telemetry_hz"][..], &port].concat());
    t.check(
        setting.is_ok_and(|s| s["value"] == 50) && lines.iter().any(|l| l.starts_with("SETTINGS 3 restored")),
        "the setting stored before the reset is restored from flash by the settings task",
    );
    let cleared = ringpod_text(&[&["device", "clear"][..], &port].concat()).0
        && ringpod_text(&[&["device", "enable"][..], &port].concat()).0
        && ringpod_text(&[&["device", "home"][..], &port].concat()).0;
    let again = ringpod_json(&[&["device", "status"][..], &port].concat());
    t.check(
        cleared && again.is_ok_and(|s| s["state"] == "Ready" && s["homed"] == true),
        "cleared, it powers up and homes again (no second stall: the last reset was the watchdog's)",
    );
    drop(emulated);
}

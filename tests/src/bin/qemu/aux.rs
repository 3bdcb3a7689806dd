//! The auxiliary outputs on the emulated MCU: a pose file's `aux1` column and `device aux` switch the
//! board's pins (the emulated machine prints `AUX n`, the pins' bits, at each change), and an e-stop drops both.

use std::time::Duration;

use crate::emulator::Emulated;
use crate::host_cli::{ringpod_json, ringpod_text};
use crate::Tally;

/// A 2 s pose file at home with `aux1` off for its first second and on after.
fn write_aux_input(path: &std::path::Path) -> std::io::Result<()> {
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma,aux1\n");
    for k in 0..=200 {
        let t = f64::from(k) * 0.01;
        csv += &format!(
            "{t:.3},0,0,{:.6},0,0,0,{}\n",
            0.227 + 0.004 * (3.0 * t).sin(),
            u8::from(t >= 1.0)
        );
    }
    std::fs::write(path, csv)
}

/// Runs on a controller started with `estop-on-aux2` (AUX2's contact in the e-stop chain), homed and Ready.
pub(crate) fn aux_on_m4f(t: &mut Tally, emulated: &Emulated) {
    println!("== the auxiliary outputs on the emulated Cortex-M4F");
    let pty = emulated.pty.as_str();
    let port = ["--port", pty];
    let input = std::env::temp_dir().join(format!("ringpod-qemu-aux-{}.csv", std::process::id()));
    if write_aux_input(&input).is_err() {
        t.check(false, "the input file is written");
        return;
    }
    let file = input.to_string_lossy().to_string();
    let streamed = ringpod_json(&[&["stream", "--input", &file, "--quiet", "--report-json"][..], &port].concat());
    let _ = std::fs::remove_file(&input);
    let pins = emulated.wait_for(Duration::from_secs(5), |l| l == "AUX 1");
    let status = ringpod_json(&[&["device", "status"][..], &port].concat());
    let streamed_ok = streamed
        .as_ref()
        .is_ok_and(|r| r["state"] == "Ready" && r["counts_agree"] == true);
    if !streamed_ok || pins.is_err() {
        println!("the stream: {streamed:?}; the pins: {pins:?}; then the status: {status:?}");
    }
    t.check(
        streamed_ok && pins.is_ok() && status.is_ok_and(|s| s["aux"] == 1),
        "a pose file's aux1 column switches AUX1's pin on as it streams, and it stays on at rest",
    );
    let off = ringpod_json(&[&["device", "aux", "1", "off"][..], &port].concat());
    let off_pin = emulated.wait_for(Duration::from_secs(5), |l| l == "AUX 0");
    let on = ringpod_json(&[&["device", "aux", "1", "on"][..], &port].concat());
    let on_pin = emulated.wait_for(Duration::from_secs(5), |l| l == "AUX 1");
    let switched = off.as_ref().is_ok_and(|s| s["aux"] == 0)
        && off_pin.is_ok()
        && on.as_ref().is_ok_and(|s| s["aux"] == 1)
        && on_pin.is_ok();
    if !switched {
        println!("off: {off:?}, pins {off_pin:?}; on: {on:?}, pins {on_pin:?}");
    }
    t.check(switched, "device aux 1 off|on switches AUX1's pin");
    // AUX2 on opens the e-stop chain (the test's wiring): the fault drops both outputs.
    let (asked, _) = ringpod_text(&[&["device", "aux", "2", "on"][..], &port].concat());
    let dropped = emulated.wait_for(Duration::from_secs(5), |l| l == "AUX 0");
    println!("pins over the e-stop: {dropped:?}");
    std::thread::sleep(Duration::from_millis(300));
    let after = ringpod_json(&[&["device", "status"][..], &port].concat());
    if let Ok(s) = &after {
        println!("after the e-stop: state {}, aux {}", s["state"], s["aux"]);
    }
    t.check(
        asked
            && dropped.is_ok_and(|l| l.iter().any(|l| l == "AUX 3"))
            && after.is_ok_and(|s| s["state"]["Fault"][0] == "EStop" && s["aux"] == 0),
        "an e-stop while AUX1 and AUX2 are on latches its fault and switches both pins off",
    );
    let refused = ringpod_text(&[&["device", "aux", "1", "on"][..], &port].concat()).0;
    let cleared = ringpod_json(&[&["device", "clear"][..], &port].concat());
    t.check(
        !refused && cleared.is_ok_and(|s| s["state"] == "Off" && s["aux"] == 0),
        "with the fault latched AUX1 is refused; cleared, the machine is off with both outputs off",
    );
}

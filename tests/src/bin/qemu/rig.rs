//! A rig of the builder's own on the emulated MCU: loaded, stored, restarted into, streamed.

use std::time::Duration;

use crate::emulator::start_or_fail;
use crate::host_cli::{ringpod_json, ringpod_text, write_input_about};
use crate::Tally;

/// A rig no preset describes, on the device: loaded over the UART (checked by the M4F), stored in its flash,
/// restored at the restart the host asks for, shown back as a rig file, and driven end to end: a CSV streamed into
/// it ends at exactly the steps the host simulator reaches with `--geometry` of the same file.
pub(crate) fn rig_on_m4f(t: &mut Tally) {
    println!("== a rig of its own on the emulated Cortex-M4F: load, restart, stream");
    let (exported, model) = ringpod_text(&["presets", "--export", "trainer-model"]);
    let wider = model
        .replace("name = \"trainer-model\"", "name = \"wider-ring\"")
        .replace("ring_radius = 0.286", "ring_radius = 0.3")
        .replace("rod_length = 0.312", "rod_length = 0.325");
    if !exported || wider == model {
        t.check(false, "the rig file is written");
        return;
    }
    drive_on_m4f(
        t,
        "wider-ring",
        &wider,
        &["ring_radius = 0.3\n", "rod_length = 0.325\n"],
        0.227,
    );
}

/// The elbow trainer (ch. 5.1 fig. 5.2 arms, rotary shoulders) on the device, as its exported rig file renamed (so
/// that it is a rig of its own, not the preset): its shoulders home to their index flags on the M4F and the stream
/// ends at the simulator's steps.
pub(crate) fn elbow_on_m4f(t: &mut Tally) {
    println!("== the elbow trainer on the emulated Cortex-M4F: load, restart, stream");
    let (exported, preset) = ringpod_text(&["presets", "--export", "trainer-elbow"]);
    let renamed = preset.replace("name = \"trainer-elbow\"", "name = \"my-elbow\"");
    if !exported || renamed == preset {
        t.check(false, "the rig file is written");
        return;
    }
    drive_on_m4f(
        t,
        "my-elbow",
        &renamed,
        &["kind = \"elbow\"", "upper_arm = 0.105\n"],
        0.227,
    );
}

/// The rotopod of chapter 4 (six carriages on one ring, six rods) on the device, as its exported rig file renamed:
/// the M4F plans its homing (six carriages that cannot pass each other), homes them to their index flags, and the
/// stream about its home height ends at the simulator's steps.
pub(crate) fn rotopod_on_m4f(t: &mut Tally) {
    println!("== the rotopod on the emulated Cortex-M4F: load, restart, stream");
    let (exported, preset) = ringpod_text(&["presets", "--export", "rotopod-ch4"]);
    let renamed = preset.replace("name = \"rotopod-ch4\"", "name = \"my-rotopod\"");
    if !exported || renamed == preset {
        t.check(false, "the rig file is written");
        return;
    }
    drive_on_m4f(
        t,
        "my-rotopod",
        &renamed,
        &["ring_radius = 1.0198\n", "rod_length = 0.98\n"],
        0.7,
    );
}

/// Loads `rig` (named `name`) into the emulated controller, restarts it into the stored rig, checks that `device rig
/// show` gives it back (`shown` among its lines), and streams a CSV about home height `z0` (m) into it and into the
/// simulator with the same file: both end at the same steps, not the trainer model's.
fn drive_on_m4f(t: &mut Tally, name: &str, rig_text: &str, shown_lines: &[&str], z0: f64) {
    let dir = std::env::temp_dir().join(format!("ringpod-qemu-{name}-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let (rig, input) = (dir.join(format!("{name}.toml")), dir.join("input.csv"));
    if std::fs::write(&rig, rig_text).is_err() || write_input_about(&input, z0).is_err() {
        t.check(false, "the rig file and the input are written");
        return;
    }
    let Some(emulated) = start_or_fail(t, &[]) else {
        return;
    };
    let pty = emulated.pty.as_str();
    let (rig_file, input_file) = (rig.to_string_lossy().to_string(), input.to_string_lossy().to_string());
    let loaded = ringpod_text(&["device", "rig", "load", &rig_file, "--port", pty]).0;
    let (restarted, said) = ringpod_text(&["device", "restart", "--port", pty]);
    let printed = emulated.wait_for(Duration::from_secs(10), |l| l.trim() == "READY");
    println!("restart: {} / {printed:?}", said.trim());
    let (_, shown) = ringpod_text(&["device", "rig", "show", "--port", pty]);
    let banner = format!("RIG {name} (Stored)");
    t.check(
        loaded
            && restarted
            && said.contains(&format!("running {name} (stored)"))
            && printed.is_ok_and(|l| l.contains(&banner))
            && shown.contains(&format!("name = \"{name}\""))
            && shown_lines.iter().all(|l| shown.contains(l)),
        &format!("{name}: a rig file loaded into the emulated controller is stored and runs after a restart"),
    );
    let args = ["--input", &input_file, "--quiet", "--report-json"];
    let emu = ringpod_json(&[&["stream", "--port", pty][..], &args].concat());
    let sim = ringpod_json(&[&["stream", "--sim", "--fast", "--geometry", &rig_file][..], &args].concat());
    let model = ringpod_json(&[&["stream", "--sim", "--fast"][..], &args].concat());
    let _ = std::fs::remove_dir_all(&dir);
    // The trainer model given the same input ends elsewhere, or refuses it outright (a rig's input can lie wholly
    // outside the model's envelope): either way the stored rig made the difference.
    let model_steps = model.as_ref().ok().map(|m| m["final_steps"].clone());
    match (&emu, &sim) {
        (Ok(e), Ok(s)) => {
            println!(
                "{name}: emulated final steps {}, simulator {}, the trainer model {}",
                e["final_steps"],
                s["final_steps"],
                model_steps
                    .as_ref()
                    .map_or("refused the input".to_string(), |m| m.to_string())
            );
            t.check(
                e["state"] == "Ready"
                    && e["counts_agree"] == true
                    && e["final_steps"] == s["final_steps"]
                    && model_steps.as_ref() != Some(&e["final_steps"]),
                &format!("{name}: the emulated controller drives the stored rig to the simulator's steps for it"),
            );
        }
        _ => {
            eprintln!("{emu:?} {sim:?} {model:?}");
            t.check(
                false,
                &format!("{name}: stream into the emulated controller's rig and the simulator's"),
            );
        }
    }
    drop(emulated);
}

//! The spare axes from the workbench, against `ringpod ui --sim` started with a rig file that fits axis 7: the pages
//! are told its position, a jog and a value move its counted steps by what was asked, the platform held, and an
//! axis that is not fitted or not a spare one is refused by name.

use std::time::Duration;

use serde_json::{json, Value};

use super::workbench::{Page, Workbench};
use super::{homed, is_reply};

/// The trainer model with the supply senses off (axis 7 takes their pins) and axis 7 fitted, 400 steps per unit.
fn rig_file(dir: &std::path::Path) -> std::path::PathBuf {
    let path = super::rig::trainer(dir);
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[supervisor]\nlogic_sense = false\npower_sense = false\nlogic_settle_ms = 100\npower_settle_ms = 200\n\
           supply_timeout_ms = 1000\ndriver_off_ms = 20\ndischarge_ms = 500\n\n[[spare]]\nenabled = true\n\
           steps_per_unit = 400.0\nvelocity = 50.0\nacceleration = 500.0\ntravel = [-5.0, 120.0]\n";
    std::fs::write(&path, text).unwrap();
    path
}

/// The next spare-axes message.
fn spare(page: &mut Page) -> Value {
    page.until(Duration::from_secs(10), |m| m["type"] == "spare").unwrap()
}

/// The reply to `request`: whether it was done, and its words.
fn ask(page: &mut Page, request: Value) -> (bool, String) {
    let id = page.send(request);
    let reply = page.until(Duration::from_secs(60), |m| is_reply(m, id)).unwrap();
    (
        reply["ok"] == true,
        reply["text"].as_str().unwrap_or_default().to_owned(),
    )
}

/// The platform's counted steps in the next frame.
fn platform_steps(page: &mut Page) -> Value {
    page.until(Duration::from_secs(10), |m| m["type"] == "frame").unwrap()["steps"].clone()
}

#[test]
fn a_jog_and_a_value_move_axis_7s_counted_steps_and_hold_the_platform() {
    let dir = std::env::temp_dir().join(format!("ringpod-ui-spare-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rig = rig_file(&dir);
    let bench = Workbench::start(&["--geometry", rig.to_str().unwrap()]);
    let mut page = bench.page();
    let first = spare(&mut page);
    assert_eq!(first["fitted"], json!([true, false]), "{first}");
    assert_eq!(first["steps"], json!([0, 0]), "{first}");

    homed(&mut page);
    let held = platform_steps(&mut page);
    // 2.5 units at 400 steps each, then to -1.25 (1,500 steps back).
    let (ok, text) = ask(&mut page, json!({ "do": "spare_jog", "axis": 7, "distance": 2.5 }));
    assert!(ok, "{text}");
    assert!(text.contains("1000 steps"), "{text}");
    let after = spare(&mut page);
    assert_eq!(after["steps"], json!([1_000, 0]), "{after}");
    assert!((after["position"][0].as_f64().unwrap() - 2.5).abs() < 1e-9, "{after}");
    let (ok, text) = ask(&mut page, json!({ "do": "spare_to", "axis": 7, "value": -1.25 }));
    assert!(ok, "{text}");
    assert_eq!(spare(&mut page)["steps"], json!([-500, 0]));
    assert_eq!(platform_steps(&mut page), held, "the platform held its pose");

    // Beyond its travel it stops at the end (-5 units), as a stream's column does.
    let (ok, text) = ask(&mut page, json!({ "do": "spare_jog", "axis": 7, "distance": -100 }));
    assert!(ok, "{text}");
    assert_eq!(spare(&mut page)["steps"], json!([-2_000, 0]));

    for (request, why) in [
        (
            json!({ "do": "spare_jog", "axis": 8, "distance": 1 }),
            "axis 8 is not fitted",
        ),
        (
            json!({ "do": "spare_to", "axis": 3, "value": 1 }),
            "the spare axes are 7 and 8, not 3",
        ),
    ] {
        let (ok, text) = ask(&mut page, request);
        assert!(!ok && text.contains(why), "{text}");
    }
    assert_eq!(spare(&mut page)["steps"], json!([-2_000, 0]), "a refusal moves nothing");
    let _ = std::fs::remove_dir_all(&dir);
}

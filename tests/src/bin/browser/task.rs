//! A rig builder's task, at each screen size: an F1 session from Off with the simulated device, the Live view read
//! (the roll chart's size and caption), the F1 profile chosen in the Cueing panel, the pitch tilt raised and the
//! live pitch seen to grow, the profile saved, the page reloaded and the profile found again. Each step is checked
//! on what is on screen: positions, sizes, text.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use fantoccini::Client;
use serde_json::{json, Value};

use crate::page::{click, js, screenshot, tab, until, STATE};
use crate::process::free_port;

/// The profile file the workbench starts with (`ringpod ui --cue-config`): an F1 profile with a gentle tilt.
pub const PROFILES: &str = "# the rig builder's cueing file\n[profiles.f1]\ntilt_scale = [0.4, 0.4]\n";

/// An F1 24 motion packet (the format's header, the player's car first): level, braking at `g` g.
fn f1_packet(time: f32, g: f32) -> Vec<u8> {
    let mut p = vec![0u8; 29 + 60 * 22];
    p[0..2].copy_from_slice(&2024u16.to_le_bytes());
    p[2] = 24;
    p[15..19].copy_from_slice(&time.to_le_bytes());
    let car = 29;
    // Forward along world z, right along world x: level, so gravity is all vertical.
    p[car + 28..car + 30].copy_from_slice(&32767i16.to_le_bytes());
    p[car + 30..car + 32].copy_from_slice(&32767i16.to_le_bytes());
    // Lateral, longitudinal, vertical g: a steady braking (longitudinal negative).
    p[car + 40..car + 44].copy_from_slice(&(-g).to_le_bytes());
    p
}

/// Sends a steady braking at 60 Hz until `stop` is set: a game running.
fn game(port: u16, stop: Arc<AtomicBool>) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let Ok(socket) = std::net::UdpSocket::bind("127.0.0.1:0") else {
            return;
        };
        let mut t = 0.0f32;
        while !stop.load(Ordering::SeqCst) {
            let _ = socket.send_to(&f1_packet(t, 0.1), ("127.0.0.1", port));
            t += 1.0 / 60.0;
            std::thread::sleep(Duration::from_millis(16));
        }
    })
}

/// The largest |pitch| (deg about home) the live history holds over its last `s` seconds.
async fn live_pitch(c: &Client, s: f64) -> Result<f64, String> {
    let v = js(
        c,
        &format!(
            "(() => {{ const h = window.ringpod.history, t1 = h.t[h.t.length - 1]; let m = 0; \
             h.t.forEach((t, i) => {{ if (t >= t1 - {s}) m = Math.max(m, Math.abs(h.pose[i][4])); }}); return m; }})()"
        ),
    )
    .await?;
    v.as_f64().ok_or_else(|| format!("no pitch history: {v}"))
}

/// The task at one window size; `raise` is the pitch tilt set.
pub async fn at_size(
    c: &Client,
    url: &str,
    (w, h): (u32, u32),
    raise: f64,
    shots: Option<&Path>,
) -> Result<String, String> {
    c.set_window_size(w, h)
        .await
        .map_err(|e| format!("window {w}x{h}: {e}"))?;
    c.goto(url).await.map_err(|e| e.to_string())?;
    until(
        c,
        "window.ringpod.rig && window.ringpod.frames > 3",
        Duration::from_secs(20),
    )
    .await?;
    until(c, &format!("{STATE} === 'Off'"), Duration::from_secs(30)).await?;
    f1_offered(c).await?;
    let port = free_port()?;
    js(
        c,
        &format!("(document.getElementById('udp-port').value = '{port}', true)"),
    )
    .await?;
    until(
        c,
        "!document.getElementById('run-udp').disabled",
        Duration::from_secs(20),
    )
    .await?;
    click(c, "#run-udp").await?;
    let stop = Arc::new(AtomicBool::new(false));
    let sender = game(port, stop.clone());
    // Beside the panels' pictures at each size (the book's).
    let sizes = shots.map(|d| d.join("sizes"));
    let ran = async {
        until(
            c,
            &format!("window.ringpod.frame.streaming && {STATE} === 'Running' && window.ringpod.frame.cue_input"),
            Duration::from_secs(60),
        )
        .await?;
        let session = until(
            c,
            "document.getElementById('live-session').textContent",
            Duration::from_secs(5),
        )
        .await?;
        if !session.as_str().unwrap_or("").contains("profile f1") {
            return Err(format!("the session did not take the F1 profile: {session}"));
        }
        let live = live_view(c, w, h).await?;
        screenshot(c, sizes.as_deref(), &format!("task-live-{w}x{h}")).await?;
        let tuned = tune(c, raise).await?;
        screenshot(c, sizes.as_deref(), &format!("task-cueing-{w}x{h}")).await?;
        Ok::<_, String>(format!("{live}; {tuned}"))
    }
    .await;
    // 4. Reloaded (the page going stops its session): the profile is found again as saved.
    c.refresh().await.map_err(|e| e.to_string())?;
    stop.store(true, Ordering::SeqCst);
    let _ = sender.join();
    let ran = ran?;
    until(
        c,
        "window.ringpod.rig && window.ringpod.frames > 3",
        Duration::from_secs(20),
    )
    .await?;
    choose_f1(c).await?;
    let found = until(
        c,
        &format!(
            "(() => {{ const i = document.querySelector('[data-path=\"tilt_scale.0\"]'); \
                  return i && Math.abs(+i.value - {raise}) < 1e-9 && i.value; }})()"
        ),
        Duration::from_secs(20),
    )
    .await?;
    until(c, &format!("{STATE} === 'Off'"), Duration::from_secs(30)).await?;
    Ok(format!("{ran}; after a reload profile f1 has pitch tilt {found}"))
}

/// Step 1: the F1 session from the Control panel, offered by the game's name with its default port, what to set
/// in the game and the profile it takes.
async fn f1_offered(c: &Client) -> Result<(), String> {
    tab(c, "control").await?;
    until(
        c,
        "document.getElementById('udp-game').options.length > 1",
        Duration::from_secs(10),
    )
    .await?;
    let chosen = js(
        c,
        "(() => { const s = document.getElementById('udp-game'); \
         s.value = [...s.options].find((o) => o.textContent.startsWith('F1 23')).value; \
         s.dispatchEvent(new Event('change')); \
         return [s.selectedOptions[0].textContent, document.getElementById('udp-port').value, \
         document.getElementById('udp-format').value, document.getElementById('udp-game-help').textContent]; })()",
    )
    .await?;
    let help = chosen[3].as_str().unwrap_or("");
    if chosen[1] != json!("20777")
        || chosen[2] != json!("f1")
        || !help.contains("UDP Telemetry On")
        || !help.contains("profile f1")
    {
        return Err(format!(
            "the F1 game is not offered with its port, settings and profile: {chosen}"
        ));
    }
    Ok(())
}

/// Step 2, the Live view: the platform beside the six charts, none below the fold; the roll chart wide enough, drawn
/// at its size times the pixel ratio, its caption readable, in degrees, with the game's cue.
async fn live_view(c: &Client, w: u32, h: u32) -> Result<String, String> {
    tab(c, "live").await?;
    let roll = until(
        c,
        "(() => { window.scrollTo(0, 0); const c = document.getElementById('live-roll'); \
         const r = c.getBoundingClientRect(), v = document.getElementById('view3d').getBoundingClientRect(); \
         const cap = c.parentElement.querySelector('figcaption'); const dpr = window.devicePixelRatio; \
         const all = ['surge', 'sway', 'heave', 'roll', 'pitch', 'yaw'].map((a) => \
           document.getElementById('live-' + a).getBoundingClientRect()); \
         const text = [...document.querySelectorAll('#panel-live figcaption, #panel-live .lamp, #live-session, #panel-live h2 .small, #counters td')] \
           .map((e) => parseFloat(getComputedStyle(e).fontSize)); \
         return cap.textContent.includes('deg/s') && { css: [Math.round(r.width), Math.round(r.height)], \
           drawn: [c.width, c.height], dpr, caption: cap.textContent.trim(), \
           whole: [...document.querySelectorAll('#live-charts figcaption')].every((e) => e.scrollWidth <= e.clientWidth + 1), \
           beside: v.right <= r.left || v.right <= Math.min(...all.map((a) => a.left)), \
           onScreen: all.every((a) => a.top >= 0 && a.bottom <= window.innerHeight && a.width >= 300), \
           smallestText: Math.min(...text), inner: [window.innerWidth, window.innerHeight], \
           tickUnit: document.getElementById('count-tick-cost').textContent }; })()",
        Duration::from_secs(10),
    )
    .await?;
    let num = |v: &Value| v.as_f64().unwrap_or(0.0);
    let (cw, ch, dw, dh, dpr) = (
        num(&roll["css"][0]),
        num(&roll["css"][1]),
        num(&roll["drawn"][0]),
        num(&roll["drawn"][1]),
        num(&roll["dpr"]),
    );
    let caption = roll["caption"].as_str().unwrap_or("");
    let mut wrong = Vec::new();
    if w == 1366 && cw < 300.0 {
        wrong.push("the roll chart under 300 CSS px wide");
    }
    if (dw - (cw * dpr).round()).abs() > 1.0 || (dh - (ch * dpr).round()).abs() > 1.0 {
        wrong.push("the roll chart not drawn at its CSS size times the pixel ratio");
    }
    if !caption.starts_with("roll")
        || !caption.contains("deg")
        || !caption.contains("deg/s")
        || !caption.contains("reach")
    {
        wrong.push("the roll caption does not say roll in deg, the cue in deg/s and the reach used");
    }
    if roll["whole"] != json!(true) {
        wrong.push("a caption cut off");
    }
    if roll["beside"] != json!(true) || roll["onScreen"] != json!(true) {
        wrong.push("the charts are not beside the platform, on screen and 300 px wide");
    }
    if num(&roll["smallestText"]) < 12.0 {
        wrong.push("text under 12 px");
    }
    if !roll["tickUnit"].as_str().unwrap_or("").ends_with(" ns") {
        wrong.push("the tick cost without its unit");
    }
    if wrong.is_empty() {
        Ok(format!("at {w}x{h} Live: {roll}"))
    } else {
        Err(format!("at {w}x{h}: {}: {roll}", wrong.join("; ")))
    }
}

/// The Cueing panel, its F1 profile chosen from the list as a person chooses it.
async fn choose_f1(c: &Client) -> Result<(), String> {
    tab(c, "cueing").await?;
    until(
        c,
        "document.querySelector('#profile option[value=f1]')",
        Duration::from_secs(20),
    )
    .await?;
    js(c, "(() => { const s = document.getElementById('profile'); s.value = 'f1'; s.dispatchEvent(new Event('change')); return true; })()").await?;
    Ok(())
}

/// Step 3: the F1 profile chosen, the pitch tilt raised: applied live, the live pitch grows on the Cueing panel's
/// charts; the profile saved.
async fn tune(c: &Client, raise: f64) -> Result<String, String> {
    choose_f1(c).await?;
    let before_tilt = until(
        c,
        "(() => { const i = document.querySelector('[data-path=\"tilt_scale.0\"]'); return i && document.getElementById('profile').value === 'f1' && i.value; })()",
        Duration::from_secs(10),
    )
    .await?;
    // The live charts are here while the session runs; the optimal cueing's fields are not (classical chosen).
    let placed = js(
        c,
        "(() => { const r = document.getElementById('live-pitch').getBoundingClientRect(); \
         return [document.getElementById('live-charts').parentElement.id, r.width > 0 && r.top < window.innerHeight, \
         !document.querySelector('[data-path^=\"optimal.\"]'), \
         document.querySelector('[data-path=\"tilt_scale.0\"]').closest('fieldset').dataset.group]; })()",
    )
    .await?;
    if placed != json!(["cue-live", true, true, "surge"]) {
        return Err(format!(
            "while tuning, the live charts are not in view or the controls not the classical's: {placed}"
        ));
    }
    // Settled on the profile's tilt first.
    tokio::time::sleep(Duration::from_secs(5)).await;
    let before = live_pitch(c, 2.0).await?;
    let applied = js(c, "window.ringpod.cueApplied || 0").await?.as_u64().unwrap_or(0);
    js(
        c,
        &format!(
            "(() => {{ const i = document.querySelector('[data-path=\"tilt_scale.0\"]'); i.value = '{raise}'; \
             i.dispatchEvent(new Event('input')); return true; }})()"
        ),
    )
    .await?;
    until(
        c,
        &format!("(window.ringpod.cueApplied || 0) > {applied}"),
        Duration::from_secs(10),
    )
    .await?;
    tokio::time::sleep(Duration::from_secs(6)).await;
    let after = live_pitch(c, 2.0).await?;
    if after < before * 1.5 + 0.2 {
        return Err(format!(
            "the live pitch did not grow with the tilt ({before_tilt} -> {raise}): {before:.2} -> {after:.2} deg"
        ));
    }
    click(c, "#profile-save").await?;
    let saved = until(
        c,
        "window.ringpod.profileSaved === 'f1' && document.getElementById('cue-status').textContent.includes('saved') && document.getElementById('cue-status').textContent",
        Duration::from_secs(10),
    )
    .await?;
    Ok(format!(
        "pitch tilt {before_tilt} -> {raise}: the live pitch {before:.2} -> {after:.2} deg; {saved}"
    ))
}

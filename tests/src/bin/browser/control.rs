//! The Live and Control panels: connecting, powering up and homing, streams, STOP, a page that goes away.

use std::path::Path;
use std::time::Duration;

use fantoccini::{Client, Locator};
use serde_json::{json, Value};

use crate::page::{click, js, screenshot, tab, until, STATE};
use crate::process::free_port;

pub async fn connects(c: &Client, url: &str) -> Result<String, String> {
    c.goto(url).await.map_err(|e| e.to_string())?;
    until(
        c,
        "window.ringpod && window.ringpod.frames > 3 && window.ringpod.rig",
        Duration::from_secs(20),
    )
    .await?;
    let state = js(c, STATE).await?;
    let pose = js(c, "document.getElementById('view3d').dataset.pose").await?;
    Ok(format!("state {state}, pose {pose}"))
}

pub async fn enable_and_home(c: &Client, shots: Option<&Path>) -> Result<String, String> {
    tab(c, "control").await?;
    let why = js(
        c,
        "document.querySelector('[data-do=home]').disabled && document.querySelector('[data-do=home]').title",
    )
    .await?;
    if !why.as_str().is_some_and(|w| w.contains("not possible")) {
        return Err(format!("Home while Off is not disabled with a reason: {why}"));
    }
    click(c, "[data-do=enable]").await?;
    until(
        c,
        "!document.querySelector('[data-do=home]').disabled",
        Duration::from_secs(15),
    )
    .await?;
    click(c, "[data-do=home]").await?;
    until(c, &format!("{STATE} === 'Ready'"), Duration::from_secs(60)).await?;
    screenshot(c, shots, "control").await?;
    Ok(format!("Home was disabled ({why}), then enabled; homed to Ready"))
}

pub async fn demo_runs(c: &Client, shots: Option<&Path>) -> Result<String, String> {
    js(c, "(document.getElementById('motion-seconds').value = '60', true)").await?;
    click(c, "#run-motion").await?;
    until(
        c,
        &format!("{STATE} === 'Running' && window.ringpod.frame.streaming"),
        Duration::from_secs(30),
    )
    .await?;
    let before = js(
        c,
        "[window.ringpod.frame.applied, document.getElementById('view3d').dataset.pose]",
    )
    .await?;
    tokio::time::sleep(Duration::from_secs(3)).await;
    let after = js(
        c,
        "[window.ringpod.frame.applied, document.getElementById('view3d').dataset.pose]",
    )
    .await?;
    let applied = |v: &Value| v[0].as_u64().unwrap_or(0);
    if applied(&after) <= applied(&before) + 100 {
        return Err(format!("the applied counter did not advance: {before} -> {after}"));
    }
    if after[1] == before[1] {
        return Err(format!("the 3D view's pose did not move: {}", after[1]));
    }
    // The counters on screen are the frame's.
    let shown = js(c, "+document.getElementById('count-applied').textContent").await?;
    if shown.as_u64().unwrap_or(0) < applied(&after) {
        return Err(format!("the counters show {shown}, the frame {}", applied(&after)));
    }
    let busy = js(c, "document.querySelector('[data-do=home]').title").await?;
    if !busy.as_str().is_some_and(|w| w.contains("stream is running")) {
        return Err(format!("Home during a stream is not gated: {busy}"));
    }
    tab(c, "live").await?;
    tokio::time::sleep(Duration::from_millis(800)).await;
    screenshot(c, shots, "live").await?;
    Ok(format!(
        "applied {} -> {}, pose {} -> {}",
        applied(&before),
        applied(&after),
        before[1],
        after[1]
    ))
}

pub async fn stop_button(c: &Client) -> Result<String, String> {
    // Homed and Ready: the demo again, straight away.
    tab(c, "control").await?;
    until(
        c,
        "!document.getElementById('run-motion').disabled",
        Duration::from_secs(20),
    )
    .await?;
    click(c, "#run-motion").await?;
    until(
        c,
        &format!("{STATE} === 'Running' && window.ringpod.frame.streaming"),
        Duration::from_secs(30),
    )
    .await?;
    click(c, "#halt").await?;
    until(
        c,
        &format!("{STATE} === 'Off' && !window.ringpod.frame.streaming"),
        Duration::from_secs(30),
    )
    .await?;
    let replies = js(c, "window.ringpod.replies.map(r => r.text).join(' | ')").await?;
    Ok(format!("Running -> Off; replies: {replies}"))
}

/// The space bar is STOP with the focus anywhere but where a space is typed: on the page, a checkbox (which it does
/// not toggle), a select and a number field.
pub async fn space_bar(c: &Client) -> Result<String, String> {
    tab(c, "control").await?;
    for focus in ["body", "#file-degrees", "#motion", "#motion-seconds"] {
        click(c, "[data-do=enable]").await?;
        until(c, &format!("{STATE} !== 'Off'"), Duration::from_secs(10)).await?;
        let before = js(c, "document.getElementById('file-degrees').checked").await?;
        c.find(Locator::Css(focus))
            .await
            .map_err(|e| e.to_string())?
            .send_keys(" ")
            .await
            .map_err(|e| e.to_string())?;
        until(c, &format!("{STATE} === 'Off'"), Duration::from_secs(20))
            .await
            .map_err(|e| format!("space on {focus}: {e}"))?;
        let after = js(c, "document.getElementById('file-degrees').checked").await?;
        if before != after {
            return Err(format!("space on {focus} toggled the checkbox"));
        }
    }
    Ok("enabled, then space on the page, a checkbox, a select and a number field: Off each time".into())
}

pub async fn udp_session(c: &Client) -> Result<String, String> {
    tab(c, "control").await?;
    let port = free_port()?;
    js(
        c,
        &format!(
            "(document.getElementById('udp-port').value = '{port}', document.getElementById('udp-holds').value = 'poses', true)"
        ),
    )
    .await?;
    until(
        c,
        "!document.getElementById('run-udp').disabled",
        Duration::from_secs(20),
    )
    .await?;
    click(c, "#run-udp").await?;
    // It powers up and homes first (from where the demo and STOP left the platform), then waits for datagrams.
    until(
        c,
        &format!("window.ringpod.frame.streaming && ({STATE} === 'Ready' || {STATE} === 'Running')"),
        Duration::from_secs(60),
    )
    .await?;
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    for _ in 0..150 {
        socket
            .send_to(b"0 0 0.237 0 0 0", ("127.0.0.1", port))
            .map_err(|e| e.to_string())?;
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    // The platform is led in to the 10 mm higher pose the datagrams hold.
    let z = until(
        c,
        "Math.abs(window.ringpod.frame.pose[2] - 0.237) < 0.0005 && window.ringpod.frame.pose[2]",
        Duration::from_secs(10),
    )
    .await?;
    click(c, "#halt").await?;
    until(c, &format!("{STATE} === 'Off'"), Duration::from_secs(30)).await?;
    let report = until(
        c,
        "window.ringpod.replies.map(r => r.text).filter(t => t.startsWith('interrupted') && !t.startsWith('interrupted: 0 ')).pop()",
        Duration::from_secs(10),
    )
    .await?;
    Ok(format!("followed to z = {z}; {report}"))
}

pub async fn lost_page(c: &Client, url: &str) -> Result<String, String> {
    // The demo of the check before still runs (60 s): its page goes away, and another one watches.
    let running = js(c, &format!("{STATE} === 'Running' && window.ringpod.frame.streaming")).await?;
    if running != json!(true) {
        return Err("no stream runs to begin with".into());
    }
    c.goto("about:blank").await.map_err(|e| e.to_string())?;
    // Past the workbench's grace (2 s) with no page: it powers down too.
    tokio::time::sleep(Duration::from_secs(4)).await;
    c.goto(url).await.map_err(|e| e.to_string())?;
    let state = until(
        c,
        &format!(
            "window.ringpod && window.ringpod.frame && !window.ringpod.frame.streaming && {STATE} === 'Off' && {STATE}"
        ),
        Duration::from_secs(30),
    )
    .await?;
    // The new page's log says what happened before it opened, numbered whole (a tenth line reads "10.", not "0.").
    let told = until(
        c,
        "[...document.querySelectorAll('#log li')].map((l) => l.textContent)\
         .find((t) => t.includes('before this page opened') && t.includes('went away')) || false",
        Duration::from_secs(10),
    )
    .await?;
    let numbers = js(c, "getComputedStyle(document.getElementById('log')).listStylePosition").await?;
    if numbers != json!("inside") {
        return Err(format!(
            "the log's numbers are outside its lines ({numbers}), where a wide one is cut"
        ));
    }
    Ok(format!(
        "the stream of the page that left ended, and with no page left the platform powered down; device {state}; \
         the new page's log says {told}"
    ))
}

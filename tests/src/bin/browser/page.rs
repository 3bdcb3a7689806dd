//! Driving the page: JavaScript in it, waiting for a condition, clicks, tabs, screenshots.

use std::path::Path;
use std::time::{Duration, Instant};

use fantoccini::{Client, Locator};
use serde_json::{json, Value};

/// Evaluates a JavaScript expression in the page.
pub async fn js(c: &Client, expression: &str) -> Result<Value, String> {
    c.execute(&format!("return ({expression});"), vec![])
        .await
        .map_err(|e| format!("{expression}: {e}"))
}

/// Polls `expression` until it is truthy; returns its value, or says what it was last.
pub async fn until(c: &Client, expression: &str, within: Duration) -> Result<Value, String> {
    let deadline = Instant::now() + within;
    loop {
        let v = js(c, expression).await?;
        let truthy = !matches!(v, Value::Null | Value::Bool(false)) && v != json!(0) && v != json!("");
        if truthy {
            return Ok(v);
        }
        if Instant::now() > deadline {
            let state = js(
                c,
                "window.ringpod && window.ringpod.frame && window.ringpod.frame.state",
            )
            .await
            .unwrap_or(Value::Null);
            return Err(format!(
                "`{expression}` not true within {within:?} (device state {state})"
            ));
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

pub async fn click(c: &Client, css: &str) -> Result<(), String> {
    // Into the middle of the view first, as a user scrolls to what they click: WebDriver scrolls an element only as
    // far as the view's edge, where the Control panel's log (sticky at the bottom) covers it.
    let selector = serde_json::to_string(css).map_err(|e| e.to_string())?;
    js(
        c,
        &format!("(document.querySelector({selector}) || document.body).scrollIntoView({{block: 'center'}}), true"),
    )
    .await?;
    c.find(Locator::Css(css))
        .await
        .map_err(|e| format!("{css}: {e}"))?
        .click()
        .await
        .map_err(|e| format!("click {css}: {e}"))
}

pub async fn tab(c: &Client, panel: &str) -> Result<(), String> {
    click(c, &format!(".tab[data-panel={panel}]")).await
}

pub async fn screenshot(c: &Client, dir: Option<&Path>, name: &str) -> Result<(), String> {
    let Some(dir) = dir else { return Ok(()) };
    let png = c.screenshot().await.map_err(|e| format!("screenshot: {e}"))?;
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    std::fs::write(dir.join(format!("{name}.png")), png).map_err(|e| e.to_string())
}

pub const STATE: &str = "window.ringpod.frame && window.ringpod.frame.state";

/// Every panel at the two screen sizes a newcomer has, as `sizes/PANEL-WxH.png` (the book's layout).
pub async fn sizes(c: &Client, dir: &Path) -> Result<String, String> {
    let dir = &dir.join("sizes");
    let mut saved = 0;
    for (w, h) in [(1366, 768), (1920, 1080)] {
        c.set_window_size(w, h)
            .await
            .map_err(|e| format!("window {w}x{h}: {e}"))?;
        for panel in ["live", "control", "cueing", "rig", "runs"] {
            tab(c, panel).await?;
            tokio::time::sleep(Duration::from_millis(600)).await;
            screenshot(c, Some(dir), &format!("{panel}-{w}x{h}")).await?;
            saved += 1;
        }
    }
    Ok(format!("{saved} pictures in {}", dir.display()))
}

/// At 1366x768 (the smallest screen the workbench is laid out for) the Control panel's every button that starts
/// something is on screen, above the log that stays at the bottom, without scrolling; then the window is put back.
pub async fn control_fits(c: &Client) -> Result<String, String> {
    let (w, h) = c.get_window_size().await.map_err(|e| format!("window size: {e}"))?;
    c.set_window_size(1366, 768)
        .await
        .map_err(|e| format!("window 1366x768: {e}"))?;
    tab(c, "control").await?;
    tokio::time::sleep(Duration::from_millis(300)).await;
    let placed = js(
        c,
        "(() => { window.scrollTo(0, 0); const log = document.querySelector('#panel-control .log-card') \
         .getBoundingClientRect().top; \
         return ['enable', 'run-motion', 'stream-file', 'run-udp', 'jog'].map((id) => { \
         const b = id === 'enable' ? document.querySelector('[data-do=enable]') : document.getElementById(id); \
         const r = b.getBoundingClientRect(); return [id, r.top >= 0 && r.bottom <= log, Math.round(r.bottom), \
         Math.round(log)]; }); })()",
    )
    .await?;
    c.set_window_size(w as u32, h as u32)
        .await
        .map_err(|e| format!("window back to {w}x{h}: {e}"))?;
    let rows = placed.as_array().cloned().unwrap_or_default();
    if rows.len() == 5 && rows.iter().all(|r| r[1] == true) {
        Ok(format!("every source's button above the log: {placed}"))
    } else {
        Err(format!(
            "below the fold or under the log ([id, on screen, bottom, log's top]): {placed}"
        ))
    }
}

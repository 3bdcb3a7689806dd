//! The Rig panel's form as a rig builder uses it, at one window size: the ring radius changed in mm and the
//! pictures following it, a bad value refused naming the field as shown with its unit and range, the rig saved to
//! the file `ringpod ui --geometry` was started with (read back by `ringpod rig check`), found again after a reload.

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use fantoccini::Client;
use serde_json::Value;

use crate::page::{click, js, screenshot, tab, until};

const RADIUS: &str = "document.getElementById('rig-f-ring-radius')";
const DRIVABLE: &str = "document.getElementById('rig-messages').textContent.includes('drivable: yes')";

/// What the pictures show: the workspace map's legend (its ring's radius in mm) and a digest of both canvases'
/// pixels, which change with the geometry.
const PICTURE: &str = "(() => { const d = (id) => { const u = document.getElementById(id).toDataURL(); \
    let h = 0; for (let i = 0; i < u.length; i++) h = (h * 31 + u.charCodeAt(i)) | 0; return h; }; \
    return [document.getElementById('rig-legend').textContent, d('rig-view'), d('rig-section')]; })()";

async fn type_radius(c: &Client, mm: &str) -> Result<(), String> {
    js(
        c,
        &format!(
            "(() => {{ const i = {RADIUS}; i.value = '{mm}'; i.dispatchEvent(new Event('input')); return true; }})()"
        ),
    )
    .await
    .map(|_| ())
}

/// Where an element is on screen, in CSS px: `[left, top, width, height]`.
async fn rect(c: &Client, id: &str) -> Result<Value, String> {
    js(
        c,
        &format!(
            "(() => {{ const r = document.getElementById('{id}').getBoundingClientRect(); \
             return [r.left, r.top, r.width, r.height].map(Math.round); }})()"
        ),
    )
    .await
}

/// What the check is given: the page's URL, the rig file the server was started with, the CLI, where pictures go.
pub struct Given<'a> {
    pub url: &'a str,
    pub rig_file: &'a Path,
    pub cli: &'a Path,
    pub shots: Option<&'a Path>,
}

pub async fn rig_form(c: &Client, given: &Given<'_>, size: (u32, u32)) -> Result<String, String> {
    let rig_file = given.rig_file;
    let original = std::fs::read(rig_file).map_err(|e| format!("{}: {e}", rig_file.display()))?;
    let result = steps(c, given, size).await;
    // The next check starts from the same file.
    std::fs::write(rig_file, original).map_err(|e| format!("{}: {e}", rig_file.display()))?;
    result
}

/// 306 mm typed and saved: the file holds 0.306 m and `ringpod rig check` reads it; reloaded, the form shows it.
async fn save_and_reload(c: &Client, url: &str, rig_file: &Path, cli: &Path) -> Result<(Value, Value), String> {
    type_radius(c, "306").await?;
    until(c, DRIVABLE, Duration::from_secs(10)).await?;
    click(c, "#rig-save").await?;
    let saved = until(
        c,
        "document.getElementById('rig-status').textContent.startsWith('saved to') && \
         document.getElementById('rig-status').textContent",
        Duration::from_secs(10),
    )
    .await?;
    let text = std::fs::read_to_string(rig_file).map_err(|e| e.to_string())?;
    if !text.contains("ring_radius = 0.306\n") {
        return Err(format!("the file does not hold 0.306 m: {text}"));
    }
    let check = Command::new(cli)
        .args(["rig", "check"])
        .arg(rig_file)
        .output()
        .map_err(|e| format!("rig check: {e}"))?;
    // Its exit status says whether the spec ranges are covered (at 306 mm the pitch is not, wholly): what matters
    // here is that the command line reads the file the form saved as the same rig.
    let report = String::from_utf8_lossy(&check.stdout);
    if !(report.contains("ring radius 0.306 m") && report.contains("drivable: yes")) {
        return Err(format!(
            "`ringpod rig check` reads the saved file otherwise: {report}{}",
            String::from_utf8_lossy(&check.stderr)
        ));
    }
    // Reloaded, the form shows the file as saved.
    c.goto(url).await.map_err(|e| e.to_string())?;
    until(c, "window.ringpod && window.ringpod.rig", Duration::from_secs(20)).await?;
    tab(c, "rig").await?;
    let again = until(
        c,
        &format!("{RADIUS} && {DRIVABLE} && {RADIUS}.value"),
        Duration::from_secs(20),
    )
    .await?;
    if again != "306" {
        return Err(format!("after a reload the ring radius is {again}, not 306 mm"));
    }
    Ok((saved, again))
}

/// Far down the form (the last axis's homing), the workspace map is still on screen; the page scrolled back.
async fn map_stays(c: &Client) -> Result<Value, String> {
    // Far down the form (the last axis's homing), the workspace map is still on screen.
    let map = js(
        c,
        "(() => { document.getElementById('rig-f-homing-axes-5-slow').closest('details').open = true; \
         document.getElementById('rig-f-homing-axes-5-slow').scrollIntoView({block: 'center'}); \
         const r = document.getElementById('rig-section').getBoundingClientRect(); \
         const out = [Math.round(window.scrollY), Math.round(r.top), Math.round(r.bottom), innerHeight]; \
         window.scrollTo(0, 0); return out; })()",
    )
    .await?;
    let at = |i: usize| map[i].as_f64().unwrap_or(f64::NAN);
    if !(at(0) > 0.0 && at(1) >= 0.0 && at(2) <= at(3)) {
        return Err(format!(
            "scrolled down the form, the map is off screen ([scrollY, top, bottom, inner height]): {map}"
        ));
    }
    Ok(map)
}

async fn steps(c: &Client, given: &Given<'_>, (w, h): (u32, u32)) -> Result<String, String> {
    let Given {
        url,
        rig_file,
        cli,
        shots,
    } = *given;
    c.set_window_size(w, h)
        .await
        .map_err(|e| format!("window {w}x{h}: {e}"))?;
    c.goto(url).await.map_err(|e| e.to_string())?;
    until(c, "window.ringpod && window.ringpod.rig", Duration::from_secs(20)).await?;
    tab(c, "rig").await?;
    until(c, &format!("{RADIUS} && {DRIVABLE}"), Duration::from_secs(20)).await?;
    let shown = js(c, &format!("[{RADIUS}.value, {RADIUS}.getAttribute('aria-label')]")).await?;
    if shown[0] != "286" || shown[1] != "Geometry · ring radius (mm)" {
        return Err(format!("the ring radius is not shown as 286 mm: {shown}"));
    }
    // The axes and their homing in the form, each in its own unit: a carriage turns (deg), a radial length slides
    // (mm).
    let units = js(
        c,
        "['axes-0-steps-per-unit', 'axes-4-steps-per-unit', 'homing-axes-4-search', 'homing-axes-0-fast'] \
         .map((k) => { const i = document.getElementById('rig-f-' + k); \
         return i && i.closest('.rig-row').querySelector('.unit').textContent; })",
    )
    .await?;
    if units != serde_json::json!(["steps/deg", "steps/mm", "mm", "deg/s"]) {
        return Err(format!("the axes' units are not the axes' own: {units}"));
    }
    let map = map_stays(c).await?;
    let before = js(c, PICTURE).await?;
    // The mechanism is drawn at its CSS size x devicePixelRatio: one drawn pixel per screen pixel.
    let drawn = js(
        c,
        "(() => { const v = document.getElementById('rig-view'), r = v.getBoundingClientRect(), d = devicePixelRatio; \
         return [v.width, v.height, r.width, r.height, d]; })()",
    )
    .await?;
    let at = |i: usize| drawn[i].as_f64().unwrap_or(f64::NAN);
    if (at(0) - (at(2) * at(4)).round()).abs() > 0.5 || (at(1) - (at(3) * at(4)).round()).abs() > 0.5 {
        return Err(format!(
            "the mechanism is not drawn 1:1 ([width, height] drawn, CSS, ratio): {drawn}"
        ));
    }
    let sizes = (
        rect(c, "rig-form").await?,
        rect(c, "rig-section").await?,
        rect(c, "rig-save").await?,
    );
    // The ring 20 mm larger: the map's ring and the picture follow.
    type_radius(c, "306").await?;
    let after = until(
        c,
        &format!(
            "{DRIVABLE} && document.getElementById('rig-legend').textContent.includes('radius 306 mm') && {PICTURE}"
        ),
        Duration::from_secs(10),
    )
    .await?;
    if after[1] == before[1] || after[2] == before[2] {
        return Err(format!("the pictures did not change: {before} -> {after}"));
    }
    // A negative radius: refused by name, unit and range; the field marked; nothing drawn.
    type_radius(c, "-5").await?;
    let refusal = until(
        c,
        "document.querySelector('.rig-error') && document.querySelector('.rig-error').textContent",
        Duration::from_secs(10),
    )
    .await?;
    let said = refusal.as_str().unwrap_or("");
    if !(said.contains("Geometry · ring radius (mm)") && said.contains("-5 mm") && said.contains("more than 0 mm")) {
        return Err(format!(
            "the refusal does not name the field, unit and range: {refusal}"
        ));
    }
    let marked = js(
        c,
        &format!("[{RADIUS}.classList.contains('bad'), document.getElementById('rig-save').disabled]"),
    )
    .await?;
    if marked != serde_json::json!([true, true]) {
        return Err(format!(
            "the bad field is not marked, or Save is not off ([marked, Save disabled]): {marked}"
        ));
    }
    // Beside the panels' pictures at each size (the book's).
    let sizes_dir = shots.map(|d| d.join("sizes"));
    screenshot(c, sizes_dir.as_deref(), &format!("rig-refused-{w}x{h}")).await?;
    let (saved, again) = save_and_reload(c, url, rig_file, cli).await?;
    Ok(format!(
        "axes {units}; the map on screen with the form scrolled {map}; mechanism drawn {drawn} ([width, height] drawn, CSS, ratio); 286 -> 306 mm redrawn ({}); -5 mm refused: {said}; {saved}, `rig check` reads it as 306 mm and drivable; {again} after a reload; \
         form {}, map {}, Save {} ([left, top, width, height] CSS px)",
        after[0].as_str().unwrap_or(""),
        sizes.0,
        sizes.1,
        sizes.2
    ))
}

//! The Rig, Cueing and Runs panels.

use std::path::Path;
use std::time::Duration;

use fantoccini::{Client, Locator};
use serde_json::{json, Value};

use crate::page::{js, screenshot, tab, until};

pub async fn rig_editor(c: &Client, url: &str, shots: Option<&Path>) -> Result<String, String> {
    c.goto(url).await.map_err(|e| e.to_string())?;
    until(c, "window.ringpod && window.ringpod.rig", Duration::from_secs(20)).await?;
    tab(c, "rig").await?;
    until(
        c,
        "document.getElementById('rig-messages').textContent.includes('drivable: yes')",
        Duration::from_secs(20),
    )
    .await?;
    screenshot(c, shots, "rig").await?;
    js(
        c,
        "(() => { const t = document.getElementById('rig-text'); \
         t.value = t.value.replace('ring_radius', 'ring_raduis'); \
         t.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    let message = until(
        c,
        "document.querySelector('.rig-error') && document.querySelector('.rig-error').textContent",
        Duration::from_secs(10),
    )
    .await?;
    if !message.as_str().is_some_and(|m| m.contains("ring_raduis")) {
        return Err(format!("the message does not name the key: {message}"));
    }
    // Mended, the rig is drawn again (and the panel is left as a user would find it).
    js(
        c,
        "(() => { const t = document.getElementById('rig-text'); \
         t.value = t.value.replace('ring_raduis', 'ring_radius'); \
         t.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    until(
        c,
        "!document.querySelector('.rig-error') && document.getElementById('rig-messages').textContent.includes('drivable: yes')",
        Duration::from_secs(20),
    )
    .await?;
    Ok(format!(
        "valid rig drawn; the typo says: {message}; mended, drawn again"
    ))
}

pub async fn cueing(c: &Client, shots: Option<&Path>) -> Result<String, String> {
    tab(c, "cueing").await?;
    until(c, "window.ringpod.cueRuns >= 1", Duration::from_secs(20)).await?;
    let first = js(c, "[window.ringpod.cueRuns, window.ringpod.cuePeak]").await?;
    screenshot(c, shots, "cueing").await?;
    // Three times the surge scale: the replay runs again and delivers more surge at its peak.
    let changed = js(
        c,
        "(() => { const i = document.querySelector('[data-path=\"translation_scale.0\"]'); if (!i) return false; \
         i.value = '0.3'; i.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    if changed != json!(true) {
        return Err("no control for translation_scale.0".into());
    }
    let runs = first[0].as_u64().unwrap_or(0);
    until(c, &format!("window.ringpod.cueRuns > {runs}"), Duration::from_secs(20)).await?;
    let second = js(c, "[window.ringpod.cueRuns, window.ringpod.cuePeak]").await?;
    let (p1, p2) = (first[1].as_f64().unwrap_or(0.0), second[1].as_f64().unwrap_or(0.0));
    // The peak is mostly tilt coordination (the sustained braking); the onset the scale cues adds to it.
    if p2 <= p1 * 1.02 {
        return Err(format!("the delivered surge did not grow with its scale: {p1} -> {p2}"));
    }
    // The parameters by channel with their units; a key of a few values is a select, and choosing the median
    // smoothing brings its window (at its starting value, which the replay takes).
    let layout = js(
        c,
        "(() => { const q = (p) => document.querySelector(`[data-path=\"${p}\"]`); \
         return [q('translation_scale.0').closest('fieldset').querySelector('legend').textContent, \
         q('tilt_limit_deg.1').closest('fieldset').querySelector('legend').textContent, \
         q('translation_limit.0').parentElement.querySelector('.unit').textContent, q('yaw').tagName, \
         !!q('smoothing.window')]; })()",
    )
    .await?;
    // The pitch's and roll's tilt with the force each cues (surge, sway); the optimal cueing's fields hidden.
    if layout != json!(["surge", "sway", "m/s²", "SELECT", false]) {
        return Err(format!(
            "the controls are not grouped by channel with units and selects: {layout}"
        ));
    }
    let runs = second[0].as_u64().unwrap_or(0);
    js(
        c,
        "(() => { const s = document.querySelector('[data-path=\"smoothing.kind\"]'); \
         s.value = [...s.options].find((o) => o.textContent === 'median').value; \
         s.dispatchEvent(new Event('change')); return true; })()",
    )
    .await?;
    until(
        c,
        &format!(
            "window.ringpod.cueRuns > {runs} && !!document.querySelector('[data-path=\"smoothing.window\"]') \
             && !document.getElementById('cue-status').className.includes('bad')"
        ),
        Duration::from_secs(20),
    )
    .await?;
    js(
        c,
        "(() => { const i = document.querySelector('[data-path=\"translation_scale.0\"]'); \
         i.value = '-5'; i.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    let refused = until(
        c,
        "document.getElementById('cue-status').className.includes('bad') && document.getElementById('cue-status').textContent",
        Duration::from_secs(10),
    )
    .await?;
    // The refusal is said beside the plots, and the value refused is marked, not somewhere below the list.
    let seen = js(
        c,
        "(() => { const r = document.getElementById('cue-status').getBoundingClientRect(); \
         return [r.top >= 0 && r.bottom <= window.innerHeight, \
         document.querySelector('[data-path=\"translation_scale.0\"]').classList.contains('bad')]; })()",
    )
    .await?;
    if seen != json!([true, true]) {
        return Err(format!("the refusal is out of view or the value not marked: {seen}"));
    }
    named_as_shown(&refused)?;
    let runs = js(c, "window.ringpod.cueRuns").await?.as_u64().unwrap_or(0);
    js(
        c,
        "(() => { const i = document.querySelector('[data-path=\"translation_scale.0\"]'); \
         i.value = '0.3'; i.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    until(
        c,
        &format!("window.ringpod.cueRuns > {runs} && !document.querySelector('#cue-controls .bad')"),
        Duration::from_secs(20),
    )
    .await?;
    let both = both_algorithms(c, shots).await?;
    Ok(format!(
        "largest surge delivered {p1:.3} -> {p2:.3} m/s^2; controls by channel with units, selects, the median's \
         window shown with it: {layout}; -5 refused in view and marked: {refused}; both: {both}"
    ))
}

/// A refusal names the field as on screen (its group and label), with the range shown, not the file's key.
fn named_as_shown(refused: &Value) -> Result<(), String> {
    let said = refused.as_str().unwrap_or("");
    if !said.starts_with("surge: ") || said.contains("translation_scale") {
        return Err(format!("the refusal does not name the field as shown: {said}"));
    }
    Ok(())
}

/// Both algorithms on the same drive: the optimal cueing beside the classical one, each scored.
async fn both_algorithms(c: &Client, shots: Option<&Path>) -> Result<String, String> {
    let runs = js(c, "window.ringpod.cueRuns").await?.as_u64().unwrap_or(0);
    js(
        c,
        "(() => { const b = document.getElementById('cue-compare'); b.checked = true; \
         b.dispatchEvent(new Event('change')); return true; })()",
    )
    .await?;
    let both = until(
        c,
        &format!(
            "window.ringpod.cueRuns > {runs} && window.ringpod.cueScores[1] && \
             [window.ringpod.cueScores.map((s) => s.algorithm), document.getElementById('cue-status').textContent]"
        ),
        Duration::from_secs(60),
    )
    .await?;
    if both[0] != json!(["classical", "optimal"]) || !both[1].as_str().unwrap_or("").contains("optimal: perceived") {
        return Err(format!("both algorithms not scored side by side: {both}"));
    }
    screenshot(c, shots, "cueing-both").await?;
    Ok(both[1].as_str().unwrap_or("").to_owned())
}

pub async fn runs(c: &Client, record: &Path, shots: Option<&Path>) -> Result<String, String> {
    tab(c, "runs").await?;
    let input = c.find(Locator::Css("#run-file")).await.map_err(|e| e.to_string())?;
    let path = record.canonicalize().map_err(|e| e.to_string())?;
    input
        .send_keys(&path.display().to_string())
        .await
        .map_err(|e| e.to_string())?;
    let status = until(
        c,
        // Drawn, or refused (the file's own name, browser-run.csv, holds "rows": the words of a drawn record are
        // waited for, not the word).
        "(document.getElementById('run-status').textContent.includes(' rows over ') \
         || document.getElementById('run-status').className.includes('bad')) && document.getElementById('run-status').textContent",
        Duration::from_secs(20),
    )
    .await?;
    let charts = js(c, "document.querySelectorAll('#run-charts canvas').length").await?;
    if charts != json!(12) {
        return Err(format!("{charts} charts instead of 12; the panel says {status}"));
    }
    // The pose in the units people read: mm for the translations, deg for the rotations.
    let captions = js(
        c,
        "[...document.querySelectorAll('#run-charts figcaption')].slice(0, 6).map((f) => f.textContent)",
    )
    .await?;
    let units: Vec<bool> = (0..6)
        .map(|i| {
            let caption = captions[i].as_str().unwrap_or("");
            caption.contains(if i < 3 { "(mm)" } else { "(deg)" })
        })
        .collect();
    if units.iter().any(|u| !u) {
        return Err(format!("the pose charts are not in mm and deg: {captions}"));
    }
    screenshot(c, shots, "runs").await?;
    Ok(format!("{status}; {captions}"))
}

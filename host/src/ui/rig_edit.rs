//! The Rig panel: the rig file as a form ([`super::rig_form`]) or as TOML, checked as it is typed by the code of
//! `ringpod rig check` (whether it is a mechanism, whether it can be driven, the mechanism at home, the workspace
//! section at the home height, the spec coverage), saved to the rig file the workbench was started with
//! (`ringpod ui --sim --geometry FILE`) only when `--geometry` could load it, and given as TOML to download.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use axum::extract::State;
use axum::response::Response;
use axum::Json;
use ringpod_core::kinematics::{Check, Pose, RingPlatform};
use serde::Deserialize;
use serde_json::{json, Value};

use super::frame::RigView;
use super::rig_form::{self, Field};
use super::{answer, files, App};
use crate::analysis::placement::place;
use crate::analysis::workspace::{classify, Cell};
use crate::rig::{RigError, RigFile};

/// Cells per side of the Rig panel's workspace section.
const SECTION_CELLS: usize = 48;

/// The rig file the workbench saves to, if it was started with one.
pub struct RigTarget {
    pub path: Option<PathBuf>,
    /// One save at a time.
    writing: Mutex<()>,
}

impl RigTarget {
    pub fn new(path: Option<PathBuf>) -> Self {
        Self {
            path,
            writing: Mutex::new(()),
        }
    }
}

/// What the panel sends: the file as TOML (the text view) or as the form's values (the file's JSON, in the file's
/// units).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigBody {
    #[serde(default)]
    text: Option<String>,
    #[serde(default)]
    rig: Option<Value>,
}

impl RigBody {
    /// The file, read: the form's values by [`rig_form::read`], a text as `rig check` reads one; a refusal with
    /// the form's fields, when the values were of the file's types.
    fn file(&self) -> Result<RigFile, (RigError, Vec<Field>)> {
        match (&self.text, &self.rig) {
            (Some(text), None) => crate::rig::parse(text).map_err(|e| (e, Vec::new())),
            (None, Some(rig)) => {
                let file = rig_form::typed(rig).map_err(|e| (e, Vec::new()))?;
                let fields = rig_form::fields(&file);
                match rig_form::in_range(&fields, rig) {
                    Ok(()) => Ok(file),
                    Err(e) => Err((e, fields)),
                }
            }
            _ => Err((
                RigError::new("", "send the rig file as `text` (TOML) or as `rig` (the form's values)"),
                Vec::new(),
            )),
        }
    }
}

/// An error of the rig module said with the field's name as the form shows it.
fn said(e: &RigError, fields: &[Field]) -> Value {
    let field = if e.key.contains(" · ") {
        e.key.clone()
    } else {
        rig_form::shown(&e.key, fields)
    };
    json!({ "key": e.key, "field": field, "why": e.why })
}

/// A rig file checked as `rig check` checks it, for the panel: the file as the form shows it (its values and
/// fields, its TOML), whether it is a mechanism at all (each error naming its field as shown), whether it can be
/// driven (and why not), the mechanism at home, an xy workspace section at the home height, and the spec coverage
/// when the file gives ranges.
pub fn check(body: &RigBody) -> Value {
    let file = match body.file() {
        Ok(f) => f,
        Err((e, fields)) => {
            let mut v = refused(&e, &fields);
            v.insert("fields".into(), json!(fields));
            return Value::Object(v);
        }
    };
    let fields = rig_form::fields(&file);
    let platform = match file.platform() {
        Ok(p) => p,
        Err(e) => {
            // The form stays as typed: its values and fields with the refusal.
            let mut v = refused(&e, &fields);
            v.insert("file".into(), json!(file));
            v.insert("fields".into(), json!(fields));
            return Value::Object(v);
        }
    };
    let drivable = file.drivable().map(|_| ()).map_err(|e| {
        let s = said(&e, &fields);
        format!("{}: {}", s["field"].as_str().unwrap_or(""), e.why)
    });
    let g = &platform.geometry;
    let m = RingPlatform::<f64>::new(g);
    let home = platform.home;
    let coverage = platform.ranges.map(|r| {
        let c = crate::rig::coverage(&m, &home, &r);
        let per_axis: Vec<Value> = ["surge", "sway", "heave", "roll", "pitch"]
            .iter()
            .zip(c.per_axis)
            .map(|(name, (inside, tried))| json!({ "axis": name, "inside": inside, "tried": tried }))
            .collect();
        json!({ "per_axis": per_axis, "combined": c.combined })
    });
    json!({
        "analysable": true,
        "drivable": drivable.is_ok(),
        "why": drivable.err(),
        "errors": [],
        "file": file,
        "fields": fields,
        "toml": file.to_toml().ok(),
        "rig": RigView::of(g, home.to_array(), "this file".into()),
        "at_home": place(&m, &home),
        "section": section(&m, g.ring_radius, home.to_array()[2]),
        "coverage": coverage,
    })
}

fn refused(e: &RigError, fields: &[Field]) -> serde_json::Map<String, Value> {
    let v = json!({ "analysable": false, "drivable": false, "errors": [said(e, fields)] });
    match v {
        Value::Object(m) => m,
        _ => unreachable!("a JSON object"),
    }
}

/// What each check failing means, as a rig builder would say it (KINEMATICS.md 4's order).
fn plain(check: Check) -> &'static str {
    match check {
        Check::Reach => "out of reach: a link too short or a stroke at its end",
        Check::CarriageSpacing => "carriages too close together or too far apart",
        Check::RodCrossing => "links would cross",
        Check::JointCones => "a joint bent past its limit",
        Check::Singularity => "near a singular pose: the platform would not be held firmly",
        Check::Stability => "the centre of mass outside the carriages",
    }
}

/// The xy section at height `z` over the ring's square: a character per cell, rows from -y up: `.` no solution,
/// a digit the first failing check (1-6, KINEMATICS.md 4's order), `#` inside every check; each check's name and
/// what its failing means.
fn section(m: &RingPlatform<f64>, r: f64, z: f64) -> Value {
    let n = SECTION_CELLS;
    let d = 2.0 * r / n as f64;
    let rows: Vec<String> = (0..n)
        .map(|j| {
            (0..n)
                .map(|i| {
                    let (x, y) = (-r + (i as f64 + 0.5) * d, -r + (j as f64 + 0.5) * d);
                    match classify(m, &Pose::new(x, y, z, 0.0, 0.0, 0.0)) {
                        Cell::Unreachable => '.',
                        Cell::Inside(_) => '#',
                        Cell::Fails(c) => {
                            let k = Check::ALL.iter().position(|a| *a == c).unwrap_or(0);
                            char::from(b'1' + k as u8)
                        }
                    }
                })
                .collect()
        })
        .collect();
    let checks: Vec<&str> = Check::ALL.iter().map(|c| c.name()).collect();
    let meanings: Vec<&str> = Check::ALL.iter().map(|c| plain(*c)).collect();
    json!({ "z": z, "half_width": r, "rows": rows, "checks": checks, "meanings": meanings })
}

pub(super) async fn check_route(Json(body): Json<RigBody>) -> Response {
    answer(
        tokio::task::spawn_blocking(move || Ok(check(&body)))
            .await
            .unwrap_or_else(|e| Err(e.to_string())),
    )
}

/// The rig file the panel starts from, as TOML with every section written out (the defaults a section left out
/// takes, so that the form shows axes, motion and homing): the file the workbench was started with, else the
/// rig the device runs (what `device rig show` prints); and whether saving is possible.
pub(super) async fn current(State(app): State<Arc<App>>) -> Response {
    let target = &app.rig_target;
    let text = match &target.path {
        Some(path) => crate::rig::read(path)
            .map_err(|e| e.to_string())
            .map(|file| match file.check() {
                Ok(rig) => file.with_sections(&rig.record),
                Err(_) => file,
            })
            .and_then(|file| file.to_toml().map_err(|e| e.to_string())),
        None => {
            let record = app.hub.record.lock().ok().and_then(|r| *r);
            record
                .ok_or_else(|| "the device's rig is not known yet".to_owned())
                .and_then(|r| crate::device::rig::as_file(&r).map_err(|e| format!("{e:#}")))
        }
    };
    let path = target.path.as_ref().map(|p| p.display().to_string());
    answer(text.map(|text| json!({ "text": text, "file": path })))
}

/// Saves the panel's rig to the file the workbench was started with: only a file `rig check` calls drivable (a
/// mechanism whose home is inside every check, its sections the controller's, homing in the simulated machine),
/// written whole with its mode kept; it must
/// read back as the same file. Nothing is written otherwise.
pub fn save(target: &RigTarget, body: &RigBody) -> Result<Value, String> {
    let Some(path) = &target.path else {
        return Err(
            "the workbench was started without a rig file (`ringpod ui --sim --geometry FILE`): \
                    download the TOML instead"
                .into(),
        );
    };
    let file = body.file().map_err(|(e, fields)| {
        let s = said(&e, &fields);
        format!("{}: {} (not saved)", s["field"].as_str().unwrap_or(""), e.why)
    })?;
    let fields = rig_form::fields(&file);
    let refusal = |e: RigError| {
        let s = said(&e, &fields);
        format!("{}: {} (not saved)", s["field"].as_str().unwrap_or(""), e.why)
    };
    file.drivable().map_err(refusal)?;
    let text = file.to_toml().map_err(|e| e.to_string())?;
    let again = crate::rig::parse(&text).map_err(refusal)?;
    again.drivable().map_err(refusal)?;
    let _one = target.writing.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    files::write_whole(path, &text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(json!({ "saved": path.display().to_string(), "toml": text }))
}

pub(super) async fn save_route(State(app): State<Arc<App>>, Json(body): Json<RigBody>) -> Response {
    answer(
        tokio::task::spawn_blocking(move || save(&app.rig_target, &body))
            .await
            .unwrap_or_else(|e| Err(e.to_string())),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(text: &str) -> RigBody {
        RigBody {
            text: Some(text.into()),
            rig: None,
        }
    }

    #[test]
    fn a_rig_file_is_checked_by_key_and_drawn() {
        let trainer = crate::rig::export("trainer-model").unwrap().text;
        let ok = check(&text(&trainer));
        assert_eq!(ok["analysable"], true, "{ok}");
        assert_eq!(ok["drivable"], true, "{ok}");
        let rows = ok["section"]["rows"].as_array().unwrap();
        assert_eq!(rows.len(), SECTION_CELLS);
        assert!(
            rows.iter().any(|r| r.as_str().unwrap().contains('#')),
            "some of the section is inside"
        );
        assert_eq!(
            ok["section"]["meanings"][1],
            "carriages too close together or too far apart"
        );
        assert_eq!(ok["at_home"]["carriages"].as_array().unwrap().len(), 4);
        let typo = trainer.replacen("ring_radius", "ring_raduis", 1);
        let bad = check(&text(&typo));
        assert_eq!(bad["analysable"], false);
        let why = bad["errors"][0]["why"].as_str().unwrap();
        assert!(why.contains("ring_raduis"), "{bad}");
        // The form's values: a chain's key the check refuses is named as the form shows it.
        let mut form = ok["file"].clone();
        form["chains"][0]["branch"] = Value::Null;
        let bad = check(&RigBody {
            text: None,
            rig: Some(form),
        });
        assert_eq!(bad["errors"][0]["field"], "Chain 1 · branch", "{bad}");
    }

    #[test]
    fn without_a_rig_file_nothing_is_saved() {
        let trainer = crate::rig::export("trainer-model").unwrap().text;
        let e = save(&RigTarget::new(None), &text(&trainer)).unwrap_err();
        assert!(e.contains("download the TOML"), "{e}");
    }
}

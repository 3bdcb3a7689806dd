//! The workbench's computations that move nothing: cueing a drive with the panel's parameters (the rig file is
//! checked in [`super::rig_edit`], run records read in [`super::runs`]). Each takes the page's JSON and gives JSON,
//! through the same code as `ringpod cue`.

use ringpod_core::cueing::{Algorithm, CueConfig};
use ringpod_core::kinematics::{Pose, RingGeometry, RingPlatform};
use serde::Deserialize;
use serde_json::{json, Value};

use crate::cueing::bench::score::score;
use crate::cueing::offline::Preview;
use crate::cueing::offline::{delivered_forces, replay, Replay, TELEMETRY_COLUMNS};

/// The example drive the Cueing panel replays until the user gives one (a braking, a lane change, a bump).
pub const EXAMPLE_DRIVE: &str = include_str!("../../../docs/drive-telemetry.csv");

/// The cueing parameters as the panel starts them: the defaults, the example drive's name, and the controls the
/// panel builds for them (channel, unit, range or choices of each value, from the core's list).
pub fn cue_defaults() -> Value {
    json!({ "config": CueConfig::default(), "drive": "example", "fields": super::cue_fields::fields() })
}

/// What the Cueing panel sends: the parameters, the drive (a telemetry CSV's text; the example without), and
/// whether to cue it by the other algorithm too (the same parameters otherwise), to see both on one drive.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CueRequest {
    pub config: Value,
    #[serde(default)]
    pub drive: Option<String>,
    #[serde(default)]
    pub compare: bool,
}

/// The panel's parameters, checked as a cueing file's are: each error names its key. With the classical washout
/// the optimal cueing's values are not read (the panel hides them): kept when they are valid, else its defaults.
pub fn cue_config(config: &Value) -> Result<CueConfig, String> {
    let mut config: CueConfig = serde_json::from_value(config.clone()).map_err(|e| e.to_string())?;
    if config.algorithm == Algorithm::Classical {
        let plain = CueConfig {
            optimal: Default::default(),
            ..config
        };
        plain.validate().map_err(|e| e.to_string())?;
        if config.validate().is_err() {
            config = plain;
        }
    }
    config.validate().map_err(|e| e.to_string())?;
    Ok(config)
}

/// Cues the drive on the platform and gives, per sample, the specific force asked (as the vehicle felt it) and
/// delivered (by the limited poses), the poses, the bench's score of the cueing (what the rider perceives, as
/// `cue --compare` scores it), and the parameters as a cueing file (TOML); with `compare`, the delivered force
/// and the score of the other algorithm on the same drive.
pub fn cue(request: &CueRequest, geometry: &RingGeometry, home: [f64; 6]) -> Result<Value, String> {
    let config = cue_config(&request.config)?;
    let text = request.drive.as_deref().unwrap_or(EXAMPLE_DRIVE);
    let (rows, mut errors) = crate::input::table::read(text, &TELEMETRY_COLUMNS)?;
    let m = RingPlatform::<f64>::new(geometry);
    let neutral = Pose::from_array(home);
    // One scan of the envelope for both algorithms' replays and scores.
    let envelope = crate::cueing::engine::envelope(&m, &neutral).map_err(|check| {
        format!(
            "the rig's home fails the {check} check: cueing moves the platform about its home, and no pose about \
             this one is inside the envelope"
        )
    })?;
    let scored = |config: CueConfig| -> Result<(Replay, Value), String> {
        let run = replay(&rows, config, &m, &neutral, &envelope, Preview::None).map_err(|e| format!("{e:#}"))?;
        let (s, _) = score(&run.cued, &neutral, &envelope.ranges, config.forward);
        let summary = json!({
            "algorithm": config.algorithm,
            "force_rms": s.force_total(),
            "false_cues": s.false_total(),
            "limited": run.limited,
            "fallbacks": run.counts.as_ref().map(|c| c.fallbacks),
        });
        Ok((run, summary))
    };
    let (run, summary) = scored(config)?;
    let other = if request.compare {
        let algorithm = match config.algorithm {
            Algorithm::Classical => Algorithm::Optimal,
            Algorithm::Optimal => Algorithm::Classical,
        };
        let (r, s) = scored(CueConfig { algorithm, ..config })?;
        Some(json!({ "delivered": delivered_forces(&r.cued), "score": s }))
    } else {
        None
    };
    errors.extend(run.errors);
    let delivered = delivered_forces(&run.cued);
    let toml = toml::to_string(&config).map_err(|e| e.to_string())?;
    let t: Vec<f64> = run.cued.iter().map(|c| c.t).collect();
    let asked: Vec<[f64; 3]> = run.cued.iter().map(|c| c.input.force).collect();
    let poses: Vec<[f64; 6]> = run.cued.iter().map(|c| c.pose.to_array()).collect();
    let errors: Vec<String> = errors
        .iter()
        .map(|e| format!("line {}: {}", e.line, e.reason))
        .collect();
    Ok(json!({
        "t": t,
        "asked": asked,
        "delivered": delivered,
        "poses": poses,
        "limited": run.limited,
        "errors": errors,
        "toml": toml,
        "score": summary,
        "other": other,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::kinematics::presets::{Preset, PresetGeometry};

    fn trainer() -> (RingGeometry, [f64; 6]) {
        let PresetGeometry::Ring(g) = Preset::TrainerModel.geometry() else {
            unreachable!("the trainer model is a ring platform")
        };
        (*g, Preset::TrainerModel.home())
    }

    /// A rig whose home is outside its own workspace (chapter 5's trainer) is not cued: no pose about it is
    /// inside the envelope.
    #[test]
    fn a_home_outside_the_workspace_is_not_cued() {
        let PresetGeometry::Ring(g) = Preset::TrainerCh5.geometry() else {
            unreachable!("chapter 5's trainer is a ring platform")
        };
        let request = CueRequest {
            compare: true,
            config: cue_defaults()["config"].clone(),
            drive: None,
        };
        let e = cue(&request, g, Preset::TrainerCh5.home()).unwrap_err();
        assert!(e.contains("home fails the carriage-spacing check"), "{e}");
    }

    #[test]
    fn the_example_drive_is_cued_and_a_bad_parameter_is_named() {
        let (g, home) = trainer();
        let request = CueRequest {
            compare: false,
            config: cue_defaults()["config"].clone(),
            drive: None,
        };
        let out = cue(&request, &g, home).unwrap();
        let n = out["t"].as_array().unwrap().len();
        assert!(n > 100, "{n} samples");
        assert_eq!(out["asked"].as_array().unwrap().len(), n);
        assert_eq!(out["delivered"].as_array().unwrap().len(), n);
        assert!(out["errors"].as_array().unwrap().is_empty());
        // The TOML is a cueing file that reads back as the same parameters.
        let again = crate::input::cueing::parse_config(out["toml"].as_str().unwrap(), None).unwrap();
        assert_eq!(again, CueConfig::default());
        // A value out of range is refused by the core's check, naming the key and the axis; a value of the wrong
        // kind by the types.
        let mut bad = cue_defaults()["config"].clone();
        bad["translation_scale"][0] = json!(-5.0);
        let e = cue(
            &CueRequest {
                compare: false,
                config: bad,
                drive: None,
            },
            &g,
            home,
        )
        .unwrap_err();
        assert!(e.contains("translation_scale (surge)"), "{e}");
        let mut wrong = cue_defaults()["config"].clone();
        wrong["forward"] = json!("sideways");
        let e = cue(
            &CueRequest {
                compare: false,
                config: wrong,
                drive: None,
            },
            &g,
            home,
        )
        .unwrap_err();
        assert!(e.contains("sideways"), "{e}");
        // The drive's unusable rows are counted, not dropped silently.
        let drive = "t,ax,ay,az,wx,wy,wz\n0,0,0,9.8,0,0,0\n0.01,x,0,9.8,0,0,0\n0.02,0,0,9.8,0,0,0\n";
        let out = cue(
            &CueRequest {
                compare: false,
                config: cue_defaults()["config"].clone(),
                drive: Some(drive.into()),
            },
            &g,
            home,
        )
        .unwrap();
        assert_eq!(out["t"].as_array().unwrap().len(), 2);
        assert_eq!(out["errors"].as_array().unwrap().len(), 1, "{out}");
    }
}

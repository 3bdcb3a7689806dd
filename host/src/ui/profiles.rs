//! Cueing profiles per game, as the page chooses, loads, saves and duplicates them: the `[profiles.NAME]` tables of
//! one cueing file, the file `stream --cue-config FILE --profile NAME` and `cue --config FILE --profile NAME`
//! read (`ringpod ui --cue-config FILE`; without it a file in the workbench's private directory, gone when it
//! ends). A profile the page saves holds every washout key, so it reads the same whatever the file's base says; a
//! profile's `outsim_opts` (the telemetry reader's, not the washout's) is kept.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use axum::extract::{Query, State};
use axum::response::Response;
use axum::Json;
use ringpod_core::cueing::CueConfig;
use serde::Deserialize;
use serde_json::{json, Value};

use super::{answer, api, files, App};
use crate::input::cueing::parse_config;

/// The longest profile name (a game's or a car's, not a path).
const NAME_MOST: usize = 40;

/// The cueing file the profiles live in.
pub struct Profiles {
    pub path: PathBuf,
    /// Whether it outlives the workbench (named by `--cue-config`) or goes with its private directory.
    pub kept: bool,
    /// One save at a time: two pages saving at once both land, one after the other.
    writing: Mutex<()>,
}

impl Profiles {
    pub fn new(path: PathBuf, kept: bool) -> Self {
        Self {
            path,
            kept,
            writing: Mutex::new(()),
        }
    }
}

/// A name a profile may have: 1 to 40 letters, digits, `-` and `_`. It is a key of the file's `[profiles]` table,
/// never a path: nothing a page gives names a file.
pub fn profile_name(name: &str) -> Result<(), String> {
    let fine = |c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_';
    if name.is_empty() || name.len() > NAME_MOST || !name.chars().all(fine) {
        return Err(format!(
            "a profile's name is 1 to {NAME_MOST} letters, digits, `-` or `_` (as `f1` or `gt3-rain`), not {name:?}"
        ));
    }
    Ok(())
}

/// The file's text: none when it does not exist yet (the first save makes it).
fn text(path: &Path) -> Result<String, String> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(String::new()),
        _ => crate::input::files::read_text(path, crate::input::files::CONFIG_LIMIT)
            .map_err(|e| format!("{}: {e}", path.display())),
    }
}

fn table(text: &str, path: &Path) -> Result<toml::Table, String> {
    toml::from_str(text).map_err(|e| format!("{}: not TOML: {}", path.display(), e.message()))
}

/// The file's profiles, by name in the file's order.
pub fn names(path: &Path) -> Result<Vec<String>, String> {
    let table = table(&text(path)?, path)?;
    Ok(match table.get("profiles") {
        Some(toml::Value::Table(p)) => p.keys().cloned().collect(),
        _ => Vec::new(),
    })
}

/// A profile's parameters as `--profile` reads them (the base's keys with the profile's over them); without a
/// name, the base's.
pub fn load(path: &Path, name: Option<&str>) -> Result<CueConfig, String> {
    if let Some(n) = name {
        profile_name(n)?;
    }
    parse_config(&text(path)?, name).map_err(|e| format!("{}: {e}", path.display()))
}

/// Saves `config` (checked as the Cueing panel's are) as profile `name`, whole, the rest of the file as it was;
/// `new` refuses a name the file has (a duplicate must not overwrite).
pub fn save(profiles: &Profiles, name: &str, config: &Value, new: bool) -> Result<(), String> {
    profile_name(name)?;
    let config = api::cue_config(config)?;
    let _one = profiles
        .writing
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let path = &profiles.path;
    let mut file = table(&text(path)?, path)?;
    let all = file
        .entry("profiles")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let toml::Value::Table(all) = all else {
        return Err(format!(
            "{}: `profiles` must be a table of tables: [profiles.NAME]",
            path.display()
        ));
    };
    if new && all.contains_key(name) {
        return Err(format!("a profile `{name}` exists already: choose another name"));
    }
    let mut own = toml::Table::try_from(config).map_err(|e| e.to_string())?;
    // The reader's option set of this game stays with its profile.
    if let Some(toml::Value::Table(old)) = all.get(name) {
        if let Some(opts) = old.get("outsim_opts") {
            own.insert("outsim_opts".into(), opts.clone());
        }
    }
    all.insert(name.to_owned(), toml::Value::Table(own));
    let written = toml::to_string(&file).map_err(|e| e.to_string())?;
    // The file as written must read back as this profile: nothing lands that `--profile` would refuse.
    parse_config(&written, Some(name)).map_err(|e| format!("profile `{name}`: {e}"))?;
    files::write_whole(path, &written).map_err(|e| format!("{}: {e}", path.display()))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Which {
    #[serde(default)]
    name: Option<String>,
    #[allow(dead_code)]
    token: Option<String>,
}

/// The file, its profiles and the games (each with the profile its session takes).
pub(super) async fn list(State(app): State<std::sync::Arc<App>>) -> Response {
    let p = &app.profiles;
    answer(names(&p.path).map(|names| {
        json!({
            "file": p.path.display().to_string(),
            "kept": p.kept,
            "names": names,
            "games": crate::games::setup::GAMES,
        })
    }))
}

/// One profile's parameters (`?name=NAME`), or the base's (no name).
pub(super) async fn get(State(app): State<std::sync::Arc<App>>, Query(which): Query<Which>) -> Response {
    answer(
        load(&app.profiles.path, which.name.as_deref().filter(|n| !n.is_empty()))
            .map(|config| json!({ "name": which.name, "config": config })),
    )
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SaveBody {
    name: String,
    config: Value,
    /// A duplicate: refused when the name is taken.
    #[serde(default)]
    new: bool,
}

/// Saves a profile (`new`: only under a name the file does not have).
pub(super) async fn put(State(app): State<std::sync::Arc<App>>, Json(body): Json<SaveBody>) -> Response {
    let app2 = app.clone();
    answer(
        tokio::task::spawn_blocking(move || {
            save(&app2.profiles, &body.name, &body.config, body.new)
                .map(|()| json!({ "saved": body.name, "file": app2.profiles.path.display().to_string() }))
        })
        .await
        .unwrap_or_else(|e| Err(e.to_string())),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_keys_never_paths() {
        for good in ["f1", "gt3-rain", "DiRT_2", &"a".repeat(NAME_MOST)] {
            profile_name(good).unwrap();
        }
        for bad in [
            "",
            "../x",
            "a/b",
            "a\\b",
            ".",
            "..",
            "f1.toml",
            "f 1",
            "ä",
            "a\0",
            &"a".repeat(NAME_MOST + 1),
        ] {
            assert!(profile_name(bad).is_err(), "{bad:?}");
        }
    }

    /// Saved, a profile reads back through `--profile` as the same parameters; the base, other profiles and a
    /// profile's `outsim_opts` stay; a duplicate of a name refused; a bad value lands nothing.
    #[test]
    fn a_saved_profile_reads_back_as_the_cli_reads_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cue.toml");
        std::fs::write(
            &path,
            "tilt_scale = 0.5\n[profiles.lfs]\noutsim_opts = \"1ff\"\nyaw_scale = 0.5\n",
        )
        .unwrap();
        let p = Profiles::new(path.clone(), true);
        let f1 = CueConfig {
            tilt_scale: [0.9, 0.3],
            ..CueConfig::default()
        };
        save(&p, "f1", &serde_json::to_value(f1).unwrap(), true).unwrap();
        assert_eq!(crate::input::cueing::load_config(Some(&path), Some("f1")).unwrap(), f1);
        assert_eq!(names(&path).unwrap(), ["lfs", "f1"], "in the file's order");
        assert_eq!(load(&p.path, None).unwrap().tilt_scale, [0.5, 0.5], "the base stays");
        let e = save(&p, "f1", &serde_json::to_value(f1).unwrap(), true).unwrap_err();
        assert!(e.contains("exists already"), "{e}");
        save(&p, "lfs", &serde_json::to_value(f1).unwrap(), false).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            crate::input::cueing::outsim_opts(&text, Some("lfs"))
                .unwrap()
                .as_deref(),
            Some("1ff")
        );
        let mut bad = serde_json::to_value(f1).unwrap();
        bad["tilt_scale"][1] = json!(-1.0);
        assert!(save(&p, "rally", &bad, true).is_err());
        assert!(!names(&path).unwrap().contains(&"rally".to_owned()), "nothing landed");
        assert!(save(&p, "../../etc/passwd", &serde_json::to_value(f1).unwrap(), false).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no other file made");
    }
}

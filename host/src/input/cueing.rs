//! Cueing files: the washout's parameters in TOML (every key optional), with named profiles, read by `cue`
//! and by `stream --telemetry-udp` (also again while it runs, when the file changes).

use std::path::{Path, PathBuf};

use ringpod_core::cueing::CueConfig;

/// Why a cueing file was not taken.
#[derive(Debug, thiserror::Error)]
pub enum CueingFileError {
    /// A profile was asked for without a file to choose it from.
    #[error("profile `{0}`: profiles are chosen from a cueing file, and none was given")]
    ProfileWithoutFile(String),
    /// The file could not be read, or its contents are not a configuration (the reason names the key).
    #[error("{}: {reason}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

/// Loads a washout configuration from TOML (every key optional), with a profile's overrides
/// ([`parse_config`]); errors name the file and the key.
pub fn load_config(path: Option<&Path>, profile: Option<&str>) -> Result<CueConfig, CueingFileError> {
    let Some(path) = path else {
        if let Some(name) = profile {
            return Err(CueingFileError::ProfileWithoutFile(name.to_owned()));
        }
        return Ok(CueConfig::default());
    };
    let in_file = |reason| CueingFileError::File {
        path: path.to_path_buf(),
        reason,
    };
    let text = super::files::read_text(path, super::files::CONFIG_LIMIT).map_err(in_file)?;
    parse_config(&text, profile).map_err(in_file)
}

/// Whether a cueing file's text is whole: not empty (an editor truncates before it writes; an empty file is not
/// a configuration of all defaults, which a file with only a comment still is) and TOML (a file cut short
/// half-way through a key is not). What it says is checked by [`parse_config`].
pub fn whole(text: &str) -> Result<(), String> {
    if text.trim().is_empty() {
        return Err("empty".into());
    }
    toml::from_str::<toml::Table>(text)
        .map(|_| ())
        .map_err(|e| format!("not TOML: {}", e.message()))
}

/// A cueing file's text: the base keys, and `[profiles.NAME]` tables, each a partial override of the base. With
/// `profile`, that profile's keys replace the base's, each key as a whole (a `[profiles.NAME.smoothing]` table
/// replaces `[smoothing]`, a per-axis list replaces the list); an unknown profile is refused naming the known
/// ones. The result is checked: an error names the key (and the axis). The file's `outsim_opts` belongs to the
/// telemetry reader, not the washout ([`outsim_opts`]).
pub fn parse_config(text: &str, profile: Option<&str>) -> Result<CueConfig, String> {
    let (mut table, where_) = merged(text, profile)?;
    opts_of(&mut table, &where_)?;
    let config: CueConfig = toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| format!("{where_}{}", e.to_string().trim_end()))?;
    config.validate().map_err(|e| format!("{where_}{e}"))?;
    Ok(config)
}

/// The `outsim_opts` of a cueing file's text, with `profile`'s override: Live for Speed's `OutSim Opts` as its
/// cfg.txt writes it (`outsim_opts = "1ff"`), what a game's profile says of its packets. The telemetry reader
/// parses it (`games::outsim2::Opts::parse_hex`); here it is only taken out of the washout's keys.
pub fn outsim_opts(text: &str, profile: Option<&str>) -> Result<Option<String>, String> {
    let (mut table, where_) = merged(text, profile)?;
    opts_of(&mut table, &where_)
}

/// [`outsim_opts`] of a cueing file (none without a file); errors name the file and the key.
pub fn load_outsim_opts(path: Option<&Path>, profile: Option<&str>) -> Result<Option<String>, CueingFileError> {
    let Some(path) = path else {
        return Ok(None);
    };
    let in_file = |reason| CueingFileError::File {
        path: path.to_path_buf(),
        reason,
    };
    let text = super::files::read_text(path, super::files::CONFIG_LIMIT).map_err(in_file)?;
    outsim_opts(&text, profile).map_err(in_file)
}

/// Takes `outsim_opts` out of a merged table: a string, or none.
fn opts_of(table: &mut toml::Table, where_: &str) -> Result<Option<String>, String> {
    match table.remove("outsim_opts") {
        None => Ok(None),
        Some(toml::Value::String(hex)) => Ok(Some(hex)),
        Some(_) => Err(format!(
            "{where_}outsim_opts must be a string of hexadecimal digits, as in LFS's cfg.txt: outsim_opts = \"1ff\""
        )),
    }
}

/// The base table with `profile`'s keys in place (each key replaced whole), and the words that say where an
/// error is (the profile's name, or nothing for the base).
fn merged(text: &str, profile: Option<&str>) -> Result<(toml::Table, String), String> {
    let mut table: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
    let profiles = match table.remove("profiles") {
        None => toml::Table::new(),
        Some(toml::Value::Table(t)) => t,
        Some(_) => return Err("`profiles` must be a table of tables: [profiles.NAME]".into()),
    };
    for (name, p) in &profiles {
        if !p.is_table() {
            return Err(format!("profiles.{name} must be a table: [profiles.{name}]"));
        }
    }
    let mut where_ = String::new();
    if let Some(name) = profile {
        let Some(toml::Value::Table(over)) = profiles.get(name) else {
            let known: Vec<&str> = profiles.keys().map(String::as_str).collect();
            return Err(if known.is_empty() {
                format!("no profile `{name}`: the file has no [profiles.NAME] table")
            } else {
                format!("no profile `{name}`; the file's profiles: {}", known.join(", "))
            });
        };
        for (k, v) in over {
            table.insert(k.clone(), v.clone());
        }
        where_ = format!("profile `{name}`: ");
    }
    Ok((table, where_))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::cueing::Algorithm;

    /// The bench's cueing files, as shipped: each loads, and says what the book's table says of it.
    #[test]
    fn the_bench_files_load_as_the_book_describes_them() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/drives");
        let load = |name: &str| load_config(Some(&dir.join(name)), None).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.ends_with(".toml"))
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                "classical-tuned.toml",
                "classical.toml",
                "optimal-tilt-kept.toml",
                "optimal-tilt-priced.toml",
                "optimal-tilt.toml",
                "optimal-unbounded.toml",
                "optimal.toml",
                "tilt-bound.toml"
            ]
        );
        assert_eq!(load("classical.toml"), CueConfig::default());
        // The tuned washout the laps are compared with: the tilt of the book's table, little translation.
        let tuned = load("classical-tuned.toml");
        assert_eq!(tuned.algorithm, Algorithm::Classical);
        assert_eq!((tuned.tilt_limit_deg, tuned.tilt_rate_deg), ([18.75; 2], [18.75; 2]));
        assert!(tuned.translation_scale.iter().all(|s| *s < 0.02), "{tuned:?}");
        let tilt = load("optimal-tilt.toml");
        assert_eq!(tilt.algorithm, Algorithm::Optimal);
        assert_eq!((tilt.optimal.envelope_share, tilt.optimal.tilt_share), (0.2, 0.95));
        assert_eq!((tilt.tilt_limit_deg, tilt.tilt_rate_deg), ([20.0; 2], [18.75; 2]));
        assert_eq!(tilt.optimal.tilt_loss_weight, 0.0);
        // The same with the tilts' loss of vertical force priced: only that weight differs.
        let priced = load("optimal-tilt-priced.toml");
        assert_eq!(priced.optimal.tilt_loss_weight, 50.0);
        let mut unpriced = priced;
        unpriced.optimal.tilt_loss_weight = 0.0;
        assert_eq!(unpriced, tilt);
        // Then the plan kept from sample to sample, the loss's price eased: only those two weights differ.
        let kept = load("optimal-tilt-kept.toml");
        assert_eq!(
            (kept.optimal.tilt_loss_weight, kept.optimal.plan_weight),
            (40.0, 1000.0)
        );
        let mut expected = priced;
        expected.optimal.tilt_loss_weight = 40.0;
        expected.optimal.plan_weight = 1000.0;
        assert_eq!(kept, expected);
        // The yardstick: tilt alone, to the trainer model's roll and pitch ranges, at once.
        let bound = load("tilt-bound.toml");
        assert_eq!(bound.algorithm, Algorithm::Classical);
        assert_eq!((bound.translation_scale, bound.rotation_scale), ([0.0; 3], [0.0; 2]));
        assert_eq!((bound.tilt_scale, bound.tilt_limit_deg), ([1.0; 2], [22.0, 20.5]));
        assert_eq!(load("optimal-unbounded.toml").optimal.budget_ms, 1000.0);
    }
}

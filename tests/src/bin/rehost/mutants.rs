//! `--mutants`: realistic faults of a board's firmware (`tests/rehost/mutants.toml`), each applied alone to a copy
//! of the sources, built as flashed and run through run.py up to the check meant to catch it. A fault no check
//! catches is a fidelity gap of the harness; one the build refuses is caught by the compiler. Prints a table:
//! mutant, fault, the check meant to catch it, what failed.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use serde::Deserialize;

use crate::prepare::{build_firmware_at, repo, run_py, target_dir};

/// The mutation list.
#[derive(Deserialize)]
struct List {
    mutant: Vec<Mutant>,
}

/// One fault: its edits of the sources, and the check that must fail.
#[derive(Deserialize)]
struct Mutant {
    name: String,
    fault: String,
    check: String,
    edit: Vec<Edit>,
}

/// `find` (exactly once in `file`) becomes `replace`.
#[derive(Deserialize)]
struct Edit {
    file: String,
    find: String,
    replace: String,
}

/// What became of one mutant.
enum Outcome {
    /// These checks failed (the first is the one that caught it).
    Caught(Vec<String>),
    /// The build refused it.
    Refused,
    /// Every check up to the named one passed.
    NotCaught,
    /// The mutant could not be made or run.
    Broken(String),
}

/// Copies the tree at `from` to `to`, leaving out build output and version control.
fn copy_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let name = entry.file_name();
        if name == "target" || name == ".git" {
            continue;
        }
        let (src, dst) = (entry.path(), to.join(&name));
        if entry.file_type()?.is_dir() {
            copy_tree(&src, &dst)?;
        } else {
            std::fs::copy(&src, &dst)?;
        }
    }
    Ok(())
}

/// The sources with the mutant's edits, in a fresh copy at `root`.
fn apply(mutant: &Mutant, root: &Path) -> Result<(), String> {
    if root.exists() {
        std::fs::remove_dir_all(root).map_err(|e| format!("{}: {e}", root.display()))?;
    }
    copy_tree(&repo(), root).map_err(|e| format!("copying the sources: {e}"))?;
    for edit in &mutant.edit {
        let path = root.join(&edit.file);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", edit.file))?;
        let found = text.matches(&edit.find).count();
        if found != 1 {
            return Err(format!(
                "{}: the text to replace occurs {found} times, not once: {:?}",
                edit.file, edit.find
            ));
        }
        std::fs::write(&path, text.replacen(&edit.find, &edit.replace, 1))
            .map_err(|e| format!("{}: {e}", edit.file))?;
    }
    Ok(())
}

/// run.py on `elf` up to `check`: the checks that failed.
fn failed_checks(python: &Path, elf: &Path, cli: &Path, check: &str) -> Result<Vec<String>, String> {
    let mut child = run_py(
        python,
        elf,
        cli,
        &["--until", check, "--max-sim-s", "150", "--max-wall-s", "2400"],
    )?;
    let mut failed = Vec::new();
    if let Some(out) = child.stdout.take() {
        for line in BufReader::new(out).lines().map_while(Result::ok) {
            if let Some(rest) = line.strip_prefix("FAIL ") {
                let name = rest.split(':').next().unwrap_or(rest).to_owned();
                println!("    {}", line.chars().take(400).collect::<String>());
                failed.push(name);
            }
        }
    }
    child.wait().map_err(|e| format!("run.py: {e}"))?;
    Ok(failed)
}

fn outcome(mutant: &Mutant, python: &Path, cli: &Path) -> Outcome {
    let root = target_dir().join("mutant-src");
    if let Err(e) = apply(mutant, &root) {
        return Outcome::Broken(e);
    }
    let elf = match build_firmware_at(&root, &target_dir().join("mutant-target")) {
        Ok(elf) => elf,
        Err(_) => return Outcome::Refused,
    };
    match failed_checks(python, &elf, cli, &mutant.check) {
        Ok(failed) if failed.is_empty() => Outcome::NotCaught,
        Ok(failed) => Outcome::Caught(failed),
        Err(e) => Outcome::Broken(e),
    }
}

/// Runs the mutants named in `only` (all when empty), one at a time; success when each was caught.
pub fn run(python: &Path, cli: &Path, only: &[String]) -> ExitCode {
    let path: PathBuf = repo().join("tests/rehost/mutants.toml");
    let list: List = match std::fs::read_to_string(&path)
        .map_err(|e| e.to_string())
        .and_then(|t| toml::from_str(&t).map_err(|e| e.to_string()))
    {
        Ok(l) => l,
        Err(e) => {
            eprintln!("rehost: {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
    };
    let mut rows = Vec::new();
    for m in list.mutant.iter().filter(|m| only.is_empty() || only.contains(&m.name)) {
        println!("== mutant {}: {}", m.name, m.fault);
        let start = Instant::now();
        let result = outcome(m, python, cli);
        let said = match &result {
            Outcome::Caught(failed) if failed[0] == m.check => format!("caught by `{}`", failed[0]),
            Outcome::Caught(failed) => format!("caught by `{}` (before `{}`)", failed[0], m.check),
            Outcome::Refused => "refused by the build".to_owned(),
            Outcome::NotCaught => format!("NOT CAUGHT: every check up to `{}` passed", m.check),
            Outcome::Broken(e) => format!("NOT RUN: {e}"),
        };
        println!("== {}: {said} ({} s)", m.name, start.elapsed().as_secs());
        rows.push((m, result, said));
    }
    println!("\n| mutant | fault | meant for | result |\n|---|---|---|---|");
    for (m, _, said) in &rows {
        println!("| {} | {} | `{}` | {said} |", m.name, m.fault, m.check);
    }
    let missed = rows
        .iter()
        .filter(|(_, r, _)| matches!(r, Outcome::NotCaught | Outcome::Broken(_)))
        .count();
    println!(
        "{} mutants, {} caught or refused, {missed} not",
        rows.len(),
        rows.len() - missed
    );
    if missed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every mutant still applies to the sources as they are: each `find` occurs exactly once in its file (a
    /// change of the firmware that moves a line a mutant edits would otherwise leave that fault untried until
    /// someone runs `--mutants`).
    #[test]
    fn every_mutant_applies_to_the_sources_as_they_are() {
        let text = std::fs::read_to_string(repo().join("tests/rehost/mutants.toml")).unwrap();
        let list: List = toml::from_str(&text).unwrap();
        assert!(list.mutant.len() >= 13, "{}", list.mutant.len());
        for mutant in &list.mutant {
            for edit in &mutant.edit {
                let source = std::fs::read_to_string(repo().join(&edit.file)).unwrap();
                assert_eq!(
                    source.matches(&edit.find).count(),
                    1,
                    "{}: {:?} in {}",
                    mutant.name,
                    edit.find,
                    edit.file
                );
            }
        }
    }
}

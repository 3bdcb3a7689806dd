//! Reading what `cargo test` printed under Wine: which tests failed, in which test program, and whether Wine itself
//! failed them by not starting a process (`CreateProcess` answering ERROR_INTERNAL_ERROR, OS error 1359, which
//! Wine does now and then under load), so that the Windows runner runs exactly those once more and says so. A
//! failure of any other kind is never run again.

/// A test that failed: the cargo arguments that select its program, its name, and whether Wine failed it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failed {
    /// `--test NAME` or `--bin ringpod`; empty when cargo's `Running` line was not read.
    pub program: Vec<String>,
    /// The test's full name, as `--exact` takes it.
    pub name: String,
    /// Its failure message holds Wine's failed process creation.
    pub by_wine: bool,
}

/// How Wine's failed process creation shows in a test's panic: the standard library's `Os { code: 1359, ...` (an
/// unwrapped error) or its `... (os error 1359)` (an error displayed, as assert_cmd's spawn failure is).
const WINE_SPAWN: [&str; 2] = ["Os { code: 1359,", "(os error 1359)"];

/// The failed tests in `output` (cargo's stdout and stderr together, in order).
pub fn failures(output: &str) -> Vec<Failed> {
    let mut program = Vec::new();
    let mut failed: Vec<Failed> = Vec::new();
    // The failure being read: after its `---- NAME stdout ----` line, up to the next block or the summary.
    let mut reading: Option<usize> = None;
    for line in output.lines().map(str::trim) {
        if let Some(running) = line.strip_prefix("Running ") {
            program = program_of(running);
            reading = None;
        } else if let Some(name) = failed_test(line) {
            failed.push(Failed {
                program: program.clone(),
                name: name.to_owned(),
                by_wine: false,
            });
        } else if let Some(name) = line.strip_prefix("---- ").and_then(|r| r.strip_suffix(" stdout ----")) {
            reading = failed.iter().rposition(|f| f.name == name && f.program == program);
        } else if line == "failures:" || line.starts_with("test result:") {
            reading = None;
        } else if let (Some(i), true) = (reading, WINE_SPAWN.iter().any(|w| line.contains(w))) {
            failed[i].by_wine = true;
        }
    }
    failed
}

/// The name in a `test NAME ... FAILED` line; Wine's own messages on stderr may come first on the same line
/// (`wine client error:63c: test NAME ... FAILED`).
fn failed_test(line: &str) -> Option<&str> {
    let (before, name) = line.strip_suffix(" ... FAILED")?.rsplit_once(' ')?;
    (before == "test" || before.ends_with(" test")).then_some(name)
}

/// The cargo arguments of the program cargo's `Running` line names: `unittests src/main.rs (...)` is the host
/// binary's own tests, `tests/suite/main.rs (...)` the integration test `suite` (a `tests/cli.rs` would be `cli`).
fn program_of(running: &str) -> Vec<String> {
    let source = running.split_whitespace().find(|w| w.ends_with(".rs")).unwrap_or("");
    let test = source.strip_prefix("tests/");
    if let Some(name) = test.and_then(|s| s.strip_suffix("/main.rs").or_else(|| s.strip_suffix(".rs"))) {
        vec!["--test".into(), name.into()]
    } else if source == "src/main.rs" {
        vec!["--bin".into(), "ringpod".into()]
    } else {
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cargo's lines of a run (from the Windows runner's log) where Wine failed one test and another failed on its own.
    const RUN: &str = "\
     Running unittests src/main.rs (target/x86_64-pc-windows-gnu/debug/deps/ringpod-1.exe)
test link::tests::ok_one ... ok
test link::tests::broken ... FAILED

failures:

---- link::tests::broken stdout ----
thread 'link::tests::broken' panicked at host/src/link/mod.rs:9:5:
assertion `left == right` failed
failures:
    link::tests::broken

test result: FAILED. 1 passed; 1 failed; 0 ignored; 0 measured; 0 filtered out; finished in 0.01s

     Running tests/suite/main.rs (target/x86_64-pc-windows-gnu/debug/deps/suite-ed2dd17e6a106a05.exe)
test cli::loads_set_the_motion_against_the_drives_of_the_rig ... FAILED
wine client error:6a0: sendmsg: Bad file descriptor
test cli::draw_refuses_bad_input_in_one_line ... ok

failures:

---- cli::loads_set_the_motion_against_the_drives_of_the_rig stdout ----

thread 'cli::loads_set_the_motion_against_the_drives_of_the_rig' (716) panicked at host/tests/suite/cli.rs:835:10:
called `Result::unwrap()` on an `Err` value: Os { code: 1359, kind: Uncategorized, message: \"Internal error.\" }

failures:
    cli::loads_set_the_motion_against_the_drives_of_the_rig

test result: FAILED. 39 passed; 1 failed; 0 ignored; 0 measured; 0 filtered out; finished in 17.35s
";

    #[test]
    fn each_failure_is_named_with_its_program_and_only_wines_own_is_marked() {
        assert_eq!(
            failures(RUN),
            [
                Failed {
                    program: vec!["--bin".into(), "ringpod".into()],
                    name: "link::tests::broken".into(),
                    by_wine: false,
                },
                Failed {
                    program: vec!["--test".into(), "suite".into()],
                    name: "cli::loads_set_the_motion_against_the_drives_of_the_rig".into(),
                    by_wine: true,
                },
            ]
        );
    }

    #[test]
    fn a_failure_after_wines_own_message_on_its_line_is_read_and_marked() {
        let run = "     Running tests/suite/main.rs (target/x86_64-pc-windows-gnu/debug/deps/suite-1.exe)
wine client error:63c: test cli::a_rig_file_drives_the_kinematics_commands ... FAILED
test cli::other ... ok

failures:

---- cli::a_rig_file_drives_the_kinematics_commands stdout ----

thread 'cli::a_rig_file_drives_the_kinematics_commands' (1536) panicked at host/tests/suite/cli.rs:634:43:
Failed to spawn Command { cmd: \"ringpod.exe\" \"rig\" }: Internal error. (os error 1359)
";
        assert_eq!(
            failures(run),
            [Failed {
                program: vec!["--test".into(), "suite".into()],
                name: "cli::a_rig_file_drives_the_kinematics_commands".into(),
                by_wine: true,
            }]
        );
        assert_eq!(failed_test("test a ... FAILED"), Some("a"));
        assert_eq!(failed_test("contest a ... FAILED"), None);
        assert_eq!(failed_test("test a ... ok"), None);
    }

    #[test]
    fn a_run_that_passed_has_no_failures_and_an_unread_program_is_empty() {
        let passed = RUN.replace(" ... FAILED", " ... ok");
        assert!(failures(&passed).is_empty());
        let alone = "test a ... FAILED\n---- a stdout ----\nOs { code: 1359, kind: Uncategorized }\n";
        assert_eq!(
            failures(alone),
            [Failed {
                program: vec![],
                name: "a".into(),
                by_wine: true,
            }]
        );
    }
}

//! A runner's independent sections, run as child processes of the runner itself, `jobs` at a time (the runner
//! decides how many its sections bear side by side). Each child prints its own `PASS`/`FAIL` lines and ends with
//! `N passed, N failed`; the parent prints each section's output whole as it ends and sums the counts.

use std::collections::VecDeque;
use std::process::{Command, Output, Stdio};
use std::sync::mpsc;

/// The sum over the sections.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub passed: u32,
    pub failed: u32,
}

/// Runs `current_exe() ARGS... --section NAME` for each name, `jobs` at a time, and prints what each printed.
pub fn run(names: &[&str], args: &[&str], jobs: usize) -> Tally {
    let exe = match std::env::current_exe() {
        Ok(exe) => exe,
        Err(e) => {
            println!("FAIL the runner cannot start its sections: {e}");
            return Tally { passed: 0, failed: 1 };
        }
    };
    let mut queue: VecDeque<&str> = names.iter().copied().collect();
    let (done, finished) = mpsc::channel();
    let mut running = 0;
    let mut tally = Tally::default();
    loop {
        while running < jobs.max(1) {
            let Some(name) = queue.pop_front() else { break };
            let child = Command::new(&exe)
                .args(args)
                .args(["--section", name])
                .stdin(Stdio::null())
                .stdout(Stdio::piped())
                .stderr(Stdio::inherit())
                .spawn();
            let done = done.clone();
            let name = name.to_string();
            std::thread::spawn(move || {
                let _ = done.send((name, child.and_then(|c| c.wait_with_output())));
            });
            running += 1;
        }
        if running == 0 {
            return tally;
        }
        let Ok((name, output)) = finished.recv() else {
            return tally;
        };
        running -= 1;
        let (passed, failed) = report(&name, output);
        tally.passed += passed;
        tally.failed += failed;
    }
}

/// Prints a section's output without its count line and returns that count; a section that ended without one (it
/// crashed, or its count disagrees with its exit status) is a failure of its own.
fn report(name: &str, output: std::io::Result<Output>) -> (u32, u32) {
    let output = match output {
        Ok(o) => o,
        Err(e) => {
            println!("FAIL section {name}: {e}");
            return (0, 1);
        }
    };
    let text = String::from_utf8_lossy(&output.stdout);
    let mut count = None;
    for line in text.lines() {
        match parse_count(line) {
            Some(c) => count = Some(c),
            None => println!("{line}"),
        }
    }
    match count {
        Some((passed, failed)) if (failed == 0) == output.status.success() => (passed, failed),
        Some((passed, failed)) => {
            println!(
                "FAIL section {name} reported {failed} failed but ended with {}",
                output.status
            );
            (passed, failed.max(1))
        }
        None => {
            println!("FAIL section {name} ended without its count ({})", output.status);
            (0, 1)
        }
    }
}

/// `N passed, N failed`, the last line of every runner and section.
fn parse_count(line: &str) -> Option<(u32, u32)> {
    let (passed, failed) = line.trim_end().split_once(" passed, ")?;
    Some((passed.parse().ok()?, failed.strip_suffix(" failed")?.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_count_line_is_read_and_nothing_else() {
        assert_eq!(parse_count("47 passed, 0 failed"), Some((47, 0)));
        assert_eq!(parse_count("3 passed, 2 failed\n"), Some((3, 2)));
        assert_eq!(parse_count("PASS 3 passed, 2 failed"), None);
        assert_eq!(parse_count("a hold-up: 6001 passed, 1 failed by"), None);
        assert_eq!(parse_count("x passed, 0 failed"), None);
    }

    #[cfg(unix)]
    fn output(code: i32, stdout: &str) -> std::io::Result<Output> {
        use std::os::unix::process::ExitStatusExt;
        // A wait status: the exit code in the second byte.
        Ok(Output {
            status: std::process::ExitStatus::from_raw(code << 8),
            stdout: stdout.into(),
            stderr: vec![],
        })
    }

    #[cfg(unix)]
    #[test]
    fn a_section_that_ends_without_its_count_or_against_its_status_fails() {
        assert_eq!(report("a", output(0, "PASS x\n2 passed, 0 failed\n")), (2, 0));
        assert_eq!(report("a", output(1, "FAIL x\n1 passed, 1 failed\n")), (1, 1));
        // Crashed half way: what it passed is not a pass of the section.
        assert_eq!(report("a", output(101, "PASS x\n")), (0, 1));
        // It said it passed but exited with a failure, or the other way round.
        assert_eq!(report("a", output(1, "2 passed, 0 failed\n")), (2, 1));
        assert_eq!(report("a", output(0, "1 passed, 1 failed\n")), (1, 1));
        assert_eq!(report("a", Err(std::io::Error::other("no such file"))), (0, 1));
    }
}

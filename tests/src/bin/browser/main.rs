//! `cargo run -p ringpod-tests --bin browser`: `ringpod ui --sim` in a real browser (Debian's headless Chromium,
//! driven through ChromeDriver over WebDriver).
//!
//! 1. Chromium and ChromeDriver (installed with apt-get when missing and allowed, as QEMU is), and the CLI (the
//!    release build the README's main command makes, `ringpod_tests::cli`), and a run record made by `ringpod
//!    stream --sim --record`.
//! 2. `ringpod ui --sim --listen 127.0.0.1:0 --geometry RIG` (the trainer model's rig file), its URL read from its first line; ChromeDriver on a free port.
//! 3. The checks, each a `PASS`/`FAIL` line: the page connects and draws; Enable and Home through the buttons, a
//!    disabled button says why; the demo runs and the 3D pose and the counters advance; STOP (the button, and the
//!    space bar) stops and powers down; a UDP session is followed; a page of another origin cannot open the WebSocket, nor can a request
//!    without the token; the rig editor names a bad key; cueing redraws when a parameter changes; a run record
//!    opens; a page that goes away stops the stream it started, and with no page left the platform powers down;
//!    the rig form at both sizes (a value in mm redrawn, a bad one named, saved to the `--geometry` file, found
//!    again; `rig`); a rig builder's task at 1366x768 and 1920x1080 (an F1 session, the Live view read, its profile tuned live,
//!    saved and found again after a reload; `task`).
//!
//! `--prepare` installs step 1's packages and stops. `--screenshots DIR` saves a picture of each panel there (the book's are in `docs/book/src/images/ui/`), and of
//! every panel at 1366x768 and 1920x1080 at the end, in `DIR/sizes/`. The last line is the
//! sum, `N passed, N failed`; the exit status is 1 when anything failed.

mod control;
mod origin;
mod page;
mod panels;
mod process;
mod rig;
mod task;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use fantoccini::ClientBuilder;
use hyper_util::client::legacy::connect::HttpConnector;
use ringpod_tests::setup;
use serde_json::json;

use control::{connects, demo_runs, enable_and_home, lost_page, space_bar, stop_button, udp_session};
use origin::other_origin;
use panels::{cueing, rig_editor, runs};
use process::{chromedriver, record, serve};
use ringpod_tests::cli;

struct Checks {
    passed: u32,
    failed: u32,
}

impl Checks {
    fn report(&mut self, name: &str, result: Result<String, String>) {
        match result {
            Ok(detail) => {
                self.passed += 1;
                println!("PASS {name}: {detail}");
            }
            Err(why) => {
                self.failed += 1;
                println!("FAIL {name}: {why}");
            }
        }
    }
}

/// What the checks are given: the CLI, its server's URL, a run record and the rig file the server was started with.
struct Given<'a> {
    cli: &'a Path,
    url: &'a str,
    record: &'a Path,
    rig: &'a Path,
}

async fn checks(driver: &str, given: &Given<'_>, shots: Option<&Path>) -> Result<Checks, String> {
    let (url, record) = (given.url, given.record);
    let mut caps = serde_json::Map::new();
    caps.insert(
        "goog:chromeOptions".into(),
        json!({
            "binary": "/usr/bin/chromium",
            "args": ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1400,1000", "--hide-scrollbars"],
        }),
    );
    let c = ClientBuilder::new(HttpConnector::new())
        .capabilities(caps)
        .connect(driver)
        .await
        .map_err(|e| format!("WebDriver session: {e}"))?;
    let mut k = Checks { passed: 0, failed: 0 };
    k.report("the page connects and draws the platform", connects(&c, url).await);
    k.report(
        "Enable and Home from the Control panel, gated by the supervisor",
        enable_and_home(&c, shots).await,
    );
    k.report(
        "the demo runs: the 3D pose and the counters advance",
        demo_runs(&c, shots).await,
    );
    k.report(
        "a page that goes away stops its stream; with no page left the platform powers down",
        lost_page(&c, url).await,
    );
    k.report("STOP ends the stream and powers down", stop_button(&c).await);
    k.report("the space bar is STOP", space_bar(&c).await);
    k.report(
        "a UDP poses session from the Control panel is followed",
        udp_session(&c).await,
    );
    k.report(
        "a page of another origin cannot open the WebSocket",
        other_origin(&c, url).await,
    );
    k.report("the rig editor names a bad key", rig_editor(&c, url, shots).await);
    k.report("cueing redraws when a parameter changes", cueing(&c, shots).await);
    k.report("a run record opens in the Runs panel", runs(&c, record, shots).await);
    k.report(
        "at 1366x768 the Control panel's buttons are on screen above its log",
        page::control_fits(&c).await,
    );
    if let Some(dir) = shots {
        k.report("every panel at 1366x768 and 1920x1080", page::sizes(&c, dir).await);
    }
    let rig_given = rig::Given {
        url,
        rig_file: given.rig,
        cli: given.cli,
        shots,
    };
    for size in [(1366, 768), (1920, 1080)] {
        k.report(
            &format!(
                "the rig form at {}x{}: the ring radius in mm redrawn, a bad value named, saved, found again",
                size.0, size.1
            ),
            rig::rig_form(&c, &rig_given, size).await,
        );
    }
    // Last: it reloads the page, and the pictures above are of the panels as the checks before left them.
    for (size, raise) in [((1366, 768), 1.2), ((1920, 1080), 2.5)] {
        k.report(
            &format!("a rig builder's task at {}x{}: an F1 session, the Live view, the F1 profile tuned live, saved and found again", size.0, size.1),
            task::at_size(&c, url, size, raise, shots).await,
        );
    }
    let _ = c.close().await;
    Ok(k)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let shots = match args.as_slice() {
        [] => None,
        [flag, dir] if flag == "--screenshots" => Some(PathBuf::from(dir)),
        // Step 1's packages only (the test command's, beside `cargo test`).
        [flag] if flag == "--prepare" => {
            return match setup::ensure_browser() {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("browser: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        _ => {
            eprintln!("usage: browser [--screenshots DIR | --prepare]");
            return ExitCode::from(2);
        }
    };
    let prepared = setup::ensure_browser()
        .and_then(|()| cli::host())
        .and_then(|cli| Ok((record(&cli)?, cli)))
        .and_then(|(record, cli)| {
            // The rig builder's cueing file, with an F1 profile (the task's), written afresh for each run.
            let profiles = process::target_dir().join("browser-cueing.toml");
            std::fs::write(&profiles, task::PROFILES).map_err(|e| format!("{}: {e}", profiles.display()))?;
            let rig = process::rig_file(&cli)?;
            Ok((record, serve(&cli, &profiles, &rig)?, chromedriver()?, rig, cli))
        });
    let (record, (_ui, url), (_driver, driver), rig, cli) = match prepared {
        Ok(p) => p,
        Err(e) => {
            eprintln!("browser: {e}");
            println!("0 passed, 1 failed");
            return ExitCode::FAILURE;
        }
    };
    let runtime = match tokio::runtime::Builder::new_multi_thread().enable_all().build() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("browser: {e}");
            return ExitCode::FAILURE;
        }
    };
    let given = Given {
        cli: &cli,
        url: &url,
        record: &record,
        rig: &rig,
    };
    match runtime.block_on(checks(&driver, &given, shots.as_deref())) {
        Ok(k) => {
            println!("{} passed, {} failed", k.passed, k.failed);
            if k.failed == 0 {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            eprintln!("browser: {e}");
            println!("0 passed, 1 failed");
            ExitCode::FAILURE
        }
    }
}

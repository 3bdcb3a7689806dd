//! What the emulator suites need on this machine before anything is built (the QEMU runner, `--bin qemu`, and the
//! rehost runner, `--bin rehost`, which needs only the target): the `thumbv7em-none-eabihf` standard library for
//! the toolchain `tests/qemu` builds with, and `qemu-system-arm`. Each is installed when missing and this process
//! may (rustup for the target; apt-get as root or through password-less sudo for QEMU); otherwise the runner stops
//! before building, with one line naming the exact command to run.
//!
//! Why the target needs this: `rust-toolchain.toml` names it, but rustup adds a toolchain file's targets only when
//! it installs the toolchain itself. A machine that already had the pinned toolchain (or links it to another) never
//! gets the target, and the build then fails deep inside cargo with "can't find crate for `core`".

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// `tests/qemu`: rustc run there picks the toolchain of the repository's `rust-toolchain.toml`, as the firmware
/// build does.
fn qemu_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("qemu")
}

/// The target the QEMU programs are built for (tests/qemu/.cargo/config.toml).
pub const TARGET: &str = "thumbv7em-none-eabihf";

/// Set to 1 to forbid the runner to install anything: it then only says what is missing and how to install it.
pub const NO_INSTALL: &str = "RINGPOD_NO_INSTALL";

/// Both requirements, in the order the build needs them; the first error stops the run.
pub fn preflight() -> Result<(), String> {
    ensure_target()?;
    ensure_qemu()
}

pub fn may_install() -> bool {
    std::env::var(NO_INSTALL).map_or(true, |v| v.is_empty() || v == "0")
}

/// A program's standard output, trimmed, when it ran and succeeded.
fn output(command: &mut Command) -> Option<String> {
    let out = command.stderr(Stdio::null()).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// `rustc` as `tests/qemu` sees it: run in that folder, so rustup picks the toolchain that build will use.
fn rustc_in_qemu_dir(args: &[&str]) -> Option<String> {
    output(Command::new("rustc").current_dir(qemu_dir()).args(args))
}

/// The folder of the target's standard library for the toolchain of `tests/qemu`, and whether `core` is in it.
fn target_library() -> Result<(PathBuf, bool), String> {
    let dir = rustc_in_qemu_dir(&["--print", "target-libdir", "--target", TARGET]).ok_or_else(|| {
        "rustc does not run in tests/qemu: install the pinned toolchain with `rustup toolchain install` (run in the \
         repository root)"
            .to_string()
    })?;
    let dir = PathBuf::from(dir);
    Ok((dir.clone(), has_core(&dir)))
}

fn has_core(dir: &Path) -> bool {
    std::fs::read_dir(dir).is_ok_and(|entries| {
        entries
            .map_while(Result::ok)
            .any(|e| e.file_name().to_string_lossy().starts_with("libcore-"))
    })
}

/// The rustup toolchain in effect in `tests/qemu` (`1.95.0-x86_64-unknown-linux-gnu`), when rustup manages it.
fn rustup_toolchain() -> Option<String> {
    let line = output(
        Command::new("rustup")
            .current_dir(qemu_dir())
            .args(["show", "active-toolchain"]),
    )?;
    line.split_whitespace().next().map(str::to_string)
}

/// Makes sure the target's standard library is installed, adding it with rustup when it is not.
pub fn ensure_target() -> Result<(), String> {
    let (dir, present) = target_library()?;
    if present {
        return Ok(());
    }
    let Some(toolchain) = rustup_toolchain() else {
        return Err(format!(
            "the {TARGET} standard library is missing from {} and rustup does not manage this toolchain: install \
             it the way the toolchain was installed (with rustup: `rustup target add {TARGET}`)",
            dir.display()
        ));
    };
    let command = format!("rustup target add --toolchain {toolchain} {TARGET}");
    if !may_install() {
        return Err(format!("the {TARGET} standard library is missing: run `{command}`"));
    }
    println!("== the {TARGET} standard library is missing: {command}");
    let added = Command::new("rustup")
        .current_dir(qemu_dir())
        .args(["target", "add", "--toolchain", &toolchain, TARGET])
        .status()
        .is_ok_and(|s| s.success());
    match target_library() {
        Ok((_, true)) if added => Ok(()),
        _ => Err(format!(
            "the {TARGET} standard library is missing and `{command}` did not install it: run it by hand"
        )),
    }
}

/// Makes sure `qemu-system-arm` is there: on a Debian or Ubuntu machine it installs it (as root, or through `sudo`
/// without a password), as the README's test command promises; otherwise it says what to install.
fn ensure_qemu() -> Result<(), String> {
    ensure_packages(
        &["qemu-system-arm"],
        &["qemu-system-arm"],
        "QEMU's Arm system emulator (7.2 or later)",
    )
}

/// What the browser tests need (`--bin browser`): Debian's Chromium and its ChromeDriver, installed as QEMU is.
pub fn ensure_browser() -> Result<(), String> {
    ensure_packages(
        &["chromium", "chromedriver"],
        &["chromium", "chromium-driver"],
        "Chromium and ChromeDriver",
    )
}

/// What the Windows runner needs (`--bin windows`): the MinGW-w64 cross compiler (it links the Windows builds and
/// builds the test-only DLL) and Wine to run them, installed as QEMU is. Debian 12's `wine` with `wine64` runs 64-bit
/// programs without the i386 architecture; the recommended packages (fonts, GStreamer, 32-bit support) are not
/// needed by a console program and are left out.
pub fn ensure_windows() -> Result<(), String> {
    ensure_packages_with(
        &["x86_64-w64-mingw32-gcc", "wine"],
        &["gcc-mingw-w64-x86-64", "wine", "wine64"],
        "the MinGW-w64 cross compiler and Wine",
        &["--no-install-recommends"],
    )
}

/// This process's turn at apt-get among the test command's runners: an exclusive lock on a file in the temporary
/// folder, held until the returned file is dropped (none when the file cannot be made: then no turns are taken).
fn apt_turn() -> Option<std::fs::File> {
    let file = std::fs::File::create(std::env::temp_dir().join("ringpod-apt.lock")).ok()?;
    file.lock().ok()?;
    Some(file)
}

/// Each of `programs` answers `--version`, or `packages` are installed with apt-get when this process may (as
/// root, or through sudo without a password); otherwise the one line that says what to run.
fn ensure_packages(programs: &[&str], packages: &[&str], what: &str) -> Result<(), String> {
    ensure_packages_with(programs, packages, what, &[])
}

/// [`ensure_packages`] with further `apt-get install` options.
fn ensure_packages_with(programs: &[&str], packages: &[&str], what: &str, options: &[&str]) -> Result<(), String> {
    let present = || {
        programs.iter().all(|p| {
            Command::new(p)
                .arg("--version")
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .is_ok_and(|s| s.success())
        })
    };
    if present() {
        return Ok(());
    }
    let root = output(Command::new("id").arg("-u")).is_some_and(|uid| uid == "0");
    let sudo = !root
        && Command::new("sudo")
            .args(["-n", "true"])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
    let apt = Command::new("apt-get")
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_ok();
    let list = options.iter().chain(packages).copied().collect::<Vec<_>>().join(" ");
    let command = if root {
        format!("apt-get update && apt-get install -y {list}")
    } else {
        format!("sudo apt-get update && sudo apt-get install -y {list}")
    };
    let missing = programs.join(" or ");
    let help = if apt {
        format!("{missing} is missing: run `{command}`")
    } else {
        format!("{missing} is missing: install {what} with this system's packages")
    };
    if !apt || !(root || sudo) || !may_install() {
        return Err(help);
    }
    // The test command's runners prepare side by side and dpkg takes one installer at a time: they take turns, and
    // another installer's lock is waited for (`DPkg::Lock::Timeout`) rather than failed on.
    let _turn = apt_turn();
    if present() {
        return Ok(());
    }
    println!("== {missing} is missing: {command}");
    let apt_get = |args: &[&str]| {
        let mut c = if root {
            Command::new("apt-get")
        } else {
            let mut c = Command::new("sudo");
            c.arg("apt-get");
            c
        };
        c.args(["-o", "DPkg::Lock::Timeout=600"])
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive")
            .status()
            .is_ok_and(|s| s.success())
    };
    let mut install = vec!["install", "-y"];
    install.extend(options);
    install.extend(packages);
    if apt_get(&["update"]) && apt_get(&install) && present() {
        Ok(())
    } else {
        Err(help)
    }
}

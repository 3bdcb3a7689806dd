//! `ringpod`: the command line of the ringpod motion controller.

mod analysis;
mod cli;
mod cueing;
mod device;
mod error;
mod flash;
mod games;
mod input;
mod link;
mod out;
mod rig;
mod signals;
mod stream;
mod ui;
mod vr;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let code = match run(&cli::Cli::parse().command) {
        Ok(code) => code,
        Err(e) => {
            out::console::err(&format!("ringpod: {}", error::in_one_line(&e)));
            out::EXIT_ERROR
        }
    };
    // What a command printed is flushed and checked here, for every command: output that could not be written
    // (a full disk, a closed pipe) is a failure, named, not an exit 0 with an empty file.
    match out::console::finish() {
        Some(failed) => {
            out::console::err(&format!("ringpod: {failed}"));
            ExitCode::from(out::EXIT_OUTPUT)
        }
        None => ExitCode::from(code),
    }
}

/// Runs one command: each module's typed error becomes anyhow here, at the top, and nowhere else.
fn run(command: &cli::Command) -> anyhow::Result<u8> {
    use cli::Command as C;
    if !command.watches_signals() {
        signals::end_on_signal()?;
    }
    Ok(match command {
        C::Presets { json, export } => answer(match export {
            Some(name) => rig::export(name).map_err(error::CliError::from),
            None => analysis::kinematics::presets(*json),
        })?,
        C::Rig { action } => answer(match action {
            cli::RigAction::Check { file, json } => rig::check_command(file, *json),
            cli::RigAction::Design {
                file,
                combined,
                arms_only,
                starts,
                steps,
                seed,
            } => rig::design_command(file, *combined, *arms_only, *starts, *steps, *seed),
        })?,
        C::Ik(args) => answer(analysis::kinematics::ik(
            &args.common.on(),
            args.pose.as_deref(),
            args.branch,
            false,
        ))?,
        C::Check(args) if args.tip_over => answer(analysis::tipover::run(&args.tip_over()))?,
        C::Check(args) => answer(analysis::kinematics::ik(
            &args.common.on(),
            args.pose.as_deref(),
            None,
            true,
        ))?,
        C::Fk(args) => answer(analysis::kinematics::fk(&args.options()))?,
        C::Rates(args) => answer(analysis::rates::run(&args.options()))?,
        C::Structure(args) => answer(analysis::structure::run(&args.options()))?,
        C::Loads(args) => answer(analysis::kinematics::loads(&args.options()))?,
        C::Dynamics(args) => answer(analysis::dynamics::command(&args.request()))?,
        C::Reactions(args) => answer(analysis::reactions::run(
            &args.common.on(),
            args.pose.as_deref(),
            &args.wrench,
        ))?,
        C::Stream(args) => stream::command::run(&args.job()?)?,
        C::Device(args) => {
            let (target, action) = args.request()?;
            device::run(&target, &action)?
        }
        C::Ports => device::ports()?,
        C::Flash { image, port, dfu } => flash::command::run(image.as_deref(), port.as_deref(), dfu.as_deref()),
        C::Ui(args) => ui::run(args.options()?)?,
        C::Simulate {
            geometry,
            mechanism,
            tcp,
            ..
        } => device::simulate(cli::platform(geometry, mechanism).as_ref(), *tcp)?,
        C::Monitor { port, sim, frames } => device::monitor(&link::Target::named(port.as_deref(), *sim)?, *frames)?,
        C::Cue(args) => {
            let (text, code) = match args.bench() {
                Some(bench) => cueing::bench::run(&bench)?,
                None => cueing::offline::run(&args.options()?)?,
            };
            print(&text);
            code
        }
        C::Plot {
            record,
            out,
            derivatives: true,
            window,
            from,
            to,
        } => say(stream::derivatives::plot_command(record, out, *window, (*from, *to)))?,
        C::Plot { record, out, .. } => say(stream::record::plot_command(record, out))?,
        C::Draw(args) => say(analysis::draw::run(&args.options()))?,
        C::Gram {
            z,
            step,
            out,
            table,
            reactions,
        } => say(analysis::gram::run(&analysis::gram::Options {
            z: *z,
            step: *step,
            out,
            table: table.as_deref(),
            reactions: reactions.as_deref(),
        }))?,
        C::Workspace(args) => say(analysis::workspace::run(&args.options()))?,
    })
}

/// Prints a command's text (a failure is kept and decides the exit code in `main`).
fn print(text: &str) {
    out::console::out(text);
}

/// Prints a kinematics command's text and passes on its exit code.
fn answer<E>(outcome: Result<out::Outcome, E>) -> Result<u8, E> {
    let outcome = outcome?;
    print(&outcome.text);
    Ok(outcome.code)
}

/// Prints a command's text: it ran, so it exits with 0.
fn say<E>(text: Result<String, E>) -> Result<u8, E> {
    print(&text?);
    Ok(0)
}

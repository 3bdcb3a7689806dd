//! `ringpod`: the command line of the ringpod motion controller.

mod analysis;
mod cli;
mod device;
mod error;
mod games;
mod input;
mod link;
mod out;
mod rig;
mod signals;
mod stream;
mod ui;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    use cli::Command as C;
    let cli = cli::Cli::parse();
    let result = match &cli.command {
        C::Presets { json, export } => answer(match export {
            Some(name) => rig::export(name),
            None => analysis::kinematics::presets(*json),
        }),
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
        }),
        C::Ik(args) => answer(analysis::kinematics::ik(
            &args.common.on(),
            args.pose.as_deref(),
            args.branch,
            false,
        )),
        C::Check(args) if args.tip_over => answer(analysis::tipover::run(&args.tip_over())),
        C::Check(args) => answer(analysis::kinematics::ik(
            &args.common.on(),
            args.pose.as_deref(),
            None,
            true,
        )),
        C::Fk(args) => answer(analysis::kinematics::fk(&args.options())),
        C::Rates(args) => answer(analysis::rates::run(&args.options())),
        C::Structure(args) => answer(analysis::structure::run(&args.options())),
        C::Loads(args) => answer(analysis::kinematics::loads(&args.options())),
        C::Reactions(args) => answer(analysis::reactions::run(
            &args.common.on(),
            args.pose.as_deref(),
            &args.wrench,
        )),
        C::Stream(args) => args
            .job()
            .map_err(anyhow::Error::from)
            .and_then(|job| stream::command::run(&job)),
        C::Device(args) => args
            .request()
            .map_err(anyhow::Error::from)
            .and_then(|(target, action)| device::run(&target, &action)),
        C::Ports => device::ports(),
        C::Ui(args) => args.options().map_err(anyhow::Error::from).and_then(ui::run),
        C::Simulate {
            geometry, mechanism, ..
        } => device::simulate(cli::platform(geometry, mechanism).as_ref()),
        C::Cue(args) => analysis::cue::run(&args.options()).map(|(text, code)| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            code
        }),
        C::Monitor { port, sim, frames } => link::Target::named(port.as_deref(), *sim)
            .map_err(anyhow::Error::from)
            .and_then(|target| device::monitor(&target, *frames)),
        C::Plot {
            record,
            out,
            derivatives,
            window,
            from,
            to,
        } => if *derivatives {
            analysis::derivatives::plot_command(
                record,
                out,
                *window,
                (from.unwrap_or(f64::NEG_INFINITY), to.unwrap_or(f64::INFINITY)),
            )
        } else {
            stream::record::plot_command(record, out)
        }
        .map(|text| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            0
        }),
        C::Draw(args) => analysis::draw::run(&args.options()).map(|text| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            0
        }),
        C::Gram { z, step, out, table } => analysis::gram::run(&analysis::gram::Options {
            z: *z,
            step: *step,
            out,
            table: table.as_deref(),
        })
        .map(|text| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            0
        }),
        C::Workspace(args) => analysis::workspace::run(&args.options()).map(|text| {
            let _ = std::io::stdout().write_all(text.as_bytes());
            0
        }),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("ringpod: {e:#}");
            ExitCode::from(error::EXIT_ERROR)
        }
    }
}

/// Prints a kinematics command's text and passes on its exit code.
fn answer(outcome: Result<out::Outcome, error::CliError>) -> anyhow::Result<u8> {
    let outcome = outcome?;
    // A closed pipe (`| head`) is not an error of ours.
    let _ = std::io::stdout().write_all(outcome.text.as_bytes());
    Ok(outcome.code)
}

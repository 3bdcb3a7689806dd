//! `ringpod`: the command line of the ringpod motion controller.

mod cli;
mod error;
mod kinematics;
mod mechanism;
mod numbers;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    match kinematics::run(&cli) {
        Ok(outcome) => {
            print!("{}", outcome.text);
            ExitCode::from(outcome.code)
        }
        Err(e) => {
            eprintln!("ringpod: {:#}", anyhow::Error::from(e));
            ExitCode::from(error::EXIT_ERROR)
        }
    }
}

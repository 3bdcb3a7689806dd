//! Experiments on the simulated platform: a generated motion streamed into a fresh simulated controller of the trainer model, as fast as it computes, with
//! its run record: the experiments of `ringpod stability` (the platform tilting toward an angle) go the very way of
//! `stream --sim --fast --input MOTION.csv --record RECORD.csv`, and the motion file is kept beside the record so
//! that the run can be repeated so.

use std::path::Path;

pub mod stability;

use crate::error::CliError;
use crate::link::{self, client};
use crate::stream::{read_csv, record::Recorder, Options, Report, Source};

/// The record's rate (Hz): a row every 4 ms, a tilt of 0.008 deg between rows at 2 deg/s.
const RECORD_HZ: u16 = 250;

/// Writes `motion` (a pose CSV, radians) to `motion_path`, streams it into a fresh simulated controller with the
/// host limiting into the envelope, records the run to `record`, and returns the stream's report. `stopped` ends
/// the run early, as a signal ends `stream`.
pub fn on_sim(motion: &str, motion_path: &Path, record: &Path, stopped: &dyn Fn() -> bool) -> Result<Report, CliError> {
    std::fs::write(motion_path, motion).map_err(|e| CliError::file(motion_path, e))?;
    let (poses, errors) = read_csv(motion, false).map_err(|e| CliError::file(motion_path, e))?;
    if !errors.is_empty() {
        return Err(CliError::Experiment(format!(
            "{}: {} rows of the generated motion could not be read",
            motion_path.display(),
            errors.len()
        )));
    }
    let transport = link::connect(&link::Target::Sim, false).map_err(|e| CliError::Experiment(e.to_string()))?;
    let mut client = client::Client::new(transport);
    let recorder = Recorder::create(record).map_err(|e| CliError::file(record, e))?;
    let options = Options {
        home: false,
        host_limits: true,
        quiet: true,
        telemetry: false,
        telemetry_hz: Some(RECORD_HZ),
        resend_stop: true,
    };
    crate::stream::run(
        &mut client,
        Source::Poses(poses),
        errors,
        &options,
        true,
        stopped,
        Some((recorder, record.display().to_string())),
    )
    .map_err(|e| CliError::Experiment(format!("the stream could not start: {e}")))
}

//! The end of a run: the stop and the wait for rest, the record and the telemetry rate closed, and the report with
//! its outcome and exit code.

use std::time::Duration;

use ringpod_core::protocol::Status;
use ringpod_core::safety::{FaultReason, State};

use super::prepare::telemetry_rate;
use super::report::{CaptureReport, DatagramReport, RecordReport, Report};
use super::session::{Stop, StreamError, Streamer};
use super::{exit, InputError};
use crate::link::client::{ClientError, Transport};
use crate::out::console;

/// How a run ended: why it stopped early, the device's status at rest, a lost link in words, what `--record`
/// wrote.
pub(super) struct Ending {
    stop: Option<Stop>,
    status: Option<Status>,
    transport: Option<String>,
    record: Option<RecordReport>,
}

/// Stops and waits for rest (also after Ctrl-C or a device that stopped by itself), closes the record and sets the
/// device's telemetry rate back.
pub(super) fn wind_down<T: Transport>(
    s: &mut Streamer<'_, T>,
    outcome: Result<(), StreamError>,
    record_path: Option<String>,
    restore_hz: Option<u16>,
    options: &super::Options,
) -> Ending {
    let telemetry_hz = options.telemetry_hz;
    let (stop, transport) = match outcome {
        Ok(()) => (None, None),
        Err(StreamError::Stop(stop)) => (Some(stop), None),
        Err(StreamError::Client(e)) => (None, Some(e)),
    };
    // A link that stalled may come back: the stop is given all the same (a closed one cannot).
    let stalled = matches!(transport, Some(ClientError::Timeout(_)));
    let status = if transport.is_none() || stalled {
        stop_and_rest(s, options.resend_stop)
    } else {
        None
    };
    // The stall is over when the stop was confirmed: the run still ended because of it.
    let transport = transport.map(|e| match (&status, e) {
        (Some(_), ClientError::Timeout(t)) => ClientError::Unexpected(format!(
            "no answer from the device within {t:?} (the link came back, and the stop was confirmed)"
        )),
        (_, e) => e,
    });
    // The samples of the stop and the ramp to rest.
    let _ = s.record();
    let mut record = record_path.map(|path| record_report(s, path));
    // The device's own telemetry rate back (a board stores it): after the record has taken its last samples.
    let rate_error = match restore_hz {
        Some(before) if transport.is_none() => telemetry_rate(s.client, before).err(),
        _ => None,
    };
    if let (Some(r), Some(e)) = (record.as_mut(), rate_error) {
        r.error
            .get_or_insert(format!("the device's telemetry rate was not set back: {e}"));
    }
    if let Some(r) = record.as_mut() {
        r.telemetry_hz = telemetry_hz;
    }
    let (status, transport) = match (status, transport) {
        (Some(st), None) => (Some(st), None),
        (None, None) => (None, Some("the device did not answer after the stop".to_string())),
        (st, Some(e)) => (st, Some(e.to_string())),
    };
    Ending {
        stop,
        status,
        transport,
        record,
    }
}

/// The report of a run: the verdict, the counts (checked against the device's), what was sent of each kind.
pub(super) fn report<T: Transport>(
    mut s: Streamer<'_, T>,
    ending: Ending,
    input_errors: Vec<InputError>,
    datagrams: Option<DatagramReport>,
    capture: Option<CaptureReport>,
) -> Report {
    let refused: u32 = s.rejected.values().sum();
    let unsaid = s.refusal_lines.unsaid();
    if unsaid > 0 {
        console::err(&format!(
            "{unsaid} more setpoints refused by the device since the last said; the report lists each"
        ));
    }
    let mut input_errors = input_errors;
    input_errors.sort_by_key(|e| e.line);
    let (outcome, reason, code) = verdict(
        ending.transport,
        ending.stop.as_ref(),
        refused,
        &input_errors,
        s.input_sent,
    );
    let status = ending.status;
    let counts_agree = status.as_ref().is_some_and(|st| {
        let b = &s.baseline;
        st.applied.wrapping_sub(b.applied) == s.applied_all
            && st.rejected.total().wrapping_sub(b.rejected.total()) == s.rejected_all
            && st.limited.count.wrapping_sub(b.limited.count) == s.device_limited
            && s.sent_all == s.applied_all + s.rejected_all
    });
    s.limited.device = s.device_limited;
    Report {
        outcome,
        reason,
        exit_code: code,
        state: status.as_ref().map_or("unknown".into(), |st| format!("{:?}", st.state)),
        setpoints_sent: s.input_sent,
        setpoints_applied: s.input_applied,
        limited: s.limited,
        rejected: s.rejected,
        refusals: s.refusals,
        lead_in_sent: s.lead_in,
        settle_sent: s.settle,
        washout_sent: s.washout,
        interpolated_sent: s.interpolated,
        restarts: s.restarts,
        held_sent: s.held,
        held_s: s.held_s,
        held_gaps: s.held_gaps,
        final_steps: status.as_ref().map_or([0; 6], |st| st.steps),
        faults: s.client.faults.iter().map(|f: &FaultReason| f.to_string()).collect(),
        input_errors,
        datagrams,
        last_applied_pose: s.last_applied.map(|p| p.to_array()),
        setpoints_unanswered: s.unanswered,
        counts_agree,
        record: ending.record,
        capture,
    }
}

/// Collects the answers still in flight (a device that stopped streaming has refused them), stops, and waits up
/// to 10 s for rest; the status at rest, or none when the device did not answer.
fn stop_and_rest<T: Transport>(s: &mut Streamer<'_, T>, resend: bool) -> Option<Status> {
    // The collection and the wait for rest run to their ends even after a signal (each bounded by its patience):
    // the platform is brought to rest, then reported.
    let cancel = s.client.cancel.take();
    while !s.in_flight.is_empty() {
        if let Err(StreamError::Client(_)) = s.collect(0) {
            break;
        }
    }
    let status = stop_confirmed(s, resend);
    s.client.cancel = cancel;
    status
}

/// How long a stop the device does not answer is given again (the device comes to rest by itself when the stream
/// stops; this is for the stop to be confirmed and the run reported as it ended).
const STOP_PATIENCE: Duration = Duration::from_secs(30);

/// Stops and waits up to 10 s for rest; through a stalled link, the stop is sent again every second for up to
/// [`STOP_PATIENCE`] when `resend`, saying so. The status at rest, or none when the device never answered.
fn stop_confirmed<T: Transport>(s: &mut Streamer<'_, T>, resend: bool) -> Option<Status> {
    let patience = if resend {
        crate::link::patience(STOP_PATIENCE)
    } else {
        Duration::ZERO
    };
    let started = std::time::Instant::now();
    let mut said = false;
    loop {
        let answered = match s.client.stop() {
            Err(ClientError::Timeout(_)) => false,
            // Refused (not running): the device answered; so did an accepted stop.
            Ok(()) | Err(ClientError::Device(_)) => true,
            Err(_) => return None,
        };
        if answered {
            let status = s.client.wait_for(Duration::from_secs(10), |st| {
                !matches!(st.state, State::Running | State::Stopping)
            });
            match status {
                Ok(st) => {
                    if said {
                        let after = started.elapsed().as_secs_f64();
                        s.bar
                            .suspend(|| console::err(&format!("the stop was confirmed after {after:.1} s")));
                    }
                    return Some(st);
                }
                Err(ClientError::Timeout(_)) => {}
                Err(_) => return None,
            }
        }
        if started.elapsed() >= patience {
            return None;
        }
        if !said {
            said = true;
            s.bar.suspend(|| {
                console::err(&format!(
                    "STOP pending: the device does not answer; the stop is sent again every second for up to {patience:?}"
                ))
            });
        }
        s.client.transport().elapse(Duration::from_secs(1));
    }
}

/// What `--record` wrote: its rows (in the file under its name: a record that failed is not put there), the
/// samples dropped, and why it failed, if it did.
fn record_report<T: Transport>(s: &mut Streamer<'_, T>, path: String) -> RecordReport {
    let dropped = s.client.telemetry_dropped;
    let unsolved = s.client.followed.as_ref().map_or(0, |f| f.unsolved);
    let (rows, error) = match (s.recorder.take(), s.record_error.take()) {
        (Some(r), None) => match r.finish() {
            Ok(rows) => (rows, None),
            Err(e) => (0, Some(e.to_string())),
        },
        (_, e) => (0, e),
    };
    RecordReport {
        path,
        rows,
        telemetry_hz: None,
        dropped,
        unsolved,
        error,
    }
}

/// A run that never moved (its input had no pose to lead in to): the device's status as it is.
pub(super) fn unmoved(status: Status) -> Ending {
    Ending {
        stop: None,
        status: Some(status),
        transport: None,
        record: None,
    }
}

/// The run's outcome, its reason and exit code: the most serious of a lost link, a device that stopped, a
/// signal, refusals, input errors, no input at all; else followed.
fn verdict(
    transport: Option<String>,
    stop: Option<&Stop>,
    refused: u32,
    input_errors: &[InputError],
    input_sent: u32,
) -> (&'static str, Option<String>, u8) {
    if let Some(t) = transport {
        ("transport_lost", Some(t), exit::TRANSPORT_LOST)
    } else if let Some(Stop::Device(why)) = stop {
        ("device_stopped", Some(why.clone()), exit::DEVICE_STOPPED)
    } else if let Some(Stop::Interrupted) = stop {
        (
            "interrupted",
            Some("interrupted (a signal, or STOP in the workbench)".to_string()),
            exit::INTERRUPTED,
        )
    } else if refused > 0 {
        (
            "refused",
            Some(format!("the device refused {refused} setpoints")),
            exit::REFUSED,
        )
    } else if input_sent == 0 {
        let unread = match input_errors.len() {
            0 => String::new(),
            n => format!(" ({n} input lines could not be read)"),
        };
        (
            "input_errors",
            Some(format!("no pose in the input{unread}")),
            exit::INPUT_ERRORS,
        )
    } else if !input_errors.is_empty() {
        (
            "input_errors",
            Some(format!("{} input lines could not be read", input_errors.len())),
            exit::INPUT_ERRORS,
        )
    } else {
        ("followed", None, exit::FOLLOWED)
    }
}

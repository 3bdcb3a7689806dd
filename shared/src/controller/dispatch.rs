//! Protocol dispatch: every request gets exactly one response, a frame that does not decode is counted and never
//! executed.

use super::homing::Homing;
use super::{Controller, Restart};
use crate::kinematics::presets::{Preset, PresetGeometry};
use crate::kinematics::{AxisKind, Mechanism};
use crate::motion::jog::Jog;
use crate::motion::{Accepted, Setpoint};
use crate::protocol::{self, DeviceMessage, HostMessage, NackReason, Request, Response, PROTOCOL_VERSION};
use crate::safety::{Aux, Command, Event, HomingSequencer, State};

impl Controller {
    /// Handles one request; always exactly one response.
    pub fn handle(&mut self, request: &Request) -> Response {
        // Any request says a host is there (a lost stream's silence starts again).
        self.host.heard();
        let body = match request.body {
            HostMessage::Hello { version } => {
                if version == PROTOCOL_VERSION {
                    self.connected = true;
                    self.hellos = self.hellos.wrapping_add(1);
                    self.telemetry.on = false;
                    DeviceMessage::Hello {
                        version: PROTOCOL_VERSION,
                        firmware: self.firmware,
                        preset: Preset::ALL
                            .into_iter()
                            .find(|p| matches!(p.geometry(), PresetGeometry::Ring(g) if *g == self.config.geometry)),
                        axes: self.pipeline.mechanism().axes(),
                    }
                } else {
                    self.connected = false;
                    DeviceMessage::Nack(NackReason::VersionMismatch {
                        device: PROTOCOL_VERSION,
                        firmware: Some(self.firmware),
                    })
                }
            }
            // Without a handshake: a host of any version can update the board (the stable head, `firmware`).
            HostMessage::EnterBootloader => match self.request_restart(Restart::Bootloader) {
                Ok(()) => DeviceMessage::Ack,
                Err(r) => DeviceMessage::Nack(r),
            },
            _ if !self.connected => DeviceMessage::Nack(NackReason::NotConnected),
            HostMessage::Setpoint(sp) => self.submit(&sp),
            HostMessage::GetStatus => DeviceMessage::Status(self.status()),
            HostMessage::GetInputs => DeviceMessage::Inputs(self.input_report()),
            HostMessage::Jog { axis, steps } => self.start_jog(axis, Some(steps)),
            HostMessage::Buzz { axis } => self.start_jog(axis, None),
            HostMessage::Telemetry(on) => {
                self.telemetry.on = on;
                self.telemetry.ticks = 0;
                DeviceMessage::Ack
            }
            HostMessage::GetSettings(kind) => self.settings_report(kind),
            HostMessage::SetSettings(settings) => match self.set_settings(&settings) {
                Ok(()) => DeviceMessage::Ack,
                Err(r) => DeviceMessage::Nack(r),
            },
            HostMessage::GetRig => self.rig_report(),
            HostMessage::SetRig(record) => match self.set_rig(&record) {
                Ok(()) => DeviceMessage::Ack,
                Err(r) => DeviceMessage::Nack(r),
            },
            HostMessage::Restart => match self.request_restart(Restart::Controller) {
                Ok(()) => DeviceMessage::Ack,
                Err(r) => DeviceMessage::Nack(r),
            },
            HostMessage::Command(command) => self.command(Event::Command(command)),
        };
        Response { id: request.id, body }
    }

    /// A setpoint for the pipeline, and its answer.
    fn submit(&mut self, setpoint: &Setpoint) -> DeviceMessage {
        match self.take_setpoint(setpoint) {
            Ok(Accepted::Applied) => DeviceMessage::Ack,
            Ok(Accepted::Limited(report)) => DeviceMessage::Limited(report),
            Err(reason) => DeviceMessage::Nack(NackReason::Rejected(reason)),
        }
    }

    /// Submits a setpoint; one the pipeline takes switches the auxiliary outputs it names, as the command would
    /// (the pipeline takes setpoints only while `Running`, where the supervisor allows them on). They switch when the
    /// setpoint is taken, one setpoint interval before the platform arrives at its pose: the interpolation runs a
    /// segment behind the newest setpoint.
    fn take_setpoint(&mut self, setpoint: &Setpoint) -> Result<Accepted, crate::motion::RejectReason> {
        let accepted = self.pipeline.submit(setpoint)?;
        for (output, level) in Aux::ALL.into_iter().zip(setpoint.aux) {
            if let Some(on) = level {
                // A refusal leaves the output as it was, and the setpoint's answer says how the pose was taken.
                let _ = self.supervisor.handle(Event::Command(Command::Aux { output, on }));
            }
        }
        Ok(accepted)
    }

    /// Starts a jog (`Some(steps)`) or a buzz (`None`) of `axis`, if the supervisor allows it.
    pub(super) fn start_jog(&mut self, axis: u8, steps: Option<i32>) -> DeviceMessage {
        let a = usize::from(axis);
        let (Some(homing), Some(kind)) = (
            self.plan.config().axes.get(a).copied(),
            self.pipeline.mechanism().axes().get(a).copied(),
        ) else {
            return DeviceMessage::Nack(NackReason::OutOfRange);
        };
        // A carriage moves at most its homing back-off unhomed or not (never far enough to reach a neighbour on
        // the ring); a linear actuator at most the travel its homing searches blind.
        let longest = match kind {
            AxisKind::Ring => homing.backoff_steps,
            AxisKind::Linear | AxisKind::Angle => homing.search_steps,
        };
        if steps.is_some_and(|s| s == 0 || s.unsigned_abs() > longest) {
            return DeviceMessage::Nack(NackReason::OutOfRange);
        }
        let answer = self.command(Event::Jog);
        if answer != DeviceMessage::Ack {
            return answer;
        }
        let from = self.scheduler.position()[a];
        let jog = match steps {
            Some(s) => Jog::one_leg(a, from, s, homing.slow_rate),
            None => {
                let amplitude = i32::try_from((homing.backoff_steps / 2).max(1)).unwrap_or(i32::MAX);
                Jog::buzz(a, from, amplitude, homing.fast_rate)
            }
        };
        self.jog = Some((jog, self.inputs.home & (1 << a) != 0));
        answer
    }

    pub(super) fn command(&mut self, e: Event) -> DeviceMessage {
        let was_fault = matches!(self.supervisor.state(), State::Fault(..));
        let was_homed = self.supervisor.homed() && self.supervisor.state() == State::Ready;
        let result = self.supervisor.handle(e);
        self.after_transition(was_fault);
        if let Err(r) = result {
            return DeviceMessage::Nack(NackReason::Refused(r));
        }
        match e {
            Event::Command(Command::Home) => {
                // A homed machine knows where its switches are: it first moves, under the normal limits and
                // checks, to where the first homing started (each axis a little before its switch), so that
                // every search is as short as the first one was. The home pose is often further from a linear
                // actuator's end switch than its search travel.
                // One homed since start but not now (powered down, jogged, faulted) first finds where its counted
                // steps put it, whole carriage turns included.
                let parking = (was_homed || (self.origins && self.resume_from_steps()))
                    && self
                        .parking_pose()
                        .is_ok_and(|pose| self.pipeline.move_to(pose).is_ok());
                self.homing = if parking {
                    Homing::Parking
                } else {
                    Homing::Searching {
                        sequencer: HomingSequencer::new(self.plan, &self.scheduler.position()),
                        carry: 0,
                    }
                };
            }
            Event::Command(Command::Start) => self.pipeline.start(),
            Event::Command(Command::Stop) => {
                self.pipeline.stop();
                if self.homing != Homing::Idle {
                    self.pipeline.halt();
                    self.homing = Homing::Idle;
                }
            }
            _ => {}
        }
        DeviceMessage::Ack
    }

    /// Decodes a frame, handles it and encodes the response into `out`; returns the response length. A frame that
    /// does not decode is counted and answered with a `Malformed` nack (id 0): it is never executed.
    ///
    /// The stream's hot path: `out` (at least [`protocol::MAX_FRAME`] long) holds the decoded payload first, so
    /// that no frame-sized buffer is zeroed per frame; a setpoint is read on its own rather than as a [`Request`],
    /// and its answer is built where it is encoded: a [`Response`] has room for the largest message (a rig record),
    /// and moving one costs thousands of instructions on the M4F (measured with `tests/qemu/profile`).
    pub fn handle_frame(&mut self, frame: &[u8], out: &mut [u8]) -> usize {
        let Ok(payload) = protocol::unframe(frame, out) else {
            return self.malformed(out);
        };
        if let (true, Some((id, setpoint))) = (self.connected, protocol::setpoint_request(payload)) {
            let encoded = match self.take_setpoint(&setpoint) {
                Ok(Accepted::Applied) => protocol::encode(
                    &Response {
                        id,
                        body: DeviceMessage::Ack,
                    },
                    out,
                ),
                Ok(Accepted::Limited(report)) => protocol::encode(
                    &Response {
                        id,
                        body: DeviceMessage::Limited(report),
                    },
                    out,
                ),
                Err(reason) => protocol::encode(
                    &Response {
                        id,
                        body: DeviceMessage::Nack(NackReason::Rejected(reason)),
                    },
                    out,
                ),
            };
            return encoded.unwrap_or(0);
        }
        match protocol::parse::<Request>(payload) {
            Ok(request) => {
                let response = self.handle(&request);
                protocol::encode(&response, out).unwrap_or(0)
            }
            Err(_) => self.malformed(out),
        }
    }

    /// Counts a frame that did not decode and answers it with a `Malformed` nack (id 0).
    fn malformed(&mut self, out: &mut [u8]) -> usize {
        self.bad_frames = self.bad_frames.saturating_add(1);
        let response = Response {
            id: 0,
            body: DeviceMessage::Nack(NackReason::Malformed),
        };
        protocol::encode(&response, out).unwrap_or(0)
    }
}

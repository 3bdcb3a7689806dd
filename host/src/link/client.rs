//! A typed client of the controller over any byte transport: a serial port to a board, or the in-process
//! simulator. Transport errors and device-reported refusals are kept apart in [`ClientError`].

use std::collections::VecDeque;
use std::time::Duration;

use ringpod_core::kinematics::presets::Preset;
use ringpod_core::motion::{Accepted, RejectReason};
use ringpod_core::protocol::endpoints::{
    Do, Endpoint, EnterBootloader, GetInputs, GetRig, GetSettings, GetStatus, Hello, Restart, SetRig, SetSettings,
    TelemetryOn,
};
use ringpod_core::protocol::{
    self, DeviceMessage, Firmware, FrameReader, HostMessage, InputReport, NackReason, Request, Response, RigRecord,
    RigSource, Settings, SettingsKind, Status, Telemetry, PROTOCOL_VERSION,
};
use ringpod_core::safety::{Command, FaultReason};

/// Telemetry samples kept for a taker (a minute at 1 kHz); older ones are dropped and counted.
pub const TELEMETRY_KEPT: usize = 60_000;

/// Sees each telemetry sample as it arrives ([`Client::tap`]).
pub type TelemetryTap = Box<dyn FnMut(&Telemetry) + Send>;

/// A byte pipe to a controller, with its notion of time.
pub trait Transport {
    /// Writes bytes.
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()>;
    /// Reads what has arrived (0 when nothing has).
    fn receive(&mut self, buf: &mut [u8]) -> std::io::Result<usize>;
    /// Lets `dt` pass: a real device runs on its own clock (sleep); the simulator ticks through it.
    fn elapse(&mut self, dt: Duration);
    /// From here the time that passes is the wall clock's (a live source's samples): a simulator that runs as fast
    /// as the machine computes ties its clock to the wall clock, as one in real time does. A board runs on its own
    /// clock: nothing to do.
    fn keep_pace(&mut self) {}
}

/// What a device says of itself in the handshake.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Device {
    /// The firmware it runs (its protocol version is this host's).
    pub firmware: Firmware,
    /// The preset it drives, if its geometry is one.
    pub preset: Option<Preset>,
    /// What each actuator coordinate measures.
    pub axes: [ringpod_core::kinematics::AxisKind; 6],
}

/// Why a request did not produce its answer.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// The transport failed.
    #[error("transport: {0}")]
    Io(#[from] std::io::Error),
    /// No answer in time.
    #[error("no answer from the device within {0:?}")]
    Timeout(Duration),
    /// The device refused the request.
    #[error("device refused: {0}")]
    Device(NackReason),
    /// Host and device speak different protocol versions: nothing was asked of it but the handshake.
    #[error("{}", mismatch(.host, .device, .firmware))]
    VersionMismatch {
        /// Ours.
        host: u16,
        /// Theirs.
        device: u16,
        /// The firmware it runs, when it names it (a board of protocol 9 or older does not).
        firmware: Option<Firmware>,
    },
    /// An answer of the wrong kind.
    #[error("unexpected answer: {0}")]
    Unexpected(String),
    /// The user interrupted a wait (Ctrl-C).
    #[error("interrupted")]
    Interrupted,
}

/// What a version mismatch tells the user: which firmware the board runs and what to do, `ringpod flash` named.
fn mismatch(host: &u16, device: &u16, firmware: &Option<Firmware>) -> String {
    let runs = match firmware {
        Some(f) => format!("{f}, protocol {device}"),
        None => format!("firmware of protocol {device}"),
    };
    if device < host {
        format!(
            "the board runs older firmware ({runs}) than this ringpod (protocol {host}): nothing was sent to it; run `ringpod flash` to update the board"
        )
    } else {
        format!(
            "the board runs newer firmware ({runs}) than this ringpod (protocol {host}): nothing was sent to it; update ringpod, or run `ringpod flash` to put this version's firmware on the board"
        )
    }
}

/// The client.
pub struct Client<T: Transport> {
    transport: T,
    reader: FrameReader,
    next_id: u32,
    inbox: VecDeque<Response>,
    /// Faults the device reported on its own.
    pub faults: Vec<FaultReason>,
    /// Telemetry samples not yet taken ([`Client::take_telemetry`]); the oldest go past [`TELEMETRY_KEPT`].
    telemetry: VecDeque<Telemetry>,
    /// Telemetry samples dropped because nobody took them.
    pub telemetry_dropped: u64,
    /// How long to wait for an answer.
    pub timeout: Duration,
    /// Set by Ctrl-C: long waits ([`Client::wait_for`]) end with [`ClientError::Interrupted`].
    pub cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Sees every telemetry sample as it arrives, whoever drives the client (the workbench's live view while a
    /// stream runs); the samples are kept for [`Client::take_telemetry`] all the same.
    pub tap: Option<TelemetryTap>,
    /// The platform and motors the device runs, when known: each telemetry sample's pose becomes the pose of the
    /// steps it counted ([`super::followed`]) before the tap and the caller see it.
    pub followed: Option<super::followed::Followed>,
    /// What the device said of itself in the last handshake that agreed.
    pub device: Option<Device>,
}

impl<T: Transport> Client<T> {
    /// A client over a transport.
    pub fn new(transport: T) -> Self {
        Self {
            transport,
            reader: FrameReader::default(),
            next_id: 0,
            inbox: VecDeque::new(),
            faults: Vec::new(),
            telemetry: VecDeque::new(),
            telemetry_dropped: 0,
            timeout: super::patience(Duration::from_secs(2)),
            cancel: None,
            tap: None,
            followed: None,
            device: None,
        }
    }

    /// Whether the cancel flag (Ctrl-C, a STOP) is raised: long waits end at once.
    pub fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(std::sync::atomic::Ordering::SeqCst))
    }

    /// The transport (to let time pass).
    pub fn transport(&mut self) -> &mut T {
        &mut self.transport
    }

    fn pump(&mut self) -> Result<(), ClientError> {
        let mut buf = [0u8; 512];
        loop {
            let n = self.transport.receive(&mut buf)?;
            if n == 0 {
                return Ok(());
            }
            for &b in &buf[..n] {
                if let Some(frame) = self.reader.push(b) {
                    // A frame that does not decode is dropped: the request it answered times out and says so. A
                    // device of another protocol version is read from the stable head its answer keeps.
                    if let Some(response) = decode(frame) {
                        match (response.id, response.body) {
                            (0, DeviceMessage::Fault(reason)) => self.faults.push(reason),
                            (0, DeviceMessage::Telemetry(mut sample)) => {
                                if let Some(followed) = &mut self.followed {
                                    followed.apply(&mut sample);
                                }
                                if let Some(tap) = &mut self.tap {
                                    tap(&sample);
                                }
                                if self.telemetry.len() >= TELEMETRY_KEPT {
                                    self.telemetry.pop_front();
                                    self.telemetry_dropped += 1;
                                }
                                self.telemetry.push_back(sample);
                            }
                            _ => self.inbox.push_back(response),
                        }
                    }
                }
            }
        }
    }

    /// Asks the device for telemetry on this connection (or to stop it).
    pub fn telemetry(&mut self, on: bool) -> Result<(), ClientError> {
        self.call(TelemetryOn(on))
    }

    /// The telemetry samples that arrived since the last call, oldest first (reads what the transport has).
    pub fn take_telemetry(&mut self) -> Result<Vec<Telemetry>, ClientError> {
        self.pump()?;
        Ok(self.telemetry.drain(..).collect())
    }

    /// Sends one request without waiting; returns its id. Its response waits in the inbox for
    /// [`Client::take_response`] (answers to other requests never displace it).
    pub fn send(&mut self, body: HostMessage) -> Result<u32, ClientError> {
        self.next_id = self.next_id.wrapping_add(1).max(1);
        let id = self.next_id;
        // A leading delimiter ends whatever partial frame line noise left in the device's reader, so that this
        // request is read on its own (an empty frame is nothing to the reader).
        let mut frame = [0u8; protocol::MAX_FRAME + 1];
        let n = protocol::encode(&Request { id, body }, &mut frame[1..])
            .map_err(|e| ClientError::Unexpected(format!("request does not encode: {e}")))?;
        self.transport.send(&frame[..n + 1])?;
        Ok(id)
    }

    /// The response to request `id` if it has arrived (reads what the transport has, does not wait).
    pub fn take_response(&mut self, id: u32) -> Result<Option<DeviceMessage>, ClientError> {
        self.pump()?;
        Ok(self
            .inbox
            .iter()
            .position(|r| r.id == id)
            .and_then(|i| self.inbox.remove(i))
            .map(|r| r.body))
    }

    /// Whether the answer to a request sent after `id` has arrived while `id`'s has not: the device answers its
    /// link's requests in order, so `id`'s request or its answer was lost on the way (a frame cut by noise or an
    /// overrun, dropped as undecodable) and will never come.
    ///
    /// Judged on what has been read, without reading more: a read may end inside `id`'s answer, and the next one
    /// bring the rest of it together with later answers.
    pub fn answered_after(&self, id: u32) -> bool {
        // Ids count up and wrap: a later one is less than half the id space ahead.
        !self.inbox.iter().any(|r| r.id == id) && self.inbox.iter().any(|r| r.id.wrapping_sub(id) < u32::MAX / 2)
    }

    /// Waits for the response to request `id`, up to the timeout; a raised cancel flag (Ctrl-C) ends the wait at
    /// once, so that a device that does not answer (a silent port, a stalled link) does not hold a signal back.
    pub fn wait_response(&mut self, id: u32) -> Result<DeviceMessage, ClientError> {
        let step = Duration::from_micros(200);
        let mut waited = Duration::ZERO;
        loop {
            if let Some(body) = self.take_response(id)? {
                return Ok(body);
            }
            if self.cancelled() {
                return Err(ClientError::Interrupted);
            }
            if waited >= self.timeout {
                return Err(ClientError::Timeout(self.timeout));
            }
            self.transport.elapse(step);
            waited += step;
        }
    }

    /// Sends one request and waits for its response.
    pub fn request(&mut self, body: HostMessage) -> Result<DeviceMessage, ClientError> {
        let id = self.send(body)?;
        self.wait_response(id)
    }

    /// Sends a request that may be lost and sent again, and waits `per_try` (not the whole timeout) for its answer;
    /// its id is kept in `tries`, so that the caller can drop the late answers to the tries before.
    fn try_once(
        &mut self,
        body: HostMessage,
        per_try: Duration,
        tries: &mut Vec<u32>,
    ) -> Result<DeviceMessage, ClientError> {
        let id = self.send(body)?;
        tries.push(id);
        let timeout = std::mem::replace(&mut self.timeout, per_try);
        let answer = self.wait_response(id);
        self.timeout = timeout;
        answer
    }

    /// Sends a request and takes the answer its [`Endpoint`] names; a Nack is [`ClientError::Device`], any other
    /// message [`ClientError::Unexpected`].
    pub fn call<E: Endpoint>(&mut self, endpoint: E) -> Result<E::Answer, ClientError> {
        let message = self.request(endpoint.request())?;
        endpoint.answer(message).map_err(|other| match other {
            DeviceMessage::Nack(reason) => ClientError::Device(reason),
            other => ClientError::Unexpected(format!("{other:?}")),
        })
    }

    /// Version handshake; returns the firmware the device runs and the geometry it drives, or the version mismatch
    /// naming its firmware.
    ///
    /// The first request on a port that was just opened can be lost: a board still enumerating, or a pseudo
    /// terminal whose other side is polled only now and then (QEMU's, about once a second). Hello changes nothing,
    /// so it is sent again every half second until the whole timeout (at least 5 s) has passed; the answers to
    /// earlier tries are dropped.
    pub fn hello(&mut self) -> Result<Device, ClientError> {
        let patience = self.timeout.max(super::patience(Duration::from_secs(5)));
        let per_try = Duration::from_millis(500);
        let mut tries = Vec::new();
        let answer = loop {
            match self.try_once(Hello.request(), per_try, &mut tries) {
                Err(ClientError::Timeout(_)) if per_try * tries.len() as u32 <= patience => continue,
                Err(ClientError::Timeout(_)) => break Err(ClientError::Timeout(patience)),
                other => break other,
            }
        };
        self.pump()?;
        self.inbox.retain(|r| !tries.contains(&r.id));
        self.greeted(answer?)
    }

    /// One handshake, waiting `wait` for its answer (`ringpod ports`, which must not wait long for each port).
    pub fn hello_once(&mut self, wait: Duration) -> Result<Device, ClientError> {
        let mut tries = Vec::new();
        let answer = self.try_once(Hello.request(), wait, &mut tries)?;
        self.greeted(answer)
    }

    /// The device of a handshake's answer, or the version mismatch it says.
    fn greeted(&mut self, answer: DeviceMessage) -> Result<Device, ClientError> {
        let (version, firmware) = match Hello.answer(answer) {
            Ok(hello) if hello.version == PROTOCOL_VERSION => {
                let device = Device {
                    firmware: hello.firmware,
                    preset: hello.preset,
                    axes: hello.axes,
                };
                self.device = Some(device);
                return Ok(device);
            }
            Ok(hello) => (hello.version, Some(hello.firmware)),
            Err(DeviceMessage::Nack(NackReason::VersionMismatch { device, firmware })) => (device, firmware),
            Err(other) => return Err(ClientError::Unexpected(format!("{other:?}"))),
        };
        self.device = None;
        Err(ClientError::VersionMismatch {
            host: PROTOCOL_VERSION,
            device: version,
            firmware,
        })
    }

    /// Asks the device to restart into its ROM bootloader (no handshake needed: any protocol version takes it),
    /// refused unless `Off`. The link goes with the reset.
    pub fn enter_bootloader(&mut self) -> Result<(), ClientError> {
        self.call(EnterBootloader)
    }

    /// Power up (logic, then power).
    pub fn enable(&mut self) -> Result<(), ClientError> {
        self.call(Do(Command::Enable))
    }
    /// Shut down.
    pub fn disable(&mut self) -> Result<(), ClientError> {
        self.call(Do(Command::Disable))
    }
    /// Home all axes.
    pub fn home(&mut self) -> Result<(), ClientError> {
        self.call(Do(Command::Home))
    }
    /// Start taking setpoints.
    pub fn start(&mut self) -> Result<(), ClientError> {
        self.call(Do(Command::Start))
    }
    /// Ramp to rest.
    pub fn stop(&mut self) -> Result<(), ClientError> {
        self.call(Do(Command::Stop))
    }
    /// Clear a latched fault.
    pub fn clear(&mut self) -> Result<(), ClientError> {
        self.call(Do(Command::ClearFault))
    }
    /// Switch an auxiliary output (on only while Ready or Running; off always).
    pub fn aux(&mut self, output: ringpod_core::safety::Aux, on: bool) -> Result<(), ClientError> {
        self.call(Do(Command::Aux { output, on }))
    }

    /// A section of settings on the device as the next start runs it (what runs now, for a live section), and
    /// whether that differs from what runs now.
    pub fn settings(&mut self, kind: SettingsKind) -> Result<(Settings, bool), ClientError> {
        self.call(GetSettings(kind)).map(|a| (a.settings, a.pending))
    }

    /// Changes a section (refused while anything may move, or with the cause the device names).
    pub fn set_settings(&mut self, settings: Settings) -> Result<(), ClientError> {
        self.call(SetSettings(settings))
    }

    /// The rig the device runs, where it came from, and whether another waits for the next start.
    pub fn rig(&mut self) -> Result<(RigRecord, RigSource, bool), ClientError> {
        self.call(GetRig).map(|a| (a.rig, a.source, a.pending))
    }

    /// Stores a rig for the next start (refused unless `Off`, or with the cause the checks give).
    pub fn set_rig(&mut self, rig: RigRecord) -> Result<(), ClientError> {
        self.call(SetRig(rig))
    }

    /// Restarts the controller once everything is stored (refused unless `Off`). The device is gone for a moment:
    /// a new connection starts with `hello`.
    pub fn restart(&mut self) -> Result<(), ClientError> {
        self.call(Restart)
    }

    /// After [`Client::restart`]: polls the status until the device answers as a new start (a request before
    /// `hello` is refused as not connected), or `limit` (lengthened by [`super::patience`]) passes. A poll sent
    /// while the board resets is lost with it, so each waits a quarter second (lengthened alike), not a request's
    /// whole timeout, before the next; answers to earlier polls are dropped. `Ok(false)`: the port closed (a board on
    /// USB leaves, and comes back under the same name in a moment).
    pub fn await_new_start(&mut self, limit: Duration) -> Result<bool, ClientError> {
        let limit = super::patience(limit);
        let per_try = super::patience(Duration::from_millis(250));
        let pause = Duration::from_millis(50);
        let mut tries = Vec::new();
        let mut waited = Duration::ZERO;
        let outcome = loop {
            match self.try_once(GetStatus.request(), per_try, &mut tries) {
                Ok(DeviceMessage::Nack(NackReason::NotConnected)) => break Ok(true),
                Err(ClientError::Io(_)) => break Ok(false),
                Err(ClientError::Timeout(_)) => waited += per_try,
                // Answered by the controller before it went (still storing), or garbled by the reset.
                _ => {}
            }
            if waited >= limit {
                break Err(ClientError::Timeout(limit));
            }
            self.transport.elapse(pause);
            waited += pause;
        };
        if matches!(outcome, Ok(true)) {
            self.pump()?;
        }
        self.inbox.retain(|r| !tries.contains(&r.id));
        outcome
    }

    /// The device's status.
    pub fn status(&mut self) -> Result<Status, ClientError> {
        self.call(GetStatus)
    }

    /// Every input's level and debounced state.
    pub fn inputs(&mut self) -> Result<InputReport, ClientError> {
        self.call(GetInputs)
    }

    /// Polls the status every 10 ms until `done` says so, or `limit` (lengthened by [`super::patience`]) passes.
    pub fn wait_for(&mut self, limit: Duration, done: impl Fn(&Status) -> bool) -> Result<Status, ClientError> {
        let limit = super::patience(limit);
        let step = Duration::from_millis(10);
        let mut waited = Duration::ZERO;
        loop {
            let s = self.status()?;
            if done(&s) {
                return Ok(s);
            }
            if self.cancelled() {
                return Err(ClientError::Interrupted);
            }
            if waited >= limit {
                return Err(ClientError::Timeout(limit));
            }
            self.transport.elapse(step);
            waited += step;
        }
    }
}

/// A device's message from one frame: this version's, or a version mismatch read from the stable head of another.
fn decode(frame: &[u8]) -> Option<Response> {
    if let Ok(response) = protocol::decode::<Response>(frame) {
        return Some(response);
    }
    let mut scratch = [0u8; protocol::MAX_FRAME];
    let payload = protocol::unframe(frame, &mut scratch).ok()?;
    let (id, device, firmware) = protocol::firmware::version_mismatch(payload)?;
    Some(Response {
        id,
        body: DeviceMessage::Nack(NackReason::VersionMismatch { device, firmware }),
    })
}

/// What a device's answer to a setpoint means: `Ok(Ok(accepted))` as applied or limited, `Ok(Err(reason))` when
/// refused, `Err` for an answer that is no answer to a setpoint.
pub fn setpoint_answer(answer: DeviceMessage) -> Result<Result<Accepted, RejectReason>, ClientError> {
    match answer {
        DeviceMessage::Ack => Ok(Ok(Accepted::Applied)),
        DeviceMessage::Limited(report) => Ok(Ok(Accepted::Limited(report))),
        DeviceMessage::Nack(NackReason::Rejected(r)) => Ok(Err(r)),
        DeviceMessage::Nack(r) => Err(ClientError::Device(r)),
        other => Err(ClientError::Unexpected(format!("{other:?}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::sim::SimDevice;

    /// The simulated device behind a link that passes the first `pass` frames the host sends, loses the next
    /// `lose`, and counts the time.
    struct Lossy {
        device: SimDevice,
        pass: usize,
        lose: usize,
        elapsed: Duration,
    }

    impl Transport for Lossy {
        fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
            if self.pass > 0 {
                self.pass -= 1;
            } else if self.lose > 0 {
                self.lose -= 1;
                return Ok(());
            }
            self.device.send(bytes)
        }
        fn receive(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            self.device.receive(buf)
        }
        fn elapse(&mut self, dt: Duration) {
            self.elapsed += dt;
            self.device.elapse(dt);
        }
    }

    fn lossy(lose: usize) -> Client<Lossy> {
        Client::new(Lossy {
            device: SimDevice::new(false),
            pass: 0,
            lose,
            elapsed: Duration::ZERO,
        })
    }

    #[test]
    fn hello_is_sent_again_when_the_first_is_lost() {
        let mut client = lossy(3);
        assert!(client.hello().is_ok());
        // Three tries lost at half a second each, the fourth answered.
        let elapsed = client.transport().elapsed;
        assert!(
            elapsed >= Duration::from_millis(1_500) && elapsed < Duration::from_millis(2_000),
            "{elapsed:?}"
        );
        // The link works normally afterwards, and no stale answer is left behind.
        assert!(client.hello().is_ok());
        assert!(client.inbox.is_empty());
    }

    #[test]
    fn a_later_answer_tells_that_an_earlier_request_was_lost() {
        let mut client = Client::new(Lossy {
            device: SimDevice::new(false),
            pass: 1,
            lose: 1,
            elapsed: Duration::ZERO,
        });
        let answered = client.send(HostMessage::GetStatus).unwrap();
        let lost = client.send(HostMessage::GetStatus).unwrap();
        let after = client.send(HostMessage::GetStatus).unwrap();
        client.transport().elapse(Duration::from_millis(10));
        assert!(client.take_response(answered).unwrap().is_some());
        // What was read holds the answer after the lost one; nothing after `after` is known lost.
        assert!(client.answered_after(lost));
        assert!(!client.answered_after(after));
        assert!(client.take_response(lost).unwrap().is_none());
        assert!(client.take_response(after).unwrap().is_some());
        assert!(!client.answered_after(lost));
    }

    /// A read that ends inside an answer: the rest of it comes with later answers in the next read, and the answer
    /// is not taken for lost.
    #[test]
    fn an_answer_read_in_two_parts_is_not_lost() {
        let mut client = lossy(0);
        let first = client.send(HostMessage::GetStatus).unwrap();
        let second = client.send(HostMessage::GetStatus).unwrap();
        client.transport().elapse(Duration::from_millis(10));
        let mut bytes = vec![0u8; 4096];
        let n = client.transport().device.receive(&mut bytes).unwrap();
        bytes.truncate(n);
        let cut = bytes.iter().position(|&b| b == 0).unwrap() / 2;
        for &b in &bytes[..cut] {
            assert!(client.reader.push(b).is_none());
        }
        assert!(client.take_response(first).unwrap().is_none());
        assert!(!client.answered_after(first));
        for &b in &bytes[cut..] {
            if let Some(frame) = client.reader.push(b) {
                let r = decode(frame).unwrap();
                client.inbox.push_back(r);
            }
        }
        assert!(!client.answered_after(first));
        assert!(client.take_response(first).unwrap().is_some());
        assert!(client.take_response(second).unwrap().is_some());
    }

    #[test]
    fn ids_that_wrap_are_still_later() {
        let mut client = lossy(0);
        client.inbox.push_back(Response {
            id: 2,
            body: DeviceMessage::Ack,
        });
        assert!(client.answered_after(u32::MAX - 1));
        assert!(!client.answered_after(2));
        assert!(!client.answered_after(3));
    }

    #[test]
    fn hello_gives_up_after_its_patience() {
        let mut client = lossy(usize::MAX);
        match client.hello() {
            Err(ClientError::Timeout(t)) => assert_eq!(t, Duration::from_secs(5)),
            other => panic!("{other:?}"),
        }
        assert!(client.transport().elapsed <= Duration::from_millis(5_600));
        assert_eq!(
            client.timeout,
            Duration::from_secs(2),
            "the request timeout is restored"
        );
    }

    #[test]
    fn a_restart_outlives_the_polls_its_reset_loses() {
        // hello and restart pass; the first two status polls are lost in the reset.
        let mut client = lossy(2);
        client.transport().pass = 2;
        client.hello().unwrap();
        let said = crate::device::rig::restart(&mut client).unwrap();
        assert_eq!(said, "restarted: running trainer-model (compiled in)");
        // Two polls lost at a quarter second each and their pauses, not two whole request timeouts.
        let elapsed = client.transport().elapsed;
        assert!(
            elapsed >= Duration::from_millis(500) && elapsed < Duration::from_millis(1_000),
            "{elapsed:?}"
        );
        assert_eq!(
            client.timeout,
            Duration::from_secs(2),
            "the request timeout is restored"
        );
        assert!(client.inbox.is_empty());
        assert!(client.status().is_ok());
    }

    #[test]
    fn a_restart_that_never_comes_back_is_said_in_its_time() {
        let mut client = lossy(usize::MAX);
        client.transport().pass = 2;
        client.hello().unwrap();
        match crate::device::rig::restart(&mut client) {
            Err(crate::device::rig::DeviceRigError::NoRestart(t)) => assert_eq!(t, Duration::from_secs(10)),
            other => panic!("{other:?}"),
        }
        let elapsed = client.transport().elapsed;
        assert!(elapsed <= Duration::from_millis(10_400), "{elapsed:?}");
    }
}

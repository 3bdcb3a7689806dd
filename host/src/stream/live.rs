//! A live source of a stream: simulator software sending one UDP datagram per pose or telemetry sample, or a game's
//! shared memory polled for its samples ([`crate::games::shm`]). Both feed the same loop ([`super::feed`]): the
//! same washout, pauses, capture and report.

use std::net::{Ipv4Addr, SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use crate::games::shm::{self, poll::Poller, Game, Memory};
use crate::games::Sample;

/// A live source of poses.
pub struct LiveSource {
    /// Where the samples come from.
    pub receiver: Receiver,
    /// What a datagram means, and the washout of telemetry.
    pub decoder: super::datagram::Decoder,
    /// End after this long without a readable sample.
    pub idle: Duration,
    /// Take datagrams from this address only.
    pub from: Option<std::net::IpAddr>,
    /// `--capture`: what arrived (every datagram, from any sender, readable or not; each new shared-memory sample as
    /// a `text` telemetry line), written to a pcap file, and the file's name.
    pub capture: Option<(Box<crate::input::capture::CaptureWriter>, String)>,
}

/// Where a live source's samples come from.
// Shared memory is built on every system, so that the stream's tests feed it snapshots from memory; outside tests
// only Windows constructs it.
#[cfg_attr(not(any(windows, test)), allow(dead_code))]
pub enum Receiver {
    /// A bound UDP socket.
    Udp(UdpSocket),
    /// A game's shared memory.
    Shm(Box<ShmSource>),
}

/// A game's shared memory and its poller.
pub struct ShmSource {
    /// Counts and stalls.
    pub poller: Poller,
    memory: Box<dyn Memory + Send>,
    /// When to poll next.
    next: Instant,
}

#[cfg_attr(not(any(windows, test)), allow(dead_code))]
impl ShmSource {
    /// Polls `game`'s `memory`.
    pub fn new(game: Game, memory: Box<dyn Memory + Send>) -> Self {
        let now = Instant::now();
        Self {
            poller: Poller::new(game, now),
            memory,
            next: now,
        }
    }
}

/// What a receiver got.
#[derive(Debug)]
pub enum Arrival {
    /// A datagram of `len` bytes (in the caller's buffer) from `from`.
    Datagram { len: usize, from: SocketAddr },
    /// A new shared-memory sample, or why the snapshot of a new one was refused.
    Sample(Result<Sample, String>),
}

/// The addresses a shared-memory sample is captured with (a capture's packets need some): loopback, port 0.
pub const SHM_CAPTURE: SocketAddr = SocketAddr::new(std::net::IpAddr::V4(Ipv4Addr::LOCALHOST), 0);

impl Receiver {
    /// Readies the receiver: a socket's reads wait at most a millisecond.
    pub fn start(&mut self) -> std::io::Result<()> {
        match self {
            Receiver::Udp(socket) => socket.set_read_timeout(Some(Duration::from_millis(1))),
            Receiver::Shm(_) => Ok(()),
        }
    }

    /// What the receiver listens to, for the line that starts the stream.
    pub fn describe(&self) -> String {
        match self {
            Receiver::Udp(socket) => {
                let addr = socket.local_addr().map_or("?".into(), |a| a.to_string());
                format!("send datagrams to {addr}")
            }
            Receiver::Shm(shm) => {
                let game = shm.poller.game();
                format!(
                    "reading {}'s shared memory {}",
                    game.title(),
                    game.mappings().join(" and ")
                )
            }
        }
    }

    /// The address a capture's packets go to.
    pub fn local_addr(&self) -> std::io::Result<SocketAddr> {
        match self {
            Receiver::Udp(socket) => socket.local_addr(),
            Receiver::Shm(_) => Ok(SHM_CAPTURE),
        }
    }

    /// Waits briefly (a socket's timeout, or until the next poll of shared memory) for something: `None` when
    /// nothing came.
    pub fn receive(&mut self, buf: &mut [u8]) -> std::io::Result<Option<Arrival>> {
        match self {
            Receiver::Udp(socket) => match socket.recv_from(buf) {
                Ok((len, from)) => Ok(Some(Arrival::Datagram { len, from })),
                // A signal (Ctrl-C) interrupts the wait: nothing arrived, and the loop then sees the flag.
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    ) =>
                {
                    Ok(None)
                }
                Err(e) => Err(e),
            },
            Receiver::Shm(shm) => Ok(shm.receive()),
        }
    }

    /// A change of the source to say on stderr (a shared-memory stall begun or ended), once.
    pub fn news(&mut self) -> Option<String> {
        match self {
            Receiver::Udp(_) => None,
            Receiver::Shm(shm) => shm.poller.news(),
        }
    }

    /// Shared memory: what was read, for the report (a stall still going on counted to now).
    pub fn shm_report(&mut self) -> Option<ShmReport> {
        let Receiver::Shm(shm) = self else {
            return None;
        };
        shm.poller.finish(Instant::now());
        let game = shm.poller.game();
        Some(ShmReport {
            game,
            mappings: game.mappings().to_vec(),
            counts: shm.poller.counts.clone(),
        })
    }
}

impl ShmSource {
    /// Sleeps until the next poll (the poller's interval after the last), then polls.
    fn receive(&mut self) -> Option<Arrival> {
        let now = Instant::now();
        if self.next > now {
            std::thread::sleep(self.next - now);
        }
        let now = Instant::now();
        self.next = now + self.poller.interval();
        match self.poller.poll(self.memory.as_mut(), now) {
            shm::poll::Outcome::New(read) => Some(Arrival::Sample(Ok(read.sample))),
            shm::poll::Outcome::Refused(e) => Some(Arrival::Sample(Err(e.to_string()))),
            shm::poll::Outcome::Nothing => None,
        }
    }
}

/// What a game's shared memory gave in a run (`--report-json`'s `datagrams.shared_memory`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ShmReport {
    /// The game.
    pub game: Game,
    /// Its mappings.
    pub mappings: Vec<&'static str>,
    /// Samples, repeats, torn reads, stalls.
    #[serde(flatten)]
    pub counts: shm::poll::Counts,
}

#[cfg(test)]
mod tests;

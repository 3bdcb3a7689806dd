//! The host link: bytes in, frames to the controller, its responses and unsolicited messages out.
//!
//! A board may serve several links at once (the F411: USB CDC-ACM and USART1), one task each over the same
//! controller. A request is answered on the link it came from; the controller has one connection, the one of the
//! last accepted hello, and its unsolicited messages (faults, telemetry) go to that hello's link
//! ([`Shared::post`]).

use core::sync::atomic::Ordering;

use embassy_futures::select::{select, Either};
use ringpod_core::protocol::{self, FrameReader, MAX_FRAME};

use super::{Shared, LINKS};

/// The link went away (USB unplugged, port closed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct Disconnected;

/// A byte link to the host: USB CDC-ACM or a USART on a board, a UART under QEMU.
pub trait Link {
    /// Waits until a host is there.
    async fn connected(&mut self);
    /// Reads what has arrived (at least one byte).
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Disconnected>;
    /// Writes all of `bytes`.
    async fn write(&mut self, bytes: &[u8]) -> Result<(), Disconnected>;
}

/// Serves the host on link number `id` (below [`LINKS`]) forever: every complete frame gets the controller's one
/// response on this link; unsolicited messages posted for this link are sent as they come. A frame that does not
/// decode is answered by the controller (a counted `Malformed` nack), never executed.
pub async fn serve(link: &mut impl Link, id: u8, shared: &Shared) -> ! {
    let outbox = &shared.outboxes[usize::from(id).min(LINKS - 1)];
    let mut reader = FrameReader::default();
    let mut out = [0u8; MAX_FRAME];
    let mut buf = [0u8; 64];
    loop {
        link.connected().await;
        defmt::info!("host connected (link {})", id);
        loop {
            match select(link.read(&mut buf), outbox.receive()).await {
                Either::First(Ok(n)) => {
                    let mut gone = false;
                    for &byte in &buf[..n] {
                        if let Some(frame) = reader.push(byte) {
                            let len = shared.with(|c| {
                                let hellos = c.hellos();
                                let len = c.handle_frame(frame, &mut out);
                                if c.hellos() != hellos {
                                    shared.host_link.store(id, Ordering::Relaxed);
                                }
                                len
                            });
                            gone |= link.write(&out[..len]).await.is_err();
                        }
                    }
                    if gone {
                        break;
                    }
                }
                Either::First(Err(Disconnected)) => break,
                Either::Second(message) => {
                    let len = protocol::encode(&message, &mut out).unwrap_or(0);
                    if link.write(&out[..len]).await.is_err() {
                        break;
                    }
                }
            }
        }
        // The stream timeout of the pipeline brings a moving platform to rest: nothing to do here but wait.
        defmt::warn!("host disconnected (link {})", id);
    }
}

//! A game's shared memory through the whole stream, on the simulated device: the memory is held in vectors and
//! written by a thread-free "game" at each read, as the poller reads it.

use std::time::{Duration, Instant};

use super::*;
use crate::games::shm::testing::{Fake, Page};
use crate::games::shm::{ams2, Game};
use crate::link::client::Client;
use crate::link::sim::SimDevice;
use crate::link::transport::AnyTransport;
use crate::stream::{Options, Source};

/// AMS2's memory: a new sample every 5 ms for `drive` (accelerating forward at 2 m/s^2), then nothing (the game
/// paused); every 50th read finds the game mid-write (an odd sequence).
fn game(drive: Duration) -> Fake {
    let start = Instant::now();
    let page = |sequence: u32| {
        let mut p = Page::zeros(ams2::SIZE);
        // The module's axes: z back, so forward is -z.
        p.u32(ams2::at::VERSION, 14)
            .f32s(ams2::at::LOCAL_ACCELERATION + 8, &[-2.0])
            .u32(ams2::at::SEQUENCE_NUMBER, sequence);
        p.0
    };
    let mut fake = Fake::new(vec![page(2)]);
    fake.game = Some(Box::new(move |read, pages| {
        let t = start.elapsed().min(drive);
        let sequence = 2 + 2 * (t.as_millis() / 5) as u32;
        let odd = u32::from(read % 50 == 49 && t < drive);
        pages[0] = Some(page(sequence + odd));
    }));
    fake
}

/// `fake` streamed whole to a simulator running as fast as the machine computes (`--fast`), the stream ending 600 ms
/// after the last sample.
fn stream(fake: Fake, capture: Option<(Box<crate::input::capture::CaptureWriter>, String)>) -> crate::stream::Report {
    let decoder =
        crate::stream::command::telemetry_decoder(crate::games::TelemetryFormat::Text, None, &None, &None, true)
            .unwrap();
    let source = Source::Live(LiveSource {
        receiver: Receiver::Shm(Box::new(ShmSource::new(Game::Ams2, Box::new(fake)))),
        decoder,
        idle: Duration::from_millis(600),
        from: None,
        capture,
    });
    let mut client = Client::new(AnyTransport::Sim(Box::new(SimDevice::new(false))));
    let options = Options {
        home: false,
        host_limits: true,
        quiet: true,
        telemetry: false,
        telemetry_hz: None,
        resend_stop: true,
    };
    crate::stream::run(&mut client, source, Vec::new(), &options, true, &|| false, None).unwrap()
}

#[test]
fn a_games_shared_memory_is_streamed_captured_and_counted() {
    let dir = std::env::temp_dir().join(format!("ringpod-shm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let capture_path = dir.join("drive.pcap");
    let writer = crate::input::capture::CaptureWriter::create(&capture_path, SHM_CAPTURE).unwrap();
    let capture = Some((Box::new(writer), capture_path.display().to_string()));
    let report = stream(game(Duration::from_millis(800)), capture);
    let d = report.datagrams.as_ref().unwrap();
    let shm = d.shared_memory.as_ref().unwrap();
    assert_eq!(report.outcome, "followed", "{report:?}");
    assert_eq!(shm.game, Game::Ams2);
    assert!(shm.counts.samples > 50, "{shm:?}");
    assert_eq!(u64::from(d.received), shm.counts.samples + shm.counts.refused);
    assert!(shm.counts.repeats > 0 && shm.counts.torn > 0, "{shm:?}");
    assert_eq!(shm.counts.stalls, 1, "the game's pause at the end: {shm:?}");
    assert!(report.setpoints_sent as u64 >= shm.counts.samples, "{report:?}");
    // The capture holds each sample as a text line, which `cue --input` reads back.
    let c = report.capture.as_ref().unwrap();
    assert_eq!((c.packets, c.error.as_deref()), (shm.counts.samples, None));
    let bytes = std::fs::read(&capture_path).unwrap();
    let (rows, errors, _) =
        crate::cueing::capture::rows(&bytes, crate::games::TelemetryFormat::Text, None, None).unwrap();
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(rows.len() as u64, shm.counts.samples);
    let row = &rows[rows.len() / 2].1;
    assert!(
        (row[1] - 2.0).abs() < 1e-6 && (row[3] - ringpod_core::cueing::G).abs() < 1e-6,
        "{row:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The process held up mid-stream (starved on a busy machine, or Wine's scheduling) for longer than the device's
/// stream timeout (100 ms): a simulator running as fast as it computes passes the periods the hold-up cost once the
/// source is live, as one in real time does, rather than ticking them in a burst that loses the stream before the
/// next sample can arrive.
#[test]
fn a_hold_up_of_the_process_does_not_lose_a_fast_simulators_stream() {
    let mut fake = game(Duration::from_millis(800));
    let mut write = fake.game.take().unwrap();
    fake.game = Some(Box::new(move |read, pages| {
        if read == 100 {
            std::thread::sleep(Duration::from_millis(300));
        }
        write(read, pages);
    }));
    let report = stream(fake, None);
    assert_eq!(report.outcome, "followed", "{report:?}");
    assert_eq!(report.setpoints_applied, report.setpoints_sent, "{report:?}");
    let shm = report.datagrams.as_ref().unwrap().shared_memory.as_ref().unwrap();
    assert!(shm.counts.samples > 50, "{shm:?}");
}

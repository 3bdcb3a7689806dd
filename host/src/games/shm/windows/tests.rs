//! The platform layer itself (run under Windows, or Wine by the Windows runner): a named mapping created as a game
//! creates it, read through [`Mappings`] by the poller.

use std::time::Instant;

use super::super::poll::{Outcome, Poller};
use super::super::testing::Page;
use super::super::{ams2, Game};
use super::*;
use crate::vr::mapping::Mapping;

fn ams2_page(sequence: u32, forward: f64) -> Vec<u8> {
    let mut p = Page::zeros(ams2::SIZE);
    p.u32(ams2::at::VERSION, 14)
        .f32s(ams2::at::LOCAL_ACCELERATION + 8, &[-forward])
        .u32(ams2::at::SEQUENCE_NUMBER, sequence);
    p.0
}

#[test]
fn a_games_mapping_is_opened_read_only_and_polled() {
    let name: &'static str = Box::leak(format!(r"Local\ringpod-test-pcars2-{}", std::process::id()).into_boxed_str());
    let names: &'static [&'static str] = Box::leak(vec![name].into_boxed_slice());
    // Not there yet: absent, looked for again later.
    let mut mem = Mappings::named(names);
    let mut poller = Poller::new(Game::Ams2, Instant::now());
    assert_eq!(poller.poll(&mut mem, Instant::now()), Outcome::Nothing);
    assert_eq!(poller.counts.absent, 1);
    let mut game = Mapping::create(name, 16 * 1024).expect("a named mapping");
    assert!(game.write(0, &ams2_page(2, 1.5)));
    let mut mem = Mappings::named(names);
    let Outcome::New(read) = poller.poll(&mut mem, Instant::now()) else {
        panic!("{:?}", poller.counts)
    };
    assert!((read.sample.telemetry.force[0] - 1.5).abs() < 1e-6, "{read:?}");
    assert_eq!(poller.poll(&mut mem, Instant::now()), Outcome::Nothing, "a repeat");
    // The game writes the next sample.
    assert!(game.write(0, &ams2_page(4, -3.0)));
    let Outcome::New(read) = poller.poll(&mut mem, Instant::now()) else {
        panic!("{:?}", poller.counts)
    };
    assert_eq!(read.tick, 4);
    assert!((read.sample.telemetry.force[0] + 3.0).abs() < 1e-6, "{read:?}");
    // A read past the section's pages is absent, not a fault.
    let mut far = [0u8; 8];
    assert_eq!(mem.read(0, 1 << 20, &mut far), Err(Absent));
}

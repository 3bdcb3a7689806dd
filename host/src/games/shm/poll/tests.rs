use std::time::{Duration, Instant};

use super::super::testing::{Fake, Page};
use super::super::{ac, ams2};
use super::*;

/// An AMS2 page with sequence `s` and a forward acceleration `a`.
fn ams2_page(s: u32, a: f64) -> Vec<u8> {
    let mut p = Page::zeros(ams2::SIZE);
    p.u32(ams2::at::VERSION, 14)
        .f32s(ams2::at::LOCAL_ACCELERATION + 8, &[-a])
        .u32(ams2::at::SEQUENCE_NUMBER, s);
    p.0
}

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

#[test]
fn a_sample_is_new_only_when_the_counter_moves() {
    let t0 = Instant::now();
    let mut mem = Fake::new(vec![ams2_page(2, 1.0)]);
    let mut p = Poller::new(Game::Ams2, t0);
    assert!(matches!(p.poll(&mut mem, t0), Outcome::New(r) if r.tick == 2));
    assert_eq!(p.poll(&mut mem, t0 + ms(1)), Outcome::Nothing);
    assert_eq!(p.poll(&mut mem, t0 + ms(2)), Outcome::Nothing);
    mem.pages[0] = Some(ams2_page(4, 2.0));
    let Outcome::New(r) = p.poll(&mut mem, t0 + ms(3)) else {
        panic!()
    };
    assert!((r.sample.telemetry.force[0] - 2.0).abs() < 1e-6);
    assert_eq!((p.counts.samples, p.counts.repeats, p.counts.torn), (2, 2, 0));
}

#[test]
fn a_copy_the_game_writes_into_is_torn_and_taken_again() {
    let t0 = Instant::now();
    // The game writes a new sample during the first copy (between the counter's read and the copy's end), then
    // is quiet: the first copy is torn, the second whole.
    let mut mem = Fake::new(vec![ams2_page(2, 1.0)]);
    mem.game = Some(Box::new(|read, pages| {
        if read == 1 {
            pages[0] = Some(ams2_page(4, 3.0));
        }
    }));
    let mut p = Poller::new(Game::Ams2, t0);
    let Outcome::New(r) = p.poll(&mut mem, t0) else {
        panic!("{:?}", p.counts)
    };
    assert_eq!(r.tick, 4);
    assert!((r.sample.telemetry.force[0] - 3.0).abs() < 1e-6);
    assert_eq!((p.counts.samples, p.counts.torn), (1, 1));
    // A game forever mid-write (an odd sequence): given up after the tries, counted, tried again next poll.
    let mut busy = Fake::new(vec![ams2_page(5, 1.0)]);
    let mut p = Poller::new(Game::Ams2, t0);
    assert_eq!(p.poll(&mut busy, t0), Outcome::Nothing);
    assert_eq!((p.counts.torn, p.counts.torn_given_up), (u64::from(TRIES), 1));
}

#[test]
fn a_paused_or_absent_game_is_one_stall_and_said() {
    let t0 = Instant::now();
    let mut page = Page::zeros(ac::AC_SIZE);
    page.i32(ac::at::PACKET_ID, 7);
    let mut mem = Fake::new(vec![page.0.clone()]);
    let mut p = Poller::new(Game::Ac, t0);
    // AC has no write guard: a new packetId stands for a poll before it is copied.
    assert_eq!(p.poll(&mut mem, t0), Outcome::Nothing);
    assert!(matches!(p.poll(&mut mem, t0), Outcome::New(_)));
    assert_eq!(p.counts.settling, 1);
    assert!(p.stall_after() >= MIN_STALL);
    for k in 1..=50 {
        p.poll(&mut mem, t0 + ms(10 * k));
    }
    assert_eq!(p.counts.stalls, 1, "one pause, counted once");
    assert!(p.news().is_some_and(|n| n.contains("no new sample")));
    // The game closes: its mapping goes away, the pause goes on.
    mem.pages[0] = None;
    p.poll(&mut mem, t0 + ms(600));
    assert_eq!((p.counts.stalls, p.counts.absent), (1, 1));
    page.i32(ac::at::PACKET_ID, 8);
    mem.pages[0] = Some(page.0);
    assert_eq!(p.poll(&mut mem, t0 + ms(999)), Outcome::Nothing);
    assert!(matches!(p.poll(&mut mem, t0 + ms(1000)), Outcome::New(_)));
    assert!(p.news().is_some_and(|n| n.contains("again after 1.0 s")));
    assert!((p.counts.stalled_s - 1.0).abs() < 1e-9, "{:?}", p.counts);
}

#[test]
fn a_refused_snapshot_is_counted_once_per_counter() {
    let t0 = Instant::now();
    let mut old = ams2_page(2, 0.0);
    old[0] = 5;
    let mut mem = Fake::new(vec![old]);
    let mut p = Poller::new(Game::Ams2, t0);
    assert!(matches!(
        p.poll(&mut mem, t0),
        Outcome::Refused(Unreadable::Header { .. })
    ));
    assert_eq!(p.poll(&mut mem, t0), Outcome::Nothing);
    assert_eq!((p.counts.refused, p.counts.repeats), (1, 1));
}

#[test]
fn the_polling_interval_follows_the_games_rate() {
    let t0 = Instant::now();
    assert_eq!(Poller::new(Game::Ac, t0).interval(), ms(1));
    assert_eq!(Poller::new(Game::Rf2, t0).interval(), ms(5));
    assert!(Poller::new(Game::Iracing, t0).interval() > ms(4));
}

#[test]
fn a_clock_that_goes_back_is_passed_on_without_its_time_once() {
    use super::super::ets2;
    let t0 = Instant::now();
    let page = |time_us: u64| {
        let mut p = Page::zeros(ets2::SIZE);
        p.put(ets2::at::SDK_ACTIVE, &[1])
            .u32(ets2::at::REVISION, 10)
            .u64(ets2::at::TIME, time_us);
        p.0
    };
    let mut mem = Fake::new(vec![page(90_000_000)]);
    let mut p = Poller::new(Game::Ets2, t0);
    // ETS2 has no write guard: each new time stands for a poll, then is taken.
    let mut time = |mem: &mut Fake| {
        assert_eq!(p.poll(mem, t0), Outcome::Nothing, "settling");
        match p.poll(mem, t0) {
            Outcome::New(r) => r.sample.time,
            other => panic!("{other:?}"),
        }
    };
    assert_eq!(time(&mut mem), Some(90.0));
    mem.pages[0] = Some(page(1_000_000));
    assert_eq!(time(&mut mem), None, "the new clock's first sample: timed by arrival");
    mem.pages[0] = Some(page(1_016_000));
    assert_eq!(time(&mut mem), Some(1.016), "then the new clock");
    assert_eq!((p.counts.clock_restarts, p.counts.settling), (1, 3));
    assert!(p.news().is_some_and(|n| n.contains("went back")));
}

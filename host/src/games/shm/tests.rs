use std::time::Instant;

use proptest::prelude::*;

use super::testing::Fake;
use super::*;

/// Whatever decodes is finite, and its time a time.
fn finite(read: &Read) -> bool {
    checked_values(&read.sample).is_ok()
}

/// The size of a snapshot of one mapping that each layout reads whole.
fn whole_size(game: Game) -> usize {
    match game {
        Game::Ac | Game::Acc => ac::size(game),
        Game::Ams2 => ams2::SIZE,
        Game::Ets2 => ets2::SIZE,
        Game::Iracing => iracing::HEADER + 2048,
        Game::Rf2 | Game::Lmu => rf2::telemetry::VEHICLES + 2 * rf2::telemetry::VEHICLE,
    }
}

#[test]
fn every_game_has_its_name_and_mappings() {
    for game in Game::ALL {
        assert_eq!(<Game as clap::ValueEnum>::from_str(game.name(), false), Ok(game));
        assert!(!game.mappings().is_empty() && game.rate_hz() > 0.0, "{game}");
        assert!(decode(game, &[]).is_err(), "{game}: nothing is not a sample");
        assert!(
            decode(game, &[vec![0; 100]]).is_err(),
            "{game}: 100 zeros are not a sample"
        );
    }
}

#[test]
fn a_sample_is_written_as_a_text_line_that_reads_back_exactly() {
    let sample = Sample {
        time: Some(12.345678901234),
        telemetry: crate::games::Telemetry {
            force: [0.1 + 0.2, -3.0e-7, crate::games::G],
            rate: [1.0 / 3.0, 0.0, -2.5],
        },
        lap: None,
    };
    let read = |s: &Sample| crate::games::parse_telemetry(text_line(s).as_bytes()).unwrap();
    assert_eq!(read(&sample), sample);
    let untimed = Sample { time: None, ..sample };
    assert_eq!(text_line(&untimed).split(' ').count(), 6);
    // The lap position goes along, after the time: read back as it was.
    let on_lap = Sample {
        lap: Some(LapPosition::Along(0.123456789012)),
        ..sample
    };
    assert_eq!(read(&on_lap), on_lap);
    assert_eq!(text_line(&Sample { time: None, ..on_lap }).split(' ').count(), 6);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, ..ProptestConfig::default() })]

    /// Any bytes, of any size, in any mapping: no decoder panics, and what decodes is finite.
    #[test]
    fn any_snapshot_never_panics(
        a in prop::collection::vec(any::<u8>(), 0..800),
        b in prop::collection::vec(any::<u8>(), 0..800),
    ) {
        for game in Game::ALL {
            if let Ok(read) = decode(game, &[a.clone(), b.clone()]) {
                prop_assert!(finite(&read), "{game}: {read:?}");
            }
        }
    }

    /// Random contents of the size each layout reads, with counts and offsets that point anywhere: refused or
    /// finite, never a panic; the poller over such memory, the same.
    #[test]
    fn random_contents_of_the_right_size(seed in prop::collection::vec(any::<u8>(), 64), small in 0u8..4) {
        for game in Game::ALL {
            let len = whole_size(game);
            let mut page: Vec<u8> = seed.iter().cycle().take(len).copied().collect();
            // Small counts and offsets now and then, so that the header's checks pass and the rest is read.
            if game == Game::Iracing {
                for (at, v) in [(24, 3), (28, 112), (32, i32::from(small)), (36, 64), (52, 600), (68, 700)] {
                    page[at..at + 4].copy_from_slice(&i32::to_le_bytes(v));
                }
            }
            if matches!(game, Game::Rf2 | Game::Lmu) {
                page[12..16].copy_from_slice(&i32::to_le_bytes(i32::from(small % 3)));
            }
            let scoring: Vec<u8> = seed.iter().rev().cycle().take(2000).copied().collect();
            if let Ok(read) = decode(game, &[page.clone(), scoring.clone()]) {
                prop_assert!(finite(&read), "{game}: {read:?}");
            }
            let mut mem = Fake::new(vec![page, scoring]);
            let mut poller = poll::Poller::new(game, Instant::now());
            for _ in 0..3 {
                if let poll::Outcome::New(read) = poller.poll(&mut mem, Instant::now()) {
                    prop_assert!(finite(&read), "{game}: {read:?}");
                }
            }
        }
    }
}

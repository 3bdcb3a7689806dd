use super::super::testing::{close, layout, Layout, Page, C, DRIVE};
use super::super::{decode as decode_game, Game, Unreadable};
use super::*;

/// `SPageFilePhysics` as AC's `SharedFileOut.h` declares it (`#pragma pack(4)`), and ACC's additions.
pub(super) fn physics(game: Game) -> Layout {
    use C::{F32, I32};
    let mut members = vec![
        ("packetId", I32, 1),
        ("gas", F32, 1),
        ("brake", F32, 1),
        ("fuel", F32, 1),
        ("gear", I32, 1),
        ("rpms", I32, 1),
        ("steerAngle", F32, 1),
        ("speedKmh", F32, 1),
        ("velocity", F32, 3),
        ("accG", F32, 3),
        (
            "wheelSlip, wheelLoad, wheelsPressure, wheelAngularSpeed, tyreWear",
            F32,
            20,
        ),
        (
            "tyreDirtyLevel, tyreCoreTemperature, camberRAD, suspensionTravel",
            F32,
            16,
        ),
        ("drs", F32, 1),
        ("tc", F32, 1),
        ("heading", F32, 1),
        ("pitch", F32, 1),
        ("roll", F32, 1),
        ("cgHeight", F32, 1),
        ("carDamage", F32, 5),
        ("numberOfTyresOut, pitLimiterOn", I32, 2),
        ("abs, kersCharge, kersInput", F32, 3),
        ("autoShifterOn", I32, 1),
        ("rideHeight", F32, 2),
        ("turboBoost, ballast, airDensity, airTemp, roadTemp", F32, 5),
        ("localAngularVel", F32, 3),
        ("finalFF, performanceMeter", F32, 2),
        ("engineBrake .. ersIsCharging", I32, 5),
        ("kersCurrentKJ", F32, 1),
        ("drsAvailable, drsEnabled", I32, 2),
        ("brakeTemp", F32, 4),
        ("clutch", F32, 1),
        ("tyreTempI, M, O", F32, 12),
        ("isAIControlled", I32, 1),
        ("tyreContactPoint, Normal, Heading", F32, 36),
        ("brakeBias", F32, 1),
    ];
    if game == Game::Acc {
        members.extend([
            ("localVelocity", F32, 3),
            ("P2PActivations, P2PStatus", I32, 2),
            ("currentMaxRpm", F32, 1),
            ("mz, fx, fy, slipRatio, slipAngle", F32, 20),
            ("tcInAction, absInAction", I32, 2),
            ("suspensionDamage, tyreTemp", F32, 8),
            ("waterTemp", F32, 1),
        ]);
    }
    layout(4, &members)
}

/// A page of `game` holding a moment of the drive, in the axes this module assumes (x left, y up, z forward).
fn page(game: Game, id: i32, accel: [f64; 3], rate: [f64; 3], pitch: f64, roll: f64) -> Vec<u8> {
    let l = physics(game);
    let g = G;
    let mut p = Page::zeros(l.size);
    p.i32(l.at("packetId"), id)
        .f32s(l.at("accG"), &[accel[1] / g, accel[2] / g, accel[0] / g])
        .f32s(l.at("pitch"), &[pitch])
        .f32s(l.at("roll"), &[roll])
        .f32s(l.at("localAngularVel"), &[rate[1], rate[2], rate[0]]);
    p.0
}

#[test]
fn the_layouts_offsets_are_the_declared_structures() {
    for game in [Game::Ac, Game::Acc] {
        let l = physics(game);
        assert_eq!(l.size, size(game), "{game}");
        assert_eq!(l.at("accG"), at::ACC_G);
        assert_eq!(l.at("pitch"), at::PITCH);
        assert_eq!(l.at("roll"), at::ROLL);
        assert_eq!(l.at("localAngularVel"), at::LOCAL_ANGULAR_VEL);
    }
    // ACC's documentation checks these offsets itself.
    assert_eq!(physics(Game::Acc).at("tcInAction, absInAction"), 672);
}

#[test]
fn a_drive_decodes_in_ringpods_axes() {
    for game in [Game::Ac, Game::Acc] {
        for (i, m) in DRIVE.iter().enumerate() {
            let bytes = page(game, 100 + i as i32, m.accel, m.rate, m.pitch, m.roll);
            let read = decode_game(game, &[bytes]).unwrap_or_else(|e| panic!("{game} {}: {e}", m.name));
            assert_eq!(read.tick, 100 + i as u64);
            assert_eq!(read.sample.time, None, "the page has no time");
            let t = read.sample.telemetry;
            assert!(close(t.force, m.force()), "{game} {}: {t:?}", m.name);
            assert!(close(t.rate, m.rate), "{game} {}: {t:?}", m.name);
        }
    }
    // Signs, said once more in words: a left turn pushes left and yaws left.
    let m = &DRIVE[3];
    let t = decode_game(Game::Ac, &[page(Game::Ac, 1, m.accel, m.rate, 0.0, 0.0)])
        .unwrap()
        .sample
        .telemetry;
    assert!(t.force[1] > 5.0 && t.rate[2] > 0.0, "{t:?}");
}

#[test]
fn short_pages_and_garbage_are_refused() {
    let acc = page(Game::Acc, 1, [0.0; 3], [0.0; 3], 0.0, 0.0);
    assert!(matches!(
        decode(Game::Acc, &acc[..AC_SIZE], &[]),
        Err(Unreadable::Size { .. })
    ));
    assert!(
        decode(Game::Ac, &acc[..AC_SIZE], &[]).is_ok(),
        "AC's page is the shorter"
    );
    assert!(matches!(decode(Game::Ac, &[], &[]), Err(Unreadable::Size { .. })));
    let mut nan = acc.clone();
    nan[at::ACC_G..at::ACC_G + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(matches!(
        decode_game(Game::Acc, &[nan]),
        Err(Unreadable::NotFinite { .. })
    ));
}

/// `SPageFileGraphic` as `SharedFileOut.h` declares it, through `normalizedCarPosition` (`wchar_t` is 2 bytes).
fn graphics() -> Layout {
    use C::{F32, I16, I32};
    layout(
        4,
        &[
            ("packetId, status, session", I32, 3),
            ("currentTime, lastTime, bestTime, split", I16, 4 * 15),
            ("completedLaps, position, iCurrentTime, iLastTime, iBestTime", I32, 5),
            ("sessionTimeLeft, distanceTraveled", F32, 2),
            ("isInPit, currentSectorIndex, lastSectorTime, numberOfLaps", I32, 4),
            ("tyreCompound", I16, 33),
            ("replayTimeMultiplier", F32, 1),
            ("normalizedCarPosition", F32, 1),
        ],
    )
}

/// The graphics page gives the lap position when it is there; without it (or short) the sample has none and
/// the motion is read all the same.
#[test]
fn the_graphics_page_gives_the_lap_position() {
    let g = graphics();
    assert_eq!(g.at("normalizedCarPosition"), at::NORMALIZED_CAR_POSITION);
    assert_eq!(g.size, GRAPHICS_SIZE);
    for game in [Game::Ac, Game::Acc] {
        let physics = page(game, 3, [1.0, 2.0, 0.0], [0.0; 3], 0.0, 0.0);
        for x in [0.0, 0.25, 0.999] {
            let mut p = Page::zeros(g.size);
            p.f32s(g.at("normalizedCarPosition"), &[x])
                .f32s(g.at("sessionTimeLeft, distanceTraveled") + 4, &[9999.0]);
            let read = decode_game(game, &[physics.clone(), p.0]).unwrap();
            assert_eq!(
                read.sample.lap,
                Some(crate::games::LapPosition::Along(f64::from(x as f32)))
            );
        }
        let read = decode_game(game, std::slice::from_ref(&physics)).unwrap();
        assert_eq!(read.sample.lap, None, "no graphics page");
        let short = decode_game(game, &[physics.clone(), vec![0; GRAPHICS_SIZE - 1]]).unwrap();
        assert_eq!(short.sample.lap, None, "a short graphics page");
        assert!(close(short.sample.telemetry.force, read.sample.telemetry.force));
    }
}

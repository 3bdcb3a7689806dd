use super::super::testing::{close, layout, Layout, Page, C, DRIVE};
use super::super::{decode as decode_game, Game, Unreadable};
use super::*;

/// `SharedMemory` of `SharedMemory.h`, through `mSequenceNumber` (every member at most 4 bytes).
pub(super) fn shared_memory() -> Layout {
    use C::{F32, I32, I8};
    layout(
        4,
        &[
            ("mVersion, mBuildVersionNumber", I32, 2),
            ("mGameState, mSessionState, mRaceState", I32, 3),
            ("mViewedParticipantIndex, mNumParticipants", I32, 2),
            // ParticipantInfo: bool, char[64], float[3], float, 4 x 4 bytes: 100 bytes, 4-aligned.
            ("mParticipantInfo", I32, 64 * 100 / 4),
            ("mUnfilteredThrottle .. mUnfilteredClutch", F32, 4),
            ("mCarName, mCarClassName", I8, 128),
            ("mLapsInEvent", I32, 1),
            ("mTrackLocation, mTrackVariation", I8, 128),
            ("mTrackLength", F32, 1),
            ("mNumSectors", I32, 1),
            ("mLapInvalidated", I8, 1),
            ("mBestLapTime .. mWorldFastestSector3Time", F32, 21),
            ("mHighestFlagColour .. mCarFlags", I32, 5),
            ("mOilTempCelsius .. mSteering", F32, 14),
            ("mGear, mNumGears", I32, 2),
            ("mOdometerKM", F32, 1),
            ("mAntiLockActive", I8, 1),
            ("mLastOpponentCollisionIndex", I32, 1),
            ("mLastOpponentCollisionMagnitude", F32, 1),
            ("mBoostActive", I8, 1),
            ("mBoostAmount", F32, 1),
            ("mOrientation", F32, 3),
            ("mLocalVelocity, mWorldVelocity", F32, 6),
            ("mAngularVelocity", F32, 3),
            ("mLocalAcceleration", F32, 3),
            ("mWorldAcceleration, mExtentsCentre", F32, 6),
            ("tyres", F32, 18 * 4),
            ("mCrashState", I32, 1),
            ("mAeroDamage .. mCloudBrightness", F32, 9),
            ("mSequenceNumber", I32, 1),
        ],
    )
}

fn page(sequence: u32, m: &super::super::testing::Moment) -> Vec<u8> {
    let l = shared_memory();
    let mut p = Page::zeros(l.size);
    // The car's axes x left, y up, z back; orientation (pitch, heading, roll).
    p.u32(l.at("mVersion, mBuildVersionNumber"), 14)
        .f32s(l.at("mOrientation"), &[m.pitch, 1.0, m.roll])
        .f32s(l.at("mAngularVelocity"), &[m.rate[1], m.rate[2], -m.rate[0]])
        .f32s(l.at("mLocalAcceleration"), &[m.accel[1], m.accel[2], -m.accel[0]])
        .u32(l.at("mSequenceNumber"), sequence);
    p.0
}

#[test]
fn the_layouts_offsets_are_the_declared_structure() {
    let l = shared_memory();
    assert_eq!(l.at("mOrientation"), at::ORIENTATION);
    assert_eq!(l.at("mAngularVelocity"), at::ANGULAR_VELOCITY);
    assert_eq!(l.at("mLocalAcceleration"), at::LOCAL_ACCELERATION);
    assert_eq!(l.at("mSequenceNumber"), at::SEQUENCE_NUMBER);
    assert_eq!(l.size, SIZE);
}

#[test]
fn a_drive_decodes_and_an_odd_sequence_is_torn() {
    for (i, m) in DRIVE.iter().enumerate() {
        let read = decode_game(Game::Ams2, &[page(2 * i as u32 + 10, m)]).unwrap();
        assert_eq!((read.tick, read.sample.time), (2 * i as u64 + 10, None));
        assert!(close(read.sample.telemetry.force, m.force()), "{}: {read:?}", m.name);
        assert!(close(read.sample.telemetry.rate, m.rate), "{}: {read:?}", m.name);
    }
    assert_eq!(decode(&page(11, &DRIVE[0])), Err(Unreadable::Torn { game: Game::Ams2 }));
    let mut old = page(10, &DRIVE[0]);
    old[0] = 7;
    assert!(matches!(decode(&old), Err(Unreadable::Header { .. })));
    assert!(matches!(decode(&old[..SIZE - 1]), Err(Unreadable::Size { .. })));
}

/// The viewed participant's `mCurrentLapDistance` over `mTrackLength`, at the offsets the declared structure
/// gives; none without a track length or with an index out of the participants.
#[test]
fn the_lap_position_is_the_viewed_participants_lap_distance_over_the_tracks() {
    let l = shared_memory();
    assert_eq!(l.at("mTrackLength"), at::TRACK_LENGTH);
    assert_eq!(
        l.at("mViewedParticipantIndex, mNumParticipants"),
        at::VIEWED_PARTICIPANT
    );
    assert_eq!(l.at("mParticipantInfo"), at::PARTICIPANTS);
    // ParticipantInfo as declared: bool, char[64], float[3], then mCurrentLapDistance.
    let p = layout(
        4,
        &[
            ("mIsActive", C::I8, 1),
            ("mName", C::I8, 64),
            ("mWorldPosition", C::F32, 3),
            ("mCurrentLapDistance", C::F32, 1),
            ("mRacePosition .. mCurrentSector", C::I32, 4),
        ],
    );
    assert_eq!(
        (p.size, p.at("mCurrentLapDistance")),
        (at::PARTICIPANT, at::CURRENT_LAP_DISTANCE)
    );
    let with = |viewed: i32, length: f64| {
        let mut page = Page(page(4, &DRIVE[0]));
        page.i32(l.at("mViewedParticipantIndex, mNumParticipants"), viewed)
            .f32s(l.at("mTrackLength"), &[length]);
        for i in 0..64 {
            let at = l.at("mParticipantInfo") + i * p.size + p.at("mCurrentLapDistance");
            page.f32s(at, &[100.0 * i as f64]);
        }
        decode(&page.0).unwrap().sample.lap
    };
    assert_eq!(with(3, 1000.0), Some(crate::games::LapPosition::Along(0.3)));
    assert_eq!(with(63, 10_000.0), Some(crate::games::LapPosition::Along(0.63)));
    assert_eq!(with(3, 0.0), None, "no track length");
    assert_eq!(with(64, 1000.0), None, "no such participant");
    assert_eq!(with(-1, 1000.0), None);
}

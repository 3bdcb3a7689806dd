use super::super::testing::{close, layout, Layout, Page, C, DRIVE};
use super::super::{decode as decode_game, Game, Unreadable};
use super::*;

/// `rF2Wheel`, as `rF2State.h` declares it (`#pragma pack(4)`): 260 bytes.
const WHEEL: usize = 260;

fn wheel() -> Layout {
    use C::{F64, I8};
    layout(
        4,
        &[
            ("mSuspensionDeflection .. mPressure", F64, 16),
            ("mTemperature", F64, 3),
            ("mWear", F64, 1),
            ("mTerrainName", I8, 16),
            ("mSurfaceType, mFlat, mDetached, mStaticUndeflectedRadius", I8, 4),
            (
                "mVerticalTireDeflection, mWheelYLocation, mToe, mTireCarcassTemperature",
                F64,
                4,
            ),
            ("mTireInnerLayerTemperature", F64, 3),
            ("mExpansion", I8, 24),
        ],
    )
}

/// `rF2VehicleTelemetry` (the plugin's copy of `TelemInfoV01`).
fn vehicle() -> Layout {
    use C::{F32, F64, I32, I8};
    layout(
        4,
        &[
            ("mID", I32, 1),
            ("mDeltaTime", F64, 1),
            ("mElapsedTime", F64, 1),
            ("mLapNumber", I32, 1),
            ("mLapStartET", F64, 1),
            ("mVehicleName, mTrackName", I8, 128),
            ("mPos", F64, 3),
            ("mLocalVel", F64, 3),
            ("mLocalAccel", F64, 3),
            ("mOri", F64, 9),
            ("mLocalRot", F64, 3),
            ("mLocalRotAccel", F64, 3),
            ("mGear", I32, 1),
            ("mEngineRPM .. mClutchRPM", F64, 4),
            ("unfiltered and filtered inputs", F64, 8),
            ("mSteeringShaftTorque, 3rd deflections", F64, 3),
            ("aerodynamics", F64, 6),
            ("mFuel, mEngineMaxRPM", F64, 2),
            ("mScheduledStops .. mHeadlights", I8, 4),
            ("mDentSeverity", I8, 8),
            ("mLastImpactET, mLastImpactMagnitude", F64, 2),
            ("mLastImpactPos", F64, 3),
            ("mEngineTorque", F64, 1),
            ("mCurrentSector", I32, 1),
            ("mSpeedLimiter .. mRearTireCompoundIndex", I8, 4),
            ("mFuelCapacity", F64, 1),
            ("mFrontFlapActivated .. mIgnitionStarter", I8, 4),
            ("tyre compound names", I8, 36),
            ("mSpeedLimiterAvailable, mAntiStallActivated, mUnused", I8, 4),
            ("mVisualSteeringWheelRange", F32, 1),
            ("mRearBrakeBias, mTurboBoostPressure", F64, 2),
            ("mPhysicsToGraphicsOffset", F32, 3),
            ("mPhysicalSteeringWheelRange", F32, 1),
            ("mBatteryChargeFraction .. mElectricBoostWaterTemperature", F64, 5),
            ("mElectricBoostMotorState", I8, 1),
            ("mExpansion", I8, 111),
            ("mWheels", I32, 4 * WHEEL / 4),
        ],
    )
}

/// `rF2ScoringInfo` and `rF2VehicleScoring` (64-bit: the pointers are 8 bytes).
fn scoring_info() -> Layout {
    use C::{F32, F64, I16, I32, I8};
    layout(
        4,
        &[
            ("mTrackName", I8, 64),
            ("mSession", I32, 1),
            ("mCurrentET, mEndET", F64, 2),
            ("mMaxLaps", I32, 1),
            ("mLapDist", F64, 1),
            ("pointer1", I8, 8),
            ("mNumVehicles", I32, 1),
            ("mGamePhase .. mInRealtime", I8, 7),
            ("mPlayerName, mPlrFileName", I8, 96),
            ("weather", F64, 4),
            ("mWind", F64, 3),
            ("wetness", F64, 2),
            ("mGameMode, mIsPasswordProtected", I8, 2),
            ("mServerPort", I16, 1),
            ("mServerPublicIP, mMaxPlayers", I32, 2),
            ("mServerName", I8, 32),
            ("mStartET", F32, 1),
            ("mAvgPathWetness", F64, 1),
            ("mExpansion", I8, 200),
            ("pointer2", I8, 8),
        ],
    )
}

fn vehicle_scoring() -> Layout {
    use C::{F32, F64, I16, I32, I8};
    layout(
        4,
        &[
            ("mID", I32, 1),
            ("mDriverName, mVehicleName", I8, 96),
            ("mTotalLaps", I16, 1),
            ("mSector, mFinishStatus", I8, 2),
            ("mLapDist .. mCurSector2", F64, 11),
            ("mNumPitstops, mNumPenalties", I16, 2),
            ("mIsPlayer", I8, 1),
            ("mControl, mInPits, mPlace", I8, 3),
            ("mVehicleClass", I8, 32),
            ("mTimeBehindNext", F64, 1),
            ("mLapsBehindNext", I32, 1),
            ("mTimeBehindLeader", F64, 1),
            ("mLapsBehindLeader", I32, 1),
            ("mLapStartET", F64, 1),
            ("position, orientation and derivatives", F64, 3 * 3 + 9 + 6),
            ("mHeadlights .. mIndividualPhase", I8, 4),
            ("mQualification", I32, 1),
            ("mTimeIntoLap, mEstimatedLapTime", F64, 2),
            ("mPitGroup", I8, 24),
            ("mFlag .. mInGarageStall", I8, 4),
            ("mUpgradePack", I8, 16),
            ("mPitLapDist, mBestLapSector1, mBestLapSector2", F32, 3),
            ("mExpansion", I8, 48),
        ],
    )
}

#[test]
fn the_layouts_offsets_are_the_declared_structures() {
    assert_eq!(wheel().size, WHEEL);
    let v = vehicle();
    assert_eq!(v.size, telemetry::VEHICLE);
    assert_eq!(v.at("mElapsedTime"), telemetry::ELAPSED_TIME);
    assert_eq!(v.at("mLocalAccel"), telemetry::LOCAL_ACCEL);
    assert_eq!(v.at("mOri") + 24, telemetry::ORI_ROW_UP);
    assert_eq!(v.at("mLocalRot"), telemetry::LOCAL_ROT);
    // The version block (8) and mBytesUpdatedHint (4) come first.
    assert_eq!(12 + scoring_info().at("mNumVehicles"), scoring::NUM_VEHICLES);
    assert_eq!(12 + scoring_info().size, scoring::VEHICLES);
    assert_eq!(vehicle_scoring().size, scoring::VEHICLE);
    assert_eq!(vehicle_scoring().at("mIsPlayer"), scoring::IS_PLAYER);
}

/// The ids of the vehicles in the scoring buffer, the player's among them.
const IDS: [i32; 3] = [3, 7, 11];
const PLAYER: i32 = 7;

/// Scoring: three vehicles, the second the player's; `version` in both halves of its block.
fn scoring_page(version: u32) -> Vec<u8> {
    let (info, veh) = (scoring_info(), vehicle_scoring());
    let first = 12 + info.size;
    let mut p = Page::zeros(first + IDS.len() * veh.size);
    p.u32(0, version)
        .u32(4, version)
        .i32(12 + info.at("mNumVehicles"), IDS.len() as i32);
    for (i, id) in IDS.iter().enumerate() {
        let at = first + i * veh.size;
        p.i32(at + veh.at("mID"), *id)
            .put(at + veh.at("mIsPlayer"), &[u8::from(*id == PLAYER)]);
    }
    p.0
}

/// Telemetry: the same vehicles in another order, the player's holding `m`; versions `begin` and `end`.
fn telemetry_page(begin: u32, end: u32, time: f64, m: &super::super::testing::Moment) -> Vec<u8> {
    let v = vehicle();
    let mut p = Page::zeros(16 + IDS.len() * v.size);
    p.u32(0, begin).u32(4, end).i32(12, IDS.len() as i32);
    let (sp, cp) = m.pitch.sin_cos();
    let (sr, cr) = m.roll.sin_cos();
    for (i, id) in [11, 3, 7].iter().enumerate() {
        let at = 16 + i * v.size;
        p.i32(at + v.at("mID"), *id);
        if *id != PLAYER {
            p.f64s(at + v.at("mLocalAccel"), &[50.0, 50.0, 50.0]);
            continue;
        }
        // Published axes: x left, y up, z back; rotations +x pitches up, +y yaws right, +z rolls right.
        p.f64s(at + v.at("mElapsedTime"), &[time])
            .f64s(at + v.at("mLocalAccel"), &[m.accel[1], m.accel[2], -m.accel[0]])
            .f64s(at + v.at("mOri") + 24, &[cp * sr, cp * cr, -sp])
            .f64s(at + v.at("mLocalRot"), &[-m.rate[1], -m.rate[2], m.rate[0]]);
    }
    p.0
}

#[test]
fn a_drive_decodes_the_players_vehicle() {
    for game in [Game::Rf2, Game::Lmu] {
        for (i, m) in DRIVE.iter().enumerate() {
            let v = 40 + i as u32;
            let pages = [telemetry_page(v, v, 100.0 + i as f64, m), scoring_page(9)];
            let read = decode_game(game, &pages).unwrap_or_else(|e| panic!("{}: {e}", m.name));
            assert_eq!((read.tick, read.sample.time), (u64::from(v), Some(100.0 + i as f64)));
            let t = read.sample.telemetry;
            assert!(close(t.force, m.force()), "{}: {t:?}", m.name);
            assert!(close(t.rate, m.rate), "{}: {t:?}", m.name);
        }
    }
}

#[test]
fn torn_buffers_and_no_player_are_refused() {
    let m = &DRIVE[1];
    let torn = decode(Game::Rf2, &telemetry_page(5, 4, 1.0, m), &scoring_page(2));
    assert_eq!(torn, Err(Unreadable::Torn { game: Game::Rf2 }));
    let mut scoring = scoring_page(2);
    scoring[4] = 3;
    assert!(matches!(
        decode(Game::Rf2, &telemetry_page(5, 5, 1.0, m), &scoring),
        Err(Unreadable::Torn { .. })
    ));
    let mut nobody = scoring_page(2);
    let at = scoring::VEHICLES + scoring::VEHICLE + scoring::IS_PLAYER;
    nobody[at] = 0;
    let e = decode(Game::Lmu, &telemetry_page(5, 5, 1.0, m), &nobody).unwrap_err();
    assert!(
        matches!(e, Unreadable::NoMotion { .. }) && e.to_string().contains("player"),
        "{e}"
    );
    let mut many = telemetry_page(5, 5, 1.0, m);
    many[12..16].copy_from_slice(&129i32.to_le_bytes());
    assert!(decode(Game::Rf2, &many, &scoring_page(2)).is_err());
    let short = telemetry_page(5, 5, 1.0, m);
    assert!(matches!(
        decode(Game::Rf2, &short[..short.len() - 1], &scoring_page(2)),
        Err(Unreadable::Size { .. })
    ));
}

/// The player's `mLapDist` over the track's (`mScoringInfo.mLapDist`): a fraction of the lap; none while the
/// track's length is not positive.
#[test]
fn the_lap_position_is_the_players_lap_distance_over_the_tracks() {
    let (info, veh) = (scoring_info(), vehicle_scoring());
    assert_eq!(12 + info.at("mLapDist"), scoring::TRACK_LENGTH);
    assert_eq!(veh.at("mLapDist .. mCurSector2"), scoring::LAP_DIST);
    let at = |i: usize| 12 + info.size + i * veh.size + veh.at("mLapDist .. mCurSector2");
    let mut p = Page(scoring_page(2));
    p.f64s(12 + info.at("mLapDist"), &[4000.0]);
    for (i, d) in [100.0, 1000.0, 3900.0].iter().enumerate() {
        // The player is the second vehicle; the others elsewhere on the lap.
        p.f64s(at(0), &[d + 50.0])
            .f64s(at(1), &[*d])
            .f64s(at(2), &[10.0 * i as f64]);
        let read = decode(Game::Rf2, &telemetry_page(5, 5, 1.0, &DRIVE[0]), &p.0).unwrap();
        assert_eq!(read.sample.lap, Some(crate::games::LapPosition::Along(d / 4000.0)));
    }
    p.f64s(12 + info.at("mLapDist"), &[0.0]);
    let read = decode(Game::Lmu, &telemetry_page(5, 5, 1.0, &DRIVE[0]), &p.0).unwrap();
    assert_eq!(read.sample.lap, None, "no track length yet");
}

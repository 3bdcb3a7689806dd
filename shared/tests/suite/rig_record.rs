//! A rig on the device: the record travels in one frame, is checked by the controller as a start will check it,
//! is stored as one versioned flash item, and comes back exactly; a record the checks refuse or cannot read leaves
//! the compiled-in rig running with the cause reported; a save cut at any byte leaves the old rig or the new one.

use crate::common::device;

use embassy_futures::block_on;
use ringpod_core::controller::{Controller, ControllerConfig, Inputs};
use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL};
use ringpod_core::kinematics::RingGeometry;
use ringpod_core::motion::{SpareAxisSettings, SPARE_AXES};
use ringpod_core::protocol::{
    self, ConfigRefusal, ControlSettings, DeviceMessage, HostMessage, NackReason, Request, RigRecord, RigSource,
    Settings, SettingsKind, StreamSettings, MAX_PAYLOAD,
};
use ringpod_core::safety::{Command, Refusal};
use ringpod_core::store::{restore, store, CONFIG_KEY, RECORD_VERSION};
use sequential_storage::cache::NoCache;
use sequential_storage::map::store_item;
use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};

/// Four pages of 2 KiB (the QEMU controller's and the simulator's layout): a rig record fits a page several times.
type Flash = MockFlashBase<4, 4, 512>;

fn flash() -> Flash {
    Flash::new(WriteCountCheck::OnceOnly, None, true)
}

/// The trainer model's chains on a wider ring with longer rods: no preset describes it.
fn wider(ring_radius: f64, rod_length: f64) -> RigRecord {
    let g = RingGeometry::new(
        "wider",
        ring_radius,
        rod_length,
        TRAINER_MODEL.chains(),
        TRAINER_MODEL.limits,
    )
    .unwrap();
    ControllerConfig::default_record("wider-ring", &g, Preset::TrainerModel.home())
}

#[test]
fn a_rig_round_trips_through_the_wire_and_flash_exactly() {
    let rig = wider(0.3, 0.325);
    // The wire: one frame, under the payload limit, decoded to the same bits.
    let mut frame = [0u8; protocol::MAX_FRAME];
    let n = protocol::encode(
        &Request {
            id: 7,
            body: HostMessage::SetRig(rig),
        },
        &mut frame,
    )
    .unwrap();
    let mut raw = [0u8; 1024];
    let payload = postcard::to_slice(&HostMessage::SetRig(rig), &mut raw).unwrap();
    assert!(payload.len() <= MAX_PAYLOAD, "{} bytes", payload.len());
    eprintln!("a rig record with six chains: {} payload bytes", payload.len());
    let back: Request = protocol::decode(&frame[..n - 1]).unwrap();
    assert_eq!(back.body, HostMessage::SetRig(rig));

    // Flash: stored with the stream and control sections as one record, restored as the running configuration.
    let defaults = ControllerConfig::trainer_model();
    let stream = Settings::Stream(StreamSettings {
        timeout_ms: 150,
        telemetry_hz: 50,
        ..defaults.stream()
    });
    let control = Settings::Control(ControlSettings { tick_hz: 2_000 });
    let mut expected = ControllerConfig::from_record(&rig).unwrap();
    expected.apply(&stream).unwrap();
    expected.apply(&control).unwrap();
    let mut f = flash();
    let range = Flash::FULL_FLASH_RANGE;
    block_on(store(&mut f, range.clone(), &expected)).unwrap();
    let (config, report) = block_on(restore(&mut f, range, defaults));
    assert_eq!(report.rig, RigSource::Stored);
    assert_eq!(
        (report.applied, report.refused, report.unreadable, report.fell_back),
        (3, 0, false, false)
    );
    assert_eq!(config.rig(), rig);
    assert_eq!(config.rig().name(), "wider-ring");
    assert_eq!(config.settings(SettingsKind::Stream), stream);
    assert_eq!(config.settings(SettingsKind::Control), control);
    assert_eq!(config, expected);
}

/// A record as an older or other firmware may have written it: the rig and sections in the record's layout.
fn raw_record(version: u16, rig: &RigRecord) -> Vec<u8> {
    let defaults = ControllerConfig::trainer_model();
    let mut raw = [0u8; 1024];
    let mut bytes = postcard::to_slice(&(version, rig, defaults.stream(), defaults.control()), &mut raw)
        .unwrap()
        .to_vec();
    if version >= 5 {
        // The spare axes' section (none fitted), after the control section.
        let spare = [SpareAxisSettings::NONE; SPARE_AXES];
        bytes.extend_from_slice(postcard::to_slice(&spare, &mut raw).unwrap());
    }
    bytes
}

fn store_raw(f: &mut Flash, bytes: &[u8]) {
    let mut buf = [0u8; 1024];
    block_on(store_item(
        f,
        Flash::FULL_FLASH_RANGE,
        &mut NoCache::new(),
        &mut buf,
        &CONFIG_KEY,
        &bytes,
    ))
    .unwrap();
}

#[test]
fn a_stored_rig_that_cannot_run_leaves_the_compiled_rig_and_says_why() {
    let defaults = ControllerConfig::trainer_model();
    let range = Flash::FULL_FLASH_RANGE;
    // Stored by an older firmware whose checks let it through: a home pose 5 m up has no solution.
    let mut unreachable = wider(0.3, 0.325);
    unreachable.home[2] = 5.0;
    let mut f = flash();
    store_raw(&mut f, &raw_record(RECORD_VERSION, &unreachable));
    let (config, report) = block_on(restore(&mut f, range.clone(), defaults));
    assert_eq!(report.rig, RigSource::Refused(ConfigRefusal::HomePose));
    assert_eq!(config, defaults);

    // A negative ring radius fails the geometry's own checks.
    let mut negative = wider(0.3, 0.325);
    negative.ring_radius = -0.3;
    let mut f = flash();
    store_raw(&mut f, &raw_record(RECORD_VERSION, &negative));
    assert_eq!(
        block_on(restore(&mut f, range.clone(), defaults)).1.rig,
        RigSource::Refused(ConfigRefusal::Geometry)
    );

    // The raw layout is the record's: the same bytes with a good rig restore it.
    let mut f = flash();
    store_raw(&mut f, &raw_record(RECORD_VERSION, &wider(0.3, 0.325)));
    assert_eq!(
        block_on(restore(&mut f, range.clone(), defaults)).1.rig,
        RigSource::Stored
    );

    // A record of another layout version, and bytes that are no record at all.
    for bytes in [raw_record(RECORD_VERSION + 1, &wider(0.3, 0.325)), vec![1, 2, 3]] {
        let mut f = flash();
        store_raw(&mut f, &bytes);
        let (config, report) = block_on(restore(&mut f, range.clone(), defaults));
        assert_eq!((report.rig, config), (RigSource::Unreadable, defaults));
    }
}

/// A history of rig saves (so that pages fill and a save must erase one), each cut at every byte it writes or
/// erases: a restore then runs the old rig or the new one, nothing else, and the next save lands.
#[test]
fn a_rig_save_cut_at_any_byte_restores_the_old_or_the_new_rig() {
    let defaults = ControllerConfig::trainer_model();
    let range = Flash::FULL_FLASH_RANGE;
    let mut live = flash();
    let mut held = defaults.rig();
    let mut cuts = 0;
    for i in 0..24 {
        let new = wider(0.29 + 0.001 * f64::from(i % 12), 0.32 + 0.0005 * f64::from(i));
        let new_config = ControllerConfig::from_record(&new).unwrap();
        // A save writes far fewer bytes than this: a save that never completes fails the test, not hangs it.
        for budget in 0u32..=20_000 {
            assert!(budget < 20_000, "save {i} never completed");
            let mut f = live.clone();
            f.bytes_until_shutoff = Some(budget);
            let done = block_on(store(&mut f, range.clone(), &new_config)).is_ok();
            f.bytes_until_shutoff = None;
            let (config, _) = block_on(restore(&mut f, range.clone(), defaults));
            let got = config.rig();
            assert!(got == held || got == new, "save {i} cut after {budget} bytes: {got:?}");
            if done {
                assert_eq!(got, new, "save {i} completed");
                break;
            }
            cuts += 1;
        }
        block_on(store(&mut live, range.clone(), &new_config)).unwrap();
        held = new;
    }
    assert!(cuts > 24 * 100, "only {cuts} cut points");
}

fn ask(c: &mut Controller, body: HostMessage) -> DeviceMessage {
    c.handle(&Request { id: 2, body }).body
}

#[test]
fn the_controller_takes_a_rig_only_when_off_and_only_one_that_can_run() {
    let mut c = device::connected();
    let rig = wider(0.3, 0.325);
    let mut bad = rig;
    bad.home[2] = 5.0;
    assert_eq!(
        ask(&mut c, HostMessage::SetRig(bad)),
        DeviceMessage::Nack(NackReason::BadConfig(ConfigRefusal::HomePose))
    );
    assert_eq!(c.take_unsaved(), None, "a refused rig is not stored");

    // Powered: refused, nothing stored, no restart.
    c.set_inputs(Inputs {
        logic_ok: true,
        power_ok: true,
        ..Inputs::default()
    });
    assert_eq!(ask(&mut c, HostMessage::Command(Command::Enable)), DeviceMessage::Ack);
    c.tick();
    let wrong_state = DeviceMessage::Nack(NackReason::Refused(Refusal::WrongState));
    assert_eq!(ask(&mut c, HostMessage::SetRig(rig)), wrong_state);
    assert_eq!(ask(&mut c, HostMessage::Restart), wrong_state);
    assert_eq!(ask(&mut c, HostMessage::Command(Command::Disable)), DeviceMessage::Ack);
    for _ in 0..3_000 {
        c.tick();
    }
    assert_eq!(c.supervisor().state(), ringpod_core::safety::State::Off);

    // Off: taken, reported as pending, handed out once for storing; the restart waits for it.
    assert_eq!(ask(&mut c, HostMessage::SetRig(rig)), DeviceMessage::Ack);
    assert_eq!(ask(&mut c, HostMessage::Restart), DeviceMessage::Ack);
    assert_eq!(c.restart_due(), None, "the rig is not stored yet");
    match ask(&mut c, HostMessage::GetRig) {
        DeviceMessage::Rig {
            rig: running,
            source,
            pending,
        } => {
            assert_eq!(
                (running, source, pending),
                (ControllerConfig::trainer_model().rig(), RigSource::Compiled, true)
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(c.take_unsaved().map(|config| config.rig()), Some(rig));
    assert_eq!(c.take_unsaved(), None);
    assert_eq!(c.restart_due(), Some(ringpod_core::controller::Restart::Controller));
}

/// The stream's hot path reads a setpoint request straight from its payload: the same request as the full
/// decode, for every setpoint; any other request is left to it.
#[test]
fn a_setpoint_request_read_on_its_own_is_the_request_decoded_whole() {
    use ringpod_core::kinematics::Pose;
    use ringpod_core::motion::Setpoint;
    let setpoint = Setpoint {
        seq: 0x1234_5678,
        time_us: 987_654_321,
        pose: Pose::from_array([0.01, -0.02, 0.23, 0.1, -0.2, 3.0]),
        aux: [None; 2],
        spare: [None; 2],
    };
    for id in [0, 1, 300, u32::MAX] {
        let mut raw = [0u8; 128];
        let payload = postcard::to_slice(
            &Request {
                id,
                body: HostMessage::Setpoint(setpoint),
            },
            &mut raw,
        )
        .unwrap();
        assert_eq!(protocol::setpoint_request(payload), Some((id, setpoint)));
        // A byte more or less is no setpoint request.
        assert_eq!(protocol::setpoint_request(&payload[..payload.len() - 1]), None);
    }
    for body in [
        HostMessage::GetStatus,
        HostMessage::Command(Command::Stop),
        HostMessage::SetRig(wider(0.3, 0.325)),
    ] {
        let mut raw = [0u8; 1024];
        let payload = postcard::to_slice(&Request { id: 9, body }, &mut raw).unwrap();
        assert_eq!(protocol::setpoint_request(payload), None);
    }
}

/// A record that a version-2 firmware stored (before the motion section carried the actuator limits), written here
/// in that layout as tuples: the update reads it, keeps the builder's rig and every section it had, and gives each
/// actuator its kind's limits, what a version-2 device drove it with: the elbow trainer's carriages 2.4 rad/s, its
/// shoulders 3 rad/s.
#[test]
fn a_version_2_record_is_migrated_with_its_actuators_kinds_limits() {
    let defaults = ControllerConfig::trainer_model();
    let mut rig = ControllerConfig::default_record(
        "my-elbow",
        &ringpod_core::kinematics::presets::TRAINER_ELBOW,
        Preset::TrainerElbow.home(),
    );
    rig.machine.motion.pose_velocity[5] = 1.5;
    rig.machine.axes[1].reverse = true;
    let m = &rig.machine;
    let old_machine = (
        m.axes,
        (m.motion.pose_velocity, m.motion.pose_acceleration),
        m.inputs,
        m.supervisor,
        m.homing,
    );
    let old_rig = (
        rig.name,
        rig.ring_radius,
        rig.rod_length,
        rig.chains,
        rig.chain_count,
        rig.limits,
        rig.home,
        old_machine,
    );
    let stream = StreamSettings {
        timeout_ms: 250,
        ..defaults.stream()
    };
    let mut raw = [0u8; 1024];
    let bytes = postcard::to_slice(&(2u16, old_rig, old_stream(&stream), defaults.control()), &mut raw).unwrap();
    let mut f = flash();
    store_raw(&mut f, bytes);
    let (config, report) = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!(report.rig, RigSource::Stored);
    assert_eq!(
        report.applied,
        1 + 1 + 1,
        "stream, control and (none fitted) the spare axes"
    );
    let limits = config.pipeline.limits;
    assert_eq!(limits.pose_velocity[5], 1.5);
    assert_eq!(limits.actuator_velocity, [2.4, 2.4, 2.4, 2.4, 3.0, 3.0]);
    assert_eq!(limits.actuator_acceleration, [100.0, 100.0, 100.0, 100.0, 60.0, 60.0]);
    assert_eq!(
        config.rig(),
        rig,
        "the rig and its sections as they were, the limits as default_record gives"
    );
    assert_eq!(config.stream(), stream);
    // Stored again, it is a record of this version that restores to the same configuration.
    let mut f = flash();
    block_on(store(&mut f, Flash::FULL_FLASH_RANGE, &config)).unwrap();
    let again = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!((again.0, again.1.rig), (config, RigSource::Stored));
}

/// The stream section as versions 2 and 3 stored it (postcard writes a struct as its fields in order): without
/// `host_gone_ms`.
fn old_stream(s: &StreamSettings) -> (u16, u16, ringpod_core::motion::FollowMode, [f32; 6], u16) {
    (s.timeout_ms, s.gross_jump_ms, s.follow, s.margins, s.telemetry_hz)
}

#[test]
fn a_version_3_record_is_migrated_with_the_default_time_for_a_host_gone() {
    let defaults = ControllerConfig::trainer_model();
    let rig = wider(0.3, 0.325);
    let stream = StreamSettings {
        timeout_ms: 250,
        telemetry_hz: 50,
        host_gone_ms: ringpod_core::safety::HOST_GONE_MS,
        ..defaults.stream()
    };
    let mut raw = [0u8; 1024];
    let bytes = postcard::to_slice(&(3u16, &rig, old_stream(&stream), defaults.control()), &mut raw).unwrap();
    let mut f = flash();
    store_raw(&mut f, bytes);
    let (config, report) = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!((report.rig, report.applied, report.refused), (RigSource::Stored, 3, 0));
    assert_eq!(config.rig(), rig);
    assert_eq!(config.stream(), stream, "the stored values, and the default time");
    // A record of this version keeps a time of its own.
    let mut changed = config;
    changed
        .apply(&Settings::Stream(StreamSettings {
            host_gone_ms: 2_500,
            ..stream
        }))
        .unwrap();
    let mut f = flash();
    block_on(store(&mut f, Flash::FULL_FLASH_RANGE, &changed)).unwrap();
    let again = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!(again.0.stream().host_gone_ms, 2_500);
    assert_eq!(again.1.rig, RigSource::Stored);
}

/// A version-4 record (no spare axes' section) restores with none fitted; a version-5 record keeps fitted spare
/// axes through flash exactly.
#[test]
fn the_spare_axes_are_stored_and_a_version_4_record_has_none() {
    let defaults = ControllerConfig::trainer_model();
    let rig = wider(0.3, 0.325);
    let mut f = flash();
    store_raw(&mut f, &raw_record(4, &rig));
    let (config, report) = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!((report.rig, report.applied, report.refused), (RigSource::Stored, 3, 0));
    assert_eq!(config.pipeline.spare, [SpareAxisSettings::NONE; SPARE_AXES]);

    let mut fitted = ControllerConfig::from_record(&rig).unwrap();
    fitted.supervisor.logic_sense = false;
    fitted.supervisor.power_sense = false;
    let axis7 = SpareAxisSettings {
        enabled: true,
        steps_per_unit: 3_200.0,
        velocity: 25.0,
        acceleration: 400.0,
        travel: [-10.0, 350.0],
    };
    fitted
        .apply(&Settings::Spare([axis7, SpareAxisSettings::NONE]))
        .unwrap();
    let mut f = flash();
    block_on(store(&mut f, Flash::FULL_FLASH_RANGE, &fitted)).unwrap();
    let (config, report) = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!((report.applied, report.refused, report.fell_back), (3, 0, false));
    assert_eq!(config.pipeline.spare, [axis7, SpareAxisSettings::NONE]);
}

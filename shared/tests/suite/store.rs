//! The configuration store survives power loss: a save cut at every byte of its writes and erases, on
//! sequential-storage's mock flash, leaves a restore with the old or the new configuration, nothing else.

use embassy_futures::block_on;
use ringpod_core::controller::ControllerConfig;
use ringpod_core::protocol::{ControlSettings, RigSource, Settings, StreamSettings};
use ringpod_core::store::{restore, store, Restored};
use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};

/// Four pages of 512 words of 4 bytes (the QEMU controller's and the simulator's layout): three records fill a page,
/// so that later saves must erase one (the path where a cut hurts most).
type Flash = MockFlashBase<4, 4, 512>;

fn flash() -> Flash {
    Flash::new(WriteCountCheck::OnceOnly, None, true)
}

/// The configuration of the `n`th save: the stream section with a stream timeout of `100 + n` ms, or the control
/// section at one of its three rates, changed in turn over `held`.
fn next(held: &ControllerConfig, n: usize) -> ControllerConfig {
    let change = if n.is_multiple_of(2) {
        Settings::Stream(StreamSettings {
            timeout_ms: 100 + n as u16,
            ..held.stream()
        })
    } else {
        Settings::Control(ControlSettings {
            tick_hz: [500, 1_000, 2_000][n % 3],
        })
    };
    let mut config = *held;
    config.apply(&change).unwrap();
    config
}

/// Every save of a long history (so that pages fill and later saves must erase one) is cut at every byte it writes
/// or erases; after each cut a restore gives the old configuration or the new one, nothing between, and a save
/// made then lands.
#[test]
fn a_save_cut_at_any_byte_restores_the_old_or_the_new_configuration() {
    let defaults = ControllerConfig::trainer_model();
    let range = Flash::FULL_FLASH_RANGE;
    let mut live = flash();
    let mut held = defaults;
    let (mut cuts, mut erasing_saves) = (0usize, 0usize);
    let saves = 40usize;
    for i in 0..saves {
        let new = next(&held, i + 1);
        // A save writes far fewer bytes than this: a save that never completes fails the test, not hangs it.
        for budget in 0u32..=20_000 {
            assert!(budget < 20_000, "save {i} never completed");
            let mut f = live.clone();
            f.bytes_until_shutoff = Some(budget);
            let done = block_on(store(&mut f, range.clone(), &new)).is_ok();
            f.bytes_until_shutoff = None;
            let (config, report) = block_on(restore(&mut f, range.clone(), defaults));
            assert!(
                config == held || config == new,
                "save {i} cut after {budget} bytes: neither the old nor the new configuration"
            );
            assert!(
                !report.fell_back && !report.unreadable && report.refused == 0,
                "save {i} cut after {budget}: {report:?}"
            );
            if done {
                assert_eq!(config, new, "save {i} completed");
                break;
            }
            block_on(store(&mut f, range.clone(), &new)).unwrap();
            let (config, _) = block_on(restore(&mut f, range.clone(), defaults));
            assert_eq!(config, new, "save {i} cut after {budget} bytes, saved again");
            cuts += 1;
        }
        let before = live.stats_snapshot();
        block_on(store(&mut live, range.clone(), &new)).unwrap();
        if before.compare_to(live.stats_snapshot()).erases > 0 {
            erasing_saves += 1;
        }
        held = new;
    }
    let (config, report) = block_on(restore(&mut live, range.clone(), defaults));
    assert_eq!(config, held);
    assert_eq!(report.rig, RigSource::Stored);
    eprintln!("{cuts} cut points over {saves} saves, {erasing_saves} of which erased a page");
    assert!(
        erasing_saves > 0,
        "no save erased a page: the test would miss that path"
    );
    assert!(cuts > saves * 400, "only {cuts} cut points");
}

#[test]
fn empty_flash_restores_the_defaults() {
    let mut f = flash();
    let defaults = ControllerConfig::trainer_model();
    let (config, report) = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!(report, Restored::default());
    assert_eq!(report.rig, RigSource::Compiled);
    assert_eq!(config, defaults);
}

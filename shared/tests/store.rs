//! The settings store survives power loss: a save cut at every byte of its writes and erases, on
//! sequential-storage's mock flash, leaves a restore with the old or the new settings, nothing else.

use embassy_futures::block_on;
use ringpod_core::controller::ControllerConfig;
use ringpod_core::protocol::{ControlSettings, Settings, SettingsKind, StreamSettings};
use ringpod_core::store::{restore, store, Restored};
use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};

/// Four pages of 64 words of 4 bytes: small enough that a handful of saves fills a page and the next save must
/// erase one (the path where a cut hurts most).
type Flash = MockFlashBase<4, 4, 64>;

fn flash() -> Flash {
    Flash::new(WriteCountCheck::OnceOnly, None, true)
}

/// The `n`th value of one of the two sections stored on their own: the stream section with a stream timeout of
/// `100 + n` ms, or the control section at one of its three rates.
fn value(defaults: &ControllerConfig, slot: usize, n: usize) -> Settings {
    match (slot, defaults.settings(SettingsKind::Stream)) {
        (0, Settings::Stream(s)) => Settings::Stream(StreamSettings {
            timeout_ms: 100 + n as u16,
            ..s
        }),
        _ => Settings::Control(ControlSettings {
            tick_hz: [500, 1_000, 2_000][n % 3],
        }),
    }
}

/// Every save of a long history (two sections in turn, so that pages fill and later saves must erase one) is cut at
/// every byte it writes or erases; after each cut a restore gives the section's old or new value and the other
/// section's value, and a save made then lands.
#[test]
fn a_save_cut_at_any_byte_restores_the_old_or_the_new_value() {
    let defaults = ControllerConfig::trainer_model();
    let range = Flash::FULL_FLASH_RANGE;
    let kinds = [SettingsKind::Stream, SettingsKind::Control];
    let mut live = flash();
    let mut held = kinds.map(|k| defaults.settings(k));
    let (mut cuts, mut erasing_saves) = (0usize, 0usize);
    for i in 0..160usize {
        let slot = i % 2;
        let (k, new) = (kinds[slot], value(&defaults, slot, i / 2 + 1));
        let other = held[1 - slot];
        // A save writes far fewer bytes than this: a save that never completes fails the test, not hangs it.
        for budget in 0u32..=20_000 {
            assert!(budget < 20_000, "save {i} never completed");
            let mut f = live.clone();
            f.bytes_until_shutoff = Some(budget);
            let done = block_on(store(&mut f, range.clone(), &new)).is_ok();
            f.bytes_until_shutoff = None;
            let (config, report) = block_on(restore(&mut f, range.clone(), defaults));
            let got = config.settings(k);
            assert!(
                got == held[slot] || got == new,
                "save {i} cut after {budget} bytes: {got:?} is neither {:?} nor {new:?}",
                held[slot]
            );
            assert_eq!(
                config.settings(kinds[1 - slot]),
                other,
                "save {i} cut after {budget}: the other section changed"
            );
            assert!(
                !report.fell_back && !report.unreadable,
                "save {i} cut after {budget}: {report:?}"
            );
            if done {
                break;
            }
            block_on(store(&mut f, range.clone(), &new)).unwrap();
            let (config, _) = block_on(restore(&mut f, range.clone(), defaults));
            assert_eq!(
                config.settings(k),
                new,
                "save {i} cut after {budget} bytes, saved again"
            );
            cuts += 1;
        }
        let before = live.stats_snapshot();
        block_on(store(&mut live, range.clone(), &new)).unwrap();
        if before.compare_to(live.stats_snapshot()).erases > 0 {
            erasing_saves += 1;
        }
        held[slot] = new;
    }
    let (config, _) = block_on(restore(&mut live, range.clone(), defaults));
    assert_eq!(kinds.map(|k| config.settings(k)), held);
    eprintln!("{cuts} cut points over 160 saves, {erasing_saves} of which erased a page");
    assert!(
        erasing_saves > 0,
        "no save erased a page: the test would miss that path"
    );
    assert!(cuts > 160 * 8, "only {cuts} cut points");
}

#[test]
fn empty_flash_restores_the_defaults() {
    let mut f = flash();
    let defaults = ControllerConfig::trainer_model();
    let (config, report) = block_on(restore(&mut f, Flash::FULL_FLASH_RANGE, defaults));
    assert_eq!(report, Restored::default());
    assert_eq!(config, defaults);
}

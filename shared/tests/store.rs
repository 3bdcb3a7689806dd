//! The settings store survives power loss: a save cut at every byte of its writes and erases, on
//! sequential-storage's mock flash, leaves a restore with the old or the new settings, nothing else.

use embassy_futures::block_on;
use ringpod_core::controller::ControllerConfig;
use ringpod_core::protocol::ConfigKey;
use ringpod_core::store::{restore, store, Restored};
use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};

/// Four pages of 64 words of 4 bytes: small enough that a handful of saves fills a page and the next save must
/// erase one (the path where a cut hurts most).
type Flash = MockFlashBase<4, 4, 64>;

fn flash() -> Flash {
    Flash::new(WriteCountCheck::OnceOnly, None, true)
}

fn key(n: usize) -> ConfigKey {
    ConfigKey::all().nth(n).unwrap()
}

/// A value for `key` that the configuration accepts, different from `defaults`, `step` apart.
fn value(defaults: &ControllerConfig, key: ConfigKey, step: f32) -> f32 {
    let base = defaults.get(key).unwrap();
    let mut c = *defaults;
    for v in [
        base * (1.0 + 0.01 * step),
        base + 0.01 * step,
        base * (1.0 - 0.01 * step),
    ] {
        if c.set(key, v).is_ok() && c.validate().is_ok() && c.get(key) != Some(base) {
            // The configuration may round what it takes: the value is what it holds.
            return c.get(key).unwrap_or(base);
        }
    }
    base
}

/// Every save of a long history (two keys in turn, so that pages fill and later saves must erase one) is cut at
/// every byte it writes or erases; after each cut a restore gives the key's old or new value and the other key's
/// value, and a save made then lands.
#[test]
fn a_save_cut_at_any_byte_restores_the_old_or_the_new_value() {
    let defaults = ControllerConfig::trainer_model();
    let range = Flash::FULL_FLASH_RANGE;
    let (a, b) = (key(0), key(1));
    let mut live = flash();
    let mut held = [defaults.get(a).unwrap(), defaults.get(b).unwrap()];
    let (mut cuts, mut erasing_saves) = (0usize, 0usize);
    for i in 0..160usize {
        let (slot, k) = if i % 2 == 0 { (0, a) } else { (1, b) };
        let new = value(&defaults, k, (i % 7 + 1) as f32);
        let other = held[1 - slot];
        for budget in 0u32.. {
            let mut f = live.clone();
            f.bytes_until_shutoff = Some(budget);
            let done = block_on(store(&mut f, range.clone(), k, new)).is_ok();
            f.bytes_until_shutoff = None;
            let (config, report) = block_on(restore(&mut f, range.clone(), defaults));
            let got = config.get(k).unwrap();
            assert!(
                got == held[slot] || got == new,
                "save {i} cut after {budget} bytes: {got} is neither {} nor {new}",
                held[slot]
            );
            let other_key = if slot == 0 { b } else { a };
            assert_eq!(
                config.get(other_key),
                Some(other),
                "save {i} cut after {budget}: the other key changed"
            );
            assert!(
                !report.fell_back && !report.unreadable,
                "save {i} cut after {budget}: {report:?}"
            );
            if done {
                break;
            }
            block_on(store(&mut f, range.clone(), k, new)).unwrap();
            let (config, _) = block_on(restore(&mut f, range.clone(), defaults));
            assert_eq!(
                config.get(k),
                Some(new),
                "save {i} cut after {budget} bytes, saved again"
            );
            cuts += 1;
        }
        let before = live.stats_snapshot();
        block_on(store(&mut live, range.clone(), k, new)).unwrap();
        if before.compare_to(live.stats_snapshot()).erases > 0 {
            erasing_saves += 1;
        }
        held[slot] = new;
    }
    let (config, _) = block_on(restore(&mut live, range.clone(), defaults));
    assert_eq!((config.get(a), config.get(b)), (Some(held[0]), Some(held[1])));
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
    assert_eq!(config.get(key(0)), defaults.get(key(0)));
}

//! Unreadable datagrams kept within a bound: a live source can send anything for as long as it likes, so each
//! reason is counted by its kind (the reason with its numbers taken out) and only the first few of a kind are kept,
//! their reasons cut to a line. Memory, stderr and the report stay bounded however many arrive; the counts add up
//! to every datagram refused.

use std::collections::BTreeMap;

use super::table::InputError;

/// Datagrams kept (and printed) per kind of reason.
pub const KEPT_PER_KIND: u64 = 5;
/// The longest reason kept (characters).
pub const REASON_CHARS: usize = 120;
/// Kinds counted apart; any further kinds are counted together under [`OTHER`].
pub const KINDS: usize = 32;
/// The kind of the reasons past [`KINDS`].
pub const OTHER: &str = "other reasons";

/// `text` cut to `max` characters, an ellipsis saying so.
pub fn cut(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_owned(),
        Some((at, _)) => format!("{}...", &text[..at]),
    }
}

/// A reason's kind: its numbers as `#`, cut to a line.
fn kind(reason: &str) -> String {
    let mut k = String::new();
    for c in reason.chars() {
        if c.is_ascii_digit() {
            if !k.ends_with('#') {
                k.push('#');
            }
        } else {
            k.push(c);
        }
    }
    cut(&k, REASON_CHARS)
}

/// Counts datagram `line`'s `reason` in `counts` (by kind); returns the datagram to keep, its reason cut, while
/// its kind has had fewer than [`KEPT_PER_KIND`].
pub fn tally(counts: &mut BTreeMap<String, u64>, line: usize, reason: &str) -> Option<InputError> {
    let mut kind = kind(reason);
    if !counts.contains_key(&kind) && counts.len() >= KINDS {
        kind = OTHER.to_owned();
    }
    let n = counts.entry(kind).or_default();
    *n += 1;
    (*n <= KEPT_PER_KIND).then(|| InputError {
        line,
        reason: cut(reason, REASON_CHARS),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 100,000 reasons of 65,507 characters, of kinds without end: the counts add up, the kinds and what is kept
    /// are bounded, each reason kept is a line.
    #[test]
    fn counts_add_up_and_what_is_kept_is_bounded() {
        let mut counts = BTreeMap::new();
        let mut kept = Vec::new();
        let long = "x".repeat(65_507);
        for i in 0..100_000usize {
            let reason = match i % 3 {
                0 => format!("not forza: {i} bytes, where forza has 232"),
                1 => format!("`{long}`: invalid float literal"),
                _ => format!(
                    "kind {} {}",
                    char::from(b'a' + (i % 26) as u8),
                    char::from(b'a' + (i / 26 % 26) as u8)
                ),
            };
            kept.extend(tally(&mut counts, i + 1, &reason));
        }
        assert_eq!(counts.values().sum::<u64>(), 100_000);
        assert_eq!(counts.len(), KINDS + 1);
        assert!(counts[OTHER] > 0);
        assert_eq!(counts["not forza: # bytes, where forza has #"], 33_334);
        assert!(kept.len() as u64 <= (KINDS as u64 + 1) * KEPT_PER_KIND);
        assert!(kept.iter().all(|e| e.reason.chars().count() <= REASON_CHARS + 3));
        assert_eq!(kept[0].line, 1);
        assert_eq!(cut("abc", 2), "ab...");
        assert_eq!(cut("äbc", 3), "äbc");
    }
}

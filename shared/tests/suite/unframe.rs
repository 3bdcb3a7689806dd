//! Unframing (COBS decoded in place, then the checksum) against the streaming decoder it replaced: over any frame
//! the frame reader can deliver (no delimiter inside), valid, corrupted or garbage, the same payload or the same
//! error; a frame holding a delimiter is refused.

use proptest::prelude::*;
use ringpod_core::protocol::{unframe, FrameError, MAX_FRAME};

const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);

/// What unframing was with `cobs::decode` (the streaming decoder into a second buffer).
fn streaming(frame: &[u8]) -> Result<Vec<u8>, FrameError> {
    if frame.is_empty() || frame.len() > MAX_FRAME {
        return Err(FrameError::Cobs);
    }
    let mut scratch = [0u8; MAX_FRAME];
    let report = cobs::decode(frame, &mut scratch).map_err(|_| FrameError::Cobs)?;
    let len = report.frame_size();
    if len < 5 {
        return Err(FrameError::TooShort);
    }
    let (payload, crc) = scratch[..len].split_at(len - 4);
    if CRC.checksum(payload).to_le_bytes() != crc {
        return Err(FrameError::Checksum);
    }
    Ok(payload.to_vec())
}

fn in_place(frame: &[u8]) -> Result<Vec<u8>, FrameError> {
    let mut scratch = [0xa5u8; MAX_FRAME];
    unframe(frame, &mut scratch).map(<[u8]>::to_vec)
}

/// A frame of `payload` with its checksum, without the delimiter.
fn framed(payload: &[u8]) -> Vec<u8> {
    let mut raw = payload.to_vec();
    raw.extend_from_slice(&CRC.checksum(payload).to_le_bytes());
    let mut out = vec![0u8; cobs::max_encoding_length(raw.len())];
    let n = cobs::encode(&raw, &mut out);
    out.truncate(n);
    out
}

/// Payloads with zeros scattered or none for hundreds of bytes (runs of 254 and more take COBS's 0xFF code).
fn payload() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        prop::collection::vec(any::<u8>(), 0..800),
        prop::collection::vec(1u8..=255, 0..800),
        prop::collection::vec(prop_oneof![Just(0u8), Just(1u8), any::<u8>()], 0..300),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3_000))]

    #[test]
    fn valid_frames_decode_as_before(payload in payload()) {
        let frame = framed(&payload);
        prop_assert_eq!(in_place(&frame), streaming(&frame));
        if frame.len() <= MAX_FRAME && !payload.is_empty() {
            prop_assert_eq!(in_place(&frame), Ok(payload));
        }
    }

    #[test]
    fn corrupted_frames_fail_as_before(payload in payload(), at in any::<prop::sample::Index>(), to in 1u8..=255) {
        let mut frame = framed(&payload);
        let i = at.index(frame.len());
        frame[i] = to;
        prop_assert_eq!(in_place(&frame), streaming(&frame));
    }

    #[test]
    fn garbage_fails_as_before(frame in prop::collection::vec(1u8..=255, 0..1200)) {
        prop_assert_eq!(in_place(&frame), streaming(&frame));
    }

    #[test]
    fn a_frame_holding_a_delimiter_is_refused(
        payload in payload(),
        at in any::<prop::sample::Index>(),
        tail in prop::collection::vec(any::<u8>(), 0..20),
    ) {
        let mut frame = framed(&payload);
        let i = at.index(frame.len());
        frame[i] = 0;
        prop_assert!(in_place(&frame).is_err());
        // Two frames run together: a valid one, a delimiter, anything.
        let mut two = framed(&payload);
        two.push(0);
        two.extend_from_slice(&tail);
        prop_assert!(in_place(&two).is_err());
    }
}

#[test]
fn a_short_scratch_is_refused() {
    let frame = framed(&[1, 2, 3, 4, 5, 6]);
    let mut scratch = [0u8; 4];
    assert_eq!(unframe(&frame, &mut scratch), Err(FrameError::Cobs));
}

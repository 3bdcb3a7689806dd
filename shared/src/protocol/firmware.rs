//! What a device says of the firmware it runs, and the part of the protocol every version keeps.
//!
//! The firmware names ringpod's version it was built from and the image in its flash: the image's length from
//! the start of flash and its CRC-32C (the frames' checksum), computed by the firmware over its own flash at boot.
//! At boot rather than at build time: a checksum cannot be linked into the image it covers without a step after
//! the link that every way of flashing (probe-rs, DFU, a copied `.bin`) would have to run, and a checksum of what
//! flash holds also tells a partly written image from the one the host flashed. The host computes the same
//! checksum over the image file it flashes ([`image_crc`]), so that "the board runs this image" is one comparison.
//!
//! **The stable head.** A host must name a board of another protocol version and send it to its bootloader
//! (`ringpod flash`), so these places in the encoding never move, in any version: the request
//! [`HostMessage::Hello`] (tag 0, its `version` first) and [`HostMessage::EnterBootloader`] ([`BOOTLOADER_TAG`]),
//! the answers [`DeviceMessage::Ack`] (tag 1) and [`DeviceMessage::Nack`] (tag 3) with
//! [`NackReason::VersionMismatch`] (tag 0: the device's version, then its firmware). A device takes the bootloader
//! request without a handshake, so that no version has to agree first.
//!
//! [`HostMessage::Hello`]: super::HostMessage::Hello
//! [`HostMessage::EnterBootloader`]: super::HostMessage::EnterBootloader
//! [`DeviceMessage::Ack`]: super::DeviceMessage::Ack
//! [`DeviceMessage::Nack`]: super::DeviceMessage::Nack
//! [`NackReason::VersionMismatch`]: super::NackReason::VersionMismatch

use core::fmt;

/// The tag of [`super::HostMessage::EnterBootloader`] on the wire: part of the stable head.
pub const BOOTLOADER_TAG: u32 = 13;

/// ringpod's version this crate was built from (the workspace's: host, core and firmware share it).
pub const BUILT_VERSION: [u16; 3] = [
    parse_u16(env!("CARGO_PKG_VERSION_MAJOR")),
    parse_u16(env!("CARGO_PKG_VERSION_MINOR")),
    parse_u16(env!("CARGO_PKG_VERSION_PATCH")),
];

/// A version part; one that is not a number reads as `u16::MAX`, which fails the build below.
const fn parse_u16(text: &str) -> u16 {
    match u16::from_str_radix(text, 10) {
        Ok(n) => n,
        Err(_) => u16::MAX,
    }
}

const _: () = assert!(
    BUILT_VERSION[0] != u16::MAX && BUILT_VERSION[1] != u16::MAX && BUILT_VERSION[2] != u16::MAX,
    "a part of the crate's version is not a number below 65,535"
);

/// The firmware a device runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Firmware {
    /// ringpod's version it was built from: major, minor, patch.
    pub version: [u16; 3],
    /// The image in its flash; `None` where there is none (the simulated controller).
    pub image: Option<Image>,
}

impl Firmware {
    /// This build's version, without an image (what the simulated controller says).
    pub const BUILT: Firmware = Firmware {
        version: BUILT_VERSION,
        image: None,
    };
}

/// A flashed image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Image {
    /// Its length from the start of flash (bytes).
    pub size: u32,
    /// Its CRC-32C ([`image_crc`]).
    pub crc: u32,
}

impl Image {
    /// The image `bytes` (laid out from the start of flash).
    pub fn of(bytes: &[u8]) -> Image {
        Image {
            size: u32::try_from(bytes.len()).unwrap_or(u32::MAX),
            crc: image_crc(bytes),
        }
    }
}

/// The CRC-32C of an image: the frames' checksum, so that the firmware has it already.
pub fn image_crc(bytes: &[u8]) -> u32 {
    super::frame::crc32c(bytes)
}

impl fmt::Display for Firmware {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [major, minor, patch] = self.version;
        write!(f, "ringpod {major}.{minor}.{patch}")?;
        match self.image {
            Some(image) => write!(f, " (image {} B, CRC-32C {:08x})", image.size, image.crc),
            None => f.write_str(" (no image: simulated)"),
        }
    }
}

/// A device's answer to a hello of another version, read from the stable head alone: the request's id, the
/// device's protocol version and its firmware. `Some((id, version, None))` from a device of protocol 9 or older,
/// which named no firmware; `None` for any other message.
pub fn version_mismatch(payload: &[u8]) -> Option<(u32, u16, Option<Firmware>)> {
    use postcard::take_from_bytes;
    let (id, rest) = take_from_bytes::<u32>(payload).ok()?;
    let (message, rest) = take_from_bytes::<u32>(rest).ok()?;
    let (reason, rest) = take_from_bytes::<u32>(rest).ok()?;
    // DeviceMessage::Nack and NackReason::VersionMismatch.
    if (message, reason) != (3, 0) {
        return None;
    }
    let (version, rest) = take_from_bytes::<u16>(rest).ok()?;
    let firmware = take_from_bytes::<Option<Firmware>>(rest).ok().and_then(|(f, _)| f);
    Some((id, version, firmware))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::protocol::{DeviceMessage, HostMessage, NackReason, Request, Response, PROTOCOL_VERSION};

    fn payload<M: serde::Serialize>(message: &M) -> Vec<u8> {
        let mut buf = [0u8; 64];
        postcard::to_slice(message, &mut buf).unwrap().to_vec()
    }

    #[test]
    fn the_stable_head_keeps_its_places() {
        // Hello: id, tag 0, the version; the bootloader request: id, its tag, nothing else.
        let hello = payload(&Request {
            id: 7,
            body: HostMessage::Hello { version: 300 },
        });
        assert_eq!(hello, [7, 0, 0xAC, 0x02]);
        let enter = payload(&Request {
            id: 7,
            body: HostMessage::EnterBootloader,
        });
        assert_eq!(enter, [7, BOOTLOADER_TAG as u8]);
        assert_eq!(
            payload(&Response {
                id: 7,
                body: DeviceMessage::Ack
            }),
            [7, 1]
        );
    }

    #[test]
    fn a_version_mismatch_is_read_from_any_version() {
        let firmware = Firmware {
            version: [0, 1, 0],
            image: Some(Image {
                size: 195_580,
                crc: 0xDEAD_BEEF,
            }),
        };
        let nack = payload(&Response {
            id: 9,
            body: DeviceMessage::Nack(NackReason::VersionMismatch {
                device: PROTOCOL_VERSION,
                firmware: Some(firmware),
            }),
        });
        assert_eq!(version_mismatch(&nack), Some((9, PROTOCOL_VERSION, Some(firmware))));
        // A device of protocol 9 sent the version alone: id 9, Nack, VersionMismatch, 9.
        assert_eq!(version_mismatch(&[9, 3, 0, 9]), Some((9, 9, None)));
        // Any other answer is not one.
        assert_eq!(
            version_mismatch(&payload(&Response {
                id: 9,
                body: DeviceMessage::Ack
            })),
            None
        );
        let other = payload(&Response {
            id: 9,
            body: DeviceMessage::Nack(NackReason::NotConnected),
        });
        assert_eq!(version_mismatch(&other), None);
        assert_eq!(version_mismatch(&[]), None);
    }

    #[test]
    fn the_image_checksum_is_crc32c() {
        // CRC-32C's check value (the catalogue's "123456789").
        assert_eq!(image_crc(b"123456789"), 0xE306_9283);
        let image = Image::of(&[0xFF; 16]);
        assert_eq!(image.size, 16);
        assert_ne!(image.crc, Image::of(&[0xFF; 17]).crc);
        let [major, minor, patch] = BUILT_VERSION;
        assert_eq!(format!("{major}.{minor}.{patch}"), env!("CARGO_PKG_VERSION"));
        let shown = Firmware {
            version: [0, 1, 0],
            image: Some(Image {
                size: 195_580,
                crc: 0xAB,
            }),
        };
        assert_eq!(shown.to_string(), "ringpod 0.1.0 (image 195580 B, CRC-32C 000000ab)");
    }
}

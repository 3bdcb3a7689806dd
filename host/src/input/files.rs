//! Reading the text files a user names: bounded, so that `/dev/zero`, a log grown for a month or a disk image given
//! by mistake is an error in a second instead of gigabytes of memory and the kernel's out-of-memory killer.

use std::io::Read;
use std::path::Path;

/// The most a data file (poses, telemetry, a run record) may hold: about 3 hours of 1 kHz poses with room to spare.
pub const DATA_LIMIT: u64 = 256 << 20;
/// The most a settings file (a rig, a washout configuration) may hold: a rig file is a few kilobytes.
pub const CONFIG_LIMIT: u64 = 1 << 20;

/// The text of the file at `path`, at most `limit` bytes, or why not, without the path: the callers name the file
/// in their own way (a rig error's key, a command's option).
pub fn read_text(path: &Path, limit: u64) -> Result<String, String> {
    as_text(read_bytes(path, limit)?)
}

/// Bytes read as UTF-8 text, or where they are not.
pub fn as_text(bytes: Vec<u8>) -> Result<String, String> {
    String::from_utf8(bytes).map_err(|e| format!("not UTF-8 text (byte {} is not)", e.utf8_error().valid_up_to() + 1))
}

/// Opens `path` to read, without waiting: on Unix non-blocking, so that a FIFO with no writer does not hold the
/// caller in `open` (where no signal reaches a command's loop), and a FIFO or socket is then refused: a file
/// named where a file is read must be one that ends. A device reads as a file does (`/dev/zero` up to the limit).
pub fn open(path: &Path) -> Result<std::fs::File, String> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(nix::libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(|e| e.to_string())?;
    let kind = file.metadata().map_err(|e| e.to_string())?.file_type();
    if kind.is_dir() {
        return Err("is a directory, not a file".into());
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() || kind.is_socket() {
            return Err("is a FIFO (named pipe) or a socket, not a file: it may never end, or never begin".into());
        }
    }
    Ok(file)
}

/// The bytes of the file at `path` (a packet capture), at most `limit`, or why not, without the path.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    read_open(open(path)?, limit)
}

/// The bytes of an open file, at most `limit`, or why not.
pub fn read_open(file: std::fs::File, limit: u64) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    // One byte more than allowed tells "too large" from "exactly the limit".
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(format!(
            "larger than {} MiB: not a file of this kind (or split it)",
            limit >> 20
        ));
    }
    Ok(bytes)
}

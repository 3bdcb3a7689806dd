//! The games' named file mappings, opened read-only (`OpenFileMappingW` with `FILE_MAP_READ`, then
//! `MapViewOfFile` of the whole section) and copied with volatile reads: the game writes them while ringpod reads,
//! so no read may be assumed to see a stable value (the torn-read checks of [`super::poll`] decide what is whole).
//!
//! A mapping that is not there (the game not running, the plugin not installed) is looked for again every
//! [`RETRY`]; once open it stays open, so a game that closes and starts again writes into the same section (the
//! poller sees its counter stand still meanwhile: a stall).

use std::time::{Duration, Instant};

use windows_sys::Win32::Foundation::{CloseHandle, HANDLE};
use windows_sys::Win32::System::Memory::{
    MapViewOfFile, OpenFileMappingW, UnmapViewOfFile, VirtualQuery, FILE_MAP_READ, MEMORY_BASIC_INFORMATION,
    MEMORY_MAPPED_VIEW_ADDRESS,
};

use super::{Absent, Game, Memory};

/// How often a missing mapping is looked for.
pub const RETRY: Duration = Duration::from_millis(500);

/// One open mapping and its view.
struct View {
    handle: HANDLE,
    view: MEMORY_MAPPED_VIEW_ADDRESS,
    /// The view's length: the section's size, rounded up to whole pages.
    len: usize,
}

// The view is read-only memory of this process, released once by `Drop`; reading it needs no thread affinity.
unsafe impl Send for View {}

fn wide(name: &str) -> Vec<u16> {
    name.encode_utf16().chain(std::iter::once(0)).collect()
}

impl View {
    /// Opens `name` read-only and maps all of it, or `None` when it is not there.
    fn open(name: &str) -> Option<Self> {
        let name = wide(name);
        // SAFETY: a NUL-terminated name; the handle is checked.
        let handle = unsafe { OpenFileMappingW(FILE_MAP_READ, 0, name.as_ptr()) };
        if handle.is_null() {
            return None;
        }
        // SAFETY: an open section handle with read access; the whole section is mapped.
        let view = unsafe { MapViewOfFile(handle, FILE_MAP_READ, 0, 0, 0) };
        if view.Value.is_null() {
            // SAFETY: the handle is ours and open.
            unsafe { CloseHandle(handle) };
            return None;
        }
        // SAFETY: `info` is written by the call, whose length argument is its size.
        let mut info: MEMORY_BASIC_INFORMATION = unsafe { std::mem::zeroed() };
        let got = unsafe { VirtualQuery(view.Value, &mut info, std::mem::size_of::<MEMORY_BASIC_INFORMATION>()) };
        let len = if got == 0 { 0 } else { info.RegionSize };
        Some(Self { handle, view, len })
    }

    /// Copies `out.len()` bytes at `at`, or `false` past the view's end.
    fn read(&self, at: usize, out: &mut [u8]) -> bool {
        if at.checked_add(out.len()).is_none_or(|end| end > self.len) {
            return false;
        }
        let base = self.view.Value.cast::<u8>().cast_const();
        let mut i = 0;
        while i < out.len() {
            // SAFETY: `at + i` is inside the view (checked above), which lives as long as `self`; volatile, because
            // the game writes it concurrently. Whole words where aligned, bytes elsewhere.
            unsafe {
                let p = base.add(at + i);
                if (p as usize).is_multiple_of(8) && out.len() - i >= 8 {
                    let word = p.cast::<u64>().read_volatile();
                    out[i..i + 8].copy_from_slice(&word.to_ne_bytes());
                    i += 8;
                } else {
                    out[i] = p.read_volatile();
                    i += 1;
                }
            }
        }
        true
    }
}

impl Drop for View {
    fn drop(&mut self) {
        // SAFETY: both were opened by `open` and are released once.
        unsafe {
            UnmapViewOfFile(self.view);
            CloseHandle(self.handle);
        }
    }
}

/// A game's mappings, opened when they appear.
pub struct Mappings {
    names: &'static [&'static str],
    views: Vec<Option<View>>,
    /// When each missing mapping was last looked for.
    looked: Vec<Option<Instant>>,
}

impl Mappings {
    /// `game`'s mappings, none open yet.
    pub fn new(game: Game) -> Self {
        Self::named(game.mappings())
    }

    /// The mappings of these names (a game's, in its order), none open yet.
    pub fn named(names: &'static [&'static str]) -> Self {
        Self {
            names,
            views: names.iter().map(|_| None).collect(),
            looked: names.iter().map(|_| None).collect(),
        }
    }

    fn view(&mut self, page: usize) -> Option<&View> {
        let missing = self.views.get(page)?.is_none();
        if missing && self.looked[page].is_none_or(|t| t.elapsed() >= RETRY) {
            self.looked[page] = Some(Instant::now());
            self.views[page] = View::open(self.names[page]);
        }
        self.views[page].as_ref()
    }
}

impl Memory for Mappings {
    fn read(&mut self, page: usize, at: usize, out: &mut [u8]) -> Result<(), Absent> {
        match self.view(page) {
            Some(view) if view.read(at, out) => Ok(()),
            _ => Err(Absent),
        }
    }
}

#[cfg(test)]
mod tests;

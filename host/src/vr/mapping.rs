//! A named file mapping backed by the paging file, created and written: the shared memory that motion software and
//! games publish and their readers open. `--motion-compensation` writes its pose in one; the games' stand-ins (the
//! shared-memory tests of `crate::games::shm` and the `shm_games` test program, which includes this file by `#[path]`
//! since the host is a binary crate) write a game's layout in theirs. Self-contained for that reason: it names
//! nothing of the crate that includes it.

use windows_sys::Win32::Foundation::{CloseHandle, HANDLE, INVALID_HANDLE_VALUE};
use windows_sys::Win32::System::Memory::{
    CreateFileMappingW, MapViewOfFile, UnmapViewOfFile, FILE_MAP_ALL_ACCESS, MEMORY_MAPPED_VIEW_ADDRESS, PAGE_READWRITE,
};

/// An open mapping and its view.
pub struct Mapping {
    handle: HANDLE,
    view: MEMORY_MAPPED_VIEW_ADDRESS,
    /// The bytes asked for (a section is whole pages, at least this).
    len: usize,
}

// The view is process memory owned by this value; only `&mut self` writes it.
unsafe impl Send for Mapping {}

impl Mapping {
    /// Creates `name` of `len` bytes, zeros (or opens it when it exists, as a reader or a previous writer left it),
    /// and maps all of it.
    pub fn create(name: &str, len: usize) -> std::io::Result<Self> {
        let size = len as u64;
        let name: Vec<u16> = name.encode_utf16().chain(std::iter::once(0)).collect();
        // SAFETY: a paging-file-backed section with a NUL-terminated name, its size split into its high and low
        // words; the handle is checked.
        let handle = unsafe {
            CreateFileMappingW(
                INVALID_HANDLE_VALUE,
                std::ptr::null(),
                PAGE_READWRITE,
                (size >> 32) as u32,
                size as u32,
                name.as_ptr(),
            )
        };
        if handle.is_null() {
            return Err(std::io::Error::last_os_error());
        }
        // SAFETY: the handle is a section of at least `len` bytes (or one that exists: mapped whole).
        let view = unsafe { MapViewOfFile(handle, FILE_MAP_ALL_ACCESS, 0, 0, 0) };
        if view.Value.is_null() {
            let e = std::io::Error::last_os_error();
            // SAFETY: the handle is ours and open.
            unsafe { CloseHandle(handle) };
            return Err(e);
        }
        Ok(Self { handle, view, len })
    }

    /// Writes `bytes` at `at`, or nothing and `false` when they would end past the `len` bytes asked for. Readers
    /// copy without a lock unless the layout has a counter of its own, so one copy is as close to atomic as the
    /// layout allows.
    pub fn write(&mut self, at: usize, bytes: &[u8]) -> bool {
        if at.checked_add(bytes.len()).is_none_or(|end| end > self.len) {
            return false;
        }
        // SAFETY: inside the first `len` bytes of the view (checked above), which is mapped writable and lives as
        // long as `self`.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), self.view.Value.cast::<u8>().add(at), bytes.len()) };
        true
    }
}

impl Drop for Mapping {
    fn drop(&mut self) {
        // SAFETY: both were created by `create` and are released once.
        unsafe {
            UnmapViewOfFile(self.view);
            CloseHandle(self.handle);
        }
    }
}

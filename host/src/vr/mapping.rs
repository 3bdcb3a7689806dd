//! A named file mapping backed by the paging file: the shared memory that motion software and its readers use.

use windows_sys::Win32::Foundation::{CloseHandle, HANDLE, INVALID_HANDLE_VALUE};
use windows_sys::Win32::System::Memory::{
    CreateFileMappingW, MapViewOfFile, UnmapViewOfFile, FILE_MAP_ALL_ACCESS, MEMORY_MAPPED_VIEW_ADDRESS, PAGE_READWRITE,
};

/// The mapping's size: one page. The pose takes 48 bytes; readers that map a larger fixed view (up to a page) find
/// it too, and a section is page-sized whatever is asked.
pub const SIZE: usize = 4096;

/// An open mapping and its view.
pub struct Mapping {
    handle: HANDLE,
    view: MEMORY_MAPPED_VIEW_ADDRESS,
}

// The view is process memory owned by this value; only `&mut self` writes it.
unsafe impl Send for Mapping {}

fn wide(name: &str) -> Vec<u16> {
    name.encode_utf16().chain(std::iter::once(0)).collect()
}

impl Mapping {
    /// Creates `name` (or opens it when it exists) and maps all of it.
    pub fn create(name: &str) -> std::io::Result<Self> {
        let name = wide(name);
        // SAFETY: a paging-file-backed section with a NUL-terminated name; the handle is checked.
        let handle = unsafe {
            CreateFileMappingW(
                INVALID_HANDLE_VALUE,
                std::ptr::null(),
                PAGE_READWRITE,
                0,
                SIZE as u32,
                name.as_ptr(),
            )
        };
        if handle.is_null() {
            return Err(std::io::Error::last_os_error());
        }
        // SAFETY: the handle is a section of at least SIZE bytes (or one that exists: mapped whole, then checked).
        let view = unsafe { MapViewOfFile(handle, FILE_MAP_ALL_ACCESS, 0, 0, 0) };
        if view.Value.is_null() {
            let e = std::io::Error::last_os_error();
            // SAFETY: the handle is ours and open.
            unsafe { CloseHandle(handle) };
            return Err(e);
        }
        Ok(Self { handle, view })
    }

    /// Writes `bytes` at the start of the view. Readers copy without a lock (the layout has no sequence number), so
    /// one copy of 48 bytes is as close to atomic as the layout allows.
    pub fn write(&mut self, bytes: &[u8]) {
        let n = bytes.len().min(SIZE);
        // SAFETY: the view is at least SIZE bytes, mapped writable, and lives as long as `self`.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), self.view.Value.cast::<u8>(), n) };
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

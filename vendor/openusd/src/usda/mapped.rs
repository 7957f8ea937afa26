//! A usda file's text mapped from disk, whose pages the parser has passed are given back
//! (ppis patch, see PATCHED.md, "A usda file's text given back as it is parsed").
//!
//! A layer's text is held whole while the layer is parsed, so at the end of parsing the
//! process holds both: for a layer of many small prims the text is a third or more of
//! that peak. Mapped privately and read-only, the text's pages are the file's, and
//! `madvise(MADV_DONTNEED)` drops the ones the parser has passed from the process without
//! changing what they read: a page touched again (a name the parser keeps a slice of, an
//! error's line) is read back from the file as it was.
//!
//! As for every mapped file, the text is what the file holds while it is parsed: a file
//! rewritten or truncated by another process meanwhile is read as it then is (the parser
//! bounds every read by the text's length, and a truncated mapping's pages raise SIGBUS).

use std::fs::File;
use std::io;
use std::os::fd::AsRawFd;

use anyhow::{anyhow, Result};

use super::parser::RELEASE_STEP;

/// A file mapped read-only and private, unmapped when dropped.
pub struct MappedText {
    ptr: *mut libc::c_void,
    len: usize,
}

// The mapping is read-only and its pages are only read or dropped (`madvise`), which any
// thread may do.
unsafe impl Send for MappedText {}
unsafe impl Sync for MappedText {}

impl MappedText {
    /// Maps `file`, or `None` if it is empty or cannot be mapped (a pipe, a device): such
    /// a file is read instead.
    pub fn map(file: &File) -> io::Result<Option<Self>> {
        let meta = file.metadata()?;
        let Ok(len) = usize::try_from(meta.len()) else { return Ok(None) };
        if !meta.is_file() || len == 0 {
            return Ok(None);
        }
        // SAFETY: a fresh private read-only mapping of `len` bytes of an open file; the
        // result is checked before use.
        let ptr =
            unsafe { libc::mmap(std::ptr::null_mut(), len, libc::PROT_READ, libc::MAP_PRIVATE, file.as_raw_fd(), 0) };
        if ptr == libc::MAP_FAILED {
            return Ok(None);
        }
        Ok(Some(Self { ptr, len }))
    }

    /// The file's bytes.
    fn bytes(&self) -> &[u8] {
        // SAFETY: `ptr` maps `len` readable bytes for as long as `self` lives.
        unsafe { std::slice::from_raw_parts(self.ptr as *const u8, self.len) }
    }

    /// The text, checked to be UTF-8 a step at a time, each step's pages given back once
    /// checked, so the check does not leave the whole file resident.
    pub fn text(&self) -> Result<&str> {
        let bytes = self.bytes();
        let mut start = 0;
        while start < bytes.len() {
            let end = (start + RELEASE_STEP).min(bytes.len());
            start = match std::str::from_utf8(&bytes[start..end]) {
                Ok(_) => end,
                // A character cut by the step's end is checked with the next step.
                Err(e) if e.error_len().is_none() && end < bytes.len() => start + e.valid_up_to(),
                Err(e) => return Err(not_utf8(start + e.valid_up_to(), e.error_len())),
            };
            self.release_before(start);
        }
        // SAFETY: every byte was checked above, and the mapping's bytes do not change
        // while it lives (see the module's note on files changed meanwhile).
        Ok(unsafe { std::str::from_utf8_unchecked(bytes) })
    }

    /// Drops from the process the whole pages that lie before `offset`. Their bytes
    /// stay as they were: a page read again is read back from the file.
    pub fn release_before(&self, offset: usize) {
        let page = page_size();
        let end = offset.min(self.len) / page * page;
        if end > 0 {
            // SAFETY: `[ptr, ptr + end)` lies in the mapping and starts at its
            // page-aligned base; MADV_DONTNEED on a private mapping never written to
            // leaves its contents as the file's.
            unsafe { libc::madvise(self.ptr, end, libc::MADV_DONTNEED) };
        }
    }
}

impl Drop for MappedText {
    fn drop(&mut self) {
        // SAFETY: `ptr` and `len` are the mapping `map` made, unmapped once.
        unsafe { libc::munmap(self.ptr, self.len) };
    }
}

/// The error a whole read's UTF-8 check gives, at the byte it names.
fn not_utf8(at: usize, error_len: Option<usize>) -> anyhow::Error {
    let cause = match error_len {
        Some(n) => anyhow!("invalid utf-8 sequence of {n} bytes from index {at}"),
        None => anyhow!("incomplete utf-8 byte sequence from index {at}"),
    };
    cause.context("layer is not valid UTF-8")
}

fn page_size() -> usize {
    // SAFETY: sysconf reads a constant of the system.
    let size = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    usize::try_from(size).ok().filter(|&s| s > 0).unwrap_or(4096)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_tempdir as tempfile;
    use std::io::Write;

    fn mapped(bytes: &[u8]) -> (tempfile::TempDir, File) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.usda");
        std::fs::File::create(&path).unwrap().write_all(bytes).unwrap();
        let file = File::open(&path).unwrap();
        (dir, file)
    }

    #[test]
    fn released_pages_read_back_as_they_were() {
        // Characters of 1 to 4 bytes, cut by every step's end somewhere.
        let text: String = "aé€😀\n".repeat(3 * RELEASE_STEP / 11 + 17);
        let (_dir, file) = mapped(text.as_bytes());
        let map = MappedText::map(&file).unwrap().expect("a regular file maps");
        let read = map.text().unwrap();
        map.release_before(read.len());
        assert_eq!(read, text, "every page is read back from the file");
    }

    #[test]
    fn invalid_utf8_is_refused_wherever_it_lies() {
        // A character begun at a step's end and never ended, a byte no character has in
        // a later step, and a character cut by the file's end.
        for (at, byte) in [(RELEASE_STEP - 1, 0xE2), (RELEASE_STEP + 3, 0xFF), (RELEASE_STEP + 4, 0xE2)] {
            let mut bytes = "x".repeat(RELEASE_STEP + 5).into_bytes();
            bytes[at] = byte;
            let (_dir, file) = mapped(&bytes);
            let map = MappedText::map(&file).unwrap().unwrap();
            let err = format!("{:#}", map.text().unwrap_err());
            let whole = String::from_utf8(bytes).unwrap_err();
            assert_eq!(err, format!("layer is not valid UTF-8: {whole}"), "as a whole read says");
        }
    }

    #[test]
    fn an_empty_file_is_not_mapped() {
        let (_dir, file) = mapped(b"");
        assert!(MappedText::map(&file).unwrap().is_none());
    }
}

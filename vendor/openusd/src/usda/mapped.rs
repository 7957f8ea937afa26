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
//! A layer stored unpacked in a usdz is a range of the package file, mapped the same way
//! (the mapping starts at the page holding the range's first byte), and its bytes are
//! checked against the entry's CRC-32 as they are checked to be UTF-8, as the zip reader
//! checks them when it reads the entry.
//!
//! As for every mapped file, the text is what the file holds while it is parsed: a file
//! rewritten or truncated by another process meanwhile is read as it then is (the parser
//! bounds every read by the text's length, and a truncated mapping's pages raise SIGBUS).

use std::io;
use std::os::fd::AsRawFd;

use anyhow::{anyhow, Result};

use super::parser::RELEASE_STEP;
use crate::ar::{self, FileRegion};


/// A file's text mapped read-only and private, unmapped when dropped.
pub struct MappedText {
    /// The mapping's page-aligned start.
    ptr: *mut libc::c_void,
    /// The mapping's length.
    map_len: usize,
    /// Where the text starts in the mapping (within its first page).
    start: usize,
    /// The text's length.
    len: usize,
    /// The CRC-32 the text's bytes must have, if one is recorded.
    crc32: Option<u32>,
}

// The mapping is read-only and its pages are only read or dropped (`madvise`), which any
// thread may do.
unsafe impl Send for MappedText {}
unsafe impl Sync for MappedText {}

impl MappedText {
    /// Maps `region`, or `None` if it is empty, lies past its file's end or cannot be
    /// mapped (a pipe, a device): such a text is read instead.
    pub fn map(region: FileRegion<'_>) -> io::Result<Option<Self>> {
        let meta = region.file.metadata()?;
        let file_len = meta.len();
        let len = region.len.unwrap_or(file_len.saturating_sub(region.offset));
        let end = region.offset.checked_add(len);
        if !meta.is_file() || len == 0 || end.is_none_or(|end| end > file_len) {
            return Ok(None);
        }
        let page = page_size() as u64;
        let base = region.offset / page * page;
        let (Ok(start), Ok(len), Ok(map_len), Ok(base_offset)) = (
            usize::try_from(region.offset - base),
            usize::try_from(len),
            usize::try_from(region.offset - base + len),
            libc::off_t::try_from(base),
        ) else {
            return Ok(None);
        };
        // SAFETY: a fresh private read-only mapping of `map_len` bytes of an open file from
        // a page-aligned offset; the result is checked before use.
        let ptr = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                map_len,
                libc::PROT_READ,
                libc::MAP_PRIVATE,
                region.file.as_raw_fd(),
                base_offset,
            )
        };
        if ptr == libc::MAP_FAILED {
            return Ok(None);
        }
        Ok(Some(Self { ptr, map_len, start, len, crc32: region.crc32 }))
    }

    /// The text's bytes.
    fn bytes(&self) -> &[u8] {
        // SAFETY: `ptr` maps `map_len` readable bytes for as long as `self` lives, and the
        // text's `len` bytes from `start` lie within them.
        unsafe { std::slice::from_raw_parts((self.ptr as *const u8).add(self.start), self.len) }
    }

    /// The text, checked to be UTF-8 (and against its CRC-32, if it has one) a step at a
    /// time, each step's pages given back once checked, so the check does not leave the
    /// whole text resident.
    pub fn text(&self) -> Result<&str> {
        let bytes = self.bytes();
        let mut crc = self.crc32.map(|_| crc32fast::Hasher::new());
        let mut start = 0;
        let mut hashed = 0;
        while start < bytes.len() {
            let end = (start + RELEASE_STEP).min(bytes.len());
            if let Some(crc) = &mut crc {
                crc.update(&bytes[hashed..end]);
                hashed = end;
            }
            start = match std::str::from_utf8(&bytes[start..end]) {
                Ok(_) => end,
                // A character cut by the step's end is checked with the next step.
                Err(e) if e.error_len().is_none() && end < bytes.len() => start + e.valid_up_to(),
                // The zip reader checks the whole entry's CRC-32 before anything reads it.
                Err(e) => return Err(self.check_rest(crc, hashed).unwrap_or_else(|| not_utf8(start + e.valid_up_to(), e.error_len()))),
            };
            self.release_before(start);
        }
        if let Some(e) = self.check_rest(crc, hashed) {
            return Err(e);
        }
        // SAFETY: every byte was checked above, and the mapping's bytes do not change
        // while it lives (see the module's note on files changed meanwhile).
        Ok(unsafe { std::str::from_utf8_unchecked(bytes) })
    }

    /// Hashes the text's bytes from `hashed` on into `crc`, a step at a time, and gives the
    /// zip reader's error if the whole does not match the recorded CRC-32.
    fn check_rest(&self, crc: Option<crc32fast::Hasher>, mut hashed: usize) -> Option<anyhow::Error> {
        let (mut crc, expected) = crc.zip(self.crc32)?;
        let bytes = self.bytes();
        while hashed < bytes.len() {
            let end = (hashed + RELEASE_STEP).min(bytes.len());
            crc.update(&bytes[hashed..end]);
            hashed = end;
            self.release_before(hashed);
        }
        (crc.finalize() != expected).then(|| ar::invalid_checksum().into())
    }

    /// Drops from the process the whole pages that lie before the text's byte `offset`.
    /// Their bytes stay as they were: a page read again is read back from the file.
    pub fn release_before(&self, offset: usize) {
        let page = page_size();
        let end = (self.start + offset.min(self.len)) / page * page;
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
        // SAFETY: `ptr` and `map_len` are the mapping `map` made, unmapped once.
        unsafe { libc::munmap(self.ptr, self.map_len) };
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
    use std::fs::File;
    use std::io::Write;

    fn mapped(bytes: &[u8]) -> (tempfile::TempDir, File) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.usda");
        std::fs::File::create(&path).unwrap().write_all(bytes).unwrap();
        let file = File::open(&path).unwrap();
        (dir, file)
    }

    fn whole(file: &File) -> FileRegion<'_> {
        FileRegion { file, offset: 0, len: None, crc32: None }
    }

    #[test]
    fn released_pages_read_back_as_they_were() {
        // Characters of 1 to 4 bytes, cut by every step's end somewhere.
        let text: String = "aé€😀\n".repeat(3 * RELEASE_STEP / 11 + 17);
        let (_dir, file) = mapped(text.as_bytes());
        let map = MappedText::map(whole(&file)).unwrap().expect("a regular file maps");
        let read = map.text().unwrap();
        map.release_before(read.len());
        assert_eq!(read, text, "every page is read back from the file");
    }

    #[test]
    fn a_range_of_a_file_maps_from_any_offset() {
        let text: String = "aé€😀\n".repeat(RELEASE_STEP / 5);
        let mut package = b"header bytes".repeat(1000);
        let offset = package.len() as u64;
        package.extend_from_slice(text.as_bytes());
        package.extend_from_slice(b"trailer");
        let (_dir, file) = mapped(&package);
        let (len, crc32) = (Some(text.len() as u64), Some(crc32fast::hash(text.as_bytes())));
        let map = MappedText::map(FileRegion { file: &file, offset, len, crc32 }).unwrap().unwrap();
        let read = map.text().unwrap();
        map.release_before(read.len());
        assert_eq!(read, text);

        let crc32 = crc32.map(|c| c ^ 1);
        let map = MappedText::map(FileRegion { file: &file, offset, len, crc32 }).unwrap().unwrap();
        assert_eq!(format!("{:#}", map.text().unwrap_err()), "Invalid checksum", "as the zip reader says");

        let past_the_end = Some(package.len() as u64 - offset + 1);
        assert!(MappedText::map(FileRegion { file: &file, offset, len: past_the_end, crc32 }).unwrap().is_none());
    }

    #[test]
    fn invalid_utf8_is_refused_wherever_it_lies() {
        // A character begun at a step's end and never ended, a byte no character has in
        // a later step, and a character cut by the file's end.
        for (at, byte) in [(RELEASE_STEP - 1, 0xE2), (RELEASE_STEP + 3, 0xFF), (RELEASE_STEP + 4, 0xE2)] {
            let mut bytes = "x".repeat(RELEASE_STEP + 5).into_bytes();
            bytes[at] = byte;
            let (_dir, file) = mapped(&bytes);
            let map = MappedText::map(whole(&file)).unwrap().unwrap();
            let err = format!("{:#}", map.text().unwrap_err());
            let whole = String::from_utf8(bytes.clone()).unwrap_err();
            assert_eq!(err, format!("layer is not valid UTF-8: {whole}"), "as a whole read says");

            // With a CRC-32, a mismatch is reported first, as the zip reader reads the
            // entry before its text is checked; a match leaves the UTF-8 error.
            let crc32 = crc32fast::hash(&bytes);
            for (crc32, expected) in [(crc32 ^ 1, "Invalid checksum".to_string()), (crc32, err)] {
                let region = FileRegion { file: &file, offset: 0, len: None, crc32: Some(crc32) };
                let map = MappedText::map(region).unwrap().unwrap();
                assert_eq!(format!("{:#}", map.text().unwrap_err()), expected);
            }
        }
    }

    #[test]
    fn an_empty_file_is_not_mapped() {
        let (_dir, file) = mapped(b"");
        assert!(MappedText::map(whole(&file)).unwrap().is_none());
    }
}

//! A package's entry stored as it is (ppis patch, see PATCHED.md, "A packaged usda layer
//! parsed in place").
//!
//! A usdz stores its files unpacked (zip method "stored"), so an entry's bytes are a range
//! of the package file. The asset names that range ([`Asset::file_region`]), so a reader
//! may map it rather than copy it, and reads it only when asked for bytes, checking the
//! entry's CRC-32 as the zip reader does.

use std::fs;
use std::io::{self, Read, Seek, SeekFrom};

use super::Asset;

/// Where an asset's bytes lie in a file, for a reader that maps them rather than read them.
pub struct FileRegion<'a> {
    /// The file holding the bytes.
    pub file: &'a fs::File,
    /// Where the bytes start in the file.
    pub offset: u64,
    /// How many bytes there are; `None` reaches to the file's end.
    pub len: Option<u64>,
    /// The CRC-32 the bytes must have (a zip entry's), `None` if none is recorded.
    pub crc32: Option<u32>,
}

/// The error the zip reader gives for an entry whose bytes do not match its CRC-32.
pub fn invalid_checksum() -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, "Invalid checksum")
}

/// An entry stored unpacked at `offset..offset + len` of its package file.
pub struct StoredEntry {
    file: fs::File,
    offset: u64,
    len: u64,
    crc32: u32,
    /// The entry's bytes once something reads them.
    bytes: Option<io::Cursor<Vec<u8>>>,
}

impl StoredEntry {
    /// The entry at `offset..offset + len` of `file`, whose bytes must have CRC-32 `crc32`.
    pub fn new(file: fs::File, offset: u64, len: u64, crc32: u32) -> Self {
        Self { file, offset, len, crc32, bytes: None }
    }

    /// The entry's bytes, read and checked on first use.
    fn bytes(&mut self) -> io::Result<&mut io::Cursor<Vec<u8>>> {
        if self.bytes.is_none() {
            let capacity = usize::try_from(self.len).map_err(|_| io::Error::from(io::ErrorKind::OutOfMemory))?;
            let mut buffer = Vec::with_capacity(capacity);
            self.file.seek(SeekFrom::Start(self.offset))?;
            (&self.file).take(self.len).read_to_end(&mut buffer)?;
            if crc32fast::hash(&buffer) != self.crc32 {
                return Err(invalid_checksum());
            }
            self.bytes = Some(io::Cursor::new(buffer));
        }
        Ok(self.bytes.as_mut().expect("read above"))
    }
}

impl Read for StoredEntry {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.bytes()?.read(buf)
    }
}

impl Seek for StoredEntry {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.bytes()?.seek(pos)
    }
}

impl Asset for StoredEntry {
    fn size(&self) -> io::Result<u64> {
        Ok(self.len)
    }

    fn read_all(&mut self) -> io::Result<Vec<u8>> {
        self.bytes()?.read_all()
    }

    fn file_region(&self) -> Option<FileRegion<'_>> {
        let (file, offset, len, crc32) = (&self.file, self.offset, Some(self.len), Some(self.crc32));
        Some(FileRegion { file, offset, len, crc32 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_tempdir as tempfile;
    use std::io::Write;

    fn entry(package: &[u8], offset: u64, stored: &[u8]) -> (tempfile::TempDir, StoredEntry) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.usdz");
        fs::File::create(&path).unwrap().write_all(package).unwrap();
        let file = fs::File::open(&path).unwrap();
        let entry = StoredEntry::new(file, offset, stored.len() as u64, crc32fast::hash(stored));
        (dir, entry)
    }

    #[test]
    fn reads_its_range_of_the_package() {
        let (_dir, mut e) = entry(b"headerTEXTtrailer", 6, b"TEXT");
        assert_eq!(e.size().unwrap(), 4);
        let region = e.file_region().unwrap();
        assert_eq!((region.offset, region.len), (6, Some(4)));
        let mut two = [0; 2];
        e.seek(SeekFrom::Start(1)).unwrap();
        e.read_exact(&mut two).unwrap();
        assert_eq!(&two, b"EX");
        assert_eq!(e.read_all().unwrap(), b"T", "from the position on");
    }

    #[test]
    fn a_checksum_mismatch_is_the_zip_readers_error() {
        let (_dir, mut e) = entry(b"headerTEXTtrailer", 6, b"TEXt");
        let err = e.read_all().unwrap_err();
        assert_eq!((err.kind(), err.to_string()), (io::ErrorKind::InvalidData, "Invalid checksum".into()));
    }
}

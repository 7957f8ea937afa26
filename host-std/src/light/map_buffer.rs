//! Storage for the environment's texels and pyramids, placed for the random reads of sampling.
//! Every light sample reads a few of their values at scattered places (a descent's nodes level
//! by level, a texel's radiance and density), so two things decide what each read costs
//! besides the caches: the address translation, and how many cache lines a read spans.
//! - The buffers (megabytes for a 1024² map) span more 4 KiB pages than the TLB holds, so most
//!   reads would also walk the page tables; the buffers ask the kernel for 2 MiB pages
//!   (`madvise(MADV_HUGEPAGE)` before they are first written, where the kernel leaves that to
//!   each mapping; a hint only).
//! - A descent reads a node's sixteen grandchildren at once (64 bytes). In the pyramid's packed
//!   layout every level from the second on starts 5 values past a multiple of 16, so the buffer
//!   starts 11 values past a 64-byte line and each block of sixteen fills one line instead of
//!   spanning two.
//!
//! Neither changes a value: the buffer reads as the slice it holds.

use std::ops::{Deref, DerefMut};

/// Bytes of a cache line.
const LINE: usize = 64;
/// Bytes of a huge page.
const HUGE_PAGE: usize = 2 << 20;

/// A slice of `T`s, zero-initialised, whose element `first_aligned` starts a cache line, in
/// memory the kernel is asked to back with huge pages.
pub struct MapBuffer<T: Copy + Default> {
    storage: Vec<T>,
    start: usize,
    len: usize,
    first_aligned: usize,
}

impl<T: Copy + Default> MapBuffer<T> {
    /// `len` default values, value `first_aligned` at the start of a cache line.
    #[must_use]
    pub fn new(len: usize, first_aligned: usize) -> Self {
        let size = size_of::<T>().max(1);
        // Room to move the start by up to a line and, for a buffer of huge pages, to begin and
        // end on their boundaries (only whole huge pages inside the mapping get one).
        let huge = len * size >= HUGE_PAGE;
        let spare = if huge { (LINE + 2 * HUGE_PAGE).div_ceil(size) } else { LINE.div_ceil(size) };
        let mut storage: Vec<T> = Vec::with_capacity(len + spare);
        if huge {
            advise_huge_pages(storage.as_ptr().cast(), storage.capacity() * size);
        }
        storage.resize(len + spare, T::default());
        let base = storage.as_ptr() as usize;
        let from = if huge { base.next_multiple_of(HUGE_PAGE) } else { base };
        // The first index from there whose value `first_aligned` starts a line.
        let mut start = (from - base) / size;
        while start < spare && !(base + (start + first_aligned) * size).is_multiple_of(LINE) {
            start += 1;
        }
        let start = if start < spare { start } else { 0 };
        Self { storage, start, len, first_aligned }
    }

    /// A buffer holding a copy of `values`.
    #[must_use]
    pub fn from_slice(values: &[T], first_aligned: usize) -> Self {
        let mut out = Self::new(values.len(), first_aligned);
        out.copy_from_slice(values);
        out
    }
}

/// The pyramid's first value of a level from the second on, modulo a line of f32s: aligning it
/// makes every block of sixteen grandchildren one cache line.
pub const PYRAMID_LINE_START: usize = 5;

impl<T: Copy + Default> Deref for MapBuffer<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.storage[self.start..self.start + self.len]
    }
}

impl<T: Copy + Default> DerefMut for MapBuffer<T> {
    fn deref_mut(&mut self) -> &mut [T] {
        &mut self.storage[self.start..self.start + self.len]
    }
}

impl<T: Copy + Default> Clone for MapBuffer<T> {
    fn clone(&self) -> Self {
        Self::from_slice(self, self.first_aligned)
    }
}

impl<T: Copy + Default + std::fmt::Debug> std::fmt::Debug for MapBuffer<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MapBuffer").field("len", &self.len).finish_non_exhaustive()
    }
}

/// Asks for huge pages over the whole pages of `bytes` bytes at `ptr`, not yet written.
fn advise_huge_pages(ptr: *const u8, bytes: usize) {
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        let (begin, end) = ((ptr as usize).next_multiple_of(PAGE), (ptr as usize + bytes) / PAGE * PAGE);
        if end >= begin + HUGE_PAGE {
            // SAFETY: the range lies inside one live allocation of ours; the advice changes no
            // contents and its failure (a kernel without transparent huge pages) is harmless.
            unsafe { libc::madvise(begin as *mut libc::c_void, end - begin, libc::MADV_HUGEPAGE) };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (ptr, bytes);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_as_its_values_with_the_asked_value_on_a_line() {
        for len in [0usize, 1, 21, 5461, 1 << 20] {
            let values: Vec<f32> = (0..len).map(|i| i as f32).collect();
            let b = MapBuffer::from_slice(&values, PYRAMID_LINE_START);
            assert_eq!(&*b, &values[..]);
            assert_eq!((b.as_ptr() as usize + 4 * PYRAMID_LINE_START) % LINE, 0);
            let c = b.clone();
            assert_eq!((&*c, (c.as_ptr() as usize + 4 * PYRAMID_LINE_START) % LINE), (&values[..], 0));
        }
        let rgb = MapBuffer::<[f32; 3]>::new(100, 0);
        assert!(rgb.iter().all(|t| *t == [0.0; 3]));
    }
}

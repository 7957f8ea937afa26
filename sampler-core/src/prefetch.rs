//! A hint to the memory system: bring the cache line holding a value closer before it is read.
//! Descents side by side know every lane's next node a level ahead of its arithmetic; asking
//! for all of them first lets their cache misses overlap instead of each lane waiting on its own.
//! A hint only: it never faults, reads nothing and changes no result.

/// Asks for the cache lines of `values` (at most the first and last line they span) to be
/// loaded into the nearest cache. A no-op where the target has no stable prefetch instruction.
#[inline(always)]
pub(crate) fn prefetch<T>(values: &[T]) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let first = values.as_ptr().cast::<i8>();
        let last = values.as_ptr_range().end.cast::<i8>().wrapping_sub(1);
        // Prefetching reads no memory and cannot fault, whatever the address.
        #[allow(unused_unsafe)]
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(first);
            // One value no larger than its alignment lies within one line.
            if values.len() != 1 || size_of::<T>() > align_of::<T>() {
                _mm_prefetch::<_MM_HINT_T0>(last);
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = values;
    }
}

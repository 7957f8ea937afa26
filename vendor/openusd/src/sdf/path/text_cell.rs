//! The text a path node makes once and keeps, in one pointer.
//!
//! Most nodes never make their text (a path is written out for errors, the layer's
//! sorted spec list and a few name queries), and every node pays for the cell: a
//! `OnceLock<Box<str>>` takes 24 bytes, this 8. The text itself is boxed twice, an
//! allocation only the nodes that make their text pay.

use std::ptr;
use std::sync::atomic::{AtomicPtr, Ordering};

pub(super) struct TextCell(AtomicPtr<Box<str>>);

impl TextCell {
    pub(super) const fn new() -> Self {
        TextCell(AtomicPtr::new(ptr::null_mut()))
    }

    /// The text, once made.
    pub(super) fn get(&self) -> Option<&str> {
        let text = self.0.load(Ordering::Acquire);
        // SAFETY: a non-null pointer came from `Box::into_raw` in `get_or_init`, is never
        // replaced once set, and is freed only by `drop`, which takes `&mut self`.
        (!text.is_null()).then(|| unsafe { &**text })
    }

    /// The text, made by `make` on the first call. Two threads may both make it; the
    /// first to store it wins and the other's copy is dropped.
    pub(super) fn get_or_init(&self, make: impl FnOnce() -> Box<str>) -> &str {
        if let Some(text) = self.get() {
            return text;
        }
        let made = Box::into_raw(Box::new(make()));
        match self.0.compare_exchange(ptr::null_mut(), made, Ordering::AcqRel, Ordering::Acquire) {
            // SAFETY: `made` is now the cell's, alive until the cell drops.
            Ok(_) => unsafe { &**made },
            Err(stored) => {
                // SAFETY: `made` was not stored, so it is still ours alone; `stored` is the
                // cell's, as in `get`.
                drop(unsafe { Box::from_raw(made) });
                unsafe { &**stored }
            }
        }
    }
}

impl Drop for TextCell {
    fn drop(&mut self) {
        let text = *self.0.get_mut();
        if !text.is_null() {
            // SAFETY: the pointer came from `Box::into_raw` and nothing else frees it.
            drop(unsafe { Box::from_raw(text) });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::TextCell;

    #[test]
    fn the_text_is_made_once() {
        let cell = TextCell::new();
        assert_eq!(cell.get(), None);
        assert_eq!(cell.get_or_init(|| "/A/B".into()), "/A/B");
        assert_eq!(cell.get_or_init(|| unreachable!("made again")), "/A/B");
        assert_eq!(cell.get(), Some("/A/B"));
    }

    #[test]
    fn a_node_is_no_larger_for_its_text() {
        assert_eq!(std::mem::size_of::<TextCell>(), 8);
    }
}

//! Fields authored on a usdc layer after it is read (ppis patch, see PATCHED.md).
//!
//! A spec read from the file keeps only its type and the start of its fieldset; what is
//! authored later is layered over those fields here, keyed by the spec's path. Kept apart
//! from the specs, the table of a layer's specs (one per spec of the file, for the layer's
//! life) holds no overlay pointer per spec that nearly always stays empty.

use crate::sdf;

/// The fields authored after load, per spec path, in authored order. `Some` sets or
/// overrides a field; `None` tombstones one so it reads as absent even when the file holds
/// it.
#[derive(Debug, Default)]
pub(super) struct Overlay(sdf::PathMap<Vec<(String, Option<sdf::Value>)>>);

impl Overlay {
    /// The fields authored on the spec at `path`.
    pub(super) fn fields(&self, path: &sdf::Path) -> &[(String, Option<sdf::Value>)] {
        if self.0.is_empty() {
            return &[];
        }
        self.0.get(path).map_or(&[], Vec::as_slice)
    }

    /// The override of `field` at `path`: `Some(&Some(value))` when set, `Some(&None)` when
    /// tombstoned, `None` when the file's fields alone decide.
    pub(super) fn get(&self, path: &sdf::Path, field: &str) -> Option<&Option<sdf::Value>> {
        self.fields(path).iter().find(|(k, _)| k == field).map(|(_, v)| v)
    }

    /// Sets the override of `field` at `path`, replacing any prior one.
    pub(super) fn set(&mut self, path: &sdf::Path, field: &str, value: Option<sdf::Value>) {
        let fields = self.0.entry(path.clone()).or_default();
        match fields.iter_mut().find(|(k, _)| k == field) {
            Some(slot) => slot.1 = value,
            None => fields.push((field.to_owned(), value)),
        }
    }

    /// Drops any override of `field` at `path`, so a later set appends it again.
    pub(super) fn remove(&mut self, path: &sdf::Path, field: &str) {
        if let Some(fields) = self.0.get_mut(path) {
            fields.retain(|(k, _)| k != field);
            if fields.is_empty() {
                self.0.remove(path);
            }
        }
    }

    /// Drops every override at `path` (its spec is made anew or erased).
    pub(super) fn clear(&mut self, path: &sdf::Path) {
        if !self.0.is_empty() {
            self.0.remove(path);
        }
    }
}

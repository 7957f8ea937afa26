//! Prim status during a top-down traversal (ppis patch, see PATCHED.md).
//!
//! The inherited status bits (active, loaded, defined, abstract, model) depend on
//! every ancestor's own opinion. [`Prim::is_active`](super::Prim::is_active) and its
//! siblings walk the ancestor chain per query, which a traversal repeats for every
//! prim: a path of depth d costs d field lookups, each hashing a d-long path. The
//! traversal instead carries what the ancestors resolved to ([`Inherited`]) down its
//! stack, so each prim consults only its own opinions.

use anyhow::Result;

use crate::sdf;

use super::prim::has_payload;
use super::stage::{PrimStatus, Stage};

/// What a prim's strict ancestors (below the pseudo-root) resolved to.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Inherited {
    /// No ancestor authors `active = false`.
    active: bool,
    /// Every ancestor's specifier is `def` or `class`.
    defined: bool,
    /// Some ancestor's specifier is `class`.
    class: bool,
    /// Every ancestor's `kind` is `group` or `assembly`.
    group: bool,
    /// No payload-carrying ancestor is excluded by the load rules.
    loaded: bool,
}

impl Inherited {
    /// The pseudo-root's children inherit nothing.
    pub(crate) const ROOT: Self = Self {
        active: true,
        defined: true,
        class: false,
        group: true,
        loaded: true,
    };
}

impl Stage {
    /// The status bits in `mask` for `prim`, whose ancestors resolved to `above`, and
    /// what `prim`'s children inherit. Gives the same bits as
    /// `prim_status_masked` (the per-query ancestor walks in `Prim`).
    pub(crate) fn prim_status_inherited(
        &self,
        prim: &sdf::Path,
        mask: PrimStatus,
        above: Inherited,
    ) -> Result<(PrimStatus, Inherited)> {
        let handle = self.prim(prim.clone());
        let mut status = PrimStatus::empty();
        let mut below = above;
        let wants = |bits: PrimStatus| mask.intersects(bits);
        let has_spec = if wants(PrimStatus::ACTIVE | PrimStatus::LOADED | PrimStatus::DEFINED)
            || wants(PrimStatus::ABSTRACT | PrimStatus::MODEL)
        {
            self.has_spec(prim)?
        } else {
            false
        };
        if wants(PrimStatus::ACTIVE | PrimStatus::LOADED) {
            below.active = above.active && self.field::<bool>(prim, sdf::FieldKey::Active)?.unwrap_or(true);
            let active = has_spec && below.active;
            status.set(PrimStatus::ACTIVE, active && mask.contains(PrimStatus::ACTIVE));
            if mask.contains(PrimStatus::LOADED) {
                // No rule anywhere means every path resolves loaded.
                if !self.cache().load_rules().is_empty() {
                    let excluded = has_payload(self, prim)? && !self.is_path_loaded(prim);
                    below.loaded = above.loaded && !excluded;
                }
                status.set(PrimStatus::LOADED, active && below.loaded);
            }
        }
        if wants(PrimStatus::DEFINED | PrimStatus::ABSTRACT) {
            let specifier = self.field::<sdf::Specifier>(prim, sdf::FieldKey::Specifier)?;
            let defining = matches!(specifier, Some(sdf::Specifier::Def | sdf::Specifier::Class));
            below.defined = above.defined && defining;
            below.class = above.class || specifier == Some(sdf::Specifier::Class);
            status.set(PrimStatus::DEFINED, has_spec && below.defined && mask.contains(PrimStatus::DEFINED));
            status.set(PrimStatus::ABSTRACT, has_spec && below.class && mask.contains(PrimStatus::ABSTRACT));
        }
        if mask.contains(PrimStatus::MODEL) {
            let kind = handle.kind()?;
            let kind = kind.as_ref().map(|k| k.as_str());
            let model = matches!(kind, Some("group" | "assembly" | "component"));
            status.set(PrimStatus::MODEL, has_spec && above.group && model);
            below.group = above.group && matches!(kind, Some("group" | "assembly"));
        }
        if mask.contains(PrimStatus::INSTANCE) {
            status.set(PrimStatus::INSTANCE, handle.is_instance()?);
        }
        if mask.contains(PrimStatus::IN_PROTOTYPE) {
            status.set(PrimStatus::IN_PROTOTYPE, handle.is_in_prototype());
        }
        Ok((status, below))
    }
}

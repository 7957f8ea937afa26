//! Which of a prim's properties have specs of both kinds (ppis patch, see PATCHED.md).
//!
//! An attribute in one layer and a relationship of the same name in another is an
//! [`Error::InconsistentPropertyType`](super::Error::InconsistentPropertyType). Looking each
//! composed property up at each of the prim's spec sites costs properties × sites, `n²` for a
//! hostile prim that one layer of `n` sublayers or references each gives a property. One
//! pass over every site's own property list finds the few names that can conflict; only
//! those are composed property by property, so the errors and their order are unchanged.

use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};

use crate::sdf::schema::ChildrenKey;
use crate::sdf::{SpecType, Value};
use crate::tf::Token;

use super::layer_graph::LayerGraph;
use super::prim_index::PrimIndex;

/// The names among each live spec site's `properties` whose specs are attributes at one
/// site and relationships at another.
pub(super) fn properties_of_both_kinds(graph: &LayerGraph, index: &PrimIndex) -> HashSet<Token> {
    let mut kinds: HashMap<Token, SpecType> = HashMap::new();
    let mut both = HashSet::new();
    for (site, node) in index.live_spec_sites() {
        let data = graph.layer(site.layer).data();
        let Ok(field) = data.get_field(node.path(), ChildrenKey::PropertyChildren.as_str()) else {
            continue;
        };
        let Value::TokenVec(names) = field.as_ref() else {
            continue;
        };
        for name in names {
            let Ok(path) = node.path().append_property(name) else {
                continue;
            };
            let Some(kind) = data.spec_type(&path) else {
                continue;
            };
            match kinds.entry(name.clone()) {
                Entry::Vacant(slot) => {
                    slot.insert(kind);
                }
                Entry::Occupied(first) if *first.get() != kind => {
                    both.insert(name.clone());
                }
                Entry::Occupied(_) => {}
            }
        }
    }
    both
}

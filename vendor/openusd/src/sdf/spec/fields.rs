//! The fields of one in-memory spec, kept compact (ppis patch, see PATCHED.md).
//!
//! Every spec of a usda layer holds its fields for the layer's life, about a dozen per
//! simple prim (`specifier`, `typeName` and `propertyChildren` of the prim, `typeName`,
//! `default` and `variability` of each property), so a field's size is the layer's size.
//! A field is its [`FieldName`] (16 bytes) and its [`Value`] (32), and a spec's fields are
//! one allocation of exactly their number: a spec authors its fields once, when it is
//! parsed, and a growable vector would hold spare slots and a capacity word for its life.
//!
//! The allocation is shared: the specs of a layer's many similar prims author the same
//! fields (every sphere's `specifier`, `typeName` and `properties`, every `xformOpOrder`),
//! and a reader that builds a layer hands each spec's finished fields to a
//! [`FieldTable`](super::FieldTable), which gives back the list an earlier spec holds when
//! it is the same. A shared list is copied when one of its specs is edited, so no other
//! spec sees the edit.

use std::fmt;
use std::sync::Arc;

use crate::sdf::{ChildrenKey, FieldKey, Value};

/// The field names Sdf registers, the most common first (a name is found by a scan when a
/// field is added). A field named otherwise keeps its own text.
const REGISTERED: &[&str] = &[
    FieldKey::TypeName.as_str(),
    FieldKey::Default.as_str(),
    FieldKey::Specifier.as_str(),
    FieldKey::Variability.as_str(),
    ChildrenKey::PropertyChildren.as_str(),
    ChildrenKey::PrimChildren.as_str(),
    FieldKey::Custom.as_str(),
    FieldKey::TimeSamples.as_str(),
    FieldKey::ApiSchemas.as_str(),
    FieldKey::Kind.as_str(),
    FieldKey::Active.as_str(),
    FieldKey::References.as_str(),
    FieldKey::Payload.as_str(),
    FieldKey::InheritPaths.as_str(),
    FieldKey::Specializes.as_str(),
    FieldKey::VariantSetNames.as_str(),
    FieldKey::VariantSelection.as_str(),
    ChildrenKey::VariantSetChildren.as_str(),
    ChildrenKey::VariantChildren.as_str(),
    FieldKey::TargetPaths.as_str(),
    ChildrenKey::RelationshipTargetChildren.as_str(),
    FieldKey::ConnectionPaths.as_str(),
    ChildrenKey::ConnectionChildren.as_str(),
    FieldKey::Instanceable.as_str(),
    FieldKey::Documentation.as_str(),
    FieldKey::CustomData.as_str(),
    FieldKey::ColorSpace.as_str(),
    FieldKey::Hidden.as_str(),
    FieldKey::Comment.as_str(),
    FieldKey::AssetInfo.as_str(),
    FieldKey::AllowedTokens.as_str(),
    FieldKey::DisplayName.as_str(),
    FieldKey::DisplayGroup.as_str(),
    FieldKey::Permission.as_str(),
    FieldKey::PrefixSubstitutions.as_str(),
    FieldKey::SuffixSubstitutions.as_str(),
    FieldKey::SymmetricPeer.as_str(),
    FieldKey::Clips.as_str(),
    FieldKey::ClipSets.as_str(),
    FieldKey::ColorConfiguration.as_str(),
    FieldKey::ColorManagementSystem.as_str(),
    FieldKey::CustomLayerData.as_str(),
    FieldKey::DefaultPrim.as_str(),
    FieldKey::DisplayGroupOrder.as_str(),
    FieldKey::DisplayUnit.as_str(),
    FieldKey::EndTimeCode.as_str(),
    FieldKey::ExpressionVariables.as_str(),
    FieldKey::FramePrecision.as_str(),
    FieldKey::FramesPerSecond.as_str(),
    FieldKey::HasOwnedSubLayers.as_str(),
    FieldKey::LayerRelocates.as_str(),
    FieldKey::PrimOrder.as_str(),
    FieldKey::NoLoadHint.as_str(),
    FieldKey::Owner.as_str(),
    FieldKey::Prefix.as_str(),
    FieldKey::PropertyOrder.as_str(),
    FieldKey::Relocates.as_str(),
    FieldKey::SessionOwner.as_str(),
    FieldKey::StartTimeCode.as_str(),
    FieldKey::SubLayers.as_str(),
    FieldKey::SubLayerOffsets.as_str(),
    FieldKey::Suffix.as_str(),
    FieldKey::SymmetryArgs.as_str(),
    FieldKey::SymmetryArguments.as_str(),
    FieldKey::SymmetryFunction.as_str(),
    FieldKey::TimeCodesPerSecond.as_str(),
    FieldKey::EndFrame.as_str(),
    FieldKey::StartFrame.as_str(),
    "interpolation",
    "elementSize",
    "properties",
    "spline",
];

/// A field's name: a registered name by its index, any other by its own text.
#[derive(Clone, PartialEq, Eq)]
pub struct FieldName(Repr);

#[derive(Clone, PartialEq, Eq)]
enum Repr {
    Registered(u16),
    Other(Box<str>),
}

// A registered name fits beside the other variant's pointer.
const _: () = assert!(std::mem::size_of::<FieldName>() == 16);
const _: () = assert!(std::mem::size_of::<Field>() == 48);

impl FieldName {
    /// The name of `text`: its registered index, or a copy of it.
    pub fn new(text: &str) -> Self {
        match REGISTERED.iter().position(|name| *name == text) {
            Some(at) => FieldName(Repr::Registered(at as u16)),
            None => FieldName(Repr::Other(text.into())),
        }
    }

    /// The name's text.
    pub fn as_str(&self) -> &str {
        match &self.0 {
            Repr::Registered(at) => REGISTERED[usize::from(*at)],
            Repr::Other(text) => text,
        }
    }
}

impl std::ops::Deref for FieldName {
    type Target = str;

    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl fmt::Debug for FieldName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

impl fmt::Display for FieldName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

#[derive(Clone)]
pub(super) struct Field {
    pub(super) name: FieldName,
    pub(super) value: Value,
}

/// A spec's fields in authored order, names unique; no allocation when there are none.
#[derive(Clone, Default)]
pub struct Fields(Option<Arc<[Field]>>);

impl Fields {
    /// The number of fields.
    pub fn len(&self) -> usize {
        self.slice().len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.slice().is_empty()
    }

    /// The names and values in authored order.
    pub fn iter(&self) -> Iter<'_> {
        Iter(self.slice().iter())
    }

    pub(super) fn slice(&self) -> &[Field] {
        self.0.as_deref().unwrap_or_default()
    }

    /// The list itself, for [`FieldTable`](super::FieldTable) to share.
    pub(super) fn shared(&mut self) -> Option<&mut Arc<[Field]>> {
        self.0.as_mut()
    }

    fn position(&self, key: &str) -> Option<usize> {
        self.slice().iter().position(|field| field.name.as_str() == key)
    }

    /// The value of the field named `key`.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.position(key).map(|at| &self.slice()[at].value)
    }

    /// The value of the field named `key`, to edit in place (a shared list is copied first).
    pub fn get_mut(&mut self, key: &str) -> Option<&mut Value> {
        let at = self.position(key)?;
        let fields = self.0.as_mut()?;
        Some(&mut Arc::make_mut(fields)[at].value)
    }

    /// Sets the field named `key`: in place if it is authored, else after the others.
    pub fn set(&mut self, key: &str, value: Value) {
        match self.get_mut(key) {
            Some(slot) => *slot = value,
            None => self.push(FieldName::new(key), value),
        }
    }

    /// Sets the field `name`, which may be authored already.
    pub fn set_named(&mut self, name: FieldName, value: Value) {
        match self.get_mut(&name) {
            Some(slot) => *slot = value,
            None => self.push(name, value),
        }
    }

    /// Appends a field not yet authored, in one allocation of exactly the new length.
    fn push(&mut self, name: FieldName, value: Value) {
        let field = std::iter::once(Field { name, value });
        self.0 = Some(match self.0.take() {
            None => field.collect(),
            Some(mut fields) => match Arc::get_mut(&mut fields) {
                Some(own) => own.iter_mut().map(take_field).chain(field).collect(),
                None => fields.iter().cloned().chain(field).collect(),
            },
        });
    }

    /// Removes the field named `key`, returning its value; the others keep their order.
    pub fn remove(&mut self, key: &str) -> Option<Value> {
        let at = self.position(key)?;
        let mut fields = into_vec(self.0.take()?);
        let removed = fields.remove(at);
        if !fields.is_empty() {
            self.0 = Some(fields.into());
        }
        Some(removed.value)
    }

    /// Whether `self` and `other` hold the same list (not merely equal fields).
    pub fn is_shared_with(&self, other: &Fields) -> bool {
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

/// The fields, moved out of a list only one spec holds or cloned from a shared one.
fn into_vec(mut fields: Arc<[Field]>) -> Vec<Field> {
    match Arc::get_mut(&mut fields) {
        Some(own) => own.iter_mut().map(take_field).collect(),
        None => fields.to_vec(),
    }
}

/// The field, moved out of a list only one spec holds; an empty placeholder is left.
fn take_field(field: &mut Field) -> Field {
    Field {
        name: std::mem::replace(&mut field.name, FieldName(Repr::Registered(0))),
        value: std::mem::replace(&mut field.value, Value::None),
    }
}

impl fmt::Debug for Fields {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map().entries(self.iter()).finish()
    }
}

impl<'a> IntoIterator for &'a Fields {
    type Item = (&'a str, &'a Value);
    type IntoIter = Iter<'a>;

    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

/// The names and values of a spec's fields, in authored order.
pub struct Iter<'a>(std::slice::Iter<'a, Field>);

impl<'a> Iterator for Iter<'a> {
    type Item = (&'a str, &'a Value);

    fn next(&mut self) -> Option<Self::Item> {
        self.0.next().map(|field| (field.name.as_str(), &field.value))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.0.size_hint()
    }
}

/// The fields taken out of a spec, in authored order.
pub struct IntoIter(std::vec::IntoIter<Field>);

impl Iterator for IntoIter {
    type Item = (FieldName, Value);

    fn next(&mut self) -> Option<Self::Item> {
        self.0.next().map(|field| (field.name, field.value))
    }
}

impl IntoIterator for Fields {
    type Item = (FieldName, Value);
    type IntoIter = IntoIter;

    fn into_iter(self) -> IntoIter {
        IntoIter(self.0.map(into_vec).unwrap_or_default().into_iter())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registered_and_other_names_read_back() {
        let mut fields = Fields::default();
        fields.set("typeName", Value::Int(1));
        fields.set("myOwnMetadata", Value::Int(2));
        fields.set("propertyChildren", Value::Int(3));
        assert_eq!(fields.len(), 3);
        assert!(matches!(FieldName::new("typeName").0, Repr::Registered(_)));
        assert!(matches!(FieldName::new("myOwnMetadata").0, Repr::Other(_)));
        let names: Vec<&str> = fields.iter().map(|(name, _)| name).collect();
        assert_eq!(names, ["typeName", "myOwnMetadata", "propertyChildren"]);
        assert_eq!(fields.get("myOwnMetadata"), Some(&Value::Int(2)));
        assert_eq!(fields.get("default"), None);
    }

    #[test]
    fn setting_again_replaces_in_place_and_removing_keeps_order() {
        let mut fields = Fields::default();
        for (at, name) in ["a", "default", "b", "c"].into_iter().enumerate() {
            fields.set(name, Value::Int(at as i32));
        }
        fields.set("default", Value::Int(10));
        assert_eq!(fields.remove("b"), Some(Value::Int(2)));
        assert_eq!(fields.remove("b"), None);
        let all: Vec<(String, Value)> = fields.into_iter().map(|(name, value)| (name.to_string(), value)).collect();
        assert_eq!(all, [("a".into(), Value::Int(0)), ("default".into(), Value::Int(10)), ("c".into(), Value::Int(3))]);
    }

    #[test]
    fn every_registered_name_is_distinct_and_indexable() {
        assert!(REGISTERED.len() <= usize::from(u16::MAX));
        for (at, name) in REGISTERED.iter().enumerate() {
            assert_eq!(REGISTERED.iter().position(|other| other == name), Some(at), "{name} twice");
            assert_eq!(FieldName::new(name).as_str(), *name);
        }
    }
}

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

/// A spec's fields in authored order, names unique.
///
/// A list is one allocation, which specs with equal lists share; a list whose last field
/// is the spec's own (an attribute's `typeName` and `variability` are those of many
/// others, its `default` its own) may instead share the fields before it and hold only
/// the last, so that a layer of many distinct values does not repeat the fields around
/// them ([`FieldTable`](super::FieldTable) decides). An empty list is one shared list.
#[derive(Clone)]
pub struct Fields(pub(super) List);

#[derive(Clone)]
pub(super) enum List {
    /// Every field, in order.
    Whole(Arc<[Field]>),
    /// A shared head and the spec's own last field.
    Split(Arc<Split>),
}

#[derive(Clone)]
pub(super) struct Split {
    pub(super) head: Arc<[Field]>,
    pub(super) last: Field,
}

// A spec record holds its fields in two words, whichever way they are kept.
const _: () = assert!(std::mem::size_of::<Fields>() == 16);

/// The one empty list, so that a spec without fields allocates none.
fn empty() -> Arc<[Field]> {
    static EMPTY: std::sync::LazyLock<Arc<[Field]>> = std::sync::LazyLock::new(|| Arc::from(Vec::new()));
    EMPTY.clone()
}

impl Default for Fields {
    fn default() -> Self {
        Fields(List::Whole(empty()))
    }
}

impl List {
    /// The fields as a leading slice and, for a split list, its last field.
    pub(super) fn parts(&self) -> (&[Field], Option<&Field>) {
        match self {
            List::Whole(fields) => (fields, None),
            List::Split(split) => (&split.head, Some(&split.last)),
        }
    }

    /// The fields in order.
    pub(super) fn iter(&self) -> FieldIter<'_> {
        let (head, last) = self.parts();
        FieldIter { head: head.iter(), last }
    }
}

/// The fields of a [`List`] in order.
#[derive(Clone)]
pub(super) struct FieldIter<'a> {
    head: std::slice::Iter<'a, Field>,
    last: Option<&'a Field>,
}

impl<'a> Iterator for FieldIter<'a> {
    type Item = &'a Field;

    fn next(&mut self) -> Option<&'a Field> {
        self.head.next().or_else(|| self.last.take())
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.head.len() + usize::from(self.last.is_some());
        (n, Some(n))
    }
}

impl ExactSizeIterator for FieldIter<'_> {}

impl Fields {
    /// The number of fields.
    pub fn len(&self) -> usize {
        let (head, last) = self.0.parts();
        head.len() + usize::from(last.is_some())
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The names and values in authored order.
    pub fn iter(&self) -> Iter<'_> {
        Iter(self.0.iter())
    }

    fn position(&self, key: &str) -> Option<usize> {
        self.0.iter().position(|field| field.name.as_str() == key)
    }

    /// The value of the field named `key`.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.0.iter().find(|field| field.name.as_str() == key).map(|field| &field.value)
    }

    /// The value of the field named `key`, to edit in place (a shared list is copied first).
    pub fn get_mut(&mut self, key: &str) -> Option<&mut Value> {
        let at = self.position(key)?;
        if let List::Split(split) = &self.0 {
            let fields: Vec<Field> = split.head.iter().chain(std::iter::once(&split.last)).cloned().collect();
            self.0 = List::Whole(fields.into());
        }
        match &mut self.0 {
            List::Whole(fields) => Some(&mut Arc::make_mut(fields)[at].value),
            List::Split(_) => unreachable!("made whole above"),
        }
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
        let fields: Arc<[Field]> = match &mut self.0 {
            List::Whole(fields) => match Arc::get_mut(fields) {
                Some(own) => own.iter_mut().map(take_field).chain(field).collect(),
                None => fields.iter().cloned().chain(field).collect(),
            },
            List::Split(split) => split.head.iter().chain(std::iter::once(&split.last)).cloned().chain(field).collect(),
        };
        self.0 = List::Whole(fields);
    }

    /// Removes the field named `key`, returning its value; the others keep their order.
    pub fn remove(&mut self, key: &str) -> Option<Value> {
        let at = self.position(key)?;
        let mut fields = into_vec(std::mem::take(self).0);
        let removed = fields.remove(at);
        if !fields.is_empty() {
            self.0 = List::Whole(fields.into());
        }
        Some(removed.value)
    }

    /// Whether `self` and `other` hold the same list (not merely equal fields).
    pub fn is_shared_with(&self, other: &Fields) -> bool {
        match (&self.0, &other.0) {
            (List::Whole(a), List::Whole(b)) => !a.is_empty() && Arc::ptr_eq(a, b),
            (List::Split(a), List::Split(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }

    /// Whether `self` holds its last field apart from a head it shares with `other`.
    pub fn shares_head_with(&self, other: &Fields) -> bool {
        let head = |fields: &Fields| match &fields.0 {
            List::Split(split) => Some(split.head.clone()),
            List::Whole(_) => None,
        };
        matches!((head(self), head(other)), (Some(a), Some(b)) if Arc::ptr_eq(&a, &b))
    }
}

/// The fields, moved out of a list only one spec holds or cloned from a shared one.
fn into_vec(list: List) -> Vec<Field> {
    match list {
        List::Whole(mut fields) => match Arc::get_mut(&mut fields) {
            Some(own) => own.iter_mut().map(take_field).collect(),
            None => fields.to_vec(),
        },
        List::Split(split) => {
            let Split { head, last } = Arc::try_unwrap(split).unwrap_or_else(|shared| (*shared).clone());
            let mut fields = Vec::with_capacity(head.len() + 1);
            fields.extend(head.iter().cloned());
            fields.push(last);
            fields
        }
    }
}

/// The field, moved out of a list only one spec holds; an empty placeholder is left.
pub(super) fn take_field(field: &mut Field) -> Field {
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
pub struct Iter<'a>(FieldIter<'a>);

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
        IntoIter(into_vec(self.0).into_iter())
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

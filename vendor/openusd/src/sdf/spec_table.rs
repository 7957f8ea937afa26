//! The specs of an in-memory layer, keyed by prim path and property name (ppis patch, see
//! PATCHED.md).
//!
//! A simple prim has several property specs. Keyed by their own paths, each needs a path
//! node and a table slot for the layer's life; keyed by their owner's path and their name,
//! they live in the owner's entry, named by an index into the layer's distinct names (the
//! record's 4 bytes, not a 24-byte token beside it). A property whose path does not take
//! apart into a structured owner and name ([`Path::as_property`]) keeps an entry of its own.

use std::collections::HashMap;

use crate::sdf::{FieldTable, Path, PathMap, SpecData};
use crate::tf;

/// The specs at one path: its own, if any, and those of the properties it owns.
#[derive(Debug, Default, Clone)]
struct Entry {
    spec: Option<SpecData>,
    properties: Properties,
}

/// How many properties an entry scans before it indexes them: most prims own a handful.
const SCAN_LIMIT: usize = 16;

/// An entry's property specs, in the order they were added, names unique; each names
/// itself by its [`SpecData::name`], an index into the table's [`Names`].
///
/// A layer holds one per prim for its life, so the common case is small: a prim's first
/// [`SCAN_LIMIT`] properties are a list of exactly their number, found by a scan. Past
/// that the list grows by doubling (a prim of `n` properties would otherwise copy it `n`
/// times) beside an index by name (a scan per property made such a prim cost `n²`).
#[derive(Debug, Clone)]
enum Properties {
    Few(Box<[SpecData]>),
    Many(Box<Indexed>),
}

#[derive(Debug, Clone)]
struct Indexed {
    specs: Vec<SpecData>,
    slots: HashMap<tf::Token, u32>,
}

// The few-properties list and the boxed index share the list's 16 bytes.
const _: () = assert!(std::mem::size_of::<Properties>() == 16);

impl Default for Properties {
    fn default() -> Self {
        Properties::Few(Box::default())
    }
}

impl Properties {
    fn specs(&self) -> &[SpecData] {
        match self {
            Properties::Few(specs) => specs,
            Properties::Many(many) => &many.specs,
        }
    }

    fn specs_mut(&mut self) -> &mut [SpecData] {
        match self {
            Properties::Few(specs) => specs,
            Properties::Many(many) => &mut many.specs,
        }
    }

    /// The slot of `name`.
    fn find(&self, names: &Names, name: &str) -> Option<usize> {
        match self {
            Properties::Few(specs) => specs.iter().position(|spec| names.text(spec.name).as_str() == name),
            Properties::Many(many) => many.slots.get(name).map(|&at| at as usize),
        }
    }

    /// Appends a property not yet here (named by its `name`), returning its slot.
    fn push(&mut self, names: &Names, spec: SpecData) -> usize {
        match self {
            Properties::Few(specs) => {
                let at = specs.len();
                // The new list is exactly one longer: shrinking a doubled list once the
                // layer is parsed would leave its tail as a hole in the heap that the
                // import's later, differently sized blocks do not fill.
                let mut list = std::mem::take(specs).into_vec();
                list.reserve_exact(1);
                list.push(spec);
                if list.len() <= SCAN_LIMIT {
                    *specs = list.into_boxed_slice();
                } else {
                    let slots = list.iter().enumerate().map(|(at, spec)| (names.text(spec.name).clone(), slot(at)));
                    let slots = slots.collect();
                    *self = Properties::Many(Box::new(Indexed { specs: list, slots }));
                }
                at
            }
            Properties::Many(many) => {
                let at = many.specs.len();
                many.slots.insert(names.text(spec.name).clone(), slot(at));
                many.specs.push(spec);
                at
            }
        }
    }

    /// Removes the property at slot `at`; the last property takes its slot.
    fn remove(&mut self, names: &Names, at: usize) -> SpecData {
        match self {
            Properties::Few(specs) => {
                let mut list = std::mem::take(specs).into_vec();
                let spec = list.swap_remove(at);
                *specs = list.into_boxed_slice();
                spec
            }
            Properties::Many(many) => {
                let spec = many.specs.swap_remove(at);
                many.slots.remove(names.text(spec.name).as_str());
                if let Some(moved) = many.specs.get(at) {
                    many.slots.insert(names.text(moved.name).clone(), slot(at));
                }
                spec
            }
        }
    }

    /// Frees a grown list's spare capacity.
    fn shrink_to_fit(&mut self) {
        if let Properties::Many(many) = self {
            many.specs.shrink_to_fit();
            many.slots.shrink_to_fit();
        }
    }
}

impl Entry {
    fn is_empty(&self) -> bool {
        self.spec.is_none() && self.properties.specs().is_empty()
    }
}

/// The distinct property names of a layer, each by an index: a property spec holds the
/// index (4 bytes) instead of a token (24). A layer's many prims author a few names, so
/// the table is small; a name stays once no spec holds it.
#[derive(Debug, Default, Clone)]
struct Names {
    texts: Vec<tf::Token>,
    ids: HashMap<tf::Token, u32>,
}

impl Names {
    /// The index of `name`, added if new.
    fn id(&mut self, name: &str, token: impl FnOnce() -> tf::Token) -> u32 {
        if let Some(&id) = self.ids.get(name) {
            return id;
        }
        let id = u32::try_from(self.texts.len()).expect("fewer than 2^32 property names");
        let token = token();
        self.texts.push(token.clone());
        self.ids.insert(token, id);
        id
    }

    /// The name of index `id`.
    fn text(&self, id: u32) -> &tf::Token {
        &self.texts[id as usize]
    }
}

/// A property's slot as the index holds it (a prim owns fewer than 2³² properties: each
/// takes bytes of its layer).
fn slot(at: usize) -> u32 {
    u32::try_from(at).expect("fewer than 2^32 properties")
}

/// A map from spec path to [`SpecData`], storing property specs under their owners.
#[derive(Debug, Default, Clone)]
pub(crate) struct SpecTable {
    entries: PathMap<Entry>,
    names: Names,
    len: usize,
}

/// A path as the table keys it: the owner's path and the property's name, or the path.
fn split(path: &Path) -> (&Path, Option<&str>) {
    match path.as_property() {
        Some((owner, name)) => (owner, Some(name)),
        None => (path, None),
    }
}

impl SpecTable {
    /// The number of specs.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    pub(crate) fn get(&self, path: &Path) -> Option<&SpecData> {
        let (key, name) = split(path);
        let entry = self.entries.get(key)?;
        match name {
            Some(name) => entry.properties.find(&self.names, name).map(|at| &entry.properties.specs()[at]),
            None => entry.spec.as_ref(),
        }
    }

    pub(crate) fn get_mut(&mut self, path: &Path) -> Option<&mut SpecData> {
        let (key, name) = split(path);
        let entry = self.entries.get_mut(key)?;
        match name {
            Some(name) => entry.properties.find(&self.names, name).map(|at| &mut entry.properties.specs_mut()[at]),
            None => entry.spec.as_mut(),
        }
    }

    pub(crate) fn contains(&self, path: &Path) -> bool {
        self.get(path).is_some()
    }

    /// The spec at `path`, made by `make` if there is none.
    pub(crate) fn get_or_insert_with(&mut self, path: &Path, make: impl FnOnce() -> SpecData) -> &mut SpecData {
        match split(path) {
            (owner, Some(name)) => self.owned_property(owner, name, || name.into(), make),
            (key, None) => {
                let entry = self.entries.entry(key.clone()).or_default();
                if entry.spec.is_none() {
                    self.len += 1;
                }
                entry.spec.get_or_insert_with(make)
            }
        }
    }

    /// The spec of `owner`'s property `name`, made by `make` if there is none. A name
    /// that `owner` does not own as a structured property goes under its whole path
    /// (an error if `owner` cannot have properties).
    pub(crate) fn property_or_insert_with(
        &mut self,
        owner: &Path,
        name: &tf::Token,
        make: impl FnOnce() -> SpecData,
    ) -> anyhow::Result<&mut SpecData> {
        if !owner.owns_property(name) {
            let path = owner.append_property(name)?;
            return Ok(self.get_or_insert_with(&path, make));
        }
        Ok(self.owned_property(owner, name, || name.clone(), make))
    }

    /// The spec of a structured property of `owner`, made (with `token` naming it) if absent.
    fn owned_property(
        &mut self,
        owner: &Path,
        name: &str,
        token: impl FnOnce() -> tf::Token,
        make: impl FnOnce() -> SpecData,
    ) -> &mut SpecData {
        let entry = self.entries.entry(owner.clone()).or_default();
        let at = match entry.properties.find(&self.names, name) {
            Some(at) => at,
            None => {
                self.len += 1;
                let mut spec = make();
                spec.name = self.names.id(name, token);
                entry.properties.push(&self.names, spec)
            }
        };
        &mut entry.properties.specs_mut()[at]
    }

    /// Puts `spec` at `path`, returning the spec it replaces.
    pub(crate) fn insert(&mut self, path: Path, spec: SpecData) -> Option<SpecData> {
        let mut spec = Some(spec);
        let slot = self.get_or_insert_with(&path, || spec.take().expect("made once"));
        spec.map(|mut new| {
            new.name = slot.name;
            std::mem::replace(slot, new)
        })
    }

    pub(crate) fn remove(&mut self, path: &Path) -> Option<SpecData> {
        let (key, name) = split(path);
        let entry = self.entries.get_mut(key)?;
        let removed = match name {
            Some(name) => entry.properties.find(&self.names, name).map(|at| entry.properties.remove(&self.names, at)),
            None => entry.spec.take(),
        };
        if entry.is_empty() {
            self.entries.remove(key);
        }
        self.len -= usize::from(removed.is_some());
        removed
    }

    /// Every spec with its path, in no particular order; a property's path is made here.
    /// Hands the fields of `path`'s own spec and of its properties' specs to `table`
    /// (see [`FieldTable`]).
    pub(crate) fn share_fields(&mut self, path: &Path, table: &mut FieldTable) {
        let Some(entry) = self.entries.get_mut(path) else { return };
        for spec in entry.spec.iter_mut().chain(entry.properties.specs_mut()) {
            table.share(&mut spec.fields);
        }
    }

    pub(crate) fn iter(&self) -> impl Iterator<Item = (Path, &SpecData)> {
        let names = &self.names;
        self.entries.iter().flat_map(move |(path, entry)| {
            let own = entry.spec.as_ref().map(|spec| (path.clone(), spec));
            let properties = entry.properties.specs().iter().map(move |spec| {
                let name = names.text(spec.name);
                let property = path.append_property(name).expect("a structured owner takes its property");
                (property, spec)
            });
            own.into_iter().chain(properties)
        })
    }

    /// Frees the spare capacity of every entry's property list.
    pub(crate) fn shrink_to_fit(&mut self) {
        for entry in self.entries.values_mut() {
            entry.properties.shrink_to_fit();
        }
    }
}

impl FromIterator<(Path, SpecData)> for SpecTable {
    fn from_iter<I: IntoIterator<Item = (Path, SpecData)>>(specs: I) -> Self {
        let mut table = Self::default();
        for (path, spec) in specs {
            table.insert(path, spec);
        }
        table
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sdf::{path, SpecType};

    fn spec(ty: SpecType) -> SpecData {
        SpecData::new(ty)
    }

    /// Property specs live under their owner and answer by path as if keyed by it.
    #[test]
    fn properties_are_found_by_owner_and_name() {
        let mut table = SpecTable::default();
        table.insert(path("/A").unwrap(), spec(SpecType::Prim));
        for name in ["z", "x", "primvars:y"] {
            table.insert(path(&format!("/A.{name}")).unwrap(), spec(SpecType::Attribute));
        }
        let rel = table.property_or_insert_with(&path("/B").unwrap(), &tf::Token::from("r"), || spec(SpecType::Relationship));
        assert_eq!(rel.unwrap().ty, SpecType::Relationship);
        assert_eq!(table.len(), 5);
        assert_eq!(table.get(&path("/A.x").unwrap()).map(|s| s.ty), Some(SpecType::Attribute));
        assert!(table.contains(&path("/B.r").unwrap()) && !table.contains(&path("/B").unwrap()));
        assert!(!table.contains(&path("/A.w").unwrap()) && !table.contains(&path("/A/x").unwrap()));

        let mut all: Vec<String> = table.iter().map(|(p, _)| p.to_string()).collect();
        all.sort();
        assert_eq!(all, ["/A", "/A.primvars:y", "/A.x", "/A.z", "/B.r"]);

        assert!(table.remove(&path("/A").unwrap()).is_some());
        assert!(table.contains(&path("/A.z").unwrap()));
        assert!(table.remove(&path("/B.r").unwrap()).is_some() && table.remove(&path("/B.r").unwrap()).is_none());
        assert_eq!(table.len(), 3);
    }

    /// A prim with more properties than an entry scans answers the same, removals included.
    #[test]
    fn many_properties_are_indexed() {
        let mut table = SpecTable::default();
        let owner = path("/A").unwrap();
        let n = 5 * SCAN_LIMIT;
        for i in (0..n).rev() {
            let ty = if i % 2 == 0 { SpecType::Attribute } else { SpecType::Relationship };
            let name = tf::Token::from(format!("p{i}"));
            table.property_or_insert_with(&owner, &name, || spec(ty)).unwrap();
        }
        for i in (0..n).step_by(3) {
            assert!(table.remove(&path(&format!("/A.p{i}")).unwrap()).is_some());
        }
        assert_eq!(table.len(), n - n.div_ceil(3));
        for i in 0..n {
            let found = table.get(&path(&format!("/A.p{i}")).unwrap()).map(|s| s.ty);
            let expected = if i % 3 == 0 {
                None
            } else if i % 2 == 0 {
                Some(SpecType::Attribute)
            } else {
                Some(SpecType::Relationship)
            };
            assert_eq!(found, expected, "p{i}");
        }
        let again = table.property_or_insert_with(&owner, &tf::Token::from("p1"), || spec(SpecType::Attribute));
        assert_eq!(again.unwrap().ty, SpecType::Relationship);
    }

    /// A property made anew or replaced keeps its name, which its record holds for the table.
    #[test]
    fn replaced_properties_keep_their_names() {
        let mut data = crate::sdf::Data::default();
        let (a, b) = (path("/P.a").unwrap(), path("/P.b").unwrap());
        data.create_spec(a.clone(), SpecType::Attribute);
        data.create_spec(b.clone(), SpecType::Attribute).add("default", 1.0);
        data.create_spec(b.clone(), SpecType::Relationship);
        data.insert_spec(a.clone(), SpecData::new(SpecType::Relationship));
        assert_eq!(data.spec(&a).map(|s| s.ty), Some(SpecType::Relationship));
        assert!(data.spec(&b).is_some_and(|s| s.ty == SpecType::Relationship && s.fields.is_empty()));
        let mut all: Vec<String> = data.iter().map(|(p, _)| p.to_string()).collect();
        all.sort();
        assert_eq!(all, ["/P.a", "/P.b"]);
    }

    /// Inserting at a path that holds a spec replaces it; merging through the accessor keeps it.
    #[test]
    fn insert_replaces_and_get_or_insert_keeps() {
        let mut table = SpecTable::default();
        let at = path("/A.x").unwrap();
        assert!(table.insert(at.clone(), spec(SpecType::Attribute)).is_none());
        let old = table.insert(at.clone(), spec(SpecType::Relationship));
        assert_eq!(old.map(|s| s.ty), Some(SpecType::Attribute));
        assert_eq!(table.get_or_insert_with(&at, || spec(SpecType::Attribute)).ty, SpecType::Relationship);
        assert_eq!(table.len(), 1);
    }
}

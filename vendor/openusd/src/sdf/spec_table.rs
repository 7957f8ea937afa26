//! The specs of an in-memory layer, keyed by prim path and property name (ppis patch, see
//! PATCHED.md).
//!
//! A simple prim has several property specs. Keyed by their own paths, each needs a path
//! node and a table slot for the layer's life; keyed by their owner's path and their name,
//! they live in the owner's entry, and the name is a token the parser shares between every
//! prim that authors it. A property whose path does not take apart into a structured owner
//! and name ([`Path::as_property`]) keeps an entry of its own.

use crate::sdf::{Path, PathMap, SpecData};
use crate::tf;

/// The specs at one path: its own, if any, and those of the properties it owns.
#[derive(Debug, Default, Clone)]
struct Entry {
    spec: Option<SpecData>,
    /// Sorted by name, names unique.
    properties: Vec<(tf::Token, SpecData)>,
}

impl Entry {
    /// The slot of `name` among the properties, or where it would go.
    fn find(&self, name: &str) -> Result<usize, usize> {
        self.properties.binary_search_by(|(token, _)| token.as_str().cmp(name))
    }

    fn is_empty(&self) -> bool {
        self.spec.is_none() && self.properties.is_empty()
    }
}

/// A map from spec path to [`SpecData`], storing property specs under their owners.
#[derive(Debug, Default, Clone)]
pub(crate) struct SpecTable {
    entries: PathMap<Entry>,
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
            Some(name) => entry.find(name).ok().map(|at| &entry.properties[at].1),
            None => entry.spec.as_ref(),
        }
    }

    pub(crate) fn get_mut(&mut self, path: &Path) -> Option<&mut SpecData> {
        let (key, name) = split(path);
        let entry = self.entries.get_mut(key)?;
        match name {
            Some(name) => entry.find(name).ok().map(|at| &mut entry.properties[at].1),
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
        let at = match entry.find(name) {
            Ok(at) => at,
            Err(at) => {
                entry.properties.insert(at, (token(), make()));
                self.len += 1;
                at
            }
        };
        &mut entry.properties[at].1
    }

    /// Puts `spec` at `path`, returning the spec it replaces.
    pub(crate) fn insert(&mut self, path: Path, spec: SpecData) -> Option<SpecData> {
        let mut spec = Some(spec);
        let slot = self.get_or_insert_with(&path, || spec.take().expect("made once"));
        spec.map(|new| std::mem::replace(slot, new))
    }

    pub(crate) fn remove(&mut self, path: &Path) -> Option<SpecData> {
        let (key, name) = split(path);
        let entry = self.entries.get_mut(key)?;
        let removed = match name {
            Some(name) => entry.find(name).ok().map(|at| entry.properties.remove(at).1),
            None => entry.spec.take(),
        };
        if entry.is_empty() {
            self.entries.remove(key);
        }
        self.len -= usize::from(removed.is_some());
        removed
    }

    /// Every spec with its path, in no particular order; a property's path is made here.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (Path, &SpecData)> {
        self.entries.iter().flat_map(|(path, entry)| {
            let own = entry.spec.as_ref().map(|spec| (path.clone(), spec));
            let properties = entry.properties.iter().map(move |(name, spec)| {
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

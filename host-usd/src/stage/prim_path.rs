//! [`PrimPath`]: how the importer names prims. A prim is asked about many times (its
//! type, attributes, ancestors' transforms and visibility), so its name is openusd's path,
//! a node of a tree sharing its ancestors: cloning, comparing and hashing one costs the
//! same at any depth, where a text as long as the prim is deep made a deep namespace
//! quadratic in time and memory.

use openusd::sdf;
use std::collections::HashMap;
use std::fmt;

/// A map keyed by prims, hashed by the hash their paths carry (no second hash per lookup).
pub type PrimMap<T> = HashMap<PrimPath, T, sdf::BuildPathHasher>;

/// The path of a prim (or of a relationship's target) on the stage. Written out by
/// `Display` (`/World/Mesh`).
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PrimPath(pub(super) sdf::Path);

impl PrimPath {
    /// The path `text` (`/World/Mesh`).
    pub fn new(text: &str) -> Result<Self, String> {
        sdf::path(text).map(PrimPath).map_err(|e| format!("{e:#}"))
    }

    /// The pseudo-root `/`.
    pub fn root() -> Self {
        PrimPath(sdf::Path::abs_root())
    }

    /// Whether this is the pseudo-root `/`.
    pub fn is_root(&self) -> bool {
        self.0.is_abs_root()
    }

    /// The parent prim's path (`/` for a root prim); `None` for the pseudo-root.
    pub fn parent(&self) -> Option<Self> {
        self.0.parent().map(PrimPath)
    }

    /// Whether this path is `other` or below it.
    pub fn is_at_or_below(&self, other: &PrimPath) -> bool {
        self.0.has_prefix(&other.0)
    }

    /// The number of prim names in the path (`/a/b` → 2).
    pub fn depth(&self) -> usize {
        self.0.prim_element_count()
    }

    /// The path's `depth`-level ancestor (`/a/b/c` at 2 → `/a/b`), or the path itself when
    /// it is no deeper.
    pub fn ancestor_at(&self, depth: usize) -> Self {
        let mut p = self.clone();
        while p.depth() > depth {
            match p.parent() {
                Some(up) => p = up,
                None => break,
            }
        }
        p
    }
}

impl fmt::Display for PrimPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl fmt::Debug for PrimPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.0.to_string())
    }
}

/// A prim named by a [`PrimPath`] or by its text (made into a path on each call: for
/// callers that name a few prims, such as materials and tests).
pub trait PrimRef: fmt::Display {
    /// The prim's path.
    fn prim_path(&self) -> Result<PrimPath, String>;
}

impl PrimRef for PrimPath {
    fn prim_path(&self) -> Result<PrimPath, String> {
        Ok(self.clone())
    }
}

impl PrimRef for str {
    fn prim_path(&self) -> Result<PrimPath, String> {
        PrimPath::new(self)
    }
}

impl PrimRef for String {
    fn prim_path(&self) -> Result<PrimPath, String> {
        PrimPath::new(self)
    }
}

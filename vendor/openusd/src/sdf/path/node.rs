//! The tree behind a [`Path`]: each path is a node holding its parent and the one
//! element it adds (a prim name, a variant selection or a property name), as Pixar's
//! `SdfPath` is. Making a child, taking the parent or prim path, and testing or
//! replacing a prefix then cost the elements involved rather than the text of the whole
//! path, and a prim's paths share their ancestors instead of each holding a copy of
//! them: a namespace `d` deep takes memory and time linear in `d`, not quadratic.
//!
//! The decomposition is canonical: a text that follows the path grammar below always
//! parses to the same chain of nodes, and the fast constructors (`child_*`) make only
//! nodes that parsing their text would make. So two paths are equal exactly when their
//! chains are, and hashing the chain is hashing the text's structure. A text outside
//! that grammar (relative paths, relationship targets `[..]`, unusual characters) is
//! one opaque [`Kind::Text`] node, on which [`Path`]'s methods work on the text.
//!
//! Prim and variant nodes are interned (`intern.rs`): a path made again, by parsing its
//! text or by appending to its parent, is the node already made, so equal paths are
//! nearly always one node and compare in one step. A node left out of the table (a
//! property, or a node on a 64-bit hash collision) is compared by its chain, which stops
//! at the first two interned ancestors.
//!
//! The grammar of structured paths: `/`, then a prim name, then any sequence of
//! `/name` (after a prim), `name` (directly after a variant selection), `{set=sel}`
//! (after a prim or a variant selection), and at most one final `.property`. Names
//! are alphanumeric or `_`; a selection may also hold `-` or `|` or be empty; a
//! property name may hold `:` and `.` but not end with `.`.

use super::intern;
use super::text_cell::TextCell;
use super::{is_prim_name_char, Path};
use std::cmp::Ordering;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::{Arc, LazyLock};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Kind {
    /// The empty path `""`.
    Empty,
    /// The absolute root `/`.
    Root,
    /// A prim child; `seg` is its name (the `/` before it follows from the parent).
    Prim,
    /// A variant selection; `seg` is `{set=sel}`.
    Variant,
    /// A property; `seg` is `.name`.
    Property,
    /// A text outside the structured grammar, whole in `seg`, with no parent.
    Text,
}

pub(super) struct Node {
    pub(super) parent: Option<Path>,
    /// Shared, so that a prim's name in its parent's `primChildren` can be this text.
    pub(super) seg: Arc<str>,
    pub(super) kind: Kind,
    /// Prim names along the chain (`Path::prim_element_count`).
    pub(super) prims: u32,
    /// Prim names and variant selections along the chain (`Path::element_count`).
    pub(super) elems: u32,
    /// Whether a variant selection is on the chain.
    pub(super) variants: bool,
    /// The length of the path's text.
    pub(super) len: usize,
    pub(super) hash: u64,
    /// Whether the node is the one in the intern table for its chain; two distinct
    /// interned nodes are different paths.
    pub(super) interned: bool,
    /// The whole text, made on the first `Path::as_str` of a node with a parent.
    text: TextCell,
}

// Every path is a node, most of them a property's (one per attribute of every spec in a
// layer), so a node stays this small: 88 bytes with the `Arc`'s counts.
const _: () = assert!(std::mem::size_of::<Node>() == 72);

impl Drop for Node {
    /// Unlinks the chain one node at a time: dropping the last path of a deep chain
    /// would otherwise recurse once per level.
    fn drop(&mut self) {
        let mut next = self.parent.take();
        while let Some(path) = next {
            next = match Arc::into_inner(path.node) {
                Some(mut node) => node.parent.take(),
                None => None,
            };
        }
    }
}

fn leaf(kind: Kind, text: &str) -> Path {
    // A fixed-key SipHash, so equal paths hash equal in every map and process.
    let mut hasher = DefaultHasher::new();
    text.hash(&mut hasher);
    let hash = hasher.finish();
    Path {
        hash,
        node: Arc::new(Node {
            parent: None,
            seg: text.into(),
            kind,
            prims: 0,
            elems: 0,
            variants: false,
            len: text.len(),
            hash,
            interned: false,
            text: TextCell::new(),
        }),
    }
}

/// The concatenated `pieces` (`seg_len` bytes) in one allocation: a property node's
/// segment is `.` and its name, and a property path is made for nearly every query.
fn shared_text(pieces: &[&str], seg_len: usize) -> Arc<str> {
    const ON_STACK: usize = 64;
    match pieces {
        [one] => Arc::from(*one),
        _ if seg_len <= ON_STACK => {
            let mut bytes = [0u8; ON_STACK];
            let mut at = 0;
            for piece in pieces {
                bytes[at..at + piece.len()].copy_from_slice(piece.as_bytes());
                at += piece.len();
            }
            // Concatenated UTF-8 texts are UTF-8.
            Arc::from(std::str::from_utf8(&bytes[..at]).expect("pieces are UTF-8"))
        }
        _ => Arc::from(pieces.concat()),
    }
}

/// The hash of a child node from its parent's: a multiply-rotate over the segment's
/// bytes, finished by Murmur3's mixer. It is computed for every path made (the intern
/// table and every path-keyed map use it), on segments of a few bytes, where SipHash's
/// setup would dominate; fixed, so equal paths hash equal in every process.
fn hash_child(parent: u64, kind: Kind, pieces: &[&str]) -> u64 {
    const K: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut h = (parent ^ kind as u64).wrapping_mul(K);
    for piece in pieces {
        let bytes = piece.as_bytes();
        h = (h.rotate_left(5) ^ bytes.len() as u64).wrapping_mul(K);
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            h = (h.rotate_left(5) ^ u64::from_le_bytes(word)).wrapping_mul(K);
        }
    }
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^ (h >> 33)
}

/// Whether `seg` is `pieces` in a row.
fn seg_is(seg: &str, pieces: &[&str]) -> bool {
    let mut rest = seg;
    for piece in pieces {
        match rest.strip_prefix(piece) {
            Some(r) => rest = r,
            None => return false,
        }
    }
    rest.is_empty()
}

fn is_prim_name(name: &str) -> bool {
    !name.is_empty() && name.chars().all(is_prim_name_char)
}

fn is_selection(text: &str) -> bool {
    text.chars().all(|c| is_prim_name_char(c) || c == '-' || c == '|')
}

/// A property name the text-based queries read back whole: no separator but `.` and
/// `:` inside it, and a last `.`-part that is non-empty (`Path::is_property_path`).
fn is_property_name(name: &str) -> bool {
    !name.is_empty() && !name.ends_with('.') && name.chars().all(|c| is_prim_name_char(c) || c == ':' || c == '.')
}

impl Path {
    pub(super) fn empty() -> Path {
        static EMPTY: LazyLock<Path> = LazyLock::new(|| leaf(Kind::Empty, ""));
        EMPTY.clone()
    }

    pub(super) fn root() -> Path {
        static ROOT: LazyLock<Path> = LazyLock::new(|| leaf(Kind::Root, "/"));
        ROOT.clone()
    }

    pub(super) fn kind(&self) -> Kind {
        self.node.kind
    }

    /// Whether the path is a chain of elements (not an opaque text).
    pub(super) fn is_structured(&self) -> bool {
        self.node.kind != Kind::Text
    }

    /// The path of `text`: its chain of nodes when it follows the grammar, else one
    /// opaque node.
    pub(super) fn parse(text: &str) -> Path {
        match text {
            "" => Path::empty(),
            "/" => Path::root(),
            _ => Path::parse_structured(text).unwrap_or_else(|| leaf(Kind::Text, text)),
        }
    }

    fn parse_structured(text: &str) -> Option<Path> {
        let mut rest = text.strip_prefix('/')?;
        let mut at = Path::root();
        while !rest.is_empty() {
            let kind = at.node.kind;
            let first = rest.chars().next()?;
            if first == '{' && kind != Kind::Root {
                let close = rest.find('}')?;
                let (set, selection) = rest[1..close].split_once('=')?;
                at = at.child_variant(set, selection)?;
                rest = &rest[close + 1..];
                continue;
            }
            if first == '.' && kind != Kind::Root {
                return at.child_property(&rest[1..]);
            }
            if first == '/' && kind == Kind::Prim {
                rest = &rest[1..];
            } else if kind == Kind::Prim {
                return None;
            }
            let end = rest.find(|c: char| !is_prim_name_char(c)).unwrap_or(rest.len());
            at = at.child_prim(&rest[..end])?;
            rest = &rest[end..];
        }
        Some(at)
    }

    /// The child of `kind` whose `seg` is `pieces` in a row (always cut the same way for
    /// a kind, so that the hash, taken piece by piece, is a function of the segment).
    fn child(&self, kind: Kind, pieces: &[&str]) -> Path {
        let up = &self.node;
        let hash = hash_child(up.hash, kind, pieces);
        let seg_len: usize = pieces.iter().map(|p| p.len()).sum();
        let make = |interned| {
            let separator = usize::from(kind == Kind::Prim && up.kind == Kind::Prim);
            Arc::new(Node {
                parent: Some(self.clone()),
                seg: shared_text(pieces, seg_len),
                kind,
                prims: up.prims + u32::from(kind == Kind::Prim),
                elems: up.elems + u32::from(matches!(kind, Kind::Prim | Kind::Variant)),
                variants: up.variants || kind == Kind::Variant,
                len: up.len + separator + seg_len,
                hash,
                interned,
                text: TextCell::new(),
            })
        };
        // Below a node left out of the table nothing is interned: an interned node's
        // ancestors are all interned, so its parent pointer names its parent path.
        // Properties are not interned: most are made for one query and dropped, and two
        // of them compare in one step past their interned prims.
        let parent_interned = up.interned || matches!(up.kind, Kind::Root | Kind::Empty);
        if !parent_interned || kind == Kind::Property {
            return Path { node: make(false), hash };
        }
        let same = |n: &Node| {
            n.kind == kind && n.parent.as_ref().is_some_and(|p| Arc::ptr_eq(&p.node, up)) && seg_is(&n.seg, pieces)
        };
        Path {
            node: intern::find_or_insert(hash, same, make),
            hash,
        }
    }

    /// The prim child `name`, when both are structured.
    pub(super) fn child_prim(&self, name: &str) -> Option<Path> {
        let fits = matches!(self.node.kind, Kind::Root | Kind::Prim | Kind::Variant);
        (fits && is_prim_name(name)).then(|| self.child(Kind::Prim, &[name]))
    }

    /// The variant selection `{set=selection}`, when both are structured.
    pub(super) fn child_variant(&self, set: &str, selection: &str) -> Option<Path> {
        let fits = matches!(self.node.kind, Kind::Prim | Kind::Variant);
        (fits && is_prim_name(set) && is_selection(selection))
            .then(|| self.child(Kind::Variant, &["{", set, "=", selection, "}"]))
    }

    /// The property `name`, when both are structured.
    pub(super) fn child_property(&self, name: &str) -> Option<Path> {
        let fits = matches!(self.node.kind, Kind::Prim | Kind::Variant);
        (fits && is_property_name(name)).then(|| self.child(Kind::Property, &[".", name]))
    }

    /// Whether [`append_property`](Path::append_property)`(name)` makes a property node
    /// of this path, which [`as_property`](Self::as_property) takes apart again: a table
    /// may then key the property by this path and `name` instead of holding its node.
    pub(crate) fn owns_property(&self, name: &str) -> bool {
        matches!(self.node.kind, Kind::Prim | Kind::Variant) && is_property_name(name)
    }

    /// The owner and the name of a property node (`/A/B.points` → `/A/B`, `points`);
    /// `None` for any other path, an opaque text included.
    pub(crate) fn as_property(&self) -> Option<(&Path, &str)> {
        match (self.node.kind, &self.node.parent) {
            (Kind::Property, Some(owner)) => Some((owner, &self.node.seg[1..])),
            _ => None,
        }
    }

    /// The nodes from the root (or opaque text) down to this one.
    pub(super) fn chain(&self) -> Vec<&Path> {
        let mut chain = Vec::with_capacity(self.node.elems as usize + 2);
        let mut at = Some(self);
        while let Some(p) = at {
            chain.push(p);
            at = p.node.parent.as_ref();
        }
        chain.reverse();
        chain
    }

    /// The text, piece by piece, root first.
    pub(super) fn for_each_piece(&self, mut f: impl FnMut(&str)) {
        if self.node.parent.is_none() {
            return f(&self.node.seg);
        }
        if let Some(text) = self.node.text.get() {
            return f(text);
        }
        for p in self.chain() {
            if p.node.kind == Kind::Prim && p.node.parent.as_ref().is_some_and(|up| up.node.kind == Kind::Prim) {
                f("/");
            }
            f(&p.node.seg);
        }
    }

    /// The whole text, made once per node and kept.
    pub(super) fn text(&self) -> &str {
        if self.node.parent.is_none() {
            return &self.node.seg;
        }
        self.node.text.get_or_init(|| {
            let mut text = String::with_capacity(self.node.len);
            self.for_each_piece(|piece| text.push_str(piece));
            text.into()
        })
    }

    pub(super) fn same(&self, other: &Path) -> bool {
        if self.hash != other.hash {
            return false;
        }
        let (mut a, mut b) = (self, other);
        loop {
            if Arc::ptr_eq(&a.node, &b.node) {
                return true;
            }
            let (x, y) = (&a.node, &b.node);
            if x.interned && y.interned {
                return false;
            }
            if x.hash != y.hash || x.len != y.len || x.kind != y.kind || x.seg != y.seg {
                return false;
            }
            match (&x.parent, &y.parent) {
                (Some(p), Some(q)) => (a, b) = (p, q),
                (None, None) => return true,
                _ => return false,
            }
        }
    }

    pub(super) fn hash_value(&self) -> u64 {
        self.hash
    }

    /// The order of the texts. Two structured paths agree in their text down to their
    /// deepest common node, so only the pieces below it are compared: for siblings (the
    /// children of one prim, kept sorted by `PathTable`) that is their own names.
    pub(super) fn text_cmp(&self, other: &Path) -> Ordering {
        if Arc::ptr_eq(&self.node, &other.node) {
            return Ordering::Equal;
        }
        if self.is_structured() && other.is_structured() {
            if let (Some(p), Some(q)) = (&self.node.parent, &other.node.parent) {
                if Arc::ptr_eq(&p.node, &q.node) {
                    return self.own_bytes().cmp(other.own_bytes());
                }
            }
            let (a, b) = (self.chain(), other.chain());
            let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
            let below_a = a[common..].iter().flat_map(|p| p.own_bytes());
            return below_a.cmp(b[common..].iter().flat_map(|p| p.own_bytes()));
        }
        let pieces = |p: &Path| {
            let mut v: Vec<u8> = Vec::with_capacity(p.node.len);
            p.for_each_piece(|s| v.extend_from_slice(s.as_bytes()));
            v
        };
        pieces(self).cmp(&pieces(other))
    }

    /// The bytes this node adds to its parent's text: its separator, if any, and segment.
    fn own_bytes(&self) -> impl Iterator<Item = u8> + '_ {
        let slash = self.node.kind == Kind::Prim && self.node.parent.as_ref().is_some_and(|up| up.node.kind == Kind::Prim);
        let separator: &[u8] = if slash { b"/" } else { b"" };
        separator.iter().chain(self.node.seg.as_bytes()).copied()
    }
}

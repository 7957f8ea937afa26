//! Prefix queries on structured paths by their nodes: whether a path lies under another,
//! the path moved from one namespace to another, and the path without its variant
//! selections. Each answers `None` where the text decides (an opaque path, or a case the
//! nodes cannot express), and `Path` then reads the text as before.

use super::node::Kind;
use super::Path;

impl Path {
    /// The nearest node at or above this one whose text is `len` bytes long or
    /// shorter, and whether it is exactly `len` long.
    fn ancestor_of_len(&self, len: usize) -> (&Path, bool) {
        let mut at = self;
        while at.node.len > len {
            match &at.node.parent {
                Some(up) => at = up,
                None => break,
            }
        }
        (at, at.node.len == len)
    }

    /// The set and selection of a variant node.
    fn variant_parts(&self) -> Option<(&str, &str)> {
        let seg = &*self.node.seg;
        (self.kind() == Kind::Variant).then(|| seg[1..seg.len() - 1].split_once('='))?
    }

    /// [`Path::has_prefix`] by the nodes, or `None` when the text decides: an opaque
    /// path, or a property prefix (whose name may be the text prefix of a longer
    /// property name, `.a` of `.a.b`).
    pub(super) fn has_prefix_node(&self, prefix: &Path) -> Option<bool> {
        if !self.is_structured() || matches!(prefix.kind(), Kind::Text | Kind::Property | Kind::Empty) {
            return None;
        }
        if prefix.kind() == Kind::Root {
            return Some(self.kind() != Kind::Empty);
        }
        let (at, exact) = self.ancestor_of_len(prefix.node.len);
        Some(exact && at.same(prefix))
    }

    /// [`Path::replace_prefix`] by the nodes: the elements below `old` re-attached
    /// under `new`. `None` when the text decides (as in `has_prefix_node`, or when an
    /// element cannot attach under `new`, such as a property under the root).
    pub(super) fn replace_prefix_nodes(&self, old: &Path, new: &Path) -> Option<Option<Path>> {
        let structured = self.is_structured() && new.is_structured();
        if !structured || matches!(new.kind(), Kind::Empty) {
            return None;
        }
        if !self.has_prefix_node(old)? {
            return Some(None);
        }
        if old.same(new) {
            return Some(Some(self.clone()));
        }
        let mut below = Vec::new();
        let mut at = self;
        while at.node.len > old.node.len {
            below.push(at);
            at = at.node.parent.as_ref()?;
        }
        let mut out = new.clone();
        for p in below.into_iter().rev() {
            out = match p.kind() {
                Kind::Prim => out.child_prim(&p.node.seg),
                Kind::Variant => p.variant_parts().and_then(|(set, sel)| out.child_variant(set, sel)),
                Kind::Property => out.child_property(&p.node.seg[1..]),
                _ => None,
            }?;
        }
        Some(Some(out))
    }

    /// [`Path::strip_all_variant_selections`] by the nodes, or `None` for an opaque path.
    pub(super) fn strip_variants_nodes(&self) -> Option<Path> {
        if !self.is_structured() {
            return None;
        }
        if !self.node.variants {
            return Some(self.clone());
        }
        let mut out = Path::root();
        for p in self.chain().into_iter().skip(1) {
            out = match p.kind() {
                Kind::Prim => out.child_prim(&p.node.seg)?,
                Kind::Property => out.child_property(&p.node.seg[1..])?,
                _ => out,
            };
        }
        Some(out)
    }
}

//! Index of a composition graph's nodes by site path.
//!
//! Adding a composition arc asks whether the graph already holds a node at the
//! arc's target site (the duplicate-site test of the class-based arcs) and
//! whether the parent already has a child there. A prim that inherits `n`
//! classes asks that `n` times, so scanning the arena each time makes its
//! composition quadratic. [`SiteIndex`] answers both from the target path in
//! constant time: it lists, per path, the arena handles of the nodes sitting at
//! that path, in arena order.
//!
//! The index is a cache of the arena, never a second source of truth: callers
//! still test every candidate's current layer stack and flags, and fall back to
//! the arena whenever the index does not cover every node (see
//! [`covers`](SiteIndex::covers)).

use std::collections::HashMap;

use crate::sdf::Path;

use super::prim_graph::{Node, NodeId};

/// Graphs smaller than this are scanned instead: the scan is as quick and a
/// small prim index, the common case, carries no map.
pub(crate) const SITE_INDEX_MIN_NODES: usize = 32;

/// Arena handles of a graph's nodes grouped by their site path.
#[derive(Debug, Clone, Default)]
pub(crate) struct SiteIndex {
    by_path: HashMap<Path, Vec<NodeId>>,
    /// How many arena nodes, from the first, have been indexed.
    indexed: usize,
}

impl SiteIndex {
    /// Indexes every node of `nodes`.
    pub(crate) fn build(nodes: &[Node]) -> Self {
        let mut index = Self::default();
        for (i, node) in nodes.iter().enumerate() {
            index.push(NodeId(i as u32), &node.path);
        }
        index
    }

    /// Records the node just appended to the arena at handle `id`.
    pub(crate) fn push(&mut self, id: NodeId, path: &Path) {
        debug_assert_eq!(id.idx(), self.indexed, "nodes are indexed in arena order");
        self.by_path.entry(path.clone()).or_default().push(id);
        self.indexed += 1;
    }

    /// Whether the index holds exactly the first `len` arena nodes — the whole
    /// arena of a graph with `len` nodes.
    pub(crate) fn covers(&self, len: usize) -> bool {
        self.indexed == len
    }

    /// Handles of the nodes at `path`, in arena order.
    pub(crate) fn nodes_at(&self, path: &Path) -> &[NodeId] {
        self.by_path.get(path).map_or(&[], Vec::as_slice)
    }
}

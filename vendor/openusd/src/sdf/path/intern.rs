//! The table of structured path nodes, so that making a path that exists returns the node
//! that exists. It holds weak references: a node lives as long as paths use it, and the
//! entries of dead nodes are dropped when the table would otherwise grow.

use super::node::Node;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::{Arc, Mutex, Weak};

/// The keys are the nodes' own 64-bit hashes, used as they are.
#[derive(Default)]
struct Identity(u64);

impl Hasher for Identity {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }
    fn write_u64(&mut self, n: u64) {
        self.0 = n;
    }
}

#[derive(Default)]
struct Table {
    nodes: HashMap<u64, Weak<Node>, BuildHasherDefault<Identity>>,
    /// The size at which dead entries are swept before the map grows.
    sweep_at: usize,
}

static TABLE: Mutex<Option<Table>> = Mutex::new(None);

/// The live node of `hash` for which `same` holds, or the node `make(true)` made and
/// entered. When another live node holds the hash (a collision) the new node is made with
/// `make(false)` and left out.
pub(super) fn find_or_insert(hash: u64, same: impl Fn(&Node) -> bool, make: impl Fn(bool) -> Arc<Node>) -> Arc<Node> {
    let mut guard = TABLE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let table = guard.get_or_insert_with(Table::default);
    if let Some(live) = table.nodes.get(&hash).and_then(Weak::upgrade) {
        if same(&live) {
            return live;
        }
        return make(false);
    }
    if table.nodes.len() >= table.sweep_at {
        table.nodes.retain(|_, weak| weak.strong_count() > 0);
        table.sweep_at = (2 * table.nodes.len()).max(1024);
    }
    let node = make(true);
    table.nodes.insert(hash, Arc::downgrade(&node));
    node
}

//! The prim indexer's open tasks (ppis patch, see PATCHED.md).
//!
//! Picking the next task by scanning every open one made a prim of `n` references cost `n²`:
//! each referenced node opens several tasks (references, payloads, inherits, specializes,
//! variant sets) before the first drains. Most kinds order by kind and then node index,
//! a total order that depends on nothing else, so they wait in a binary heap; the variant
//! and implied-class tasks, which order by the graph's live node strength, are scanned as
//! before. Tasks of different kinds order by kind, so the best task is the better of the
//! heap's top and the scan's best.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::{Task, TaskKind};

/// Open tasks, split by how their kind orders them.
#[derive(Default)]
pub(super) struct TaskQueue {
    /// Tasks ordered by kind, then node.
    by_node: BinaryHeap<ByNode>,
    /// Tasks whose order the indexer's state decides.
    scanned: Vec<Task>,
}

/// A task whose kind orders it by node index alone.
struct ByNode(Task);

impl PartialEq for ByNode {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for ByNode {}

impl PartialOrd for ByNode {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for ByNode {
    fn cmp(&self, other: &Self) -> Ordering {
        (self.0.kind, self.0.node).cmp(&(other.0.kind, other.0.node))
    }
}

/// Whether `kind`'s tasks order by node index (the last arm of the indexer's
/// `task_priority_cmp`).
fn orders_by_node(kind: TaskKind) -> bool {
    !matches!(
        kind,
        TaskKind::EvalNodeVariantAuthored
            | TaskKind::EvalNodeVariantFallback
            | TaskKind::EvalNodeAncestralVariantAuthored
            | TaskKind::EvalNodeAncestralVariantFallback
            | TaskKind::EvalNodeVariantNoneFound
            | TaskKind::EvalNodeAncestralVariantNoneFound
            | TaskKind::EvalImpliedClasses
    )
}

impl TaskQueue {
    pub(super) fn push(&mut self, task: Task) {
        if orders_by_node(task.kind) && task.variant.is_none() {
            self.by_node.push(ByNode(task));
        } else {
            self.scanned.push(task);
        }
    }

    /// Removes and returns the greatest task under `priority` (the indexer's
    /// `task_priority_cmp`).
    pub(super) fn take_best(&mut self, priority: impl Fn(&Task, &Task) -> Ordering) -> Option<Task> {
        let scanned = &self.scanned;
        let best = (0..scanned.len()).max_by(|&i, &j| priority(&scanned[i], &scanned[j]));
        match (best, self.by_node.peek()) {
            (Some(at), Some(top)) if priority(&scanned[at], &top.0) == Ordering::Less => {
                self.by_node.pop().map(|t| t.0)
            }
            (Some(at), _) => Some(self.scanned.swap_remove(at)),
            (None, _) => self.by_node.pop().map(|t| t.0),
        }
    }

    /// The tasks whose kind a retry may change (every task that does not order by node).
    pub(super) fn scanned_mut(&mut self) -> impl Iterator<Item = &mut Task> {
        self.scanned.iter_mut()
    }
}

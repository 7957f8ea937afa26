//! The prim indexer's open tasks (ppis patch, see PATCHED.md).
//!
//! Picking the next task by scanning every open one made a prim of `n` references cost `n²`:
//! each referenced node opens several tasks (references, payloads, inherits, specializes,
//! variant sets) before the first drains. Most kinds order by kind and then node index,
//! a total order that depends on nothing else, so they wait in a binary heap. The variant
//! and implied-class tasks order by the graph's live node strength, so they are scanned;
//! but tasks of one kind on one node order by their variant set alone (a prim of `n`
//! variant sets opens `n` tasks on its node), so the scan is over groups of one kind and
//! node, each a heap by variant set. Tasks of different kinds order by kind, so the best
//! task is the better of the heap's top and the scan's best.

use std::cmp::Ordering;
use std::collections::{BTreeMap, BinaryHeap};

use super::{NodeId, Task, TaskKind};

/// Open tasks, split by how their kind orders them.
#[derive(Default)]
pub(super) struct TaskQueue {
    /// Tasks ordered by kind, then node.
    by_node: BinaryHeap<ByNode>,
    /// Tasks whose order the indexer's state decides, by kind and node.
    scanned: BTreeMap<(TaskKind, NodeId), BinaryHeap<ByVariantSet>>,
}

/// A scanned task among those of its kind and node: the stronger variant set (the lower
/// `(vset_path, vset_num)`, as the indexer's `task_priority_cmp` orders them) is greater.
struct ByVariantSet(Task);

impl ByVariantSet {
    fn key(&self) -> Option<(&str, u16)> {
        self.0.variant.as_ref().map(|v| (v.vset_path.as_str(), v.vset_num))
    }
}

impl PartialEq for ByVariantSet {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for ByVariantSet {}

impl PartialOrd for ByVariantSet {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for ByVariantSet {
    fn cmp(&self, other: &Self) -> Ordering {
        other.key().cmp(&self.key())
    }
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
            self.scanned.entry((task.kind, task.node)).or_default().push(ByVariantSet(task));
        }
    }

    /// Removes and returns the greatest task under `priority` (the indexer's
    /// `task_priority_cmp`), which orders tasks of one kind and node as
    /// [`ByVariantSet`] does.
    pub(super) fn take_best(&mut self, priority: impl Fn(&Task, &Task) -> Ordering) -> Option<Task> {
        let best = self
            .scanned
            .iter()
            .filter_map(|(group, tasks)| Some((*group, &tasks.peek()?.0)))
            .max_by(|(_, a), (_, b)| priority(a, b));
        match (best, self.by_node.peek()) {
            (Some((_, task)), Some(top)) if priority(task, &top.0) == Ordering::Less => {
                self.by_node.pop().map(|t| t.0)
            }
            (Some((group, _)), _) => {
                let tasks = self.scanned.get_mut(&group).expect("a group just seen");
                let task = tasks.pop().map(|t| t.0);
                if tasks.is_empty() {
                    self.scanned.remove(&group);
                }
                task
            }
            (None, _) => self.by_node.pop().map(|t| t.0),
        }
    }

    /// Gives every scanned task of a kind that `retry` changes that new kind (a retry of
    /// variant tasks that found no selection).
    pub(super) fn retry_kinds(&mut self, retry: impl Fn(TaskKind) -> TaskKind) {
        let moved: Vec<(TaskKind, NodeId)> =
            self.scanned.keys().filter(|(kind, _)| retry(*kind) != *kind).copied().collect();
        for (kind, node) in moved {
            let tasks = self.scanned.remove(&(kind, node)).expect("a listed group");
            let into = self.scanned.entry((retry(kind), node)).or_default();
            for ByVariantSet(mut task) in tasks {
                task.kind = retry(kind);
                into.push(ByVariantSet(task));
            }
        }
    }
}

//! The hierarchy's build: binned surface-area heuristic (32 bins along each centroid axis, the
//! cheapest split of the three kept; up to 4 primitives per leaf, leaves of up to 16 where no
//! split pays), median splits past depth 40 so that the depth stays logarithmic. Subtrees of
//! many primitives build their two halves on two threads; the halves are joined in the
//! sequential build's order, so the tree is the same node for node at any thread count.

use super::{Aabb, Node, Primitive};
use rayon::prelude::*;
use sampler_core::glam::Vec3;

const BINS: usize = 32;
/// A node of at most this many primitives is a leaf.
const LEAF_SIZE: usize = 4;
/// A node of at most this many primitives may stay a leaf when no split is cheaper.
const LEAF_MAX: usize = 16;
/// A scene of at most this many primitives is one leaf: its two blocks tested outright
/// cost a ray less than the root's box test and the traversal (docs/bvh.md, "Figures").
const ONE_LEAF: usize = 8;
/// Depth from which nodes split at the median.
const MEDIAN_DEPTH: u32 = 40;
/// Subtrees of at least this many primitives build their halves in parallel (below it the
/// join costs more than it saves).
const PARALLEL_MIN: usize = 1 << 14;

/// A primitive's box beside its index, so that a build reads memory in order.
#[derive(Clone, Copy)]
struct Item {
    bounds: Aabb,
    prim: u32,
}

impl Item {
    fn centroid(&self) -> Vec3 {
        0.5 * (self.bounds.min + self.bounds.max)
    }
}

/// The boxes of a set of items and of their centroids.
#[derive(Clone, Copy)]
struct Extent {
    bounds: Aabb,
    centroids: Aabb,
}

impl Extent {
    const EMPTY: Extent = Extent { bounds: Aabb::EMPTY, centroids: Aabb::EMPTY };

    fn add(self, it: &Item) -> Extent {
        let c = it.centroid();
        Extent { bounds: self.bounds.union(it.bounds), centroids: self.centroids.union(Aabb { min: c, max: c }) }
    }

    fn union(self, o: Extent) -> Extent {
        Extent { bounds: self.bounds.union(o.bounds), centroids: self.centroids.union(o.centroids) }
    }

    fn of(items: &[Item]) -> Extent {
        let gather = |items: &[Item]| items.iter().fold(Extent::EMPTY, Extent::add);
        if items.len() >= PARALLEL_MIN {
            items.par_chunks(PARALLEL_MIN).map(gather).reduce(|| Extent::EMPTY, Extent::union)
        } else {
            gather(items)
        }
    }
}

/// One bin of a split: the extent of the items that fall in it, and their count.
type Bin = (Extent, usize);

/// The nodes over `prims`, and the primitives reordered so that every leaf's are contiguous.
pub(super) fn build(prims: Vec<Primitive>) -> (Vec<Primitive>, Vec<Node>) {
    if prims.is_empty() {
        return (prims, Vec::new());
    }
    let mut items: Vec<Item> =
        prims.par_iter().enumerate().map(|(k, p)| Item { bounds: p.aabb(), prim: k as u32 }).collect();
    let mut nodes = Vec::with_capacity(2 * prims.len() / LEAF_SIZE + 1);
    let extent = Extent::of(&items);
    if prims.len() <= ONE_LEAF {
        nodes.push(Node { bounds: extent.bounds, offset: 0, count: prims.len() as u32 });
        return (prims, nodes);
    }
    subtree(&mut items, 0, 0, extent, &mut nodes);
    let ordered = items.par_iter().map(|it| prims[it.prim as usize]).collect();
    (ordered, nodes)
}

/// Appends the nodes of the subtree over `items` (the primitives from `first` on, of
/// `extent`), its root first, then its first child's subtree, then its second's.
fn subtree(items: &mut [Item], first: usize, depth: u32, extent: Extent, nodes: &mut Vec<Node>) {
    let bounds = extent.bounds;
    let index = nodes.len();
    nodes.push(Node { bounds, offset: first as u32, count: items.len() as u32 });
    let Some((mid, [le, re])) = split(items, extent, depth) else { return };
    let parallel = items.len() >= PARALLEL_MIN;
    let (left, right) = items.split_at_mut(mid);
    let second = if parallel {
        let mut right_nodes = Vec::new();
        rayon::join(
            || subtree(left, first, depth + 1, le, nodes),
            || subtree(right, first + mid, depth + 1, re, &mut right_nodes),
        );
        // The second subtree's child links are relative to its own root.
        let base = nodes.len();
        nodes.extend(right_nodes.into_iter().map(|mut n| {
            if n.count == 0 {
                n.offset += base as u32;
            }
            n
        }));
        base
    } else {
        subtree(left, first, depth + 1, le, nodes);
        let base = nodes.len();
        subtree(right, first + mid, depth + 1, re, nodes);
        base
    };
    nodes[index] = Node { bounds, offset: second as u32, count: 0 };
}

/// Where to split `items` (reordering them): the size of the first part and the extents of
/// both parts, or `None` for a leaf.
fn split(items: &mut [Item], extent: Extent, depth: u32) -> Option<(usize, [Extent; 2])> {
    let n = items.len();
    if n <= LEAF_SIZE {
        return None;
    }
    let cb = extent.centroids;
    let size = cb.max - cb.min;
    if size.max_element() <= 0.0 {
        return None; // all centroids coincide: keep one leaf
    }
    let bin_of =
        |axis: usize| move |c: Vec3| (((c[axis] - cb.min[axis]) / size[axis] * BINS as f32) as usize).min(BINS - 1);
    // The cheapest split over the three axes (the first of equal costs).
    let mut best: Option<(f32, usize, usize, [Bin; BINS])> = None;
    for axis in (0..3).filter(|&a| size[a] > 0.0) {
        let bins = binned(items, &bin_of(axis));
        let (cost, last_left) = best_split(&bins);
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, axis, last_left, bins));
        }
    }
    let (cost, mut axis, last_left, bins) = best?;
    if cost == f32::INFINITY {
        // No axis separates the bins: the median split below goes along the widest.
        axis = size.max_position();
    }
    let bin_of = bin_of(axis);
    if cost >= extent.bounds.area() * n as f32 && n <= LEAF_MAX {
        return None;
    }
    let mid = if depth < MEDIAN_DEPTH { partition(items, |it| bin_of(it.centroid()) <= last_left) } else { 0 };
    if mid == 0 || mid == n {
        let m = n / 2;
        items.select_nth_unstable_by(m, |a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
        let (l, r) = items.split_at(m);
        return Some((m, [Extent::of(l), Extent::of(r)]));
    }
    let side = |bins: &[Bin]| bins.iter().fold(Extent::EMPTY, |e, b| e.union(b.0));
    Some((mid, [side(&bins[..=last_left]), side(&bins[last_left + 1..])]))
}

/// The items' bins (in parallel for many items: the union and the counts do not depend on
/// the order they are gathered in).
fn binned(items: &[Item], bin_of: &(impl Fn(Vec3) -> usize + Sync)) -> [Bin; BINS] {
    let gather = |items: &[Item]| {
        let mut bins = [(Extent::EMPTY, 0usize); BINS];
        for it in items {
            let b = &mut bins[bin_of(it.centroid())];
            *b = (b.0.add(it), b.1 + 1);
        }
        bins
    };
    if items.len() < PARALLEL_MIN {
        return gather(items);
    }
    let merge = |a: [Bin; BINS], b: [Bin; BINS]| std::array::from_fn(|k| (a[k].0.union(b[k].0), a[k].1 + b[k].1));
    items.par_chunks(PARALLEL_MIN).map(gather).reduce(|| [(Extent::EMPTY, 0usize); BINS], merge)
}

/// The cheapest split between bins, as (SAH cost, last bin of the first part): prefix and
/// suffix unions in one sweep each.
fn best_split(bins: &[Bin; BINS]) -> (f32, usize) {
    let mut right = [(Aabb::EMPTY, 0usize); BINS];
    let mut acc = (Aabb::EMPTY, 0);
    for k in (1..BINS).rev() {
        acc = (acc.0.union(bins[k].0.bounds), acc.1 + bins[k].1);
        right[k] = acc;
    }
    let mut best = (f32::INFINITY, 0);
    let mut left = (Aabb::EMPTY, 0);
    for k in 0..BINS - 1 {
        left = (left.0.union(bins[k].0.bounds), left.1 + bins[k].1);
        let (rb, rn) = right[k + 1];
        if left.1 == 0 || rn == 0 {
            continue;
        }
        let cost = left.0.area() * left.1 as f32 + rb.area() * rn as f32;
        if cost < best.0 {
            best = (cost, k);
        }
    }
    best
}

/// In-place partition: the elements satisfying `pred` first; returns their count.
fn partition<T>(v: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut k = 0;
    for i in 0..v.len() {
        if pred(&v[i]) {
            v.swap(i, k);
            k += 1;
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small triangles scattered in a box, and some coincident ones (equal centroids).
    fn triangles(n: usize) -> Vec<Primitive> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|k| {
                let v0 = if k % 10 == 0 { Vec3::ONE } else { Vec3::new(next(), next(), next()) * 100.0 };
                let e1 = Vec3::new(next(), next(), next());
                let e2 = Vec3::new(next(), next(), next());
                Primitive::Triangle { v0, e1, e2, surface: k as u32, attrs: u32::MAX }
            })
            .collect()
    }

    fn build_on(threads: usize, prims: &[Primitive]) -> (Vec<Primitive>, Vec<Node>) {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| build(prims.to_vec()))
    }

    fn key(n: &Node) -> ([f32; 6], u32, u32) {
        let b = n.bounds;
        ([b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z], n.offset, n.count)
    }

    fn surface(p: &Primitive) -> u32 {
        match *p {
            Primitive::Triangle { surface, .. } | Primitive::Sphere { surface, .. } => surface,
        }
    }

    #[test]
    fn the_tree_is_the_same_at_any_thread_count() {
        let prims = triangles(4 * PARALLEL_MIN);
        let (p1, n1) = build_on(1, &prims);
        let (p3, n3) = build_on(3, &prims);
        assert_eq!(n1.iter().map(key).collect::<Vec<_>>(), n3.iter().map(key).collect::<Vec<_>>());
        assert_eq!(p1.iter().map(surface).collect::<Vec<_>>(), p3.iter().map(surface).collect::<Vec<_>>());
    }

    #[test]
    fn every_primitive_is_in_one_leaf_inside_its_ancestors_boxes() {
        let prims = triangles(2 * PARALLEL_MIN + 123);
        let (ordered, nodes) = build_on(2, &prims);
        let inside = |a: Aabb, b: Aabb| a.min.cmpge(b.min).all() && a.max.cmple(b.max).all();
        let mut seen = vec![0u32; prims.len()];
        // (node, box of its parent)
        let mut stack = vec![(0usize, nodes[0].bounds)];
        while let Some((i, parent)) = stack.pop() {
            let n = nodes[i];
            assert!(inside(n.bounds, parent), "node {i} leaves its parent's box");
            if n.count > 0 {
                assert!(n.count as usize <= LEAF_MAX, "leaf {i} holds {}", n.count);
                for p in &ordered[n.offset as usize..(n.offset + n.count) as usize] {
                    assert!(inside(p.aabb(), n.bounds));
                    seen[surface(p) as usize] += 1;
                }
            } else {
                stack.push((i + 1, n.bounds));
                stack.push((n.offset as usize, n.bounds));
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "each primitive in exactly one leaf");
    }
}

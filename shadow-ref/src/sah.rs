//! A top-down binned SAH build of the binary BVH (Wald, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies", RT 2007): each node sorts its primitives' centroids into
//! [`BINS`] bins along each axis, sweeps the bins for the split of least surface-area cost, and
//! partitions; nodes of at most [`SWEEP`] primitives try every split of their sorted centroids.
//! Its cost is `O(n log n)` whatever the input.
//!
//! Why not `obvhs`'s PLOC: PLOC merges mutual nearest neighbours pass by pass, and when the
//! boxes overlap alike (a fan of needle triangles from one vertex, all of whose boxes hold the
//! fan's centre) few pairs agree per pass and the passes become linear in `n`: 100k needles
//! took 22 s to build (issue 51), where this build takes a fraction of a second. The output has
//! `obvhs`'s [`Bvh2`] layout (children after their parents, one primitive per leaf), so the
//! reinsertion optimiser, the CWBVH conversion and the wide BVH take it as they took PLOC's.
//!
//! The price, measured on an idle machine with `query_bench` (reference trace, M rays/s, two
//! or three runs): `bunny` 20.1-20.3 against PLOC's 18.8-19.8, `spot-self-shadow` 12.7 against
//! 12.4, `grass` 4.6 against 4.9 (its blades suit PLOC's bottom-up clustering; the sweep at
//! small nodes took it from 4.5).

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::node::Bvh2Node;

/// Bins per axis.
pub const BINS: usize = 16;

/// The BVH2 over `boxes` (one per primitive, in input order): `primitive_indices` maps leaf
/// slots to input indices.
pub fn build(boxes: &[Aabb]) -> Bvh2 {
    let n = boxes.len();
    let mut bvh = Bvh2 {
        children_are_ordered_after_parents: true,
        ..Bvh2::default()
    };
    if n == 0 {
        return bvh;
    }
    let centroids: Vec<Vec3A> = boxes.iter().map(Aabb::center).collect();
    let mut order: Vec<u32> = (0..n as u32).collect();
    bvh.nodes.reserve(2 * n - 1);
    bvh.nodes.push(Bvh2Node::new(Aabb::empty(), 0, 0));
    // (node, first primitive, end, depth).
    let mut work = vec![(0usize, 0usize, n, 1usize)];
    let mut max_depth = 1;
    while let Some((node, start, end, depth)) = work.pop() {
        max_depth = max_depth.max(depth);
        let range = &mut order[start..end];
        let bounds = range
            .iter()
            .fold(Aabb::empty(), |b, &i| b.union(&boxes[i as usize]));
        if range.len() == 1 {
            bvh.nodes[node] = Bvh2Node::new(bounds, 1, start as u32);
            continue;
        }
        let mid = start + split(range, boxes, &centroids);
        let first = bvh.nodes.len();
        bvh.nodes.push(Bvh2Node::new(Aabb::empty(), 0, 0));
        bvh.nodes.push(Bvh2Node::new(Aabb::empty(), 0, 0));
        bvh.nodes[node] = Bvh2Node::new(bounds, 0, first as u32);
        work.push((first + 1, mid, end, depth + 1));
        work.push((first, start, mid, depth + 1));
    }
    bvh.primitive_indices = order;
    bvh.max_depth = obvhs::bvh2::DEFAULT_MAX_STACK_DEPTH.max(max_depth + 1);
    bvh
}

/// Partitions `range` (at least two primitives) at the binned split of least SAH cost and
/// returns the size of the left part, at least one and less than the whole. Primitives whose
/// centroids coincide are halved in input order.
fn split(range: &mut [u32], boxes: &[Aabb], centroids: &[Vec3A]) -> usize {
    if range.len() <= SWEEP {
        return sweep_split(range, boxes, centroids);
    }
    let (lo, hi) = range.iter().fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), &i| (lo.min(centroids[i as usize]), hi.max(centroids[i as usize])),
    );
    let extent = hi - lo;
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        if !(extent[axis] > 0.0) {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of =
            |i: u32| (((centroids[i as usize][axis] - lo[axis]) * scale) as usize).min(BINS - 1);
        let mut count = [0usize; BINS];
        let mut bound = [Aabb::empty(); BINS];
        for &i in range.iter() {
            let b = bin_of(i);
            count[b] += 1;
            bound[b] = bound[b].union(&boxes[i as usize]);
        }
        // Costs of the left parts swept from the left, then of the right parts from the right.
        let mut left_cost = [0.0f32; BINS];
        let (mut acc, mut n) = (Aabb::empty(), 0usize);
        for k in 0..BINS - 1 {
            acc = acc.union(&bound[k]);
            n += count[k];
            left_cost[k] = if n > 0 {
                acc.half_area() * n as f32
            } else {
                0.0
            };
        }
        let (mut acc, mut n) = (Aabb::empty(), 0usize);
        for k in (1..BINS).rev() {
            acc = acc.union(&bound[k]);
            n += count[k];
            let left_n = range.len() - n;
            if n == 0 || left_n == 0 {
                continue;
            }
            let cost = left_cost[k - 1] + acc.half_area() * n as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, k));
            }
        }
    }
    let Some((_, axis, k)) = best else {
        return range.len() / 2;
    };
    let scale = BINS as f32 / extent[axis];
    let goes_left =
        |i: &u32| (((centroids[*i as usize][axis] - lo[axis]) * scale) as usize).min(BINS - 1) < k;
    let mut left = 0;
    for j in 0..range.len() {
        if goes_left(&range[j]) {
            range.swap(left, j);
            left += 1;
        }
    }
    left
}

/// Nodes of at most this many primitives are split by a full sweep over their sorted
/// centroids (every split on every axis) rather than by bins.
pub const SWEEP: usize = 64;

/// The split of least SAH cost among all `n - 1` splits of the centroid order on each axis
/// (`range` left sorted along the chosen axis); the size of the left part.
fn sweep_split(range: &mut [u32], boxes: &[Aabb], centroids: &[Vec3A]) -> usize {
    let n = range.len();
    let mut best = (f32::INFINITY, 0usize, n / 2);
    let mut right_cost = vec![0.0f32; n];
    for axis in 0..3 {
        range.sort_unstable_by(|a, b| {
            centroids[*a as usize][axis]
                .total_cmp(&centroids[*b as usize][axis])
                .then(a.cmp(b))
        });
        let mut acc = Aabb::empty();
        for k in (1..n).rev() {
            acc = acc.union(&boxes[range[k] as usize]);
            right_cost[k] = acc.half_area() * (n - k) as f32;
        }
        let mut acc = Aabb::empty();
        for k in 1..n {
            acc = acc.union(&boxes[range[k - 1] as usize]);
            let cost = acc.half_area() * k as f32 + right_cost[k];
            if cost < best.0 {
                best = (cost, axis, k);
            }
        }
    }
    let (_, axis, k) = best;
    range.sort_unstable_by(|a, b| {
        centroids[*a as usize][axis]
            .total_cmp(&centroids[*b as usize][axis])
            .then(a.cmp(b))
    });
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box(c: Vec3A, r: f32) -> Aabb {
        Aabb::new(c - Vec3A::splat(r), c + Vec3A::splat(r))
    }

    /// Every primitive sits in exactly one leaf whose box holds it, every inner node's box
    /// holds its children's, and children come after their parents.
    fn check(bvh: &Bvh2, boxes: &[Aabb]) {
        let mut seen = vec![0u32; boxes.len()];
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &bvh.nodes[i];
            if n.prim_count > 0 {
                for s in n.first_index..n.first_index + n.prim_count {
                    let p = bvh.primitive_indices[s as usize] as usize;
                    seen[p] += 1;
                    let b = &boxes[p];
                    assert!(n.aabb().min.cmple(b.min).all() && n.aabb().max.cmpge(b.max).all());
                }
            } else {
                for c in [n.first_index as usize, n.first_index as usize + 1] {
                    assert!(c > i);
                    let (a, b) = (n.aabb(), bvh.nodes[c].aabb());
                    assert!(a.min.cmple(b.min).all() && a.max.cmpge(b.max).all());
                    stack.push(c);
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "{seen:?}");
    }

    /// Issue 51: PLOC took 22 s on 100k needle triangles fanned from one vertex (every box
    /// holds the fan's centre). The binned build splits them like any other input: its depth
    /// stays logarithmic.
    #[test]
    fn a_fan_of_needle_triangles_gets_a_balanced_tree() {
        let n = 20_000;
        let boxes: Vec<Aabb> = (0..n)
            .map(|i| {
                let a = std::f32::consts::TAU * i as f32 / n as f32;
                let rim = Vec3A::new(a.cos(), 0.0, a.sin());
                Aabb::new(rim.min(Vec3A::ZERO), rim.max(Vec3A::ZERO))
            })
            .collect();
        let bvh = build(&boxes);
        check(&bvh, &boxes);
        let depth = tree_depth(&bvh);
        assert!(depth <= 4 * (n as f32).log2() as usize, "depth {depth}");
    }

    fn tree_depth(bvh: &Bvh2) -> usize {
        let mut deepest = 0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((i, d)) = stack.pop() {
            deepest = deepest.max(d);
            let n = &bvh.nodes[i];
            if n.prim_count == 0 {
                stack.push((n.first_index as usize, d + 1));
                stack.push((n.first_index as usize + 1, d + 1));
            }
        }
        deepest
    }

    #[test]
    fn every_primitive_lands_in_one_leaf_that_holds_it() {
        let boxes: Vec<Aabb> = (0..1000)
            .map(|i| {
                let t = i as f32 * 0.37;
                unit_box(
                    Vec3A::new(t.sin() * 5.0, t.cos() * 3.0, (i % 7) as f32),
                    0.1,
                )
            })
            .collect();
        check(&build(&boxes), &boxes);
        // Coincident centroids, and one primitive.
        let same = vec![unit_box(Vec3A::ONE, 1.0); 33];
        let bvh = build(&same);
        check(&bvh, &same);
        assert_eq!(bvh.nodes.len(), 65);
        check(&build(&same[..1]), &same[..1]);
    }
}

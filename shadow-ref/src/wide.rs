//! A wide BVH for the single-ray occlusion query and beam culling: sixteen children per node,
//! in four SIMD groups of four, collapsed from the BVH2 the reference builds (binned SAH, then
//! `obvhs`'s reinsertion), so only the layout and traversal are new here.
//!
//! Why a second layout: `obvhs`'s CWBVH (Ylitie, Karras and Laine, HPG 2017) stores child boxes
//! quantised to 8 bits, which suits a GPU's memory bandwidth; on a CPU every visited node is
//! decoded first. Here a node holds its children's boxes uncompressed, one SIMD lane per child
//! (structure of arrays, as in Wald et al., "Embree: A Kernel Framework for Efficient CPU Ray
//! Tracing", SIGGRAPH 2014, section 4), so one group test is six subtractions, six products and
//! the min/max reductions, four children at a time (SSE2 through `glam::Vec4`, scalar
//! elsewhere; the workspace builds for the machine it runs on, `.cargo/config.toml`, so the
//! same code gets the VEX encodings of AVX where there is one). Sixteen children per node, as in the multi-branching BVHs of Wald, Benthin and
//! Boulos, "Getting Rid of Packets" (RT 2008), make the tree shallow, so a segment visits few
//! nodes and a beam few levels (measured against four and eight: see `docs/benchmarks.md`).
//!
//! Robustness: the slab distances use `(bound - origin) * inverse`, and the far distance is
//! widened by a few ulps (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013), over triangle boxes
//! already padded at the build. A box test can therefore only accept too much, never reject a
//! box the exact triangle test needs; the answer is decided by the watertight triangle test
//! alone, the same as on the CWBVH path (tested to agree exactly).

use glam::{Vec3A, Vec4};
use obvhs::bvh2::Bvh2;

/// Marks a leaf child: bit 31 set, the leaf's number in the other bits.
const LEAF: u32 = 1 << 31;
/// An empty child slot (its box is empty too).
const EMPTY: u32 = u32::MAX;
/// Most primitives in one leaf: one four-triangle test.
pub const MAX_LEAF: usize = 4;
/// Traversal stack entries; a tree deeper than this allows is not built (the CWBVH answers).
const STACK: usize = 1024;
/// Relative widening of the far slab distance: `1 + 2 gamma(3)` of Ize's bound, rounded up.
const FAR_WIDEN: f32 = 1.0 + 8.0 * f32::EPSILON;

/// Groups of four children per node.
const HALVES: usize = 4;
/// Children per node.
const WIDTH: usize = 4 * HALVES;

/// One node: the boxes of its children, four to a group, one lane each, and the children.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct WideNode {
    /// Per group, `[min x, min y, min z, max x, max y, max z]` over its four children.
    bounds: [[Vec4; 6]; HALVES],
    /// Inner child: node index. Leaf child: [`LEAF`] and the leaf number. Empty slots have an
    /// empty box and are never visited.
    child: [u32; WIDTH],
}

/// The collapsed tree: nodes and its leaves' primitives.
#[derive(Debug, Clone)]
pub struct WideBvh {
    nodes: Vec<WideNode>,
    /// Primitive (input) indices in leaf order: a leaf's primitives are contiguous.
    order: Vec<u32>,
    /// Each leaf's range in `order`.
    leaves: Vec<std::ops::Range<u32>>,
}

impl WideBvh {
    /// Collapses `bvh2` into a wide tree whose leaves hold at most `max_leaf` primitives (a
    /// BVH2 subtree with that many or fewer becomes one leaf). Each node takes the two children
    /// of its BVH2 node and keeps opening the child with the largest surface area until it has
    /// sixteen (the greedy collapse of Wald, Benthin and Boulos 2008). `None` when the tree
    /// cannot be represented (a BVH2 leaf with more than [`MAX_LEAF`] primitives, 2^31 leaves
    /// or more, or deeper than the traversal stack allows).
    pub fn collapse(bvh2: &Bvh2, max_leaf: usize) -> Option<Self> {
        let nodes2 = &bvh2.nodes;
        if nodes2.is_empty() {
            return None;
        }
        let max_leaf = max_leaf.clamp(1, MAX_LEAF);
        let counts = subtree_counts(bvh2);
        // A BVH2 node becomes a leaf when it is one or when its subtree is small enough.
        let is_leaf = |i: usize| nodes2[i].prim_count > 0 || counts[i] as usize <= max_leaf;
        let mut out = Self {
            // Grown as needed: a node is 448 bytes and there are about a hundred BVH2 nodes
            // per node (reserving one per two BVH2 nodes took 3.6 GB at 8 million triangles).
            nodes: Vec::new(),
            order: Vec::with_capacity(bvh2.primitive_indices.len()),
            leaves: Vec::new(),
        };
        // (BVH2 node, output node, depth of the output node).
        let mut work = vec![(0usize, 0usize, 1usize)];
        out.nodes.push(empty_node());
        let mut depth = 1;
        let mut scratch = Vec::new();
        while let Some((n2, slot, d)) = work.pop() {
            depth = depth.max(d);
            let mut kids = arrayvec::ArrayVec::<usize, WIDTH>::new();
            if is_leaf(n2) {
                kids.push(n2);
            } else {
                let f = nodes2[n2].first_index as usize;
                kids.extend([f, f + 1]);
            }
            while kids.len() < WIDTH {
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|(_, k)| !is_leaf(**k))
                    .max_by(|a, b| {
                        let sa = nodes2[*a.1].aabb.half_area();
                        let sb = nodes2[*b.1].aabb.half_area();
                        sa.total_cmp(&sb)
                    })
                    .map(|(i, _)| i);
                let Some(i) = open else { break };
                let f = nodes2[kids[i]].first_index as usize;
                kids[i] = f;
                kids.push(f + 1);
            }
            for (lane, &k) in kids.iter().enumerate() {
                let b = &nodes2[k].aabb;
                let (h, l) = (lane / 4, lane % 4);
                for axis in 0..3 {
                    out.nodes[slot].bounds[h][axis][l] = b.min[axis];
                    out.nodes[slot].bounds[h][axis + 3][l] = b.max[axis];
                }
                out.nodes[slot].child[lane] = if is_leaf(k) {
                    out.leaf(bvh2, k, &mut scratch)?
                } else {
                    out.nodes.push(empty_node());
                    let child = out.nodes.len() - 1;
                    work.push((k, child, d + 1));
                    child as u32
                };
            }
        }
        if (WIDTH - 1) * depth + WIDTH > STACK {
            return None;
        }
        Some(out)
    }

    /// Appends the primitives of BVH2 subtree `n2` as a new leaf; the leaf child code. `stack`
    /// is scratch space.
    fn leaf(&mut self, bvh2: &Bvh2, n2: usize, stack: &mut Vec<usize>) -> Option<u32> {
        let first = self.order.len();
        stack.clear();
        stack.push(n2);
        while let Some(i) = stack.pop() {
            let n = &bvh2.nodes[i];
            if n.prim_count > 0 {
                let s = n.first_index as usize;
                self.order
                    .extend_from_slice(&bvh2.primitive_indices[s..s + n.prim_count as usize]);
            } else {
                stack.push(n.first_index as usize + 1);
                stack.push(n.first_index as usize);
            }
        }
        let count = self.order.len() - first;
        let number = self.leaves.len();
        if count == 0 || count > MAX_LEAF || number >= (EMPTY & !LEAF) as usize {
            return None;
        }
        self.leaves
            .push(u32::try_from(first).ok()?..u32::try_from(self.order.len()).ok()?);
        Some(LEAF | number as u32)
    }

    /// The primitives (input indices) of every leaf, by leaf number: one to [`MAX_LEAF`] each.
    pub fn leaves(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.leaves
            .iter()
            .map(|r| &self.order[r.start as usize..r.end as usize])
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Visits the leaves whose boxes the segment `origin + t dir`, `0 <= t <= t_max`, may touch,
    /// calling `test` with each leaf's number (as in [`WideBvh::leaves`]) until it returns
    /// true. Returns true when it did (the segment is blocked). `dir` must be finite and
    /// non-zero; negative zeros are harmless.
    #[inline]
    pub fn any_hit(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        t_max: f32,
        mut test: impl FnMut(usize) -> bool,
    ) -> bool {
        // A zero component gives an infinite inverse; clamping it keeps every product a number
        // (0 * 1e30 = 0, never 0 * inf = NaN) while still sending the slab to +-infinity.
        let inv = dir.recip().clamp(Vec3A::splat(-1e30), Vec3A::splat(1e30));
        let (ox, oy, oz) = (
            Vec4::splat(origin.x),
            Vec4::splat(origin.y),
            Vec4::splat(origin.z),
        );
        let (ix, iy, iz) = (Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z));
        // The far distances use the inverse widened by `FAR_WIDEN` (the same bound as widening
        // each far distance, one product fewer per node).
        let wide = inv * FAR_WIDEN;
        let (jx, jy, jz) = (
            Vec4::splat(wide.x),
            Vec4::splat(wide.y),
            Vec4::splat(wide.z),
        );
        // Near and far bound of each axis by the direction's sign.
        let near = |a: usize, i: f32| if i >= 0.0 { a } else { a + 3 };
        let (nx, ny, nz) = (near(0, inv.x), near(1, inv.y), near(2, inv.z));
        let (fx, fy, fz) = ((nx + 3) % 6, (ny + 3) % 6, (nz + 3) % 6);
        let t_far = Vec4::splat(t_max * FAR_WIDEN);
        let mut stack = Stack::new();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            let mut mask = 0u32;
            let mut entry = [0.0f32; WIDTH];
            for (h, b) in node.bounds.iter().enumerate() {
                let t0 = ((b[nx] - ox) * ix)
                    .max((b[ny] - oy) * iy)
                    .max((b[nz] - oz) * iz)
                    .max(Vec4::ZERO);
                let t1 = ((b[fx] - ox) * jx)
                    .min((b[fy] - oy) * jy)
                    .min((b[fz] - oz) * jz)
                    .min(t_far);
                mask |= t0.cmple(t1).bitmask() << (4 * h);
                entry[4 * h..4 * h + 4].copy_from_slice(&t0.to_array());
            }
            // Inner children go on the stack farthest first, so the nearest is visited next:
            // a blocked segment is usually answered by the first occluder it meets.
            let mut near = [(0.0f32, 0u32); WIDTH];
            let mut inner = 0;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let c = node.child[lane];
                if c & LEAF != 0 {
                    if test((c & !LEAF) as usize) {
                        return true;
                    }
                } else {
                    // Insertion by decreasing entry distance.
                    let t = entry[lane];
                    let mut k = inner;
                    while k > 0 && near[k - 1].0 < t {
                        near[k] = near[k - 1];
                        k -= 1;
                    }
                    near[k] = (t, c);
                    inner += 1;
                }
            }
            for &(_, c) in &near[..inner] {
                stack.push(c);
            }
        }
        false
    }
}

impl WideBvh {
    /// Visits the leaves of every child box that `outside` does not reject: `outside` gets a
    /// group of four child boxes of a node (`[min x, min y, min z, max x, max y, max z]`, one
    /// lane each) and returns a bit mask of those to skip; `leaf` gets a leaf's number and returns
    /// false to stop. Returns false when `leaf` stopped the traversal.
    pub fn visit(
        &self,
        mut outside: impl FnMut(&[Vec4; 6]) -> u32,
        mut leaf: impl FnMut(usize) -> bool,
    ) -> bool {
        let mut stack = Stack::new();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            let mut mask = 0u32;
            for (h, b) in node.bounds.iter().enumerate() {
                mask |= (!outside(b) & 0xf) << (4 * h);
            }
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let c = node.child[lane];
                if c == EMPTY {
                    continue;
                }
                if c & LEAF != 0 {
                    if !leaf((c & !LEAF) as usize) {
                        return false;
                    }
                } else {
                    stack.push(c);
                }
            }
        }
        true
    }
}

/// The traversal stack, uninitialised until pushed (a zeroed array would cost a memset per
/// ray). The build keeps trees shallow enough that it never overflows.
type Stack = arrayvec::ArrayVec<u32, STACK>;

fn empty_node() -> WideNode {
    let (inf, neg) = (Vec4::splat(f32::INFINITY), Vec4::splat(f32::NEG_INFINITY));
    WideNode {
        bounds: [[inf, inf, inf, neg, neg, neg]; HALVES],
        child: [EMPTY; WIDTH],
    }
}

/// Primitives under every BVH2 node.
fn subtree_counts(bvh2: &Bvh2) -> Vec<u32> {
    let nodes = &bvh2.nodes;
    let mut order = Vec::with_capacity(nodes.len());
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        order.push(i);
        if nodes[i].prim_count == 0 {
            stack.push(nodes[i].first_index as usize);
            stack.push(nodes[i].first_index as usize + 1);
        }
    }
    let mut counts = vec![0u32; nodes.len()];
    for &i in order.iter().rev() {
        let n = &nodes[i];
        counts[i] = if n.prim_count > 0 {
            n.prim_count
        } else {
            let f = n.first_index as usize;
            counts[f].saturating_add(counts[f + 1])
        };
    }
    counts
}

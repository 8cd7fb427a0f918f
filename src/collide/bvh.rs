//! A bounding-volume hierarchy over axis-aligned boxes: built once for a fixed list of items
//! (a mesh's triangles, a cloth's edges), refitted in linear time when they move, queried for
//! every item whose box overlaps a box, or for the nearest item to a point.
//!
//! Median split on the longest axis of the centroids, at most four items a leaf; nodes are
//! stored parent before children, so a refit is one backward sweep.

use crate::math::Vec3;

/// Items in a leaf, at most.
const LEAF: usize = 4;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (grows to anything it is joined with).
    pub fn empty() -> Aabb {
        Aabb {
            min: Vec3::repeat(f64::INFINITY),
            max: Vec3::repeat(f64::NEG_INFINITY),
        }
    }

    /// The box of some points.
    #[inline]
    pub fn of<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Aabb {
        let mut b = Aabb::empty();
        for p in points {
            b.grow(p);
        }
        b
    }

    #[inline]
    pub fn grow(&mut self, p: &Vec3) {
        // Component by component (the generic `inf` / `sup` cost several times as much).
        self.min = Vec3::new(self.min.x.min(p.x), self.min.y.min(p.y), self.min.z.min(p.z));
        self.max = Vec3::new(self.max.x.max(p.x), self.max.y.max(p.y), self.max.z.max(p.z));
    }

    /// This box grown by every difference `a[i] - base[i]`. Plain comparisons (a NaN is
    /// passed over, as by [`Aabb::grow`]) over the coordinates as one array, eight points at a
    /// time in 24 lanes (lane `k` holds coordinate `k % 3`) at the CPU's widest vectors, then
    /// the lanes folded: the self-collision's watches run it every step over the cloth.
    pub fn grown_by_differences(self, a: &[Vec3], base: &[Vec3]) -> Aabb {
        let n = a.len().min(base.len());
        let (a, base) = (&a[..n], &base[..n]);
        let whole = n / 8 * 8;
        let mut lo = [0.0; LANES];
        let mut hi = [0.0; LANES];
        for k in 0..LANES {
            (lo[k], hi[k]) = (self.min[k % 3], self.max[k % 3]);
        }
        differences_widest(
            bytemuck::cast_slice(&a[..whole]),
            bytemuck::cast_slice(&base[..whole]),
            &mut lo,
            &mut hi,
        );
        let mut min = [lo[0], lo[1], lo[2]];
        let mut max = [hi[0], hi[1], hi[2]];
        for k in 3..LANES {
            let c = k % 3;
            min[c] = if lo[k] < min[c] { lo[k] } else { min[c] };
            max[c] = if hi[k] > max[c] { hi[k] } else { max[c] };
        }
        for (p, o) in a[whole..].iter().zip(&base[whole..]) {
            for c in 0..3 {
                let d = p[c] - o[c];
                min[c] = if d < min[c] { d } else { min[c] };
                max[c] = if d > max[c] { d } else { max[c] };
            }
        }
        Aabb {
            min: Vec3::from(min),
            max: Vec3::from(max),
        }
    }

    pub fn join(&self, o: &Aabb) -> Aabb {
        let mut b = *self;
        b.grow(&o.min);
        b.grow(&o.max);
        b
    }

    /// The box grown by `r` on every side.
    #[inline]
    pub fn inflated(&self, r: f64) -> Aabb {
        Aabb {
            min: self.min.add_scalar(-r),
            max: self.max.add_scalar(r),
        }
    }

    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        // Every comparison made, none skipped: one branch, not six hard to predict.
        (self.min.x <= o.max.x)
            & (o.min.x <= self.max.x)
            & (self.min.y <= o.max.y)
            & (o.min.y <= self.max.y)
            & (self.min.z <= o.max.z)
            & (o.min.z <= self.max.z)
    }

    pub fn contains(&self, p: &Vec3) -> bool {
        (self.min.x <= p.x)
            & (p.x <= self.max.x)
            & (self.min.y <= p.y)
            & (p.y <= self.max.y)
            & (self.min.z <= p.z)
            & (p.z <= self.max.z)
    }

    /// The squared distance of the two furthest points of this box and `o`.
    pub fn farthest2(&self, o: &Aabb) -> f64 {
        (0..3)
            .map(|k| {
                let d = (self.max[k] - o.min[k]).max(o.max[k] - self.min[k]);
                d * d
            })
            .sum()
    }

    /// Squared distance from `p` to the box (0 inside).
    pub fn distance2(&self, p: &Vec3) -> f64 {
        let d = (self.min - p).sup(&Vec3::zeros()).sup(&(p - self.max));
        d.norm_squared()
    }

    /// Squared distance between the nearest points of this box and `o` (0 when they overlap):
    /// no point of one is nearer any point of the other.
    pub fn gap2(&self, o: &Aabb) -> f64 {
        let d = (self.min - o.max).sup(&Vec3::zeros()).sup(&(o.min - self.max));
        d.norm_squared()
    }

    /// How far apart this box and `o` are along the axis they are furthest apart on (0 when
    /// they overlap): either must move at least this far, in any direction, before they
    /// overlap.
    pub fn separation(&self, o: &Aabb) -> f64 {
        (o.min - self.max).sup(&(self.min - o.max)).max().max(0.0)
    }

    fn centre(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
}

/// Lanes of [`Aabb::grown_by_differences`]: eight points' coordinates.
const LANES: usize = 24;

crate::simd_dispatch! { fn differences_widest(a: &[f64], base: &[f64], lo: &mut [f64; LANES], hi: &mut [f64; LANES]) => differences }

/// `lo` and `hi` grown lane by lane by the differences `a - base`, taken `LANES` at a time
/// (both as long, a multiple of `LANES`).
#[inline(always)]
fn differences(a: &[f64], base: &[f64], lo: &mut [f64; LANES], hi: &mut [f64; LANES]) {
    for (p, o) in a.chunks_exact(LANES).zip(base.chunks_exact(LANES)) {
        for k in 0..LANES {
            let d = p[k] - o[k];
            lo[k] = if d < lo[k] { d } else { lo[k] };
            hi[k] = if d > hi[k] { d } else { hi[k] };
        }
    }
}

/// Splits a node's `items` as the build does: the lower half (by the centres along the axis
/// they spread most on) first, the item at the median in between.
fn split_at_median(items: &mut [u32], centres: &[Vec3]) {
    let spread = Aabb::of(items.iter().map(|&i| &centres[i as usize]));
    let axis = (spread.max - spread.min).imax();
    items.select_nth_unstable_by(items.len() / 2, |&a, &b| {
        centres[a as usize][axis].total_cmp(&centres[b as usize][axis])
    });
}

/// Fewest items a node must hold for [`split_items`] to split its halves on two threads.
const PARALLEL_SPLIT: usize = 16_384;

/// Every split of the tree over `items` (the nodes' item ranges as [`Bvh::try_build_on`]
/// makes them), the halves of large nodes on two threads when `parallel`.
fn split_items(items: &mut [u32], centres: &[Vec3], parallel: bool) {
    if items.len() <= LEAF {
        return;
    }
    split_at_median(items, centres);
    let large = parallel && items.len() >= PARALLEL_SPLIT;
    let (lower, upper) = items.split_at_mut(items.len() / 2);
    if large {
        rayon::join(
            || split_items(lower, centres, true),
            || split_items(upper, centres, true),
        );
    } else {
        split_items(lower, centres, false);
        split_items(upper, centres, false);
    }
}

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// A leaf's first item in `order` and count; an inner node's first child (`count` 0, the
    /// second child is `first + 1`).
    first: u32,
    count: u32,
}

/// The hierarchy; see the module docs.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Item indices, leaf by leaf.
    order: Vec<u32>,
    /// The items' boxes in the same order (`boxes[k]` is item `order[k]`'s), so a leaf's
    /// boxes lie together.
    boxes: Vec<Aabb>,
}

impl Bvh {
    /// Builds the hierarchy over `boxes` (item k has box k).
    pub fn build(boxes: &[Aabb]) -> Bvh {
        Self::build_on(boxes, false)
    }

    /// [`Bvh::build`], split on rayon's current pool when `parallel` (the same tree; see
    /// [`Bvh::try_build_on`]).
    pub fn build_on(boxes: &[Aabb], parallel: bool) -> Bvh {
        match Self::try_build_on(boxes, parallel) {
            Ok(bvh) => bvh,
            // As a `Vec` that cannot grow.
            Err(_) => std::alloc::handle_alloc_error(std::alloc::Layout::new::<Node>()),
        }
    }

    /// [`Bvh::build`], asking the allocator fallibly for everything whose size the item
    /// count sets (the walk's own list of nodes to split is as deep as the tree).
    pub fn try_build(boxes: &[Aabb]) -> Result<Bvh, std::collections::TryReserveError> {
        Self::try_build_on(boxes, false)
    }

    /// [`Bvh::try_build`], its splits made on rayon's current pool when `parallel`: the same
    /// tree either way (each node's split reads and reorders only its own items, so the order
    /// the nodes are split in changes nothing; the nodes are then numbered as one thread does).
    pub fn try_build_on(boxes: &[Aabb], parallel: bool) -> Result<Bvh, std::collections::TryReserveError> {
        let n = boxes.len();
        if n == 0 {
            return Ok(Bvh::default());
        }
        // Leaves hold at least LEAF / 2 items (a node of more than LEAF is halved): at most
        // 2n / LEAF leaves, and fewer than twice that in nodes (`the_nodes_fit_their_room`).
        let (mut nodes, mut order, mut sorted, mut centres) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        nodes.try_reserve_exact(4 * n / LEAF + 1)?;
        order.try_reserve_exact(n)?;
        sorted.try_reserve_exact(n)?;
        centres.try_reserve_exact(n)?;
        order.extend(0..n as u32);
        let mut bvh = Bvh {
            nodes,
            order,
            boxes: Vec::new(),
        };
        centres.extend(boxes.iter().map(Aabb::centre));
        bvh.nodes.push(Node {
            bounds: Aabb::empty(),
            first: 0,
            count: boxes.len() as u32,
        });
        if parallel {
            split_items(&mut bvh.order, &centres, true);
        }
        // (node, first item, item count): split until leaves are small (already split in
        // parallel: only numbered and bounded here).
        let mut todo = vec![(0usize, 0usize, boxes.len())];
        while let Some((node, lo, n)) = todo.pop() {
            let items = &mut bvh.order[lo..lo + n];
            bvh.nodes[node].bounds = items
                .iter()
                .fold(Aabb::empty(), |b, &i| b.join(&boxes[i as usize]));
            if n <= LEAF {
                bvh.nodes[node].first = lo as u32;
                bvh.nodes[node].count = n as u32;
                continue;
            }
            let half = n / 2;
            if !parallel {
                split_at_median(items, &centres);
            }
            let child = bvh.nodes.len();
            for _ in 0..2 {
                bvh.nodes.push(Node {
                    bounds: Aabb::empty(),
                    first: 0,
                    count: 0,
                });
            }
            bvh.nodes[node].first = child as u32;
            bvh.nodes[node].count = 0;
            todo.push((child, lo, half));
            todo.push((child + 1, lo + half, n - half));
        }
        sorted.extend(bvh.order.iter().map(|&i| boxes[i as usize]));
        bvh.boxes = sorted;
        Ok(bvh)
    }

    /// Items in the hierarchy.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// New boxes for the same items: the tree is kept, its bounds recomputed.
    pub fn refit(&mut self, boxes: &[Aabb]) {
        debug_assert_eq!(boxes.len(), self.order.len());
        for (b, &i) in self.boxes.iter_mut().zip(&self.order) {
            *b = boxes[i as usize];
        }
        for k in (0..self.nodes.len()).rev() {
            let Node { first, count, .. } = self.nodes[k];
            let (first, count) = (first as usize, count as usize);
            self.nodes[k].bounds = if count > 0 {
                self.boxes[first..first + count]
                    .iter()
                    .fold(Aabb::empty(), |b, o| b.join(o))
            } else {
                self.nodes[first].bounds.join(&self.nodes[first + 1].bounds)
            };
        }
    }

    /// The box of everything.
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::empty(), |n| n.bounds)
    }

    /// The tree against itself split into independent walks for [`Bvh::self_overlapping`]:
    /// node pairs whose item pairs together are every pair once, expanded level by level
    /// until there are at least `tasks` of them (fewer when the tree is small), for a pool.
    pub fn self_tasks(&self, tasks: usize) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        self.self_tasks_into(tasks, &mut out, &mut Vec::new());
        out
    }

    /// [`Bvh::self_tasks`] into `out`, with `spare` for the level being expanded: both keep
    /// their room from one call to the next (a self-collision look allocates nothing once its
    /// lists have grown; the lists are a few times `tasks` long, whatever the tree's size).
    pub fn self_tasks_into(&self, tasks: usize, out: &mut Vec<(u32, u32)>, spare: &mut Vec<(u32, u32)>) {
        out.clear();
        if self.nodes.is_empty() {
            return;
        }
        out.push((0, 0));
        while out.len() < tasks {
            spare.clear();
            let mut grew = false;
            for &(a, b) in out.iter() {
                let before = spare.len();
                self.expand(a, b, spare);
                grew |= !(spare.len() == before + 1 && spare[before] == (a, b));
            }
            std::mem::swap(out, spare);
            if !grew {
                break;
            }
        }
    }

    /// One level of the walk of node pair `(a, b)`: pushes its children's pairs onto `out`, or
    /// the pair itself when both are leaves (nothing when their bounds are apart).
    fn expand(&self, a: u32, b: u32, out: &mut Vec<(u32, u32)>) {
        let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
        if a == b {
            if na.count > 0 {
                out.push((a, b));
            } else {
                let c = na.first;
                out.extend([(c, c), (c + 1, c + 1), (c, c + 1)]);
            }
            return;
        }
        if !na.bounds.overlaps(&nb.bounds) {
            return;
        }
        match (na.count > 0, nb.count > 0) {
            (true, true) => out.push((a, b)),
            (true, false) => out.extend([(a, nb.first), (a, nb.first + 1)]),
            (false, true) => out.extend([(na.first, b), (na.first + 1, b)]),
            (false, false) => {
                let (ca, cb) = (na.first, nb.first);
                out.extend([(ca, cb), (ca, cb + 1), (ca + 1, cb), (ca + 1, cb + 1)]);
            }
        }
    }

    /// Calls `f(i, j)` once for every pair of distinct items under the node pair `task` (from
    /// [`Bvh::self_tasks`]) whose boxes overlap, `i` and `j` in no set order. The tree walked
    /// against itself visits each pair of overlapping nodes once, where a query per item walks
    /// from the root for each and meets each pair twice.
    pub fn self_overlapping(&self, task: (u32, u32), f: impl FnMut(u32, u32)) {
        self.walk_self(
            task,
            &mut Vec::new(),
            |k, l| self.boxes[k].overlaps(&self.boxes[l]),
            f,
        );
    }

    /// The items' `boxes` (item k's is `boxes[k]`) in the tree's order, for
    /// [`Bvh::self_overlapping_apart`].
    pub fn in_order(&self, boxes: &[Aabb]) -> Vec<Aabb> {
        let mut out = Vec::new();
        self.in_order_into(boxes, &mut out);
        out
    }

    /// [`Bvh::in_order`] appended to `out` (which the caller may have reserved fallibly).
    pub fn in_order_into(&self, boxes: &[Aabb], out: &mut Vec<Aabb>) {
        out.extend(self.order.iter().map(|&i| boxes[i as usize]));
    }

    /// As [`Bvh::self_overlapping`], but only the pairs whose `other` boxes (one per item, in
    /// the tree's order: [`Bvh::in_order`]) are apart: the self-collision's walk, which leaves
    /// out the triangles near each other at rest. Both tests are made for every pair of a
    /// leaf pair, and the one branch (mostly not taken: neighbours) is easy to predict.
    /// `stack` is the walk's (its room is kept for the next walk: no allocation once it has
    /// grown to a few times the tree's depth).
    pub fn self_overlapping_apart(
        &self,
        task: (u32, u32),
        other: &[Aabb],
        stack: &mut Vec<(u32, u32)>,
        f: impl FnMut(u32, u32),
    ) {
        debug_assert_eq!(other.len(), self.boxes.len());
        self.walk_self(
            task,
            stack,
            |k, l| self.boxes[k].overlaps(&self.boxes[l]) & !other[k].overlaps(&other[l]),
            f,
        );
    }

    /// Each node's box of the items' `boxes` (in the tree's order, [`Bvh::in_order`]), into
    /// `out` (which the caller may have reserved fallibly): boxes of another shape of the same
    /// items, for [`Bvh::self_overlapping_apart_within`].
    pub fn node_boxes_into(&self, boxes: &[Aabb], out: &mut Vec<Aabb>) {
        debug_assert_eq!(boxes.len(), self.boxes.len());
        out.clear();
        out.resize(self.nodes.len(), Aabb::empty());
        for k in (0..self.nodes.len()).rev() {
            let Node { first, count, .. } = self.nodes[k];
            let (first, count) = (first as usize, count as usize);
            out[k] = if count > 0 {
                boxes[first..first + count]
                    .iter()
                    .fold(Aabb::empty(), |b, o| b.join(o))
            } else {
                out[first].join(&out[first + 1])
            };
        }
    }

    /// As [`Bvh::self_overlapping_apart`], leaving out whole the node pairs whose `nodes`
    /// boxes (one per node: [`Bvh::node_boxes_into`]) hold no two points `within` or further
    /// apart: self-collision's walk where a proof covers the pairs nearer than that at rest.
    pub fn self_overlapping_apart_within(
        &self,
        task: (u32, u32),
        other: &[Aabb],
        nodes: &[Aabb],
        within: f64,
        stack: &mut Vec<(u32, u32)>,
        f: impl FnMut(u32, u32),
    ) {
        debug_assert_eq!(other.len(), self.boxes.len());
        debug_assert_eq!(nodes.len(), self.nodes.len());
        let within2 = within * within;
        self.walk_self_skipping(
            task,
            stack,
            |a, b| nodes[a as usize].farthest2(&nodes[b as usize]) < within2,
            |k, l| self.boxes[k].overlaps(&self.boxes[l]) & !other[k].overlaps(&other[l]),
            f,
        );
    }

    /// The tree against itself from the node pair `task`: `f(i, j)` for the items of the
    /// slots `k`, `l` (places in `order`) of every leaf pair whose bounds overlap where
    /// `pair(k, l)`.
    #[inline(always)]
    fn walk_self(
        &self,
        task: (u32, u32),
        stack: &mut Vec<(u32, u32)>,
        pair: impl Fn(usize, usize) -> bool,
        f: impl FnMut(u32, u32),
    ) {
        self.walk_self_skipping(task, stack, |_, _| false, pair, f);
    }

    /// [`Bvh::walk_self`], leaving out the node pairs where `skip(a, b)`.
    #[inline(always)]
    fn walk_self_skipping(
        &self,
        task: (u32, u32),
        stack: &mut Vec<(u32, u32)>,
        skip: impl Fn(u32, u32) -> bool,
        pair: impl Fn(usize, usize) -> bool,
        mut f: impl FnMut(u32, u32),
    ) {
        stack.clear();
        stack.push(task);
        while let Some((a, b)) = stack.pop() {
            if skip(a, b) {
                continue;
            }
            let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
            let leaves = na.count > 0 && nb.count > 0;
            if !leaves {
                // Never a leaf with itself: `expand` only pushes children.
                self.expand(a, b, stack);
                continue;
            }
            let range = |n: &Node| n.first as usize..(n.first + n.count) as usize;
            let (ra, rb) = (range(na), range(nb));
            if a == b {
                for k in ra.clone() {
                    for l in k + 1..ra.end {
                        if pair(k, l) {
                            f(self.order[k], self.order[l]);
                        }
                    }
                }
            } else if na.bounds.overlaps(&nb.bounds) {
                for k in ra {
                    if !self.boxes[k].overlaps(&nb.bounds) {
                        continue;
                    }
                    for l in rb.clone() {
                        if pair(k, l) {
                            f(self.order[k], self.order[l]);
                        }
                    }
                }
            }
        }
    }

    /// Calls `f` with every item whose box overlaps `q`.
    pub fn overlapping(&self, q: &Aabb, f: impl FnMut(u32)) {
        self.walk_overlapping::<false>(q, f);
    }

    /// As [`Bvh::overlapping`], returning how far apart `q` is from the boxes of every item
    /// it did not report: a lower bound of their [`Aabb::separation`]s from `q`, taken from the
    /// boxes the walk passed over (an item's box lies in its nodes'); infinite with none.
    pub fn overlapping_apart(&self, q: &Aabb, f: impl FnMut(u32)) -> f64 {
        self.walk_overlapping::<true>(q, f)
    }

    /// The walk of [`Bvh::overlapping`], keeping the gap when `GAP` (else infinite).
    #[inline(always)]
    fn walk_overlapping<const GAP: bool>(&self, q: &Aabb, mut f: impl FnMut(u32)) -> f64 {
        let mut gap = f64::INFINITY;
        if self.nodes.is_empty() {
            return gap;
        }
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !node.bounds.overlaps(q) {
                if GAP {
                    gap = gap.min(node.bounds.separation(q));
                }
                continue;
            }
            let first = node.first as usize;
            if node.count > 0 {
                let range = first..first + node.count as usize;
                for (&i, b) in self.order[range.clone()].iter().zip(&self.boxes[range]) {
                    if b.overlaps(q) {
                        f(i);
                    } else if GAP {
                        gap = gap.min(b.separation(q));
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = first as u32;
                stack[top + 1] = first as u32 + 1;
                top += 2;
            } else {
                // A subtree not walked (deeper than any tree built here): nothing is known
                // of its items.
                gap = 0.0;
            }
        }
        gap
    }

    /// The item nearest to `p` within squared distance `max2`, by `dist2(item)`, an item's
    /// exact squared distance (its box must hold it): `(item, squared distance)`.
    pub fn nearest(&self, p: &Vec3, max2: f64, mut dist2: impl FnMut(u32) -> f64) -> Option<(u32, f64)> {
        let mut best: Option<(u32, f64)> = None;
        let mut limit = max2;
        if self.nodes.is_empty() {
            return None;
        }
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if node.bounds.distance2(p) > limit {
                continue;
            }
            let first = node.first as usize;
            if node.count > 0 {
                for &i in &self.order[first..first + node.count as usize] {
                    let d = dist2(i);
                    if d <= limit {
                        limit = d;
                        best = Some((i, d));
                    }
                }
            } else if top + 2 <= stack.len() {
                // The nearer child last, so it is searched first.
                let (a, b) = (first as u32, first as u32 + 1);
                let near_a =
                    self.nodes[a as usize].bounds.distance2(p) <= self.nodes[b as usize].bounds.distance2(p);
                let (far, near) = if near_a { (b, a) } else { (a, b) };
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests;

//! A mesh collider's candidate lists (the module docs of `mesh.rs`, "Search"): each cloth
//! vertex's, triangle's and edge's candidates, kept from substep to substep and looked up again
//! only where the cloth may have come near what it did not find.

use super::*;

/// Each cloth vertex's, triangle's and edge's candidates (see the module docs), and which of
/// them have any (the contact loops visit only those, in ascending order).
#[derive(Clone, Debug, Default)]
pub(super) struct Candidates {
    pub(super) vertex: Vec<Vec<u32>>,
    pub(super) vertex_at: Vec<Vec3>,
    /// How far each cloth vertex may move from `vertex_at` before it looks again: half the
    /// skin, and half the gap its own and its triangles' and edges' last lookups left to what
    /// they did not find (`Bvh::overlapping_apart`), see `refresh_candidates`.
    pub(super) vertex_slack: Vec<f64>,
    /// The gaps of the last lookups of each cloth vertex, triangle and edge.
    pub(super) vertex_gap: Vec<f64>,
    pub(super) triangle_gap: Vec<f64>,
    pub(super) edge_gap: Vec<f64>,
    /// The vertices that looked at this refresh (set while it runs), and those still to look.
    pub(super) looked_now: Vec<bool>,
    pub(super) pending: Vec<u32>,
    /// The vertices whose slack a round of lookups changed.
    pub(super) affected: Vec<u32>,
    pub(super) triangle: Vec<Vec<u32>>,
    /// The cloth's edges (each once) and each one's candidate mesh edges.
    pub(super) cloth_edges: Vec<[u32; 2]>,
    pub(super) edge: Vec<Vec<u32>>,
    /// The cloth's triangles and edges of each vertex (a triangle or edge looks again when
    /// one of its vertices does).
    pub(super) vertex_triangles: Adjacency,
    pub(super) vertex_edges: Adjacency,
    /// The vertices, triangles and edges with candidates, ascending.
    pub(super) with_vertex: Vec<u32>,
    pub(super) with_triangle: Vec<u32>,
    pub(super) with_edge: Vec<u32>,
    /// Vertices, triangles and edges that look again at this substep.
    pub(super) looked: Vec<u32>,
    pub(super) dirty_triangles: Vec<u32>,
    pub(super) dirty_edges: Vec<u32>,
    /// Each cloth vertex's nearest triangle at the last substep (tested first).
    pub(super) nearest: Vec<u32>,
    /// Whether each cloth vertex touches the mesh at this substep (its edges then need no
    /// edge contact), and the vertices set.
    pub(super) touching: Vec<bool>,
    /// Whether each cloth vertex is inside the (closed) mesh at this substep (touching too).
    pub(super) inside: Vec<bool>,
    /// Each cloth vertex's (unsigned) distance from its nearest candidate triangle at this
    /// substep (infinite with none), for the continuous check's first cut.
    pub(super) distance: Vec<f64>,
    pub(super) touched: Vec<u32>,
    /// Every list must be looked up again (the mesh moved, or the cloth changed).
    pub(super) stale: bool,
    /// Entries in all the lists together.
    pub(super) total: usize,
}

impl Candidates {
    /// Holds nothing, as a new one, but keeps its lists' room: each list is emptied and every
    /// one is looked up again at the next refresh (`stale`). The lists by cloth vertex,
    /// triangle and edge keep their count (the cloth's), and the cloth's edges and incidences
    /// are kept: they are the same cloth's.
    pub(super) fn empty_keeping_room(&mut self) {
        for list in self
            .vertex
            .iter_mut()
            .chain(&mut self.triangle)
            .chain(&mut self.edge)
        {
            list.clear();
        }
        for list in [
            &mut self.with_vertex,
            &mut self.with_triangle,
            &mut self.with_edge,
            &mut self.looked,
            &mut self.dirty_triangles,
            &mut self.dirty_edges,
            &mut self.nearest,
            &mut self.touched,
            &mut self.pending,
            &mut self.affected,
        ] {
            list.clear();
        }
        for list in [
            &mut self.vertex_slack,
            &mut self.vertex_gap,
            &mut self.triangle_gap,
            &mut self.edge_gap,
        ] {
            list.clear();
        }
        self.looked_now.clear();
        self.touching.clear();
        self.inside.clear();
        self.distance.clear();
        self.stale = true;
        self.total = 0;
    }
}

/// Room for a mesh collider's candidate lists: this many entries a cloth vertex (vertex,
/// triangle and edge lists together) above [`CANDIDATES_FLOOR`]. A cloth near a mesh has a few
/// a vertex (a towel on the 10k-triangle ball: under 10); a margin many times the mesh's
/// triangles across makes every cloth vertex keep every triangle within it, and past this room
/// the step is refused with an error instead of filling memory.
pub const CANDIDATES_PER_VERTEX: usize = 256;
/// Room every cloth has, whatever its size (4 MB of entries).
pub const CANDIDATES_FLOOR: usize = 1 << 20;

/// The entries a mesh collider's candidate lists may hold against a cloth of `vertices`.
pub(crate) fn candidate_room(vertices: usize) -> usize {
    CANDIDATES_PER_VERTEX
        .saturating_mul(vertices)
        .saturating_add(CANDIDATES_FLOOR)
}

/// Refills `list` with what `query` finds (it calls its argument once a feature, and returns
/// the gap to what it did not find) within `room`: the gap, or `None` when the room refused.
fn refill(
    list: &mut Vec<u32>,
    room: &mut Room,
    query: impl FnOnce(&mut dyn FnMut(u32)) -> f64,
) -> Option<f64> {
    room.give_back(list.len());
    list.clear();
    let gap = query(&mut |t| {
        room.push(list, t);
    });
    room.full.is_none().then_some(gap)
}

/// Updates `with` (ascending indices of non-empty `lists`) after the lists of `changed` were
/// looked up again.
fn update_with(with: &mut Vec<u32>, lists: &[Vec<u32>], changed: &[u32]) {
    if changed.is_empty() {
        return;
    }
    with.retain(|&k| !lists[k as usize].is_empty());
    let before = with.len();
    with.extend(changed.iter().filter(|&&k| !lists[k as usize].is_empty()));
    if with.len() > before {
        with.sort_unstable();
        with.dedup();
    }
}

impl MeshCollider {
    /// Looks up again the candidates of every cloth vertex that moved more than its slack
    /// since it last looked, and of its triangles and edges (all of them after the mesh moved).
    /// Refused past the lists' room ([`CANDIDATES_PER_VERTEX`]); the caller then marks every
    /// list to be looked up again.
    ///
    /// **Why the lists stay whole.** Each lookup also returns its gap `G`: how far its query
    /// box is from every box it did not find, along the axis they are furthest apart on. A
    /// vertex's slack is `skin / 2 + min(G) / 2` over its own lookup and its triangles' and
    /// edges' (the rule before gaps, `skin / 2`, when every `G` is 0), recomputed whenever one
    /// of them looks. Then:
    /// - *the vertex's own list*: it has moved at most its slack, under `skin + G_v`, since
    ///   its query box (`margin + skin` around it) missed every other triangle's box by `G_v`;
    ///   so no triangle it did not find comes within `margin` of it;
    /// - *a triangle's (an edge's) list*: each of its vertices has moved at most twice its
    ///   slack, `skin + G_t`, since the triangle looked (it was within its slack of where it
    ///   last looked both then and now, and its slack held `G_t` from then on; a vertex past
    ///   the new slack when the triangle looks, looks with it). The query took the triangle's
    ///   box grown by `skin` against the mesh vertices' boxes grown by `margin + skin`, so a
    ///   mesh vertex it did not find is `2 skin + margin + G_t` from where the box was, and
    ///   the box has moved at most `skin + G_t`: still past `margin`.
    ///
    /// So what each list holds within `margin` (the contacts) is what a fresh lookup finds;
    /// far from the mesh, where nearly every lookup finds nothing, the gaps let the cloth
    /// move much further between lookups.
    pub(super) fn refresh_candidates(
        &mut self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        margin: f64,
        skin: f64,
    ) -> Result<(), Full> {
        // The lists apart from the mesh they are looked up in, for the refresh's steps.
        let mut c = std::mem::take(&mut self.cache);
        let done = self.refresh_lists(&mut c, x, cloth_triangles, margin + skin, skin);
        self.cache = c;
        done
    }

    /// [`Self::refresh_candidates`] on the lists `c`, `reach` the margin and the skin.
    fn refresh_lists(
        &self,
        c: &mut Candidates,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        reach: f64,
        skin: f64,
    ) -> Result<(), Full> {
        let capacity = candidate_room(x.len());
        let all = c.prepare(x, cloth_triangles);
        let mut room = Room::new(capacity.saturating_sub(c.total));
        // The entries the lists hold once the room is spent as far as it is.
        let refused = |c: &mut Candidates, room: &Room| {
            c.total = capacity - room.left();
            for &i in c.looked.iter().chain(&c.pending) {
                c.looked_now[i as usize] = false;
            }
            Err(room.full.unwrap_or(Full::Entries))
        };
        c.looked.clear();
        c.dirty_triangles.clear();
        c.dirty_edges.clear();
        c.pending.clear();
        c.pending.extend((0..x.len() as u32).filter(|&i| {
            all || moved(
                &c.vertex_at[i as usize],
                &x[i as usize],
                c.vertex_slack[i as usize],
            )
        }));
        // Rounds: the vertices that moved past their slack look, with their triangles and
        // edges; a vertex of those triangles and edges that is past its new slack looks in the
        // next round (rarely more than one).
        while !c.pending.is_empty() {
            let from = (c.dirty_triangles.len(), c.dirty_edges.len());
            for k in 0..c.pending.len() {
                let i = c.pending[k] as usize;
                if !self.vertex_looks(c, &mut room, x, i, reach) {
                    return refused(c, &room);
                }
                if !all {
                    c.dirty_triangles.extend_from_slice(c.vertex_triangles.row(i));
                    c.dirty_edges.extend_from_slice(c.vertex_edges.row(i));
                }
            }
            if all {
                c.dirty_triangles.extend(0..cloth_triangles.len() as u32);
                c.dirty_edges.extend(0..c.cloth_edges.len() as u32);
            } else {
                sort_dedup_tail(&mut c.dirty_triangles, from.0);
                sort_dedup_tail(&mut c.dirty_edges, from.1);
            }
            if !self.dirty_look(c, &mut room, x, cloth_triangles, skin, from) {
                return refused(c, &room);
            }
            c.next_round(x, cloth_triangles, skin, all, from);
        }
        c.finish(all);
        c.total = capacity - room.left();
        Ok(())
    }

    /// Cloth vertex `i` at `x` looks up its candidate triangles within `reach` into its list
    /// (in `room`); one that finds none inside a closed mesh takes the nearest of the whole
    /// mesh. False when the room is spent.
    fn vertex_looks(&self, c: &mut Candidates, room: &mut Room, x: &[Vec3], i: usize, reach: f64) -> bool {
        let p = x[i];
        c.vertex_at[i] = p;
        c.looked_now[i] = true;
        c.looked.push(i as u32);
        let q = Aabb { min: p, max: p }.inflated(reach);
        let Some(gap) = refill(&mut c.vertex[i], room, |push| {
            self.tri_bvh.overlapping_apart(&q, push)
        }) else {
            return false;
        };
        c.vertex_gap[i] = gap;
        let list = &mut c.vertex[i];
        if list.is_empty() && self.closed && self.tri_bvh.bounds().contains(&p) {
            // Possibly deep inside: the nearest triangle of the whole mesh decides.
            let (tris, target) = (&self.triangles, &self.target);
            let nearest = self.tri_bvh.nearest(&p, f64::INFINITY, |t| {
                closest_at(target, &tris[t as usize], &p).1.norm_squared()
            });
            if let Some((t, _)) = nearest {
                if !room.push(list, t) {
                    return false;
                }
                // Inside, the nearest of the whole mesh changes with every move: looked up
                // again at the next substep (outside, it is beyond reach: no contact).
                let (w, r) = closest_at(target, &tris[t as usize], &p);
                let n = pseudo_normal(
                    tris,
                    &self.neighbours,
                    &self.face_normal,
                    &self.vertex_normal,
                    t,
                    w,
                );
                if r.dot(&n) < 0.0 {
                    c.vertex_at[i] = Vec3::repeat(f64::INFINITY);
                }
            }
        }
        true
    }

    /// The cloth triangles and edges made dirty in this round (from `from`) look up their
    /// candidate mesh vertices and edges (the mesh's boxes hold the reach already; theirs grow
    /// by the skin). False when the room is spent.
    fn dirty_look(
        &self,
        c: &mut Candidates,
        room: &mut Room,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        skin: f64,
        (triangles_from, edges_from): (usize, usize),
    ) -> bool {
        for &t in &c.dirty_triangles[triangles_from..] {
            let tri = &cloth_triangles[t as usize];
            let q = Aabb::of(tri.iter().map(|&i| &x[i as usize])).inflated(skin);
            let Some(gap) = refill(&mut c.triangle[t as usize], room, |push| {
                self.vert_bvh.overlapping_apart(&q, push)
            }) else {
                return false;
            };
            c.triangle_gap[t as usize] = gap;
        }
        for &e in &c.dirty_edges[edges_from..] {
            let [i0, i1] = c.cloth_edges[e as usize];
            let q = Aabb::of([&x[i0 as usize], &x[i1 as usize]]).inflated(skin);
            let Some(gap) = refill(&mut c.edge[e as usize], room, |push| {
                self.edge_bvh.overlapping_apart(&q, push)
            }) else {
                return false;
            };
            c.edge_gap[e as usize] = gap;
        }
        true
    }
}

/// Whether a vertex at `p` has moved past `slack` from `at`.
fn moved(at: &Vec3, p: &Vec3, slack: f64) -> bool {
    (p - at).norm_squared() > slack * slack
}

impl Candidates {
    /// Sizes the lists for a cloth at `x` of `cloth_triangles` (its edges and incidences
    /// found once); whether every list is looked up again (the mesh moved, or the cloth
    /// changed), every list then emptied.
    fn prepare(&mut self, x: &[Vec3], cloth_triangles: &[[u32; 3]]) -> bool {
        let c = self;
        let resized = c.vertex.len() != x.len() || c.triangle.len() != cloth_triangles.len();
        if resized || c.cloth_edges.is_empty() {
            // The cloth's edges and incidences once (a moving mesh makes every call `all`).
            c.cloth_edges = edges_of(cloth_triangles);
            c.vertex_triangles = Adjacency::triangles(x.len(), cloth_triangles);
            c.vertex_edges = Adjacency::edges(x.len(), &c.cloth_edges);
        }
        let all = c.stale || resized;
        if all {
            c.vertex.resize_with(x.len(), Vec::new);
            c.vertex_at.resize(x.len(), Vec3::zeros());
            c.triangle.resize_with(cloth_triangles.len(), Vec::new);
            c.edge.resize_with(c.cloth_edges.len(), Vec::new);
            for list in c.vertex.iter_mut().chain(&mut c.triangle).chain(&mut c.edge) {
                list.clear();
            }
            // Every list is looked up below, and every gap with it.
            c.vertex_slack.resize(x.len(), 0.0);
            c.vertex_gap.resize(x.len(), 0.0);
            c.triangle_gap.resize(cloth_triangles.len(), 0.0);
            c.edge_gap.resize(c.cloth_edges.len(), 0.0);
            c.looked_now.resize(x.len(), false);
            c.total = 0;
            c.stale = false;
        }
        all
    }

    /// The new slacks of the vertices that looked in this round and of every vertex of the
    /// triangles and edges that looked (from `from`; a vertex in no triangle has only its own
    /// lookup): those past theirs look in the next round.
    fn next_round(
        &mut self,
        x: &[Vec3],
        cloth_triangles: &[[u32; 3]],
        skin: f64,
        all: bool,
        (triangles_from, edges_from): (usize, usize),
    ) {
        let c = self;
        c.affected.clear();
        if all {
            c.affected.extend(0..x.len() as u32);
        } else {
            c.affected.extend_from_slice(&c.pending);
            c.affected.extend(
                c.dirty_triangles[triangles_from..]
                    .iter()
                    .flat_map(|&t| cloth_triangles[t as usize])
                    .chain(
                        c.dirty_edges[edges_from..]
                            .iter()
                            .flat_map(|&e| c.cloth_edges[e as usize]),
                    ),
            );
            sort_dedup_tail(&mut c.affected, 0);
        }
        c.pending.clear();
        for &b in &c.affected {
            let b = b as usize;
            let gap = c
                .vertex_triangles
                .row(b)
                .iter()
                .map(|&t| c.triangle_gap[t as usize])
                .chain(c.vertex_edges.row(b).iter().map(|&e| c.edge_gap[e as usize]))
                .fold(c.vertex_gap[b], f64::min);
            let slack = if skin > 0.0 { 0.5 * (skin + gap) } else { 0.0 };
            c.vertex_slack[b] = slack;
            if !c.looked_now[b] && moved(&c.vertex_at[b], &x[b], slack) {
                c.looked_now[b] = true;
                c.pending.push(b as u32);
            }
        }
    }

    /// The refresh is done: the looked flags cleared, the dirty lists each once, and the
    /// lists of what has candidates brought up to date.
    fn finish(&mut self, all: bool) {
        let c = self;
        for &i in &c.looked {
            c.looked_now[i as usize] = false;
        }
        if !all {
            c.dirty_triangles.sort_unstable();
            c.dirty_triangles.dedup();
            c.dirty_edges.sort_unstable();
            c.dirty_edges.dedup();
        }
        if all {
            c.with_vertex.clear();
            c.with_triangle.clear();
            c.with_edge.clear();
        }
        update_with(&mut c.with_vertex, &c.vertex, &c.looked);
        update_with(&mut c.with_triangle, &c.triangle, &c.dirty_triangles);
        update_with(&mut c.with_edge, &c.edge, &c.dirty_edges);
    }
}

/// Sorts `list[from..]` and removes its repeats in place, leaving `list[..from]` as it is.
fn sort_dedup_tail(list: &mut Vec<u32>, from: usize) {
    list[from..].sort_unstable();
    let mut kept = from;
    for k in from..list.len() {
        if k == from || list[k] != list[kept - 1] {
            list[kept] = list[k];
            kept += 1;
        }
    }
    list.truncate(kept);
}

//! Size grown from the surface (AG1 + AG3): with seeds `(x_i, h_i)` (surface
//! points and their sizes) and slope `c = g - 1`,
//!
//! `f(x) = min_i h_i + c |x - x_i|`,
//!
//! the largest c-Lipschitz field that does not exceed any `h_i`.
//!
//! Evaluating the min over all seeds is O(N), so an octree is built once:
//! - each cell carries the seeds that can be the minimum somewhere in it
//!   (lower bound `h_j + c dist(x_j, cell)` <= an upper bound of `f` on the
//!   cell), filtered from its parent's; below far cells, seeds that could
//!   lower `f` by less than 1% are dropped;
//! - near leaves (a seed within one cell size, at most `NEAR_MAX` seeds after
//!   a 2x2x2 sub-cell test) evaluate the min over their seeds: exact at the
//!   surface points whose own size is not dominated by a neighbour's growth
//!   (the others may lie in far leaves: within 2%);
//! - far leaves store `f` at their 8 corners and interpolate trilinearly;
//!   they are split until the interpolant matches `f` at the centre and face
//!   centres to 2% (over) / 20% (under). The concave kinks where cones meet
//!   are underestimated (the safe side: smaller elements);
//! - cells wholly outside the surface (`outside.rs`, when the build is
//!   given the surface) are far leaves at once: no size is asked for there
//!   (sphere_1e6: 118k nodes -> 87k, torus_1e6: 216k -> 170k, the build
//!   26 % and 40 % faster);
//! - the build passes over a cell's list once for all eight children's
//!   lists, and once for a far cell's 15 values, with the roundings of a
//!   pass per child or point (the same octree; 30-45 % faster).
//!
//! Queries descend the octree (no allocation), then do <= `NEAR_MAX` cone
//! evaluations or one trilinear interpolation. A [`GrowthCursor`] remembers
//! the last leaf, so nearby queries skip the descent.
use crate::outside::Outside;
use crate::share::{Alone, OctreeShare, Subtree};
use parafront_geom::{dist, P3};
use rayon::prelude::*;

mod near;
mod query;

use near::NearLists;

/// Cells with a seed closer than this many cell sizes are near leaves.
const NEAR_FACTOR: f64 = 1.0;
/// A near cell with more candidates is split (unless forced to be a leaf).
const NEAR_MAX: usize = 40;
/// Candidate lists of forced leaves are cut to this many (smallest bound).
const FORCED_MAX: usize = 256;
/// Far cells: allowed relative over- / under-estimate at the test points.
const TOL_OVER: f64 = 0.02;
const TOL_UNDER: f64 = 0.2;
/// Split far cells pass their children only the seeds that may lower f by
/// more than this fraction (the seed bounding f on the child always stays).
const PRUNE_EPS: f64 = 0.01;
const MAX_DEPTH: u32 = 24;
/// Cells the build's first phase leaves for the second, whose subtrees are
/// built in parallel (and over processes): many more than threads, so
/// that the uneven subtrees balance.
const FRONTIER: usize = 512;

const KIND_SHIFT: u32 = 30;
const IDX_MASK: u32 = (1 << KIND_SHIFT) - 1;
const K_INTERNAL: u32 = 0;
const K_NEAR: u32 = 1;
const K_FAR: u32 = 2;

/// A seed: position and size, kept together for cache locality.
#[derive(Clone, Copy, Debug)]
struct Seed {
    p: P3,
    h: f64,
}

#[inline(always)]
fn point_box_d2(p: P3, lo: P3, hi: P3) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        let e = (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0);
        d2 += e * e;
    }
    d2
}

impl Subtree {
    /// Cell `node`'s decision: a leaf's entry, or a block of eight child
    /// nodes (their first index and seed lists, to push).
    fn record(&mut self, node: usize, dec: Decision) -> Option<(usize, Vec<Vec<u32>>)> {
        match dec {
            Decision::Near(list) => {
                self.nodes[node] = (K_NEAR << KIND_SHIFT) | self.near.len() as u32;
                self.near.push((self.cand.len() as u32, list.len() as u32));
                self.cand.extend_from_slice(&list);
                None
            }
            Decision::Far(v) => {
                self.nodes[node] = (K_FAR << KIND_SHIFT) | self.far.len() as u32;
                self.far.push(v);
                None
            }
            Decision::Split(lists) => {
                let first = self.nodes.len();
                self.nodes[node] = first as u32;
                self.nodes.extend_from_slice(&[0; 8]);
                Some((first, lists))
            }
        }
    }
}

/// The eight children of split cell `p`, their nodes from `first`, with
/// their seed lists.
fn children(p: &Pending, first: usize, lists: Vec<Vec<u32>>) -> impl Iterator<Item = Pending> + '_ {
    let h = p.s / 2.0;
    lists
        .into_iter()
        .enumerate()
        .map(move |(ch, list)| Pending {
            node: first + ch,
            lo: corner(p.lo, h, ch),
            s: h,
            depth: p.depth + 1,
            list,
        })
}

enum Decision {
    Near(Vec<u32>),
    Far([f64; 8]),
    Split(Vec<Vec<u32>>),
}

/// Build statistics (for reports and tests).
#[derive(Clone, Debug, Default)]
pub struct GrowthStats {
    /// Surface points the size grows from.
    pub seeds: usize,
    /// Octree nodes.
    pub nodes: usize,
    /// Leaves that take the min over a list of candidate seeds.
    pub near_leaves: usize,
    /// Leaves that interpolate the field from their corners.
    pub far_leaves: usize,
    /// Candidate seeds over all near leaves.
    pub candidates: usize,
    /// Near leaves forced by the depth or node cap whose list was cut: the
    /// field may be too large there.
    pub truncated: usize,
    /// Depth of the octree.
    pub depth: u32,
    /// Bytes of the octree, its lists and seeds (an estimate).
    pub bytes: usize,
}

/// Remembers the last octree leaf for [`SurfaceGrowth::size_with`].
#[derive(Clone, Copy, Debug)]
pub struct GrowthCursor {
    code: u32,
    lo: P3,
    s: f64,
}

impl Default for GrowthCursor {
    fn default() -> Self {
        GrowthCursor {
            code: u32::MAX,
            lo: [0.0; 3],
            s: -1.0,
        }
    }
}

/// The surface-grown size field (see the module doc).
#[derive(Clone, Debug)]
pub struct SurfaceGrowth {
    /// Seeds in Morton order (nearby seeds nearby in memory).
    seeds: Vec<Seed>,
    c: f64,
    /// The field is `min(f, cap)`.
    cap: f64,
    root_lo: P3,
    root_s: f64,
    nodes: Vec<u32>,
    /// The near leaves' seed ids.
    near: NearLists,
    far: Vec<[f64; 8]>,
    stats: GrowthStats,
}

/// A cell waiting for its decision, with the seeds that can be the minimum
/// somewhere in it (a subset of its parent's).
struct Pending {
    node: usize,
    lo: P3,
    s: f64,
    depth: u32,
    list: Vec<u32>,
}

impl SurfaceGrowth {
    /// `seeds`: (position, size > 0) pairs; `slope` = gradation - 1 >= 0.
    /// Positions must be finite. With no seeds the field is +inf.
    pub fn new(seeds: &[(P3, f64)], slope: f64) -> SurfaceGrowth {
        Self::with_cap(seeds, slope, f64::INFINITY)
    }

    /// The field `min(f, cap)`: what a size capped at `cap` needs. Seeds of
    /// size `cap` or more never lower it and are dropped, and cells where
    /// every cone is above `cap` are leaves at once; with a global size
    /// (every seed clamped to it) most of the octree goes (sphere_5e6 at
    /// 0.021: 2.2 s -> 0.24 s on 2 threads).
    pub fn with_cap(seeds: &[(P3, f64)], slope: f64, cap: f64) -> SurfaceGrowth {
        Self::build(seeds, slope, cap, None, &Alone)
    }

    /// [`with_cap`](Self::with_cap) for the domain bounded by the surface
    /// `tris` of `points` (the seeds are its points): the octree is not
    /// refined where its cube lies outside the surface, which no size is
    /// asked for.
    pub fn in_domain(
        seeds: &[(P3, f64)],
        slope: f64,
        cap: f64,
        points: &[P3],
        tris: &[[u32; 3]],
    ) -> SurfaceGrowth {
        Self::in_domain_shared(seeds, slope, cap, points, tris, &Alone)
    }

    /// [`in_domain`](Self::in_domain), its octree's subtrees built where
    /// `share` says (the same field on every process).
    pub fn in_domain_shared(
        seeds: &[(P3, f64)],
        slope: f64,
        cap: f64,
        points: &[P3],
        tris: &[[u32; 3]],
        share: &dyn OctreeShare,
    ) -> SurfaceGrowth {
        Self::build(seeds, slope, cap, Some((points, tris)), share)
    }

    fn build(
        seeds: &[(P3, f64)],
        slope: f64,
        cap: f64,
        domain: Option<(&[P3], &[[u32; 3]])>,
        share: &dyn OctreeShare,
    ) -> SurfaceGrowth {
        // The tree spans every seed's box, the dropped ones too: the kept
        // seeds can sit in a corner of the surface (a small feature under a
        // global size), and a query outside the tree's box is clamped to it.
        let mut bb = parafront_geom::Aabb::from_points(seeds.iter().map(|s| &s.0));
        let seeds: Vec<(P3, f64)> = seeds.iter().copied().filter(|s| s.1 < cap).collect();
        let seeds = &seeds[..];
        if bb.is_empty() {
            bb = parafront_geom::Aabb {
                min: [0.0; 3],
                max: [0.0; 3],
            };
        }
        let ext = (0..3).map(|k| bb.max[k] - bb.min[k]).fold(0.0, f64::max);
        // A margin so that points just outside the surface's box are not clamped.
        let root_s = (ext * 1.1).max(1e-300);
        let cen = bb.center();
        let root_lo = [
            cen[0] - root_s / 2.0,
            cen[1] - root_s / 2.0,
            cen[2] - root_s / 2.0,
        ];
        let morton = |p: P3| parafront_geom::morton_key(p, root_lo, root_s);
        let mut s: Vec<Seed> = seeds.iter().map(|&(p, h)| Seed { p, h }).collect();
        s.sort_by_cached_key(|sd| morton(sd.p));
        let mut g = SurfaceGrowth {
            seeds: s,
            c: slope,
            cap,
            root_lo,
            root_s,
            nodes: vec![0],
            near: NearLists::default(),
            far: Vec::new(),
            stats: GrowthStats {
                seeds: seeds.len(),
                ..Default::default()
            },
        };
        if slope > 0.0 {
            // Where the cube lies outside the surface: left coarse.
            let outside = domain.and_then(|(p, t)| Outside::new(root_lo, root_s, p, t));
            g.build_octree(outside.as_ref(), share);
        } else {
            // No growth: the field is the smallest seed size everywhere.
            let hmin = g.seeds.iter().map(|s| s.h).fold(cap, f64::min);
            g.nodes[0] = K_FAR << KIND_SHIFT;
            g.far.push([hmin; 8]);
        }
        g
    }

    #[inline(always)]
    fn cone(&self, j: u32, x: P3) -> f64 {
        let sd = &self.seeds[j as usize];
        sd.h + self.c * dist(x, sd.p)
    }

    /// The field (uncapped) at `N` points, in one pass over `list`: each
    /// cone as `dist` rounds it, and `min` is exact in any order, so the
    /// values are those of a pass per point.
    fn min_at<const N: usize>(&self, list: &[u32], pts: &[P3; N]) -> [f64; N] {
        const { assert!(N.is_multiple_of(2), "points in pairs") };
        let [xs, ys, zs] = [0, 1, 2].map(|k| pts.map(|p| p[k]));
        let mut m = [f64::INFINITY; N];
        for &j in list {
            let sd = &self.seeds[j as usize];
            // Two points per step, written out: the pairs vectorise (two
            // square roots per instruction), a loop per point did not.
            for i in (0..N).step_by(2) {
                let (dx0, dy0, dz0) = (xs[i] - sd.p[0], ys[i] - sd.p[1], zs[i] - sd.p[2]);
                let (dx1, dy1, dz1) = (
                    xs[i + 1] - sd.p[0],
                    ys[i + 1] - sd.p[1],
                    zs[i + 1] - sd.p[2],
                );
                let v0 = sd.h + self.c * (dx0 * dx0 + dy0 * dy0 + dz0 * dz0).sqrt();
                let v1 = sd.h + self.c * (dx1 * dx1 + dy1 * dy1 + dz1 * dz1).sqrt();
                // `f64::min`, as no cone is NaN: a select.
                m[i] = if v0 < m[i] { v0 } else { m[i] };
                m[i + 1] = if v1 < m[i + 1] { v1 } else { m[i + 1] };
            }
        }
        m
    }

    /// The field `min(f, cap)` at `N` points ([`min_at`](Self::min_at)).
    fn capped_at<const N: usize>(&self, list: &[u32], pts: &[P3; N]) -> [f64; N] {
        self.min_at(list, pts).map(|f| f.min(self.cap))
    }

    /// For each child `ch` of the cell `[lo, lo+2h]` (`corner(lo, h, ch)`),
    /// the seeds of `list` that can be the minimum somewhere in it: lower
    /// bound `h_j + c dist(x_j, child)` <= an upper bound of `f` on the
    /// child. Exact when `list` is exact for a box around the cell; `eps >
    /// 0` drops seeds that improve `f` by less than that fraction.
    ///
    /// One pass over the list for the eight children (the centre minimum),
    /// one for their bounds: per axis a seed has two offsets, one per half,
    /// and the eight children combine them, each in the order and with the
    /// roundings of `dist` and `point_box_d2` (the lists do not depend on
    /// the fusing).
    fn child_lists(&self, list: &[u32], lo: P3, h: f64, eps: f64) -> [Vec<u32>; 8] {
        self.child_lists_and::<false>(list, lo, h, eps).0
    }

    /// [`child_lists`](Self::child_lists), and with `UNION` their union:
    /// the seeds of `list` in any child's list, in `list`'s order (the
    /// near cells' test wants it, and a sort of the eight lists joined
    /// was a tenth of the build).
    fn child_lists_and<const UNION: bool>(
        &self,
        list: &[u32],
        lo: P3,
        h: f64,
        eps: f64,
    ) -> ([Vec<u32>; 8], Vec<u32>) {
        let c = self.c;
        // The halves' bounds and centres per axis: [lower, upper].
        let los = [0, 1, 2].map(|k| [lo[k], lo[k] + h]);
        let his = [0, 1, 2].map(|k| [los[k][0] + h, los[k][1] + h]);
        let cens = [0, 1, 2].map(|k| [los[k][0] + h / 2.0, los[k][1] + h / 2.0]);
        let bit = |ch: usize, k: usize| (ch >> k) & 1;
        let mut best = [u32::MAX; 8];
        let mut fc = [f64::INFINITY; 8];
        for &j in list {
            let sd = &self.seeds[j as usize];
            let sq = [0, 1, 2].map(|k| {
                let a = cens[k][0] - sd.p[k];
                let b = cens[k][1] - sd.p[k];
                [a * a, b * b]
            });
            let mut v = [0.0; 8];
            for (ch, v) in v.iter_mut().enumerate() {
                let d2 = sq[0][bit(ch, 0)] + sq[1][bit(ch, 1)] + sq[2][bit(ch, 2)];
                *v = sd.h + c * d2.sqrt();
            }
            for ch in 0..8 {
                if v[ch] < fc[ch] {
                    (best[ch], fc[ch]) = (j, v[ch]);
                }
            }
        }
        // f is c-Lipschitz: f <= f(centre) + c * half-diagonal on a child.
        let u = fc.map(|f| ((f + c * h * 0.5 * 3f64.sqrt()) * (1.0 + 1e-12)).min(self.cap));
        // Which children keep each seed, as a mask, then lists of their
        // exact size: pushes that grew eight lists were a tenth of the build.
        let mut masks: Vec<u8> = Vec::with_capacity(list.len());
        let mut count = [0usize; 8];
        for &j in list {
            let sd = &self.seeds[j as usize];
            let sq = [0, 1, 2].map(|k| {
                let e = |i: usize| (los[k][i] - sd.p[k]).max(sd.p[k] - his[k][i]).max(0.0);
                let (a, b) = (e(0), e(1));
                [a * a, b * b]
            });
            let mut m = 0u8;
            for ch in 0..8 {
                let d2 = 0.0 + sq[0][bit(ch, 0)] + sq[1][bit(ch, 1)] + sq[2][bit(ch, 2)];
                let keep = (sd.h + c * d2.sqrt()) * (1.0 + eps) <= u[ch];
                m |= (keep as u8) << ch;
                count[ch] += keep as usize;
            }
            masks.push(m);
        }
        // One more for the bounding seed below.
        let mut out: [Vec<u32>; 8] = count.map(|n| Vec::with_capacity(n + 1));
        let mut union = Vec::new();
        for (&j, &m) in list.iter().zip(&masks) {
            for (ch, out) in out.iter_mut().enumerate() {
                if m >> ch & 1 == 1 {
                    out.push(j);
                }
            }
            if UNION && m != 0 {
                union.push(j);
            }
        }
        // With eps > 0 the seed that bounds f on a child must stay.
        for (ch, out) in out.iter_mut().enumerate() {
            if best[ch] != u32::MAX && !out.contains(&best[ch]) {
                out.push(best[ch]);
                if UNION && !union.contains(&best[ch]) {
                    union.push(best[ch]);
                }
            }
        }
        (out, union)
    }

    /// The octree in two phases: breadth first to a frontier of about
    /// [`FRONTIER`] cells, the same on every process, then the frontier's
    /// subtrees, each depth first on its own, shared out by `share` and
    /// stitched in frontier order. A cell's decision depends on the cell
    /// alone (until a node cap binds), so the field is the same however the
    /// subtrees are shared.
    fn build_octree(&mut self, outside: Option<&Outside>, share: &dyn OctreeShare) {
        // Bounded memory whatever the input: past the cap every cell is a
        // leaf (phase 2 gives each subtree a share of it).
        let cap = (32 * self.seeds.len() + 4096).min(1 << 28);
        // Phase 1's nodes, which the subtrees then hang from.
        let mut top = Subtree {
            nodes: vec![0],
            ..Default::default()
        };
        let mut level = vec![Pending {
            node: 0,
            lo: self.root_lo,
            s: self.root_s,
            depth: 0,
            list: (0..self.seeds.len() as u32).collect(),
        }];
        while !level.is_empty() && level.len() < FRONTIER {
            let decisions: Vec<Decision> = level
                .par_iter()
                .map(|p| self.classify(p, p.depth >= MAX_DEPTH, outside))
                .collect();
            let mut next = Vec::new();
            for (p, dec) in level.into_iter().zip(decisions) {
                top.depth = top.depth.max(p.depth);
                if let Some((first, lists)) = top.record(p.node, dec) {
                    next.extend(children(&p, first, lists));
                }
            }
            level = next;
        }
        let n = level.len();
        let frontier: Vec<usize> = level.iter().map(|p| p.node).collect();
        // Each frontier cell's list goes to its subtree's build, and is
        // freed with it (or at once, where another process builds it).
        let mine: Vec<(u32, Subtree)> = level
            .into_par_iter()
            .enumerate()
            .filter(|(i, _)| share.builds(*i, n))
            .map(|(i, p)| {
                let cap_i = 32 * p.list.len() + cap / n + 4096;
                (i as u32, self.subtree(p, outside, cap_i))
            })
            .collect();
        let subs = share.gather(mine, n);
        assert_eq!(subs.len(), n, "every subtree of the frontier");
        let total = |f: fn(&Subtree) -> usize| subs.iter().chain([&top]).map(f).sum::<usize>();
        self.near = NearLists::default();
        self.near
            .reserve(total(|t| t.near.len()), total(|t| t.cand.len()));
        self.add_near(&top);
        self.nodes = top.nodes;
        self.far = top.far;
        self.stats.depth = top.depth;
        let total = |f: fn(&Subtree) -> usize| subs.iter().map(f).sum::<usize>();
        self.nodes.reserve_exact(total(|t| t.nodes.len()));
        self.far.reserve_exact(total(|t| t.far.len()));
        for (node, sub) in frontier.into_iter().zip(subs) {
            self.stitch(node, sub);
        }
        let st = &mut self.stats;
        st.nodes = self.nodes.len();
        st.near_leaves = self.near.leaves.len();
        st.far_leaves = self.far.len();
        st.candidates = self.near.ids;
        st.bytes =
            self.nodes.len() * 4 + self.near.bytes() + self.far.len() * 64 + self.seeds.len() * 32;
    }

    /// The subtree under frontier cell `root`, depth first, at most about
    /// `cap` nodes before every cell is a leaf.
    fn subtree(&self, root: Pending, outside: Option<&Outside>, cap: usize) -> Subtree {
        let mut t = Subtree {
            nodes: vec![0],
            ..Default::default()
        };
        let mut stack = vec![Pending { node: 0, ..root }];
        while let Some(p) = stack.pop() {
            let force = t.nodes.len() > cap || p.depth >= MAX_DEPTH;
            t.depth = t.depth.max(p.depth);
            if let Some((first, lists)) = t.record(p.node, self.classify(&p, force, outside)) {
                stack.extend(children(&p, first, lists));
            }
        }
        t
    }

    /// Subtree `sub` in place of frontier node `node`: its nodes after the
    /// octree's (its local node `j > 0` at `base + j - 1`), its lists after
    /// the octree's.
    fn stitch(&mut self, node: usize, sub: Subtree) {
        let base = self.nodes.len() as u32;
        let (near0, far0) = (self.near.leaves.len() as u32, self.far.len() as u32);
        let remap = |code: u32| match code >> KIND_SHIFT {
            K_INTERNAL => base + code - 1,
            K_NEAR => (K_NEAR << KIND_SHIFT) | ((code & IDX_MASK) + near0),
            _ => (K_FAR << KIND_SHIFT) | ((code & IDX_MASK) + far0),
        };
        self.nodes[node] = remap(sub.nodes[0]);
        self.nodes.extend(sub.nodes[1..].iter().map(|&c| remap(c)));
        self.add_near(&sub);
        self.far.extend_from_slice(&sub.far);
        self.stats.depth = self.stats.depth.max(sub.depth);
    }

    /// The near leaves of `t`, in order, after the octree's.
    fn add_near(&mut self, t: &Subtree) {
        for &(a, l) in &t.near {
            self.near.push(&t.cand[a as usize..(a + l) as usize]);
        }
    }

    fn split(&self, p: &Pending, eps: f64) -> Decision {
        Decision::Split(self.child_lists(&p.list, p.lo, p.s / 2.0, eps).into())
    }

    fn classify(&self, p: &Pending, force: bool, outside: Option<&Outside>) -> Decision {
        let (lo, s) = (p.lo, p.s);
        let hi = [lo[0] + s, lo[1] + s, lo[2] + s];
        // Outside the surface: the corners exact, the rest interpolated.
        let centre = [lo[0] + s / 2.0, lo[1] + s / 2.0, lo[2] + s / 2.0];
        let corners: [P3; 8] = std::array::from_fn(|ch| corner(lo, s, ch));
        if outside.is_some_and(|o| o.holds(centre, p.depth)) {
            return Decision::Far(self.capped_at(&p.list, &corners));
        }
        // Some cone below the cap in the cell (the root only until one is found)?
        let (mut r2, mut below) = (f64::INFINITY, false);
        for &j in &p.list {
            let sd = &self.seeds[j as usize];
            let d2 = point_box_d2(sd.p, lo, hi);
            r2 = r2.min(d2);
            below = below || sd.h + self.c * d2.sqrt() < self.cap;
        }
        if !below {
            return Decision::Far([self.cap; 8]);
        }
        if r2 < (NEAR_FACTOR * s).powi(2) {
            if p.list.len() <= NEAR_MAX {
                return Decision::Near(p.list.clone());
            }
            if p.list.len() <= 8 * NEAR_MAX || force {
                // Tighter: union of the sets of the 2x2x2 sub-cells, which
                // are also the children's lists if the cell splits.
                let (lists, mut list) = self.child_lists_and::<true>(&p.list, lo, s / 2.0, 0.0);
                // Ascending and distinct, as the lists joined, sorted and
                // deduplicated were: the union is in the parent's order, but
                // for a bounding seed kept last.
                if !list.is_sorted() {
                    list.sort_unstable();
                }
                if list.len() <= NEAR_MAX {
                    return Decision::Near(list);
                }
                if force {
                    if list.len() > FORCED_MAX {
                        let key = |j: &u32| {
                            let sd = &self.seeds[*j as usize];
                            sd.h + self.c * point_box_d2(sd.p, lo, hi).sqrt()
                        };
                        list.sort_by(|a, b| key(a).total_cmp(&key(b)));
                        list.truncate(FORCED_MAX);
                    }
                    return Decision::Near(list);
                }
                return Decision::Split(lists.into());
            }
            // Exact lists below near cells: cells holding seeds stay exact.
            return self.split(p, 0.0);
        }
        // The corners, then the centre and the face centres to test.
        const TESTS: [[f64; 3]; 7] = [
            [0.5, 0.5, 0.5],
            [0.0, 0.5, 0.5],
            [1.0, 0.5, 0.5],
            [0.5, 0.0, 0.5],
            [0.5, 1.0, 0.5],
            [0.5, 0.5, 0.0],
            [0.5, 0.5, 1.0],
        ];
        if force {
            return Decision::Far(self.capped_at(&p.list, &corners));
        }
        // The 15 points and the last again: the values go in pairs.
        let pts: [P3; 16] = std::array::from_fn(|i| match i {
            0..8 => corners[i],
            _ => {
                let t = TESTS[(i - 8).min(6)];
                [lo[0] + t[0] * s, lo[1] + t[1] * s, lo[2] + t[2] * s]
            }
        });
        let f = self.capped_at(&p.list, &pts);
        let v: [f64; 8] = std::array::from_fn(|ch| f[ch]);
        for (k, t) in TESTS.into_iter().enumerate() {
            let (i, f) = (trilinear(&v, t), f[8 + k]);
            if i > f * (1.0 + TOL_OVER) || i < f * (1.0 - TOL_UNDER) {
                return self.split(p, PRUNE_EPS);
            }
        }
        Decision::Far(v)
    }
}

#[inline(always)]
fn corner(lo: P3, s: f64, ch: usize) -> P3 {
    [
        lo[0] + if ch & 1 != 0 { s } else { 0.0 },
        lo[1] + if ch & 2 != 0 { s } else { 0.0 },
        lo[2] + if ch & 4 != 0 { s } else { 0.0 },
    ]
}

/// Trilinear interpolation; `v[ch]` at corner `ch` (bit k = upper side in k).
#[inline(always)]
fn trilinear(v: &[f64; 8], t: [f64; 3]) -> f64 {
    let x0 = v[0] + (v[1] - v[0]) * t[0];
    let x1 = v[2] + (v[3] - v[2]) * t[0];
    let x2 = v[4] + (v[5] - v[4]) * t[0];
    let x3 = v[6] + (v[7] - v[6]) * t[0];
    let y0 = x0 + (x1 - x0) * t[1];
    let y1 = x2 + (x3 - x2) * t[1];
    y0 + (y1 - y0) * t[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xorshift(mut x: u64) -> impl FnMut() -> f64 {
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The list filter one child at a time, as the build did before it
    /// fused the children.
    fn filter(g: &SurfaceGrowth, list: &[u32], lo: P3, s: f64, eps: f64) -> Vec<u32> {
        let hi = [lo[0] + s, lo[1] + s, lo[2] + s];
        let cen = [lo[0] + s / 2.0, lo[1] + s / 2.0, lo[2] + s / 2.0];
        let (mut best, mut fc) = (u32::MAX, f64::INFINITY);
        for &j in list {
            let v = g.cone(j, cen);
            if v < fc {
                (best, fc) = (j, v);
            }
        }
        let u = ((fc + g.c * s * 0.5 * 3f64.sqrt()) * (1.0 + 1e-12)).min(g.cap);
        let mut out = Vec::new();
        for &j in list {
            let sd = &g.seeds[j as usize];
            if (sd.h + g.c * point_box_d2(sd.p, lo, hi).sqrt()) * (1.0 + eps) <= u {
                out.push(j);
            }
        }
        if best != u32::MAX && !out.contains(&best) {
            out.push(best);
        }
        out
    }

    #[test]
    fn fused_passes_give_the_lists_and_values_of_one_pass_each() {
        let mut rnd = xorshift(0x9e37_79b9_7f4a_7c15);
        let seeds: Vec<(P3, f64)> = (0..300)
            .map(|_| ([rnd(), rnd(), rnd()], 0.005 + 0.05 * rnd()))
            .collect();
        let g = SurfaceGrowth::with_cap(&seeds, 0.25, 0.04);
        let all: Vec<u32> = (0..g.seeds.len() as u32).collect();
        let mut kept = 0;
        for _ in 0..300 {
            let s = 0.01 + 0.3 * rnd();
            let lo = [rnd() - 0.1, rnd() - 0.1, rnd() - 0.1];
            for eps in [0.0, PRUNE_EPS] {
                let fused = g.child_lists(&all, lo, s / 2.0, eps);
                for (ch, list) in fused.iter().enumerate() {
                    let one = filter(&g, &all, corner(lo, s / 2.0, ch), s / 2.0, eps);
                    assert_eq!(list, &one, "child {ch} of {lo:?} size {s}");
                    kept += list.len();
                }
                // The union, sorted: the lists joined, sorted and
                // deduplicated (a bounding seed the cap would drop comes
                // last, out of the parent's order).
                let (lists, mut union) = g.child_lists_and::<true>(&all, lo, s / 2.0, eps);
                assert_eq!(lists, fused);
                let mut want = lists.concat();
                want.sort_unstable();
                want.dedup();
                union.sort_unstable();
                assert_eq!(union, want);
                let rev: Vec<u32> = all.iter().rev().copied().collect();
                let (_, mut union) = g.child_lists_and::<true>(&rev, lo, s / 2.0, eps);
                union.sort_unstable();
                assert_eq!(union, want);
            }
            let pts: [P3; 16] = std::array::from_fn(|i| {
                if i < 8 {
                    corner(lo, s, i)
                } else {
                    [lo[0] + rnd() * s, lo[1] + rnd() * s, lo[2] + rnd() * s]
                }
            });
            let fused = g.min_at(&all, &pts);
            for (x, f) in pts.iter().zip(fused) {
                let one = all
                    .iter()
                    .map(|&j| g.cone(j, *x))
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(f.to_bits(), one.to_bits(), "at {x:?}");
            }
        }
        // The cells were neither all empty nor all full.
        assert!(kept > 0 && kept < 300 * 2 * 8 * all.len(), "{kept}");
    }
}

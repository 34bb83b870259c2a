//! Operations on tets far apart evaluated at once, committed in order.
//! An operation on tet `t` reads and changes only the tets on `t`'s
//! corners and their faces' neighbours, so two tets whose corner balls
//! share no point cannot see each other's changes. A pass's list is cut
//! into batches of such tets: each batch takes the list's next entries
//! that are apart from it (those that are not wait, in order, for the
//! next), is evaluated in parallel, and is committed in its order. The
//! batches depend on the list and the mesh only, so the mesh is the same
//! on any number of threads.
use crate::work::Work;
use crate::{Improver, Outcome};
use parafront_geom::P3;
use parafront_mesh::{Marks, PointId};
use rayon::prelude::*;

/// Tets in a batch at most (fixed: the batches, and so the order of
/// everything, do not depend on the threads).
pub(crate) const BATCH: usize = 32;
/// Entries a batch looks at, at most: those it passes over are looked at
/// again by the next.
const WINDOW: usize = 2 * BATCH;

/// The points a batch holds, and the scratch to find a tet's.
#[derive(Default)]
pub(crate) struct Batch {
    /// The points the batch holds.
    taken: Marks,
    ball: Vec<u32>,
    pts: Vec<PointId>,
    rest: Vec<(f64, u32)>,
    /// The tets of the batch, in list order.
    pub tets: Vec<u32>,
}

impl Batch {
    /// Empty, for a mesh of `n` points.
    fn clear(&mut self, n: usize) {
        self.taken.clear(n);
        self.tets.clear();
    }

    /// Whether none of the points of the tets on `t`'s corners is the
    /// batch's yet; if so, they are in `self.pts` (for [`Batch::take`]).
    /// Stops at the first that is: most entries a batch passes over meet
    /// it near their own tet (this test was most of the serial part of the
    /// insertion pass). `t` is alive.
    pub(crate) fn apart(&mut self, w: &mut Work, t: u32) -> bool {
        self.pts.clear();
        for p in w.m.tets[t as usize] {
            w.ball(p, &mut self.ball);
            for &u in &self.ball {
                let v = w.m.tets[u as usize];
                if v.iter().any(|q| self.taken.contains(q.idx())) {
                    return false;
                }
                self.pts.extend_from_slice(&v);
            }
        }
        true
    }

    /// `t` (checked [`Batch::apart`] just before) joins the batch.
    pub(crate) fn take(&mut self, t: u32) {
        for p in &self.pts {
            self.taken.insert(p.idx());
        }
        self.tets.push(t);
    }
}

impl Improver<'_> {
    /// The next batch from `pending` (a pass's list, each tet with the
    /// value it was listed at) into `b`: entries whose tet is apart from
    /// the batch's, those `keep` takes (the others are dropped, as the pass
    /// skips them: nothing in the batch can change them). Entries that
    /// meet the batch, or a dead slot that one of its commits may take,
    /// stay in `pending`, in order.
    pub(crate) fn next_batch(
        &mut self,
        b: &mut Batch,
        pending: &mut Vec<(f64, u32)>,
        keep: impl Fn(&Self, f64, u32) -> bool,
    ) {
        b.clear(self.w.m.points.len());
        let mut rest = std::mem::take(&mut b.rest);
        rest.clear();
        for (k, &(x0, t)) in pending.iter().enumerate() {
            if b.tets.len() >= BATCH || k >= WINDOW {
                rest.extend_from_slice(&pending[k..]);
                break;
            }
            if !self.w.alive(t) {
                if !b.tets.is_empty() {
                    rest.push((x0, t));
                }
                continue;
            }
            if !b.apart(&mut self.w, t) {
                rest.push((x0, t));
                continue;
            }
            if keep(self, x0, t) {
                b.take(t);
            }
        }
        std::mem::swap(pending, &mut rest);
        b.rest = rest;
    }
}

/// Points in a batch of moves at most. Larger batches take points further
/// down a worst-first list before the corners of the tets above them
/// (adjacent, so waiting), and leave a little more under 10°: with 1, 4,
/// 8 and 32 the tray kept 27.08, 26.99, 27.29 and 27.82 % of its tets
/// under 10°, the idler 5.04, 5.47, 5.51 and 5.46 %; the improvement
/// took 1.50 -> 1.30 s on the tray at 4 (2 threads).
const POINT_BATCH: usize = 4;

/// A batch of point moves (the compass and selective searches): moving
/// `p` changes only the tets of its ball, and a search around `q` reads
/// only the points of `q`'s ball. Two points that share no tet cannot see
/// each other's moves, so a batch takes points none of which is on a tet
/// of another's ball, and keeps each one's ball for the evaluation.
#[derive(Default)]
pub(crate) struct PointBatch {
    /// The points the batch holds.
    taken: Marks,
    ball: Vec<u32>,
    rest: Vec<PointId>,
    /// The points of the batch, in list order.
    pub pts: Vec<PointId>,
    /// Point `i`'s ball is `tets[start[i]..start[i + 1]]`.
    tets: Vec<u32>,
    start: Vec<usize>,
}

impl PointBatch {
    /// Empty, for a mesh of `n` points.
    fn clear(&mut self, n: usize) {
        self.taken.clear(n);
        self.pts.clear();
        self.tets.clear();
        self.start.clear();
        self.start.push(0);
    }

    /// The ball of the batch's `i`-th point.
    pub(crate) fn ball(&self, i: usize) -> &[u32] {
        &self.tets[self.start[i]..self.start[i + 1]]
    }
}

impl Improver<'_> {
    /// Moves the points of `list` (in order, each once) in batches: the
    /// points that `keep` takes are evaluated by `eval` (a search over the
    /// mesh as the batch found it: `eval(work, p, ball, scratch)` gives
    /// where `p` goes, if anywhere) in parallel, then moved in list order;
    /// `done(self, p, outcome)` follows each.
    pub(crate) fn move_in_batches(
        &mut self,
        list: Vec<PointId>,
        keep: impl Fn(&Self, PointId) -> bool,
        eval: impl Fn(&Work, PointId, &[u32], &mut Vec<PointId>) -> Option<P3> + Sync,
        mut done: impl FnMut(&mut Self, PointId, Outcome),
    ) {
        let mut b = std::mem::take(&mut self.points);
        let mut pending = list;
        while !pending.is_empty() {
            self.next_point_batch(&mut b, &mut pending, &keep);
            let w = &self.w;
            let found: Vec<Option<P3>> = (0..b.pts.len())
                .into_par_iter()
                .with_max_len(1)
                .map_init(Vec::new, |nb, i| eval(w, b.pts[i], b.ball(i), nb))
                .collect();
            for (i, pos) in found.into_iter().enumerate() {
                let p = b.pts[i];
                let o = self.w.commit_found(p, pos, b.ball(i));
                done(self, p, o);
            }
        }
        self.points = b;
    }

    /// The next batch from `pending` into `b`: points apart from the
    /// batch's that `keep` takes (the others are dropped); points that
    /// meet the batch stay in `pending`, in order.
    fn next_point_batch(
        &mut self,
        b: &mut PointBatch,
        pending: &mut Vec<PointId>,
        keep: impl Fn(&Self, PointId) -> bool,
    ) {
        b.clear(self.w.m.points.len());
        let mut rest = std::mem::take(&mut b.rest);
        rest.clear();
        for (k, &p) in pending.iter().enumerate() {
            if b.pts.len() >= POINT_BATCH || k >= WINDOW {
                rest.extend_from_slice(&pending[k..]);
                break;
            }
            self.w.ball(p, &mut b.ball);
            let meets = b.ball.iter().any(|&t| {
                self.w.m.tets[t as usize]
                    .iter()
                    .any(|x| b.taken.contains(x.idx()))
            });
            if meets {
                rest.push(p);
                continue;
            }
            if keep(self, p) {
                b.taken.insert(p.idx());
                b.pts.push(p);
                b.tets.extend_from_slice(&b.ball);
                b.start.push(b.tets.len());
            }
        }
        std::mem::swap(pending, &mut rest);
        b.rest = rest;
    }
}

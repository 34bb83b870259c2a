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
use crate::Improver;
use parafront_mesh::PointId;

/// Tets in a batch at most (fixed: the batches, and so the order of
/// everything, do not depend on the threads).
pub(crate) const BATCH: usize = 32;
/// Entries a batch looks at, at most: those it passes over are looked at
/// again by the next.
const WINDOW: usize = 2 * BATCH;

/// The points a batch holds, and the scratch to find a tet's.
#[derive(Default)]
pub(crate) struct Batch {
    /// Per point, the batch that holds it (`epoch`) or an older one.
    taken: Vec<u32>,
    epoch: u32,
    ball: Vec<u32>,
    pts: Vec<PointId>,
    rest: Vec<(f64, u32)>,
    /// The tets of the batch, in list order.
    pub tets: Vec<u32>,
}

impl Batch {
    pub(crate) fn clear(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.taken.iter_mut().for_each(|e| *e = 0);
            self.epoch = 1;
        }
        self.tets.clear();
    }

    /// The points of the tets on `t`'s corners into `self.pts`; whether
    /// none of them is the batch's yet. `t` is alive.
    pub(crate) fn apart(&mut self, w: &mut Work, t: u32) -> bool {
        self.pts.clear();
        for p in w.m.tets[t as usize] {
            w.ball(p, &mut self.ball);
            for &u in &self.ball {
                self.pts.extend_from_slice(&w.m.tets[u as usize]);
            }
        }
        if self.taken.len() < w.m.points.len() {
            self.taken.resize(w.m.points.len(), 0);
        }
        !self.pts.iter().any(|p| self.taken[p.idx()] == self.epoch)
    }

    /// `t` (checked [`Batch::apart`] just before) joins the batch.
    pub(crate) fn take(&mut self, t: u32) {
        for p in &self.pts {
            self.taken[p.idx()] = self.epoch;
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
        b.clear();
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

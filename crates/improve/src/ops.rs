//! The local operations of §9: face swap 2-3 and edge removal (3-2 and
//! n -> 2n-4, §9.1), edge collapse (§9.2), Laplacian smoothing with move
//! rejection (§9.3), selective movement along edges (§9.4) and two moves
//! for the dihedral angles (the last polish, and fewer tets under 10°).
//! Each first evaluates a candidate without touching the
//! mesh and keeps it only when the worst quality of the tets it makes
//! beats the worst of those it replaces, and every new tet is positive
//! under the exact predicate and in floating point.
use crate::quality::{
    min_dihedral_deg, positive_min_dihedral_under, positive_quality, quality, quality_over,
};
use crate::work::{ring_tets, Work, MAX_RING};
use parafront_geom::{cross, dist2, norm, sub, P3};
use parafront_mesh::{PointId, TET_FACES};

/// What a local operation did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The mesh changed.
    Done,
    /// Valid, but the worst quality would not improve.
    NotBetter,
    /// A new tet would be inverted or flat (exactly or in floating point).
    Inverted,
    /// The operation would cross a boundary or region interface, or the
    /// edge's ring is too long.
    Constrained,
    /// A point that must stay would move or disappear.
    Frozen,
    /// Edge collapse: the link condition fails.
    LinkCondition,
    /// The ids do not name an edge, face or live point of the mesh.
    NotFound,
}

/// A replacement the operations evaluate before committing it.
#[derive(Clone, Default)]
pub(crate) struct Cand {
    pub old: Vec<u32>,
    pub new: Vec<[PointId; 4]>,
    pub qmin: f64,
}

impl Cand {
    /// The change: tets `old` out, `new` in.
    pub(crate) fn set(&mut self, old: &[u32], new: impl IntoIterator<Item = [PointId; 4]>) {
        self.old.clear();
        self.old.extend_from_slice(old);
        self.new.clear();
        self.new.extend(new);
    }
}

/// Relative margin a change must beat the old worst quality by, so that
/// operations never cycle.
pub(crate) const MARGIN: f64 = 1e-3;

#[inline]
pub(crate) fn beats(new: f64, old: f64) -> bool {
    new > bar(old)
}

/// What a quality must exceed to [`beats`] `old`.
#[inline]
pub(crate) fn bar(old: f64) -> f64 {
    old + MARGIN * old.abs() + 1e-12
}

#[inline]
pub(crate) fn positive(p: [P3; 4]) -> bool {
    crate::quality::positive_volume6(p).is_some()
}

/// A ball's quality with one point moved.
pub(crate) enum BallQ {
    /// A tet would not be positive.
    Inverted,
    /// A tet would be under the floor asked for.
    Below,
    /// Worst and mean quality.
    Ok(f64, f64),
}

/// The compass search's directions: the axes and the cube's diagonals.
const S: f64 = 0.577_350_269_189_625_8;
const DIRS: [P3; 14] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
    [S, S, S],
    [-S, -S, -S],
    [S, -S, S],
    [-S, S, -S],
    [S, S, -S],
    [-S, -S, S],
    [-S, S, S],
    [S, -S, -S],
];

/// Compass search (§9.4's selective movement): from `pos`, valued
/// `best`, try a step along each of [`DIRS`] and move to the best one
/// that `better` prefers, else halve the step; at most `iters` rounds,
/// until the step is under `stop`. `eval(p, cur)` values `p` given the
/// best value so far (`None`: not allowed there).
pub(crate) fn compass<E>(
    mut pos: P3,
    mut best: E,
    mut step: f64,
    stop: f64,
    iters: usize,
    mut eval: impl FnMut(P3, &E) -> Option<E>,
    better: impl Fn(&E, &E) -> bool,
) -> (E, P3) {
    for _ in 0..iters {
        if step < stop {
            break;
        }
        let mut moved: Option<(E, P3)> = None;
        for dir in DIRS {
            let c = [0, 1, 2].map(|k| pos[k] + step * dir[k]);
            let cur = moved.as_ref().map_or(&best, |m| &m.0);
            if let Some(e) = eval(c, cur) {
                if better(&e, cur) {
                    moved = Some((e, c));
                }
            }
        }
        match moved {
            Some((e, c)) => {
                best = e;
                pos = c;
            }
            None => step *= 0.5,
        }
    }
    (best, pos)
}

/// How much of the ball's mean mean ratio selective movement may give for
/// each unit it adds to the ball's worst. Without a limit, selective moves
/// around the tets under 0.7 pulled skull.obj's mean radius ratio from
/// 0.826 down to 0.801 (72k points moved); with 0.2 it ends at 0.823,
/// and base_interface_gmsh keeps the min dihedral the moves buy it (16.5°
/// against 14.2° without them) at a mean radius ratio of 0.7725, not 0.7717.
pub(crate) const SELECTIVE_TRADE: f64 = 0.2;

/// Scratch space for the operations, kept between calls.
#[derive(Default)]
pub(crate) struct Scratch {
    pub tets: Vec<u32>,
    pub ring: Vec<PointId>,
    pub ball: Vec<u32>,
    pub ball2: Vec<u32>,
    pub nb: Vec<PointId>,
    pub nb2: Vec<PointId>,
    tq: Vec<f64>,
    dp: Vec<(f64, u8)>,
}

impl Work<'_> {
    fn all_positive(&self, new: &[[PointId; 4]]) -> bool {
        new.iter().all(|&v| positive(self.pts(v)))
    }

    /// §9.1 face swap 2-3: face `f` of `t` and the tet behind it become
    /// three tets around the edge joining their apexes.
    pub(crate) fn eval_23(&self, t: u32, f: usize, c: &mut Cand) -> Outcome {
        let Some((nt, new)) = self.face_swap(t, f) else {
            return Outcome::Constrained;
        };
        let qold = self.q[t as usize].min(self.q[nt as usize]);
        let qbar = bar(qold);
        let mut qmin = f64::INFINITY;
        for &nv in &new {
            qmin = qmin.min(quality_over(self.pts(nv), qbar));
            if !beats(qmin, qold) {
                return Outcome::NotBetter; // first sign of worse (§9.1)
            }
        }
        if !self.all_positive(&new) {
            return Outcome::Inverted;
        }
        c.set(&[t, nt], new);
        c.qmin = qmin;
        Outcome::Done
    }

    /// §9.1 edge removal: the `n` tets around edge `ab` become `2n-4`, two
    /// per triangle of the best triangulation of the ring. Klincsek's
    /// dynamic programme (Shewchuk 2002) maximises the worst tet over all
    /// triangulations in O(n^3); `n = 3` is the 3-2 swap.
    pub(crate) fn eval_edge_removal(
        &self,
        t: u32,
        a: PointId,
        b: PointId,
        s: &mut Scratch,
        c: &mut Cand,
    ) -> Outcome {
        if self.ring(t, a, b, &mut s.tets, &mut s.ring).is_none() {
            return Outcome::Constrained;
        }
        let n = s.ring.len();
        let qold = self.ball_qmin(&s.tets);
        let qbar = bar(qold);
        // Tables of stride `n` (at most MAX_RING): only what this ring
        // uses is reset.
        s.tq.clear();
        s.tq.resize(n * n * n, f64::NAN);
        s.dp.clear();
        s.dp.resize(n * n, (f64::INFINITY, 0));
        let (pa, pb) = (self.m.points[a.idx()], self.m.points[b.idx()]);
        let r: [P3; MAX_RING] =
            std::array::from_fn(|i| s.ring.get(i).map_or([0.0; 3], |p| self.m.points[p.idx()]));
        for len in 2..n {
            for i in 0..n - len {
                let j = i + len;
                let mut best = (f64::NEG_INFINITY, 0u8);
                for k in i + 1..j {
                    let m = s.dp[i * n + k].0.min(s.dp[k * n + j].0);
                    // Reject at the first sign of worse (§9.1).
                    if m <= best.0 || !beats(m, qold) {
                        continue;
                    }
                    let slot = &mut s.tq[(i * n + k) * n + j];
                    if slot.is_nan() {
                        // A pair that cannot beat `qold` is scored -inf: no
                        // choice below reads more of it than that.
                        let q1 = quality_over([r[i], r[k], r[j], pb], qbar);
                        *slot = if beats(q1, qold) {
                            q1.min(quality_over([r[i], r[j], r[k], pa], qbar))
                        } else {
                            q1
                        };
                    }
                    let v = m.min(*slot);
                    if v > best.0 && beats(v, qold) {
                        best = (v, k as u8);
                    }
                }
                s.dp[i * n + j] = best;
            }
        }
        let (qnew, _) = s.dp[n - 1];
        if !beats(qnew, qold) {
            return Outcome::NotBetter;
        }
        c.new.clear();
        let dp = &s.dp;
        ring_tets(
            &s.ring,
            (0, n - 1),
            &|i, j| dp[i * n + j].1 as usize,
            a,
            b,
            &mut c.new,
        );
        if !self.all_positive(&c.new) {
            return Outcome::Inverted;
        }
        c.old.clear();
        c.old.extend_from_slice(&s.tets);
        c.qmin = qnew;
        Outcome::Done
    }

    /// The distinct vertices of `tets` other than `p`, into `out`.
    fn neighbours(&self, p: PointId, tets: &[u32], out: &mut Vec<PointId>) {
        out.clear();
        for &t in tets {
            for v in self.m.tets[t as usize] {
                if v != p && !out.contains(&v) {
                    out.push(v);
                }
            }
        }
    }

    /// §9.2 edge collapse: point `a` merges into `b`; the tets around the
    /// edge go, the rest of `a`'s ball is re-pointed at `b`. Needs `a` free
    /// (it disappears) and the link condition Lk(a) ∩ Lk(b) = Lk(ab).
    pub(crate) fn eval_collapse(
        &mut self,
        a: PointId,
        b: PointId,
        s: &mut Scratch,
        c: &mut Cand,
    ) -> Outcome {
        if a == b || self.dead_pt[a.idx()] || self.dead_pt[b.idx()] {
            return Outcome::NotFound;
        }
        if self.frozen[a.idx()] {
            return Outcome::Frozen;
        }
        self.ball(a, &mut s.ball);
        if s.ball.is_empty() {
            return Outcome::NotFound;
        }
        // Ring of ab: the vertices of the tets holding both.
        s.ring.clear();
        let mut on_edge = 0;
        for &t in &s.ball {
            let v = self.m.tets[t as usize];
            if v.contains(&b) {
                on_edge += 1;
                for x in v {
                    if x != a && x != b && !s.ring.contains(&x) {
                        s.ring.push(x);
                    }
                }
            }
        }
        if on_edge == 0 {
            return Outcome::NotFound;
        }
        // The worst new tet first: it is cheaper than the link condition,
        // and most collapses fail it.
        let qold = self.ball_qmin(&s.ball);
        let qbar = bar(qold);
        c.new.clear();
        let mut qmin = f64::INFINITY;
        for &t in &s.ball {
            let v = self.m.tets[t as usize];
            if v.contains(&b) {
                continue;
            }
            let nv = v.map(|x| if x == a { b } else { x });
            qmin = qmin.min(quality_over(self.pts(nv), qbar));
            if !beats(qmin, qold) {
                return Outcome::NotBetter;
            }
            c.new.push(nv);
        }
        if !self.link_holds(a, b, s) {
            return Outcome::LinkCondition;
        }
        if !self.all_positive(&c.new) {
            return Outcome::Inverted;
        }
        c.old.clear();
        c.old.extend_from_slice(&s.ball);
        c.qmin = qmin;
        Outcome::Done
    }

    /// §9.2's link condition for collapsing `a` into `b`, Lk(a) ∩ Lk(b) =
    /// Lk(ab), with `s.ball` and `s.ring` as [`Work::eval_collapse`] found
    /// them (`a`'s ball, and the other corners of the tets on `ab`).
    pub(crate) fn link_holds(&mut self, a: PointId, b: PointId, s: &mut Scratch) -> bool {
        // Link condition, vertices: a common neighbour must be on the ring.
        self.neighbours(a, &s.ball, &mut s.nb);
        self.ball(b, &mut s.ball2);
        self.neighbours(b, &s.ball2, &mut s.nb2);
        for &x in &s.nb {
            if x != b && s.nb2.contains(&x) && !s.ring.contains(&x) {
                return false;
            }
        }
        // Edges: xy in Lk(a) and Lk(b) must be in Lk(ab), i.e. abxy a tet.
        let has = |tets: &[u32], x: PointId, y: PointId| {
            tets.iter().any(|&t| {
                let v = &self.m.tets[t as usize];
                v.contains(&x) && v.contains(&y)
            })
        };
        for i in 0..s.ring.len() {
            for j in i + 1..s.ring.len() {
                let (x, y) = (s.ring[i], s.ring[j]);
                let in_ab = s.ball.iter().any(|&t| {
                    let v = &self.m.tets[t as usize];
                    v.contains(&b) && v.contains(&x) && v.contains(&y)
                });
                if !in_ab && has(&s.ball, x, y) && has(&s.ball2, x, y) {
                    return false;
                }
            }
        }
        true
    }

    /// Worst and mean quality of `ball` with `p` at `pos`, stopping at the
    /// first tet that would not be positive (exactly and in floating
    /// point) or would be under `floor` (a move no caller keeps).
    pub(crate) fn ball_quality_above(
        &self,
        p: PointId,
        pos: P3,
        ball: &[u32],
        floor: f64,
    ) -> BallQ {
        let mut qmin = f64::INFINITY;
        let mut sum = 0.0;
        for &t in ball {
            let x = self.pts_moved(t, p, pos);
            let Some(q) = positive_quality(x) else {
                return BallQ::Inverted;
            };
            if q < floor {
                return BallQ::Below;
            }
            qmin = qmin.min(q);
            sum += q;
        }
        BallQ::Ok(qmin, sum / ball.len() as f64)
    }

    /// Moves `p` to `pos` and refreshes the qualities of its ball.
    pub(crate) fn commit_move(&mut self, p: PointId, pos: P3, ball: &[u32]) {
        self.m.points[p.idx()] = pos;
        for &t in ball {
            let v = self.m.tets[t as usize];
            self.q[t as usize] = quality(self.pts(v));
            self.tested[t as usize] = false;
            self.dok[t as usize] = false;
            for x in v {
                self.settled[x.idx()] = false;
                self.touched[x.idx()] = self.clock;
            }
        }
    }

    /// Why point `p` may not move (gone, or on the surface or an
    /// interface), if it may not.
    fn pinned(&self, p: PointId) -> Option<Outcome> {
        if self.dead_pt[p.idx()] {
            Some(Outcome::NotFound)
        } else if self.frozen[p.idx()] {
            Some(Outcome::Frozen)
        } else {
            None
        }
    }

    /// §9.3 Laplacian smoothing of one point with move rejection: `p` goes
    /// towards the mean of its neighbours (full, half, quarter step); a move
    /// is kept only when no tet inverts and the ball's worst quality does
    /// not drop (and its mean rises).
    pub(crate) fn smooth_point(&mut self, p: PointId, s: &mut Scratch) -> Outcome {
        self.on_ball(p, s, |w, ball, s| w.smooth_in(p, ball, s))
    }

    fn smooth_in(&mut self, p: PointId, ball: &[u32], s: &mut Scratch) -> Outcome {
        if ball.is_empty() {
            return Outcome::NotFound;
        }
        self.neighbours(p, ball, &mut s.nb);
        let mut c = [0.0; 3];
        for &x in &s.nb {
            let q = self.m.points[x.idx()];
            for k in 0..3 {
                c[k] += q[k];
            }
        }
        let lap = c.map(|x| x / s.nb.len() as f64);
        // The mean of the points that would make each tet of the ball
        // regular on its face opposite p: follows the local size where
        // the plain Laplacian mean drifts in graded meshes.
        let mut ideal = [0.0; 3];
        for &t in ball {
            let v = self.m.tets[t as usize];
            let Some(k) = v.iter().position(|&x| x == p) else {
                continue;
            };
            let [x, y, z] = TET_FACES[k].map(|l| self.m.points[v[l].idx()]);
            let n = cross(sub(y, x), sub(z, x));
            let nn = norm(n);
            let l2 = (dist2(x, y) + dist2(y, z) + dist2(z, x)) / 3.0;
            let h = (l2 * 2.0 / 3.0).sqrt();
            for i in 0..3 {
                // The face's normal points away from p.
                ideal[i] += (x[i] + y[i] + z[i]) / 3.0 - n[i] / nn.max(f64::MIN_POSITIVE) * h;
            }
        }
        let ideal = ideal.map(|x| x / ball.len() as f64);
        let p0 = self.m.points[p.idx()];
        let (qmin, qmean) = ball
            .iter()
            .map(|&t| self.q[t as usize])
            .fold((f64::INFINITY, 0.0), |(m, s), q| (m.min(q), s + q));
        let qmean = qmean / ball.len() as f64;
        let mut inverted = false;
        for (c, w) in [
            (ideal, 1.0),
            (ideal, 0.5),
            (lap, 1.0),
            (lap, 0.5),
            (lap, 0.25),
        ] {
            let pos = [0, 1, 2].map(|k| p0[k] + w * (c[k] - p0[k]));
            match self.ball_quality_above(p, pos, ball, qmin) {
                BallQ::Inverted => inverted = true,
                BallQ::Below => {}
                BallQ::Ok(m, mean) => {
                    if beats(m, qmin) || (m >= qmin && mean > qmean + 1e-9) {
                        self.commit_move(p, pos, ball);
                        return Outcome::Done;
                    }
                }
            }
        }
        if inverted {
            Outcome::Inverted
        } else {
            Outcome::NotBetter
        }
    }

    /// The moves' frame: `op` on free point `p`'s ball, taken from the
    /// scratch and put back (a pinned point is not moved).
    #[inline(always)]
    fn on_ball(
        &mut self,
        p: PointId,
        s: &mut Scratch,
        op: impl FnOnce(&mut Self, &[u32], &mut Scratch) -> Outcome,
    ) -> Outcome {
        if let Some(o) = self.pinned(p) {
            return o;
        }
        let mut ball = std::mem::take(&mut s.ball);
        self.ball(p, &mut ball);
        let out = op(self, &ball, s);
        s.ball = ball;
        out
    }

    /// Moves free point `p` to `pos` if no tet inverts and the worst
    /// quality of its ball does not drop.
    pub(crate) fn try_move(&mut self, p: PointId, pos: P3, s: &mut Scratch) -> Outcome {
        self.on_ball(p, s, |w, ball, _| w.try_move_in(p, pos, ball))
    }

    fn try_move_in(&mut self, p: PointId, pos: P3, ball: &[u32]) -> Outcome {
        let qmin = self.ball_qmin(ball);
        match self.ball_quality_above(p, pos, ball, qmin) {
            BallQ::Inverted => Outcome::Inverted,
            BallQ::Below => Outcome::NotBetter,
            BallQ::Ok(..) => {
                self.commit_move(p, pos, ball);
                Outcome::Done
            }
        }
    }

    /// §9.4 selective movement: where to move `p` (its ball `ball`) along
    /// each of its edges, both ways, at a few fractions of the edge
    /// length: the best move if it raises the worst quality of the ball
    /// and the ball's mean quality drops by at most [`SELECTIVE_TRADE`]
    /// times that gain. `nb` is scratch.
    pub(crate) fn eval_selective(
        &self,
        p: PointId,
        ball: &[u32],
        nb: &mut Vec<PointId>,
    ) -> Option<P3> {
        self.neighbours(p, ball, nb);
        let qmin = self.ball_qmin(ball);
        let p0 = self.m.points[p.idx()];
        let mean0 = ball.iter().map(|&t| self.q[t as usize]).sum::<f64>() / ball.len() as f64;
        let mut best: Option<(f64, P3)> = None;
        for &x in nb.iter() {
            let d = parafront_geom::sub(self.m.points[x.idx()], p0);
            for f in [0.25, 0.1, 0.03, -0.03, -0.1, -0.25] {
                let pos = [0, 1, 2].map(|k| p0[k] + f * d[k]);
                let floor = best.map_or(qmin, |b| b.0);
                if let BallQ::Ok(m, mean) = self.ball_quality_above(p, pos, ball, floor) {
                    if beats(m, floor) && mean >= mean0 - SELECTIVE_TRADE * (m - qmin) {
                        best = Some((m, pos));
                    }
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Moves `p` (its ball `ball`) to `pos` if a search found it.
    pub(crate) fn commit_found(&mut self, p: PointId, pos: Option<P3>, ball: &[u32]) -> Outcome {
        match pos {
            Some(pos) => {
                self.commit_move(p, pos, ball);
                Outcome::Done
            }
            None => Outcome::NotBetter,
        }
    }

    /// The last polish for the min dihedral (§9.4's selective movement,
    /// by a compass search): where to move free point `p` (its ball
    /// `ball`) to raise the smallest dihedral angle of its ball, while no
    /// tet inverts and the ball's worst mean ratio stays above `keep` times
    /// what it was and no more of its tets are under 10°. Caps (a surface
    /// triangle with an angle near 180° and a free apex) sit where the
    /// mean ratio is best but their dihedral is not: on skull.obj a tenth
    /// of the worst mean ratio buys 0.14° -> 0.22°. `nb` is scratch.
    pub(crate) fn eval_dihedral(
        &self,
        p: PointId,
        keep: f64,
        ball: &[u32],
        nb: &mut Vec<PointId>,
    ) -> Option<P3> {
        self.neighbours(p, ball, nb);
        let floor = keep * self.ball_qmin(ball);
        // (min dihedral, tets under 10°) of the ball with p at pos, when no
        // tet inverts or falls under the mean ratio floor, and the min
        // dihedral stays over `bar` (it only falls as tets are added).
        let eval = |w: &Self, pos: P3, bar: f64| -> Option<(f64, usize)> {
            let mut d = f64::INFINITY;
            let mut under = 0;
            for &t in ball {
                let x = w.pts_moved(t, p, pos);
                if positive_quality(x).is_none_or(|q| q < floor) {
                    return None;
                }
                let dt = min_dihedral_deg(x);
                d = d.min(dt);
                if d <= bar {
                    return None;
                }
                under += usize::from(dt < crate::insert::SMALL_DIHEDRAL);
            }
            Some((d, under))
        };
        let p0 = self.m.points[p.idx()];
        let len = nb
            .iter()
            .map(|x| dist2(self.m.points[x.idx()], p0).sqrt())
            .sum::<f64>()
            / nb.len().max(1) as f64;
        let (d0, under0) = eval(self, p0, f64::NEG_INFINITY)?;
        // No more tets under 10° than before: the share under 10° is the
        // issue's other criterion.
        let (best, pos) = compass(
            p0,
            d0,
            0.1 * len,
            1e-3 * len,
            60,
            // A step no better than `cur` is not taken: its search stops
            // at the first tet that shows it.
            |c, cur| {
                let bar = if self.shortcuts {
                    *cur + 1e-9
                } else {
                    f64::NEG_INFINITY
                };
                eval(self, c, bar).filter(|e| e.1 <= under0).map(|e| e.0)
            },
            |d, cur| *d > *cur + 1e-9,
        );
        (best > d0 * (1.0 + MARGIN) + 1e-9).then_some(pos)
    }

    /// Where to move free point `p` (its ball `ball`) by a compass search
    /// to leave fewer tets of its ball under 10°, with a min dihedral no
    /// lower (the measure is the point here, not the mean ratio;
    /// see `insert.rs`). `nb` is scratch.
    pub(crate) fn eval_count_move(
        &self,
        p: PointId,
        ball: &[u32],
        nb: &mut Vec<PointId>,
    ) -> Option<P3> {
        self.neighbours(p, ball, nb);
        // (tets under 10°, shortfall below 12°, min dihedral) with p at pos;
        // None when a tet inverts, more than `cap` are under 10° or one is
        // under `floor` (the search's bounds, checked as it goes), or when
        // `cap` are and the shortfall has reached `short_cap` (it only
        // grows, so the step cannot be better).
        // `fast`: the search's steps, whose min dihedral is not read.
        let eval = |w: &Self,
                    pos: P3,
                    (cap, short_cap): (usize, f64),
                    floor: f64,
                    fast: bool|
         -> Option<(usize, f64, f64)> {
            let (mut under, mut short, mut dmin) = (0, 0.0, f64::INFINITY);
            for &t in ball {
                let x = w.pts_moved(t, p, pos);
                // A tet with no angle under 12.5° (the tangent test, no arc
                // tangent) adds nothing to the count or the shortfall and
                // passes a floor under 12°: only its sign matters.
                let (d, known_positive) = if fast && floor < 12.0 {
                    match positive_min_dihedral_under(x, crate::TAN_12_5) {
                        Some(Some(d)) => (d, true),
                        Some(None) => continue,
                        None => return None,
                    }
                } else {
                    (min_dihedral_deg(x), false)
                };
                under += usize::from(d < crate::insert::SMALL_DIHEDRAL);
                if under > cap || d < floor || !(known_positive || positive(x)) {
                    return None;
                }
                short += (12.0 - d).max(0.0);
                if under == cap && short >= short_cap {
                    return None;
                }
                dmin = dmin.min(d);
            }
            Some((under, short, dmin))
        };
        let better = |a: (usize, f64, f64), b: (usize, f64, f64)| {
            a.0 < b.0 || (a.0 == b.0 && a.1 < b.1 - 1e-9)
        };
        let p0 = self.m.points[p.idx()];
        let len = nb
            .iter()
            .map(|x| dist2(self.m.points[x.idx()], p0).sqrt())
            .fold(f64::INFINITY, f64::min);
        let e0 = eval(
            self,
            p0,
            (usize::MAX, f64::INFINITY),
            f64::NEG_INFINITY,
            false,
        )?;
        let (best, pos) = compass(
            p0,
            e0,
            0.3 * len,
            1e-2 * len,
            20,
            |c, cur| {
                let short_cap = if self.shortcuts {
                    cur.1 - 1e-9
                } else {
                    f64::INFINITY
                };
                eval(self, c, (cur.0, short_cap), e0.2, true)
            },
            |a, b| better(*a, *b),
        );
        (best.0 < e0.0).then_some(pos)
    }
}

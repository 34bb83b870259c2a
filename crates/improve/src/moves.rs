//! The point moves of §9: Laplacian smoothing with move rejection
//! (§9.3), selective movement along edges (§9.4) and two moves for the
//! dihedral angles (the last polish, and fewer tets under 10°). As the
//! other operations, each keeps a move only when every tet of the ball
//! stays positive (exactly and in floating point) and its quality rises.
use crate::ops::{beats, compass, positive, BallQ, Outcome, Scratch, MARGIN, SELECTIVE_TRADE};
use crate::quality::{
    mean_ratio_under, min_dihedral_deg, positive_min_dihedral_under, positive_quality,
    positive_volume6, quality,
};
use crate::work::Work;
use parafront_geom::{cross, dist2, norm, sub, P3};
use parafront_mesh::quality::{edge_length2_sum, mean_ratio_of};
use parafront_mesh::{PointId, TET_FACES};

impl Work<'_> {
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
        self.ball_quality_into(p, pos, ball, floor, |_| {})
    }

    /// [`Work::ball_quality_above`], giving each tet's quality to `keep`
    /// in the ball's order: all of them when the answer is `Ok`, the only
    /// case a caller reads them.
    ///
    /// First the verdict, tet by tet in the ball's order as before, with no
    /// cube root where a tet is certainly under the floor or certainly
    /// not (most moves tried fail on a tet: their other tets' roots were a
    /// sixth of the improvement's time); then the qualities, when all pass.
    #[inline(always)]
    fn ball_quality_into(
        &self,
        p: PointId,
        pos: P3,
        ball: &[u32],
        floor: f64,
        mut keep: impl FnMut(f64),
    ) -> BallQ {
        if !self.shortcuts {
            return self.ball_quality_plain(p, pos, ball, floor, keep);
        }
        const HELD: usize = 64;
        let mut held = [(0.0f64, 0.0f64); HELD];
        for (i, &t) in ball.iter().enumerate() {
            let x = self.pts_moved(t, p, pos);
            let Some(v6) = positive_volume6(x) else {
                return BallQ::Inverted;
            };
            let l2 = edge_length2_sum(x);
            if mean_ratio_under(v6, l2, floor) {
                return BallQ::Below;
            }
            if i < HELD {
                held[i] = (v6, l2);
            }
        }
        let mut qmin = f64::INFINITY;
        let mut sum = 0.0;
        for (i, &t) in ball.iter().enumerate() {
            let (v6, l2) = if i < HELD {
                held[i]
            } else {
                let x = self.pts_moved(t, p, pos);
                (positive_volume6(x).unwrap_or(0.0), edge_length2_sum(x))
            };
            // `positive_quality(x)`, to the bit.
            let q = mean_ratio_of(v6, l2);
            keep(q);
            qmin = qmin.min(q);
            sum += q;
        }
        BallQ::Ok(qmin, sum / ball.len() as f64)
    }

    /// [`Work::ball_quality_into`] as it was, each tet's quality computed
    /// as it comes (the test that turns the shortcuts off compares them).
    fn ball_quality_plain(
        &self,
        p: PointId,
        pos: P3,
        ball: &[u32],
        floor: f64,
        mut keep: impl FnMut(f64),
    ) -> BallQ {
        let mut qmin = f64::INFINITY;
        let mut sum = 0.0;
        for &t in ball {
            let Some(q) = positive_quality(self.pts_moved(t, p, pos)) else {
                return BallQ::Inverted;
            };
            if q < floor {
                return BallQ::Below;
            }
            keep(q);
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
            self.moved_in(v, t);
        }
    }

    /// [`Work::commit_move`] with the ball's qualities at `pos` known
    /// (`ball_quality_into` gave them, to the bit the ones
    /// [`quality`] gives: `positive_quality`'s test).
    fn commit_move_scored(&mut self, p: PointId, pos: P3, ball: &[u32], q: &[f64]) {
        debug_assert_eq!(q.len(), ball.len());
        self.m.points[p.idx()] = pos;
        for (&t, &qt) in ball.iter().zip(q) {
            let v = self.m.tets[t as usize];
            debug_assert_eq!(qt.to_bits(), quality(self.pts(v)).to_bits());
            self.q[t as usize] = qt;
            self.moved_in(v, t);
        }
    }

    /// Tet `t` (corners `v`) changed shape: its caches and the idle marks
    /// of its corners go.
    #[inline]
    fn moved_in(&mut self, v: [PointId; 4], t: u32) {
        self.tested[t as usize] = false;
        self.dok[t as usize] = false;
        for x in v {
            self.settled[x.idx()] = false;
            self.touched[x.idx()] = self.clock;
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
            let q = &mut s.moved_q;
            q.clear();
            match self.ball_quality_into(p, pos, ball, qmin, |x| q.push(x)) {
                BallQ::Inverted => inverted = true,
                BallQ::Below => {}
                BallQ::Ok(m, mean) => {
                    if beats(m, qmin) || (m >= qmin && mean > qmean + 1e-9) {
                        self.commit_move_scored(p, pos, ball, &s.moved_q);
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

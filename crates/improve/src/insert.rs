//! Steiner point insertion, an addition to §9 (the paper's improver only
//! swaps, collapses and moves): a new free point `p` replaces a small
//! cavity around a tet with small dihedral angles by the star of `p` over
//! the cavity's outer faces. Boundary faces stay faces of the new tets,
//! so the surface is untouched. Cavities: the tet and one neighbour, the
//! tet and all its neighbours, the ring of one of its edges (a point
//! inside the tet alone never helped on the tray). The point starts at the best of a few candidates (the centroid,
//! edge midpoints, points at the short edge's distance around the
//! shortest edge: the apex of a needle tet) and a compass search moves it.
//!
//! Dihedral angles are the point here, not the mean ratio: a needle tet
//! (a short edge, the other points far) can have good dihedral angles but
//! has a low mean ratio. A candidate is kept only when the cavity ends
//! with fewer tets under [`SMALL_DIHEDRAL`] and a min dihedral no lower; or, for
//! a tet under [`LIFT_DEG`], when the cavity's min dihedral rises.
use crate::ops::{positive, Cand, MARGIN};
use crate::quality::{min_dihedral_deg, positive_min_dihedral_under, quality};
use crate::work::{ring_tets, Work};
use parafront_geom::{cross, dist2, norm, sub, P3};
use parafront_mesh::quality::TET_EDGES;
use parafront_mesh::{PointId, TET_FACES};

/// A tet with a min dihedral under this many degrees is bad: the quality
/// report's threshold.
pub(crate) use parafront_mesh::quality::SMALL_DIHEDRAL;
/// Tets under this min dihedral (degrees) may get a point that only lifts
/// the min dihedral of their cavity, even at the cost of more tets under
/// [`SMALL_DIHEDRAL`] (the worst tet is the first criterion).
pub(crate) const LIFT_DEG: f64 = 0.1;
/// The min dihedral (degrees) a lift aims at before it minds the count.
pub(crate) const LIFT_GOAL: f64 = 0.2;
/// The angle (degrees) from which a tet adds nothing to a star's count or
/// shortfall ([`Score::add_angle`]).
const SHORT_DEG: f64 = 12.0;
/// Cavity kinds ([`Work::cavity`]).
const CAVITIES: usize = 11;
/// Largest cavity (tets) considered.
const MAX_CAVITY: usize = 12;

/// Scratch of the insertion.
#[derive(Default)]
pub(crate) struct InsScratch {
    cav: Vec<u32>,
    /// Outer faces as (tet vertices, local index the new point takes).
    star: Vec<([PointId; 4], usize)>,
    best_cav: Vec<u32>,
    best_star: Vec<([PointId; 4], usize)>,
    tets: Vec<u32>,
    ring: Vec<PointId>,
    pts: Vec<PointId>,
}

/// How good a star is: tets under [`SMALL_DIHEDRAL`], summed shortfall below
/// 12° (what the search minimises after the count) and min dihedral (the
/// kept star's mean ratio is taken once, at the end).
#[derive(Clone, Copy, Debug)]
struct Score {
    under: usize,
    short: f64,
    dmin: f64,
}

impl Score {
    /// Of no tet: the start of a sum.
    const NONE: Score = Score {
        under: 0,
        short: 0.0,
        dmin: f64::INFINITY,
    };

    /// Adds a tet of min dihedral `d`.
    fn add_angle(&mut self, d: f64) {
        self.under += usize::from(d < SMALL_DIHEDRAL);
        self.short += (SHORT_DEG - d).max(0.0);
        self.dmin = self.dmin.min(d);
    }

    /// What the search minimises: the count under [`SMALL_DIHEDRAL`] then the
    /// shortfall; with `lift` (a tet under [`LIFT_DEG`]) first the min
    /// dihedral up to [`LIFT_GOAL`].
    /// Relative to the cavity's tets before (`old`), so that cavities of
    /// different sizes compare.
    fn key(&self, old: &Score, lift: Option<f64>) -> (f64, isize, f64) {
        let d = lift.map_or(0.0, |g| -self.dmin.min(g));
        (
            d,
            self.under as isize - old.under as isize,
            self.short - old.short,
        )
    }
}

type Key = (f64, isize, f64);

/// How the insertion's search ranks stars: the lift it aims at, and the
/// angle from which a tet adds nothing to a key but its min dihedral,
/// which the key clamps there. Such a tet is scored at the clamp without
/// its arc tangent ([`Work::exact_score`] gives the kept star's true one).
struct Rank {
    lift: Option<f64>,
    clamp: f64,
    tan_clamp: f64,
}

impl Rank {
    fn new(lift: Option<f64>) -> Rank {
        let clamp = lift.map_or(SHORT_DEG, |g| g.max(SHORT_DEG));
        Rank {
            lift,
            clamp,
            tan_clamp: clamp.to_radians().tan(),
        }
    }
}

fn less(a: Key, b: Key) -> bool {
    a.0 < b.0 - 1e-12 || (a.0 <= b.0 && (a.1 < b.1 || (a.1 == b.1 && a.2 < b.2 - 1e-9)))
}

/// Whether no star whose first tets give the key `part` can be [`less`]
/// than `b`: each tet added keeps every part of a key or raises it.
fn cannot_beat(part: Key, b: Key) -> bool {
    if part.0 > b.0 {
        return true;
    }
    if part.0 < b.0 - 1e-12 {
        return false;
    }
    part.1 > b.1 || (part.1 == b.1 && part.2 >= b.2 - 1e-9)
}

impl Work<'_> {
    /// Fills `s.star` with the outer faces of `s.cav`; false when the
    /// cavity is not one region, holds a point in its interior (every
    /// point must stay on an outer face) or is too large.
    fn star_of(&self, s: &mut InsScratch) -> bool {
        s.star.clear();
        if s.cav.len() > MAX_CAVITY {
            return false;
        }
        let region = self.m.region[s.cav[0] as usize];
        for &t in &s.cav {
            if self.m.region[t as usize] != region {
                return false;
            }
            let v = self.m.tets[t as usize];
            for f in 0..4 {
                let n = self.m.neigh[4 * t as usize + f];
                if !n.is_none() && s.cav.contains(&n.tet().raw()) {
                    continue;
                }
                s.star.push((v, f));
            }
        }
        s.pts.clear();
        for &t in &s.cav {
            for p in self.m.tets[t as usize] {
                if !s.pts.contains(&p) {
                    s.pts.push(p);
                }
            }
        }
        s.pts.iter().all(|&p| {
            s.star
                .iter()
                .any(|(v, f)| TET_FACES[*f].iter().any(|&l| v[l] == p))
        })
    }

    /// The star's angle score with the new point at `pos` (relative to the
    /// cavity's `old` one, under `rank`'s lift); `None` when a tet is not
    /// positive or once the star cannot be [`less`] than `bound`.
    fn score_star(
        &self,
        star: &[([PointId; 4], usize)],
        pos: P3,
        old: &Score,
        rank: &Rank,
        bound: Option<Key>,
    ) -> Option<Score> {
        let (lift, clamp, tan_clamp) = (rank.lift, rank.clamp, rank.tan_clamp);
        let mut sc = Score::NONE;
        for &(v, f) in star {
            let mut x = self.pts(v);
            x[f] = pos;
            let d = positive_min_dihedral_under(x, tan_clamp)?.unwrap_or(clamp);
            sc.add_angle(d);
            if bound.is_some_and(|b| cannot_beat(sc.key(old, lift), b)) {
                return None;
            }
        }
        Some(sc)
    }

    /// The star's score with every min dihedral taken exactly.
    fn exact_score(&self, star: &[([PointId; 4], usize)], pos: P3) -> Score {
        let mut sc = Score::NONE;
        for &(v, f) in star {
            let mut x = self.pts(v);
            x[f] = pos;
            sc.add_angle(min_dihedral_deg(x));
        }
        sc
    }

    /// The star's worst mean ratio with the new point at `pos`.
    fn star_qmin(&self, star: &[([PointId; 4], usize)], pos: P3) -> f64 {
        star.iter()
            .map(|&(v, f)| {
                let mut x = self.pts(v);
                x[f] = pos;
                quality(x)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Cavity `k` of tet `t` into `s.cav`: 0-3 the tet and its neighbour
    /// across face k, 4 the tet and all its neighbours, 5-10 the ring of
    /// edge k-5. False when it does not exist.
    fn cavity(&self, t: u32, k: usize, s: &mut InsScratch) -> bool {
        s.cav.clear();
        s.cav.push(t);
        match k {
            0..=3 => match self.free_neighbour(t, k) {
                Some(n) => {
                    s.cav.push(n.tet().raw());
                    true
                }
                None => false,
            },
            4 => {
                for f in 0..4 {
                    if let Some(n) = self.free_neighbour(t, f) {
                        if !s.cav.contains(&n.tet().raw()) {
                            s.cav.push(n.tet().raw());
                        }
                    }
                }
                s.cav.len() > 2
            }
            _ => {
                let v = self.m.tets[t as usize];
                let e = TET_EDGES[k - 5];
                if self
                    .ring(t, v[e[0]], v[e[1]], &mut s.tets, &mut s.ring)
                    .is_none()
                {
                    return false;
                }
                s.cav.clear();
                s.cav.extend_from_slice(&s.tets);
                true
            }
        }
    }

    /// Old cavity's score from the stored tets.
    fn score_old(&self, cav: &[u32]) -> Score {
        let mut sc = Score::NONE;
        for &t in cav {
            sc.add_angle(min_dihedral_deg(self.pts(self.m.tets[t as usize])));
        }
        sc
    }

    /// The min dihedral an insertion around tet `t` aims at first:
    /// [`LIFT_GOAL`] with `lift` for a tet under [`LIFT_DEG`], else none
    /// (the count under [`SMALL_DIHEDRAL`]).
    pub(crate) fn lift_goal(&self, t: u32, lift: bool) -> Option<f64> {
        (lift && min_dihedral_deg(self.pts(self.m.tets[t as usize])) < LIFT_DEG)
            .then_some(LIFT_GOAL)
    }

    /// Evaluates inserting a point around bad tet `t`; on success `c`
    /// holds the replacement (the new point's id is `m.points.len()`) and
    /// the point's position is returned. `lift`: the min dihedral to aim
    /// at first (`None`: the count under [`SMALL_DIHEDRAL`]).
    pub(crate) fn eval_insert(
        &self,
        t: u32,
        lift: Option<f64>,
        s: &mut InsScratch,
        c: &mut Cand,
    ) -> Result<P3, crate::Outcome> {
        use crate::Outcome;
        let v = self.m.tets[t as usize];
        let x = self.pts(v);
        // Candidate points.
        let mut cands: Vec<P3> = Vec::with_capacity(24);
        let cen = [0, 1, 2].map(|k| 0.25 * (x[0][k] + x[1][k] + x[2][k] + x[3][k]));
        cands.push(cen);
        let mut short = (f64::INFINITY, 0);
        for (i, e) in TET_EDGES.iter().enumerate() {
            let (a, b) = (x[e[0]], x[e[1]]);
            cands.push([0, 1, 2].map(|k| 0.5 * (a[k] + b[k])));
            let l = dist2(a, b);
            if l < short.0 {
                short = (l, i);
            }
        }
        // Around the shortest edge, at its length: a needle tet's apex.
        let e = TET_EDGES[short.1];
        let (a, b) = (x[e[0]], x[e[1]]);
        let l = short.0.sqrt();
        let m = [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
        let ab = sub(b, a);
        let oth: Vec<P3> = (0..4)
            .filter(|&i| i != e[0] && i != e[1])
            .map(|i| x[i])
            .collect();
        for o in &oth {
            let n = cross(ab, sub(*o, a));
            let u = cross(n, ab);
            let nu = norm(u);
            if nu > 0.0 {
                for f in [0.5, 0.87, 1.5] {
                    cands.push([0, 1, 2].map(|k| m[k] + f * l * u[k] / nu));
                }
            }
        }
        let rank = Rank::new(lift);
        let mut best: Option<(Score, Score, P3)> = None;
        for k in 0..CAVITIES {
            if !self.cavity(t, k, s) || !self.star_of(s) {
                continue;
            }
            let old = self.score_old(&s.cav);
            for &p in &cands {
                let bound = best.as_ref().map(|b| b.0.key(&b.1, lift));
                if let Some(sc) = self.score_star(&s.star, p, &old, &rank, bound) {
                    if bound.is_none_or(|b| less(sc.key(&old, lift), b)) {
                        best = Some((sc, old, p));
                        s.best_star.clear();
                        s.best_star.extend_from_slice(&s.star);
                        s.best_cav.clear();
                        s.best_cav.extend_from_slice(&s.cav);
                    }
                }
            }
        }
        let Some((sc, old, pos)) = best else {
            return Err(Outcome::Inverted);
        };
        // Compass search on the chosen cavity.
        let len = s
            .best_star
            .iter()
            .map(|(v, f)| {
                let q = self.m.points[v[TET_FACES[*f][0]].idx()];
                dist2(q, pos).sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        // Lifting the worst tet needs a finer search (they are few).
        let (iters, stop) = if lift.is_some() {
            (60, 1e-4)
        } else {
            (20, 1e-2)
        };
        let (_, pos) = crate::ops::compass(
            pos,
            sc,
            0.3 * len,
            stop * len,
            iters,
            |p, cur| {
                let bound = Some(cur.key(&old, lift));
                self.score_star(&s.best_star, p, &old, &rank, bound)
            },
            |n, cur| less(n.key(&old, lift), cur.key(&old, lift)),
        );
        let sc = self.exact_score(&s.best_star, pos);
        let ok = (sc.under < old.under && sc.dmin >= old.dmin)
            || (lift.is_some()
                && sc.dmin > old.dmin * (1.0 + MARGIN) + 1e-9
                // A lift above the bad angle leaves none under it.
                && lift.is_none_or(|g| g <= SMALL_DIHEDRAL || sc.dmin >= SMALL_DIHEDRAL));
        if !ok {
            return Err(Outcome::NotBetter);
        }
        let np = PointId::new(self.m.points.len());
        c.set(
            &s.best_cav,
            s.best_star.iter().map(|&(mut v, f)| {
                v[f] = np;
                v
            }),
        );
        c.qmin = self.star_qmin(&s.best_star, pos);
        Ok(pos)
    }

    /// Appends a free point at `pos` (for an insertion about to commit).
    pub(crate) fn push_point(&mut self, pos: P3) -> PointId {
        if self.m.points.len() == self.m.points.capacity() {
            self.grow_points();
        }
        self.m.points.push(pos);
        self.frozen.push(false);
        self.dead_pt.push(false);
        self.p2t.push(u32::MAX);
        self.settled.push(false);
        self.touched.push(self.clock);
        self.move_idle.push(0);
        PointId::new(self.m.points.len() - 1)
    }
}

/// Cost of a new tet for the count swaps: 1000 if under [`SMALL_DIHEDRAL`],
/// plus its shortfall below 12°; `None` when not positive. Also its min
/// dihedral.
fn cost(x: [P3; 4]) -> Option<(f64, f64)> {
    if !positive(x) {
        return None;
    }
    let d = min_dihedral_deg(x);
    let bad = if d < SMALL_DIHEDRAL { 1000.0 } else { 0.0 };
    Some((bad + (12.0 - d).max(0.0), d))
}

impl Work<'_> {
    /// Swaps for the dihedral count (§9.1's 2-3 and edge removal, judged
    /// as the insertion is): the best of the 4 face swaps and 6 edge
    /// removals of tet `t` that leaves fewer tets under [`SMALL_DIHEDRAL`] and a
    /// min dihedral no lower. Edge removal takes the triangulation of the
    /// ring with the least summed cost (Klincsek's programme on a sum).
    /// `idle(key)`: an option known to fail (`Improver::idle_at`'s keys),
    /// skipped; the keys of the options that fail here go to `failed`.
    pub(crate) fn eval_count_swap(
        &self,
        t: u32,
        s: &mut InsScratch,
        c: &mut Cand,
        idle: impl Fn([u32; 3]) -> bool,
        failed: &mut Vec<[u32; 3]>,
    ) -> crate::Outcome {
        use crate::Outcome;
        let v = self.m.tets[t as usize];
        // (cost change, under, dmin) of the best candidate so far.
        let mut best: Option<(f64, usize, f64)> = None;
        let mut found = Outcome::NotBetter;
        for f in 0..4 {
            let key = crate::passes::face_key(v, f);
            if idle(key) {
                continue;
            }
            let Some((nt, new)) = self.face_swap(t, f) else {
                failed.push(key);
                continue;
            };
            let old = self.score_old(&[t, nt]);
            let mut sum = 0.0;
            let mut under = 0;
            let mut dmin = f64::INFINITY;
            let mut ok = true;
            for nv in new {
                match cost(self.pts(nv)) {
                    Some((k, dd)) => {
                        sum += k;
                        under += usize::from(dd < SMALL_DIHEDRAL);
                        dmin = dmin.min(dd);
                    }
                    None => ok = false,
                }
            }
            let gain = sum - (1000.0 * old.under as f64 + old.short);
            if !(ok && under < old.under && dmin >= old.dmin) {
                failed.push(key);
            } else if best.is_none_or(|b| gain < b.0) {
                best = Some((gain, under, dmin));
                c.set(&[t, nt], new);
                found = Outcome::Done;
            }
        }
        for e in TET_EDGES {
            let (a, b) = (v[e[0]], v[e[1]]);
            let key = crate::passes::edge_key(a, b);
            if idle(key) {
                continue;
            }
            if self.ring(t, a, b, &mut s.tets, &mut s.ring).is_none() {
                failed.push(key);
                continue;
            }
            let old = self.score_old(&s.tets);
            let n = s.ring.len();
            let (pa, pb) = (self.m.points[a.idx()], self.m.points[b.idx()]);
            let r: Vec<P3> = s.ring.iter().map(|p| self.m.points[p.idx()]).collect();
            // dp[i][j]: (cost, k, under, dmin) of the best triangulation of
            // the ring polygon i..j.
            const N: usize = crate::work::MAX_RING;
            let mut dp = [[(0.0f64, 0usize, 0usize, f64::INFINITY); N]; N];
            for len in 2..n {
                for i in 0..n - len {
                    let j = i + len;
                    let mut bk = (f64::INFINITY, 0, 0, 0.0);
                    for k in i + 1..j {
                        let (l, rr) = (dp[i][k], dp[k][j]);
                        if l.0 + rr.0 >= bk.0 {
                            continue;
                        }
                        let (Some(t1), Some(t2)) =
                            (cost([r[i], r[k], r[j], pb]), cost([r[i], r[j], r[k], pa]))
                        else {
                            continue;
                        };
                        let sum = l.0 + rr.0 + t1.0 + t2.0;
                        if sum < bk.0 {
                            let under = l.2
                                + rr.2
                                + usize::from(t1.1 < SMALL_DIHEDRAL)
                                + usize::from(t2.1 < SMALL_DIHEDRAL);
                            bk = (sum, k, under, l.3.min(rr.3).min(t1.1).min(t2.1));
                        }
                    }
                    dp[i][j] = bk;
                }
            }
            let (sum, _, under, dmin) = dp[0][n - 1];
            let gain = sum - (1000.0 * old.under as f64 + old.short);
            if !sum.is_finite() || under >= old.under || dmin < old.dmin {
                failed.push(key);
                continue;
            }
            if best.is_some_and(|b| gain >= b.0) {
                continue;
            }
            best = Some((gain, under, dmin));
            c.new.clear();
            ring_tets(&s.ring, (0, n - 1), &|i, j| dp[i][j].1, a, b, &mut c.new);
            c.old.clear();
            c.old.extend_from_slice(&s.tets);
            found = Outcome::Done;
        }
        found
    }
}

impl Work<'_> {
    /// Swaps that lift the min dihedral (§9.1's 2-3 and edge removal):
    /// the best of tet `t`'s 4 face swaps and 6 edge removals by the
    /// cavity's min dihedral, kept when it is higher than before and at
    /// least [`SMALL_DIHEDRAL`] (the count passes see to the tets under it). Edge
    /// removal takes the ring's max-min triangulation (Klincsek's
    /// programme on the min). Where every point is on the surface (a plate
    /// one size thick) swaps are all that can raise it.
    pub(crate) fn eval_lift_swap(
        &self,
        t: u32,
        s: &mut InsScratch,
        c: &mut Cand,
    ) -> crate::Outcome {
        use crate::Outcome;
        let v = self.m.tets[t as usize];
        let d_of = |x: [P3; 4]| positive(x).then(|| min_dihedral_deg(x));
        let mut best = f64::NEG_INFINITY;
        let mut found = Outcome::NotBetter;
        for f in 0..4 {
            let Some((nt, new)) = self.face_swap(t, f) else {
                continue;
            };
            let old = self.score_old(&[t, nt]).dmin;
            let dmin = new
                .iter()
                .map(|&nv| d_of(self.pts(nv)).unwrap_or(f64::NEG_INFINITY))
                .fold(f64::INFINITY, f64::min);
            if dmin > old && dmin >= SMALL_DIHEDRAL && dmin > best {
                best = dmin;
                c.set(&[t, nt], new);
                found = Outcome::Done;
            }
        }
        for e in TET_EDGES {
            let (a, b) = (v[e[0]], v[e[1]]);
            if self.ring(t, a, b, &mut s.tets, &mut s.ring).is_none() {
                continue;
            }
            let old = self.score_old(&s.tets).dmin;
            let n = s.ring.len();
            let (pa, pb) = (self.m.points[a.idx()], self.m.points[b.idx()]);
            let r: Vec<P3> = s.ring.iter().map(|p| self.m.points[p.idx()]).collect();
            // dp[i][j]: (min dihedral, k) of the best triangulation of the
            // ring polygon i..j.
            const N: usize = crate::work::MAX_RING;
            let mut dp = [[(f64::INFINITY, 0usize); N]; N];
            for len in 2..n {
                for i in 0..n - len {
                    let j = i + len;
                    let mut bk = (f64::NEG_INFINITY, 0);
                    for k in i + 1..j {
                        let m = dp[i][k].0.min(dp[k][j].0);
                        if m <= bk.0 {
                            continue;
                        }
                        let (Some(t1), Some(t2)) =
                            (d_of([r[i], r[k], r[j], pb]), d_of([r[i], r[j], r[k], pa]))
                        else {
                            continue;
                        };
                        let m = m.min(t1).min(t2);
                        if m > bk.0 {
                            bk = (m, k);
                        }
                    }
                    dp[i][j] = bk;
                }
            }
            let dmin = dp[0][n - 1].0;
            if !(dmin > old && dmin >= SMALL_DIHEDRAL && dmin > best) {
                continue;
            }
            best = dmin;
            c.new.clear();
            ring_tets(&s.ring, (0, n - 1), &|i, j| dp[i][j].1, a, b, &mut c.new);
            c.old.clear();
            c.old.extend_from_slice(&s.tets);
            found = Outcome::Done;
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::has_dihedral_under;

    /// A tet the cheap test passes has its min dihedral at the clamp or
    /// above, so taking it as the clamp leaves every key as it was.
    #[test]
    fn a_tet_with_no_angle_under_the_clamp_has_its_min_there_or_above() {
        let mut r = crate::test_rng(0x5151_7a7a_0f0f_3c3cu64);
        let mut passed = 0;
        for _ in 0..50_000 {
            let p: [P3; 4] = std::array::from_fn(|_| [r(), r(), r()]);
            for clamp in [SHORT_DEG, 18.0] {
                if !has_dihedral_under(p, clamp.to_radians().tan()) {
                    passed += 1;
                    assert!(min_dihedral_deg(p) >= clamp * (1.0 - 1e-12), "{p:?}");
                }
            }
        }
        assert!(passed > 1000, "{passed}");
    }

    /// The search's pruning is sound: a star whose first tets cannot beat
    /// a key never does, whatever tets follow.
    #[test]
    fn a_pruned_star_never_beats_the_bound() {
        let mut r = crate::test_rng(0x1234_5678_9abc_def1u64);
        let mut pruned = 0;
        for k in 0..20_000 {
            let lift = (k % 2 == 0).then_some(LIFT_GOAL);
            let mut old = Score::NONE;
            for _ in 0..3 {
                old.add_angle(15.0 * r());
            }
            let mut b = Score::NONE;
            for _ in 0..6 {
                // Angles near the thresholds, so that keys tie often.
                b.add_angle([0.05, 0.2, 9.99, 10.0, 12.0, 20.0][(r() * 6.0) as usize]);
            }
            let bound = b.key(&old, lift);
            let mut sc = Score::NONE;
            let mut was_pruned = false;
            for _ in 0..6 {
                sc.add_angle([0.05, 0.2, 9.99, 10.0, 12.0, 20.0][(r() * 6.0) as usize]);
                was_pruned |= cannot_beat(sc.key(&old, lift), bound);
                if was_pruned {
                    assert!(!less(sc.key(&old, lift), bound));
                }
            }
            pruned += usize::from(was_pruned);
        }
        assert!(pruned > 1000, "{pruned}");
    }
}

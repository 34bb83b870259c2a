//! The improvement's passes over the whole mesh (§9): which tets each
//! operation is tried on, in which order, and how often; the operations
//! themselves are in `ops.rs` (swaps, collapse), `moves.rs` (point moves)
//! and `insert.rs`.
use super::*;
use rayon::prelude::*;

/// The third entry of an edge removal's key in [`Improver::idle_at`]'s
/// memo (no point has this id).
const EDGE_KEY: u32 = u32::MAX;
/// The third entry of a collapse's key.
const COLLAPSE_KEY: u32 = u32::MAX - 1;

/// An edge removal's key in the idle memos: its ends, lower first, then
/// [`EDGE_KEY`].
#[inline]
pub(crate) fn edge_key(a: PointId, b: PointId) -> [u32; 3] {
    [a.raw().min(b.raw()), a.raw().max(b.raw()), EDGE_KEY]
}

/// A 2-3 swap's key in the idle memos: the corners of the face of `v`
/// opposite corner `f`, sorted.
#[inline]
pub(crate) fn face_key(v: [PointId; 4], f: usize) -> [u32; 3] {
    let mut key = [1, 2, 3].map(|k| v[(f + k) % 4].raw());
    key.sort_unstable();
    key
}

impl Improver<'_> {
    /// What follows the last dihedral polish on a whole mesh (parts leave
    /// it to the final polish): the passes for the tets under 10°, the
    /// polish again, and the lift of the worst.
    pub(crate) fn whole_mesh_passes(&mut self, st: &mut ImproveStats) {
        self.dihedral_count_passes(st);
        self.dihedral_pass(st);
        self.lift_worst_pass(st);
    }

    /// Whether tet `t` is alive with min dihedral still `d0` (what a
    /// worst-first list saw before the operations on it).
    pub(crate) fn unchanged(&self, t: u32, d0: f64) -> bool {
        self.w.alive(t) && quality::min_dihedral_deg(self.w.pts(self.w.m.tets[t as usize])) == d0
    }

    /// The worst tets under [`LIFT_SWAP_DEG`] ([`LIFT_WORST`] of them),
    /// worst first, each lifted by a swap or else a point, when that
    /// raises its cavity's min dihedral to at least 10°: the mesh's min
    /// dihedral is the first measure (base_interface at the
    /// peers' h: 13.19° -> 17.63°). Then the free points of those still
    /// under it move (counted with the selective movement).
    pub(crate) fn lift_worst_pass(&mut self, st: &mut ImproveStats) {
        let t0 = Instant::now();
        // Again while it lifts any: a lift may leave a new worst tet under
        // the floor (a torus in 8 parts: 17.02° became 17.64°).
        for _ in 0..LIFT_PASSES {
            let worst = self.worst_under_lift();
            if worst.is_empty() {
                break;
            }
            let lifted = self.lift_worst_once(worst, st);
            // Then their points: a lift's new point stays where its
            // cavity's search put it, and a tet no swap or point lifts
            // may still be lifted by a move (spheres27_1e5 at --size 0.1
            // in 6 parts: 16.71° -> 20.22°).
            let moved = self.lift_move_once(st);
            if lifted + moved == 0 {
                break;
            }
        }
        // Counted with the insertion.
        st.insert.seconds += t0.elapsed().as_secs_f64();
    }

    /// The free points of the worst tets under [`LIFT_SWAP_DEG`] move to
    /// raise their ball's min dihedral ([`Work::eval_dihedral`]); how many
    /// moved.
    fn lift_move_once(&mut self, st: &mut ImproveStats) -> usize {
        let worst = self.worst_under_lift();
        self.move_for_dihedral(&worst, st)
    }

    /// The free points of `worst` (tets, worst first), each moved to raise
    /// its ball's min dihedral ([`Work::eval_dihedral`]); how many moved.
    /// Counted with the selective movement.
    fn move_for_dihedral(&mut self, worst: &[(f64, u32)], st: &mut ImproveStats) -> usize {
        let mut list = vec![];
        for &(_, t) in worst {
            for p in self.w.m.tets[t as usize] {
                if !self.w.frozen[p.idx()] && !list.contains(&p) {
                    list.push(p);
                }
            }
        }
        let mut moved = 0;
        self.move_in_batches(
            list,
            |_, _| true,
            |w, p, ball, nb| w.eval_dihedral(p, DIHEDRAL_KEEP, ball, nb),
            |_, _, o| {
                st.selective.tried += 1;
                moved += usize::from(o == Outcome::Done);
            },
        );
        st.selective.done += moved;
        moved
    }

    /// The live tets under [`LIFT_SWAP_DEG`], worst first, at most
    /// [`LIFT_WORST`].
    fn worst_under_lift(&self) -> Vec<(f64, u32)> {
        let mut worst: Vec<(f64, u32)> = (0..self.w.m.tets.len() as u32)
            .filter(|&t| {
                self.w.alive(t)
                    && quality::has_dihedral_under(self.w.pts(self.w.m.tets[t as usize]), TAN_LIFT)
            })
            .map(|t| {
                (
                    quality::min_dihedral_deg(self.w.pts(self.w.m.tets[t as usize])),
                    t,
                )
            })
            .filter(|x| x.0 < LIFT_SWAP_DEG)
            .collect();
        worst.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        worst.truncate(LIFT_WORST);
        worst
    }

    /// The lifts of one pass of [`Improver::lift_worst_pass`] on `worst`;
    /// how many tets they lifted.
    fn lift_worst_once(&mut self, worst: Vec<(f64, u32)>, st: &mut ImproveStats) -> usize {
        let mut lifted = 0;
        for (d0, t) in worst {
            if !self.unchanged(t, d0) {
                continue;
            }
            st.swap.tried += 1;
            if self.swap_for_min_dihedral(t) == Outcome::Done {
                st.swap.done += 1;
                lifted += 1;
                continue;
            }
            st.insert.tried += 1;
            if self.insert_with(t, Some(LIFT_SWAP_DEG)) == Outcome::Done {
                st.insert.done += 1;
                st.points_inserted += 1;
                lifted += 1;
            }
        }
        lifted
    }

    /// Point insertion around the tets under 10°, worst first, a few
    /// rounds while it changes anything; then rounds that lift the tets
    /// under 0.1° and a last plain round.
    pub(crate) fn insert_pass(&mut self, st: &mut ImproveStats) {
        let t0 = Instant::now();
        // A tet whose insertion failed is not tried again until its
        // neighbourhood changes (§9.1's marks).
        self.w.tested.iter_mut().for_each(|x| *x = false);
        let mut round = 0;
        while round < INSERT_ROUNDS + LIFT_ROUNDS + 1 {
            let lift = (INSERT_ROUNDS..INSERT_ROUNDS + LIFT_ROUNDS).contains(&round);
            let bad = self.under_deg(if lift {
                insert::LIFT_DEG
            } else {
                insert::SMALL_DIHEDRAL
            });
            if bad.is_empty() && round == 0 {
                break; // none under 10°, so none under 0.1°
            }
            let mut changed = 0;
            // In batches of tets far apart, each evaluated at once (the
            // insertion's search is most of the improvement's time on CAD
            // parts) and committed in order.
            let mut b = std::mem::take(&mut self.batch);
            let mut pending = bad;
            while !pending.is_empty() {
                self.next_batch(&mut b, &mut pending, |s, d0, t| {
                    s.unchanged(t, d0) && (lift || !s.w.tested[t as usize])
                });
                let found = self.eval_inserts(&b.tets, lift);
                let next = PointId::new(self.w.m.points.len());
                for (&t, r) in b.tets.iter().zip(found) {
                    st.insert.tried += 1;
                    let o = match r {
                        Ok((pos, mut c)) => {
                            // Each commit's point takes the next id.
                            let p = PointId::new(self.w.m.points.len());
                            c.new.iter_mut().flatten().for_each(|v| {
                                if *v == next {
                                    *v = p;
                                }
                            });
                            self.best = c;
                            self.commit_insert(pos)
                        }
                        Err(o) => o,
                    };
                    if o == Outcome::Done {
                        st.insert.done += 1;
                        st.points_inserted += 1;
                        changed += 1;
                    } else if !lift {
                        self.w.tested[t as usize] = true;
                    }
                }
            }
            self.batch = b;
            // Plain rounds stop when nothing changes.
            round = if changed == 0 && round < INSERT_ROUNDS {
                INSERT_ROUNDS
            } else {
                round + 1
            };
        }
        st.insert.seconds += t0.elapsed().as_secs_f64();
    }

    /// For the share of tets under 10°: moves, swaps, point
    /// insertion, moves, swaps, moves. Measured on the
    /// tray (5,090 such tets after the passes before): moves alone leave
    /// 3,962; moves, insertion and moves 3,368; with the swaps 3,051;
    /// the same again with a second insertion 3,009 for 385 more tets.
    pub(crate) fn dihedral_count_passes(&mut self, st: &mut ImproveStats) {
        // One scan when there is nothing to do (the smooth parts).
        if !(0..self.w.m.tets.len() as u32).any(|t| self.w.alive(t) && self.under_bad(t)) {
            return;
        }
        self.count_pass(st);
        self.count_swap_pass(st);
        self.insert_pass(st);
        self.count_pass(st);
        self.count_swap_pass(st);
        self.count_pass(st);
    }

    /// [`Work::eval_insert`] on each of `tets` (a batch: far apart), at
    /// once; `lift` as [`Improver::insert_point`] takes it.
    fn eval_inserts(&self, tets: &[u32], lift: bool) -> Vec<Result<(P3, Cand), Outcome>> {
        let w = &self.w;
        // One tet per task: their searches' costs differ tenfold, and
        // rayon's halves would leave a thread waiting on the slower half.
        tets.par_iter()
            .with_max_len(1)
            .map_init(
                || (insert::InsScratch::default(), Cand::default()),
                |(s, c), &t| {
                    w.eval_insert(t, w.lift_goal(t, lift), s, c)
                        .map(|pos| (pos, c.clone()))
                },
            )
            .collect()
    }

    /// Swaps around the tets under 10° that leave fewer of them
    /// ([`Work::eval_count_swap`]), worst first, while any is done.
    /// Counted with the swaps.
    pub(crate) fn count_swap_pass(&mut self, st: &mut ImproveStats) {
        let t0 = Instant::now();
        for _round in 0..INSERT_ROUNDS {
            let bad = self.under_deg(insert::SMALL_DIHEDRAL);
            let mut changed = 0;
            for (d0, t) in bad {
                if !self.unchanged(t, d0) || self.w.swap_idle(t) {
                    continue;
                }
                st.swap.tried += 1;
                if self.swap_for_dihedral(t) == Outcome::Done {
                    st.swap.done += 1;
                    changed += 1;
                } else {
                    self.w.swap_idle[t as usize] = self.w.tick();
                }
            }
            if changed == 0 {
                break;
            }
        }
        st.swap.seconds += t0.elapsed().as_secs_f64();
    }

    /// Whether tet `t` has a dihedral angle under 10° (cheap test,
    /// cached while the tet does not change).
    pub(crate) fn under_bad(&mut self, t: u32) -> bool {
        if self.w.dok[t as usize] {
            return false;
        }
        let bad =
            quality::has_dihedral_under(self.w.pts(self.w.m.tets[t as usize]), TAN_SMALL_DIHEDRAL);
        self.w.dok[t as usize] = !bad;
        bad
    }

    /// The live tets with a dihedral angle under `deg` (at most 10°) and
    /// their min dihedral, worst first.
    pub(crate) fn under_deg(&mut self, deg: f64) -> Vec<(f64, u32)> {
        let mut bad = Vec::new();
        for t in 0..self.w.m.tets.len() as u32 {
            if self.w.alive(t) && self.under_bad(t) {
                let d = quality::min_dihedral_deg(self.w.pts(self.w.m.tets[t as usize]));
                if d < deg {
                    bad.push((d, t));
                }
            }
        }
        bad.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        bad
    }

    /// Moves the free points of the tets under 10° to leave fewer of them
    /// ([`Work::eval_count_move`]), worst tet first. Counted with the
    /// selective movement.
    pub(crate) fn count_pass(&mut self, st: &mut ImproveStats) {
        let t0 = Instant::now();
        let bad = self.under_deg(insert::SMALL_DIHEDRAL);
        let mut seen = vec![false; self.w.m.points.len()];
        let mut list = Vec::new();
        for (_, t) in bad {
            for p in self.w.m.tets[t as usize] {
                if !self.w.frozen[p.idx()] && !seen[p.idx()] {
                    seen[p.idx()] = true;
                    list.push(p);
                }
            }
        }
        // The compass searches are most of this pass's time: in batches.
        self.move_in_batches(
            list,
            |s, p| !s.w.move_idle(p),
            |w, p, ball, nb| w.eval_count_move(p, ball, nb),
            |s, p, o| {
                st.selective.tried += 1;
                if o == Outcome::Done {
                    st.selective.done += 1;
                } else {
                    s.w.move_idle[p.idx()] = s.w.tick();
                }
            },
        );
        st.selective.seconds += t0.elapsed().as_secs_f64();
    }

    pub(crate) fn finish_op(&mut self, o: Outcome) -> Outcome {
        if o == Outcome::Done && !self.commit() {
            debug_assert!(false, "a replacement did not fit its cavity");
            return Outcome::Inverted;
        }
        o
    }

    /// Live tets with quality below `thr` and not marked tested, worst
    /// first (§9.1).
    pub(crate) fn bad_tets(&self, thr: f64, skip_tested: bool) -> Vec<(f64, u32)> {
        let mut bad: Vec<(f64, u32)> = (0..self.w.m.tets.len() as u32)
            .filter(|&t| {
                let q = self.w.q[t as usize];
                q < thr && !(skip_tested && self.w.tested[t as usize])
            })
            .map(|t| (self.w.q[t as usize], t))
            .collect();
        bad.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        bad
    }

    /// §9.1: swap around bad tets, worst first, until a round changes
    /// nothing. For each tet the best of its 4 face swaps and 6 edge
    /// removals is kept.
    pub(crate) fn swap_pass(&mut self, thr: f64, st: &mut ImproveStats) {
        let t0 = Instant::now();
        // Marks hold within a pass (§9.1); smoothing in between may have
        // changed a ring without touching the marked tet.
        self.w.tested.iter_mut().for_each(|x| *x = false);
        for _round in 0..10 {
            let bad = self.bad_tets(thr, true);
            let mut changed = 0;
            for (q0, t) in bad {
                if self.w.q[t as usize] != q0 {
                    continue; // replaced since the list was made
                }
                st.swap.tried += 1;
                if let Some(kind) = self.improve_tet(t) {
                    changed += 1;
                    st.swap.done += 1;
                    match kind {
                        0 => st.swaps_23 += 1,
                        3 => st.swaps_32 += 1,
                        _ => st.edge_removals += 1,
                    }
                } else {
                    self.w.tested[t as usize] = true;
                }
            }
            if changed == 0 {
                break;
            }
        }
        st.swap.seconds += t0.elapsed().as_secs_f64();
    }

    /// The best swap around `t`, committed; returns 0 for a 2-3 swap or
    /// the ring size of an edge removal.
    pub(crate) fn improve_tet(&mut self, t: u32) -> Option<usize> {
        let mut best_q = f64::NEG_INFINITY;
        let mut kind = None;
        let v = self.w.m.tets[t as usize];
        let mut failed = std::mem::take(&mut self.failed);
        failed.clear();
        for e in TET_EDGES {
            let (a, b) = (v[e[0]], v[e[1]]);
            let key = edge_key(a, b);
            if self.idle_at(key) {
                continue;
            }
            let o = self.w.eval_edge_removal(t, a, b, &mut self.s, &mut self.c);
            if o != Outcome::Done {
                failed.push(key);
            } else if self.c.qmin > best_q {
                best_q = self.c.qmin;
                kind = Some(self.c.old.len());
                std::mem::swap(&mut self.c, &mut self.best);
            }
        }
        for f in 0..4 {
            let key = face_key(v, f);
            if self.idle_at(key) {
                continue;
            }
            let o = self.w.eval_23(t, f, &mut self.c);
            if o != Outcome::Done {
                failed.push(key);
            } else if self.c.qmin > best_q {
                best_q = self.c.qmin;
                kind = Some(0);
                std::mem::swap(&mut self.c, &mut self.best);
            }
        }
        note_idle(&mut self.w, &mut self.idle_memo, &failed);
        self.failed = failed;
        let k = kind?;
        self.commit().then_some(k)
    }

    /// The operation keyed `key` did nothing when last tried, and none of
    /// its points has been touched since: tried again from a neighbouring
    /// tet (or in a later pass) it would do nothing again. Keys: an edge
    /// removal's ends (lower first) then [`EDGE_KEY`], a 2-3 swap's face
    /// corners (sorted), a collapse's two ends (the one that goes first)
    /// then [`COLLAPSE_KEY`].
    fn idle_at(&mut self, key: [u32; 3]) -> bool {
        let idle = idle_in(&self.w, &self.idle_memo, key);
        self.idle_skips += usize::from(idle);
        idle
    }

    /// §9.2: collapse an edge of each very bad tet, worst first, when the
    /// worst tet around the removed point gets better.
    pub(crate) fn collapse_pass(&mut self, thr: f64, st: &mut ImproveStats) {
        let t0 = Instant::now();
        for (q0, t) in self.bad_tets(thr, false) {
            if self.w.q[t as usize] != q0 {
                continue;
            }
            st.collapse.tried += 1;
            let v = self.w.m.tets[t as usize];
            let mut best_q = f64::NEG_INFINITY;
            let mut gone = None;
            let mut failed = std::mem::take(&mut self.failed);
            failed.clear();
            for e in TET_EDGES {
                for (a, b) in [(v[e[0]], v[e[1]]), (v[e[1]], v[e[0]])] {
                    if self.w.frozen[a.idx()] {
                        continue;
                    }
                    let key = [a.raw(), b.raw(), COLLAPSE_KEY];
                    if self.idle_at(key) {
                        continue;
                    }
                    let o = self.w.eval_collapse(a, b, &mut self.s, &mut self.c);
                    if o != Outcome::Done {
                        failed.push(key);
                    } else if self.c.qmin > best_q {
                        best_q = self.c.qmin;
                        gone = Some(a);
                        std::mem::swap(&mut self.c, &mut self.best);
                    }
                }
            }
            note_idle(&mut self.w, &mut self.idle_memo, &failed);
            self.failed = failed;
            if let Some(a) = gone {
                if self.commit() {
                    self.remove_point(a);
                    st.collapse.done += 1;
                }
            }
        }
        st.collapse.seconds += t0.elapsed().as_secs_f64();
    }

    /// §9.3: one Gauss-Seidel pass of Laplacian smoothing over the free
    /// points, in id order.
    pub(crate) fn smooth_pass(&mut self, st: &mut ImproveStats) {
        let t0 = Instant::now();
        for p in 0..self.w.m.points.len() {
            if self.w.frozen[p] || self.w.dead_pt[p] || self.w.settled[p] {
                continue;
            }
            st.smooth.tried += 1;
            if self.w.smooth_point(PointId::new(p), &mut self.s) == Outcome::Done {
                st.smooth.done += 1;
            } else {
                self.w.settled[p] = true;
            }
        }
        st.smooth.seconds += t0.elapsed().as_secs_f64();
    }

    /// The last polish: the free points of the tets under
    /// [`DIHEDRAL_POLISH`] degrees, worst tet first, move to raise their
    /// ball's min dihedral ([`Work::eval_dihedral`]). Counted with the
    /// selective movement.
    pub(crate) fn dihedral_pass(&mut self, st: &mut ImproveStats) {
        let t0 = Instant::now();
        let mut worst: Vec<(f64, u32)> = self
            .bad_tets(VERY_BAD, false)
            .into_iter()
            .map(|(_, t)| {
                (
                    quality::min_dihedral_deg(self.w.pts(self.w.m.tets[t as usize])),
                    t,
                )
            })
            .filter(|&(d, _)| d < DIHEDRAL_POLISH)
            .collect();
        worst.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        self.move_for_dihedral(&worst, st);
        st.selective.seconds += t0.elapsed().as_secs_f64();
    }

    /// §9.4: selective movement of the free points of bad tets.
    pub(crate) fn selective_pass(&mut self, thr: f64, st: &mut ImproveStats) {
        let t0 = Instant::now();
        let mut pts: Vec<PointId> = self
            .bad_tets(thr, false)
            .iter()
            .flat_map(|&(_, t)| self.w.m.tets[t as usize])
            .filter(|p| !self.w.frozen[p.idx()])
            .collect();
        pts.sort_unstable();
        pts.dedup();
        self.move_in_batches(
            pts,
            |_, _| true,
            |w, p, ball, nb| w.eval_selective(p, ball, nb),
            |_, _, o| {
                st.selective.tried += 1;
                st.selective.done += usize::from(o == Outcome::Done);
            },
        );
        st.selective.seconds += t0.elapsed().as_secs_f64();
    }
}

/// Whether `memo` holds `key` from a try at a clock after every change to
/// its points (and the shortcuts are on).
pub(crate) fn idle_in(w: &Work, memo: &crate::memo::IdleMemo, key: [u32; 3]) -> bool {
    w.shortcuts
        && memo.get(key).is_some_and(|at| {
            key.iter()
                .filter(|&&p| p < COLLAPSE_KEY)
                .all(|&p| w.touched[p as usize] < at)
        })
}

/// The tries keyed `keys` did nothing: into `memo`, with one tick of the
/// clock for them all (nothing changed between them), so that it does not
/// run out on large meshes.
pub(crate) fn note_idle(w: &mut Work, memo: &mut crate::memo::IdleMemo, keys: &[[u32; 3]]) {
    if keys.is_empty() {
        return;
    }
    let at = w.tick();
    for &key in keys {
        memo.insert(key, at);
    }
}

//! Mesh improvement (Löhner 2014, §9): works on any valid tet mesh.
//!
//! - §9.1 diagonal swapping: 2-3 face swaps and edge removal (3-2, and the
//!   general n -> 2n-4 by an optimal triangulation of the edge's ring).
//!   Only bad tets, worst first; a candidate is dropped at the first new
//!   tet that is not better; tets tested and left alone are marked.
//! - §9.2 removal of bad elements by edge collapse, with the link
//!   condition.
//! - §9.3 Laplacian smoothing with move rejection (no tet may invert and
//!   the worst quality of the ball may not drop).
//! - §9.4 selective movement of the points of bad tets along their edges,
//!   as a final polish.
//!
//! - A last polish moves the free points of tets under 1° to raise their
//!   ball's min dihedral, within a tenth of the ball's worst mean ratio.
//! - For the tets under 10°, after all that: their free points
//!   move and swaps are done to leave fewer of them, and new points go in
//!   (Steiner points, not in the paper: `insert.rs`); in serial runs and
//!   in the final polish of a parallel one (parts keep their point ids).
//!
//! One quality measure drives every operation but the last four: the
//! mean ratio ([`quality::quality`]); those work on the dihedral angles,
//! which are what they are for. Faces on the boundary or between regions are
//! constraints: nothing swaps across them and their points never move.
//! Everything is serial and in index order, so the result is determined
//! by the input.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod batch;
mod insert;
mod memo;
mod moves;
mod ops;
pub mod parallel;
mod passes;
pub mod quality;
mod work;

/// The tests' random numbers: xorshift64, uniform in [0, 1).
#[cfg(test)]
pub(crate) fn test_rng(mut x: u64) -> impl FnMut() -> f64 {
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
}

pub use ops::Outcome;

use ops::{Cand, Scratch};
use parafront_geom::P3;
use parafront_mesh::quality::TET_EDGES;
use parafront_mesh::{PointId, TetMesh, TopoError};
use serde::{Deserialize, Serialize};
use std::time::Instant;
use work::Work;

/// How hard to improve.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImproveOptions {
    /// 0: off. 1: swaps of tets with mean ratio below 0.4 and two
    /// smoothing passes. 2 (default): swaps below 0.7, edge collapse of
    /// tets below 0.1, three smoothing passes, selective movement and a
    /// last swap pass below 0.8.
    /// 3: one more smoothing and one more selective pass.
    #[serde(default = "default_level")]
    pub level: u8,
    /// Parts improved in parallel (§9.5), each with its interface frozen,
    /// then a second pass on parts shifted by two layers. 0 (default):
    /// one part per [`parallel::TETS_PER_PART`] tets; 1: serial. The
    /// result depends on the parts, not on the threads.
    #[serde(default)]
    pub parts: usize,
}

fn default_level() -> u8 {
    2
}

impl Default for ImproveOptions {
    fn default() -> Self {
        ImproveOptions {
            level: default_level(),
            parts: 0,
        }
    }
}

/// Counts and time of one kind of operation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OpStats {
    /// Candidates evaluated (tets, points).
    pub tried: usize,
    /// Changes kept.
    pub done: usize,
    /// Time spent in this operation's passes, in seconds; with parallel parts
    /// (§9.5) the parts' times are summed, so it can exceed the wall time.
    pub seconds: f64,
}

/// What an improvement run did, per operation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImproveStats {
    /// Diagonal swapping (§9.1): 2-3 face swaps and edge removals.
    pub swap: OpStats,
    /// Removal of bad tets by edge collapse (§9.2).
    pub collapse: OpStats,
    /// Laplacian smoothing with move rejection (§9.3).
    pub smooth: OpStats,
    /// Selective point movement (§9.4), and the later point moves that work
    /// on the dihedral angles.
    pub selective: OpStats,
    /// Steiner point insertion around tets under 10° (an addition to §9).
    pub insert: OpStats,
    /// 2-3 swaps, 3-2 swaps, edge removals with n >= 4 among `swap.done`.
    pub swaps_23: usize,
    /// 3-2 swaps (edge removal on a ring of three tets) among `swap.done`.
    pub swaps_32: usize,
    /// Edge removals on rings of four or more tets (n -> 2n-4) among
    /// `swap.done`.
    pub edge_removals: usize,
    /// Points removed by edge collapse (§9.2), counted when the mesh is compacted.
    pub points_removed: usize,
    /// Steiner points inserted (an addition to §9).
    pub points_inserted: usize,
    /// Tets in the mesh on entry.
    pub tets_before: usize,
    /// Tets in the mesh on return, after dead tets are dropped.
    pub tets_after: usize,
    /// Wall time of the whole improvement, in seconds.
    pub seconds: f64,
}

impl ImproveStats {
    /// Adds `b`'s operation counts and seconds (the parts of one run).
    pub fn add_ops(&mut self, b: &ImproveStats) {
        for (x, y) in [
            (&mut self.swap, b.swap),
            (&mut self.collapse, b.collapse),
            (&mut self.smooth, b.smooth),
            (&mut self.selective, b.selective),
            (&mut self.insert, b.insert),
        ] {
            x.tried += y.tried;
            x.done += y.done;
            x.seconds += y.seconds;
        }
        self.swaps_23 += b.swaps_23;
        self.swaps_32 += b.swaps_32;
        self.edge_removals += b.edge_removals;
    }

    /// (operation, stats) in a fixed order, for reports.
    pub fn ops(&self) -> [(&'static str, OpStats); 5] {
        [
            ("swap", self.swap),
            ("collapse", self.collapse),
            ("smooth", self.smooth),
            ("selective", self.selective),
            ("insert", self.insert),
        ]
    }
}

/// Improves `mesh` in place. `frozen[p]` marks points that must not move
/// or disappear (shorter than the point array: the rest is free); points
/// of boundary and region-interface faces are frozen regardless. Builds
/// the adjacency if it is missing. The mesh stays valid after every
/// operation; dead tets and points are dropped at the end (surviving ids
/// keep their order, so a point below every removed one keeps its id).
/// With more than one part (§9.5) the parts are improved in parallel, and
/// the result depends on the number of parts, never on the threads.
pub fn improve(
    mesh: &mut TetMesh,
    frozen: &[bool],
    opts: &ImproveOptions,
) -> Result<ImproveStats, TopoError> {
    let mut st = ImproveStats {
        tets_before: mesh.tets.len(),
        tets_after: mesh.tets.len(),
        ..Default::default()
    };
    if opts.level == 0 || mesh.tets.is_empty() {
        return Ok(st);
    }
    let t0 = Instant::now();
    let parts = parallel::part_count(opts.parts, mesh.tets.len());
    if parts <= 1 {
        let dead = run(mesh, frozen, opts.level, &mut st, true, true)?;
        st.points_removed = dead.iter().filter(|&&d| d).count();
    } else {
        parallel::improve_parts(mesh, frozen, opts.level, parts, &mut st)?;
        // §9.4 final polish over the whole mesh: the few bad tets left
        // where many parts met (cheap: only bad tets are visited).
        let mut imp = Improver::new(mesh, frozen)?;
        imp.collapse_pass(VERY_BAD, &mut st);
        imp.swap_pass(POLISH, &mut st);
        imp.selective_pass(POLISH, &mut st);
        imp.swap_pass(POLISH, &mut st);
        imp.dihedral_pass(&mut st);
        imp.whole_mesh_passes(&mut st);
        st.points_removed += imp.w.compact(true).iter().filter(|&&d| d).count();
    }
    st.tets_after = mesh.tets.len();
    st.seconds = t0.elapsed().as_secs_f64();
    Ok(st)
}

/// Mean ratio under which edge collapse is tried (§9.2).
const VERY_BAD: f64 = 0.1;
/// Mean ratio under which the last swap pass of levels 2 and 3 works,
/// after the smoothing and selective movement have settled the points.
/// Measured on base_interface_gmsh (a 4.8 mm plate at h = 6.6, where 90 %
/// of the points are on the surface and swaps are what is left): mean
/// radius ratio 0.770 -> 0.772 for 0.04 s; 0.75 gives 0.771, 0.85-1.0 no
/// more than 0.8 for 2-4x the time, and swapping up to 0.9 in every pass
/// instead gives 0.771 for 5x the time.
const FINAL_SWAP: f64 = 0.8;
/// Tets under this min dihedral (degrees) and under [`VERY_BAD`] get the
/// last polish of their free points for the dihedral angle.
const DIHEDRAL_POLISH: f64 = 1.0;
/// The share of the ball's worst mean ratio that polish may give up.
const DIHEDRAL_KEEP: f64 = 0.9;
/// tan(`SMALL_DIHEDRAL`) (10°), for [`quality::has_dihedral_under`]; a
/// test holds them together.
const TAN_SMALL_DIHEDRAL: f64 = 0.176_326_980_708_464_98;
/// tan(12.5°): the dihedral count's search takes a tet with no angle
/// under it (the cheap tangent test) as adding nothing to its count or
/// shortfall, which stop at 10° and 12°.
const TAN_12_5: f64 = 0.221_694_662_642_939_88;
/// Rounds of point insertion.
const INSERT_ROUNDS: usize = 3;
/// Rounds of insertion that lift the tets under 0.1°, after those.
const LIFT_ROUNDS: usize = 2;
/// Tets under this min dihedral (degrees) may be lifted, last: the
/// issue's floor of 20° (at 18°, sphere_1e6 at `--parts 4` kept a tet of
/// 18.57° where the passes met).
pub const LIFT_SWAP_DEG: f64 = 20.0;
/// Its tangent.
const TAN_LIFT: f64 = 0.363_970_234_266_202_34;
/// The worst tets (at most) that get a swap or a point to lift them.
const LIFT_WORST: usize = 64;
/// Passes of that lift, while one lifts any.
const LIFT_PASSES: usize = 3;
/// Mean ratio under which the final polish after a parallel run works.
const POLISH: f64 = 0.5;

/// The serial schedule of one level over a whole mesh (or one part);
/// returns which points died. With `drop_points` false the dead points
/// stay in the array (unused) so that ids do not shift. `whole`: the
/// whole mesh, not a part; only then the passes for the tets under 10°.
pub(crate) fn run(
    mesh: &mut TetMesh,
    frozen: &[bool],
    level: u8,
    st: &mut ImproveStats,
    drop_points: bool,
    whole: bool,
) -> Result<Vec<bool>, TopoError> {
    let mut imp = Improver::new(mesh, frozen)?;
    schedule(&mut imp, level, st, whole);
    Ok(imp.w.compact(drop_points))
}

/// [`run`]'s passes on `imp`.
fn schedule(imp: &mut Improver, level: u8, st: &mut ImproveStats, whole: bool) {
    let lv = level.min(3);
    // Thresholds on the mean ratio: "bad" for swaps and movement, "very
    // bad" for collapse (§9.2 is a pre-smoothing cleaner). Measured on
    // sphere_1e5: swapping up to 0.7 lifts the mean radius ratio from
    // 0.836 to 0.852 for twice the time; 0.8 or 0.9 cost 3-10x more and
    // gain nothing; collapsing up to 0.3 or 0.5 loses a little.
    let bad = [0.0, 0.4, 0.7, 0.7][lv as usize];
    let very_bad = VERY_BAD;
    let smooth_passes = [0, 2, 3, 4][lv as usize];
    if lv >= 2 {
        imp.collapse_pass(very_bad, st);
    }
    imp.swap_pass(bad, st);
    for _ in 0..smooth_passes {
        imp.smooth_pass(st);
        imp.swap_pass(bad, st);
    }
    if lv >= 2 {
        imp.collapse_pass(very_bad, st);
        for _ in 0..lv - 1 {
            imp.selective_pass(bad, st);
            imp.swap_pass(bad, st);
        }
    }
    if lv >= 2 {
        imp.swap_pass(FINAL_SWAP, st);
        imp.dihedral_pass(st);
        // On the whole mesh only (parts leave it to the final polish):
        // what follows never lowers the min dihedral, so the result keeps
        // at least the min of the passes before.
        if whole {
            imp.whole_mesh_passes(st);
        }
    }
}

/// The improver's state over a mesh: single operations for tests and
/// tools, the passes for [`improve`]. Call [`Improver::finish`] to drop
/// the dead tets and points.
pub struct Improver<'m> {
    w: Work<'m>,
    s: Scratch,
    ins: insert::InsScratch,
    c: Cand,
    best: Cand,
    batch: batch::Batch,
    points: batch::PointBatch,
    /// Swaps and collapses that did nothing, at the clock of the try
    /// (`Improver::idle_at`).
    idle_memo: memo::IdleMemo,
    /// The same for the count swaps' options (`Work::eval_count_swap`),
    /// which fail by another test.
    count_memo: memo::IdleMemo,
    /// Scratch: the keys of one tet's tries that did nothing.
    failed: Vec<[u32; 3]>,
    /// Tries the idle memo skipped.
    idle_skips: usize,
}

impl<'m> Improver<'m> {
    /// Builds the adjacency when `mesh.neigh` is not complete.
    pub fn new(mesh: &'m mut TetMesh, frozen: &[bool]) -> Result<Improver<'m>, TopoError> {
        if mesh.neigh.len() != 4 * mesh.tets.len() {
            mesh.build_adjacency()?;
        }
        let nt = mesh.tets.len();
        Ok(Improver {
            w: Work::new(mesh, frozen),
            s: Scratch::default(),
            ins: Default::default(),
            c: Cand::default(),
            best: Cand::default(),
            batch: Default::default(),
            points: Default::default(),
            idle_memo: memo::IdleMemo::new(nt),
            count_memo: memo::IdleMemo::new(nt),
            failed: Vec::new(),
            idle_skips: 0,
        })
    }

    /// The mesh as it stands (dead tets are `[u32::MAX; 4]` until
    /// [`finish`](Self::finish)).
    pub fn mesh(&self) -> &TetMesh {
        self.w.m
    }

    /// Whether point `p` may move (not frozen, not removed).
    pub fn is_free(&self, p: PointId) -> bool {
        !self.w.frozen[p.idx()] && !self.w.dead_pt[p.idx()]
    }

    /// The last passes for the mesh's min dihedral: the worst tets under
    /// [`LIFT_SWAP_DEG`] lifted by a swap or a point, and their free
    /// points moved, a few rounds while any changes.
    pub fn lift_worst(&mut self) -> ImproveStats {
        let mut st = ImproveStats::default();
        self.lift_worst_pass(&mut st);
        st
    }

    /// Drops dead tets and points.
    pub fn finish(self) {
        self.w.compact(true);
    }

    fn commit(&mut self) -> bool {
        let Improver { w, best, .. } = self;
        w.replace(&best.old, &best.new)
    }

    /// 2-3 swap of face `f` of tet `t` (§9.1).
    pub fn swap_face(&mut self, t: u32, f: usize) -> Outcome {
        if t as usize >= self.w.m.tets.len() || !self.w.alive(t) || f > 3 {
            return Outcome::NotFound;
        }
        let o = self.w.eval_23(t, f, &mut self.best);
        self.finish_op(o)
    }

    /// Removal of edge `ab` of tet `t` (§9.1; 3-2 swap when 3 tets).
    pub fn remove_edge(&mut self, t: u32, a: PointId, b: PointId) -> Outcome {
        if t as usize >= self.w.m.tets.len() || !self.w.alive(t) {
            return Outcome::NotFound;
        }
        let o = self
            .w
            .eval_edge_removal(t, a, b, &mut self.s, &mut self.best);
        self.finish_op(o)
    }

    /// Collapse of point `a` into `b` along their edge (§9.2).
    pub fn collapse(&mut self, a: PointId, b: PointId) -> Outcome {
        if a.idx() >= self.w.m.points.len() || b.idx() >= self.w.m.points.len() {
            return Outcome::NotFound;
        }
        let o = self.w.eval_collapse(a, b, &mut self.s, &mut self.best);
        // The search tries the new tets' quality first (most collapses
        // fail it, and it is cheaper); one collapse asked for names the
        // link condition first, the rule §9.2 puts first.
        let o = if o == Outcome::NotBetter && !self.w.link_holds(a, b, &mut self.s) {
            Outcome::LinkCondition
        } else {
            o
        };
        let o = self.finish_op(o);
        if o == Outcome::Done {
            self.remove_point(a);
        }
        o
    }

    fn remove_point(&mut self, a: PointId) {
        self.w.dead_pt[a.idx()] = true;
        self.w.p2t[a.idx()] = u32::MAX;
    }

    /// Laplacian smoothing step of point `p` with move rejection (§9.3).
    pub fn smooth_point(&mut self, p: PointId) -> Outcome {
        if p.idx() >= self.w.m.points.len() {
            return Outcome::NotFound;
        }
        self.w.smooth_point(p, &mut self.s)
    }

    /// Moves `p` to `pos` unless a tet would invert or the worst quality
    /// of its ball would drop.
    pub fn move_point(&mut self, p: PointId, pos: P3) -> Outcome {
        if p.idx() >= self.w.m.points.len() {
            return Outcome::NotFound;
        }
        self.w.try_move(p, pos, &mut self.s)
    }

    /// Steiner point insertion around tet `t` (see `insert.rs`): a new
    /// free point replaces a small cavity when that leaves fewer tets
    /// under 10° and no smaller min dihedral; with `lift`, for a tet under
    /// 0.1°, also when it only raises the cavity's min dihedral.
    pub fn insert_point(&mut self, t: u32, lift: bool) -> Outcome {
        if t as usize >= self.w.m.tets.len() || !self.w.alive(t) {
            return Outcome::NotFound;
        }
        let lift = self.w.lift_goal(t, lift);
        self.insert_with(t, lift)
    }

    /// [`Improver::insert_point`] with the min dihedral to aim at first.
    fn insert_with(&mut self, t: u32, lift: Option<f64>) -> Outcome {
        match self.w.eval_insert(t, lift, &mut self.ins, &mut self.best) {
            Ok(pos) => self.commit_insert(pos),
            Err(o) => o,
        }
    }

    /// Adds the point at `pos` and commits `self.best`, whose star names
    /// the new point by the next id.
    fn commit_insert(&mut self, pos: P3) -> Outcome {
        let p = self.w.push_point(pos);
        let ok = self.commit();
        debug_assert!(ok, "a star did not fit its cavity");
        if !ok {
            self.remove_point(p);
            return Outcome::Inverted;
        }
        Outcome::Done
    }

    /// The best face swap or edge removal around tet `t` for the
    /// dihedral angles: kept when it leaves fewer tets under 10° and no
    /// smaller min dihedral (`Work::eval_count_swap`).
    pub fn swap_for_dihedral(&mut self, t: u32) -> Outcome {
        if t as usize >= self.w.m.tets.len() || !self.w.alive(t) {
            return Outcome::NotFound;
        }
        let mut failed = std::mem::take(&mut self.failed);
        failed.clear();
        let (w, memo) = (&self.w, &self.count_memo);
        let o = w.eval_count_swap(
            t,
            &mut self.ins,
            &mut self.best,
            |key| passes::idle_in(w, memo, key),
            &mut failed,
        );
        passes::note_idle(&mut self.w, &mut self.count_memo, &failed);
        self.failed = failed;
        self.finish_op(o)
    }

    /// The face swap or edge removal around tet `t` that lifts its
    /// cavity's min dihedral most (`Work::eval_lift_swap`).
    pub fn swap_for_min_dihedral(&mut self, t: u32) -> Outcome {
        if t as usize >= self.w.m.tets.len() || !self.w.alive(t) {
            return Outcome::NotFound;
        }
        let o = self.w.eval_lift_swap(t, &mut self.ins, &mut self.best);
        self.finish_op(o)
    }
}

#[cfg(test)]
mod tan_tests {
    #[test]
    fn tan_small_dihedral_is_tan_of_the_threshold() {
        let t = parafront_mesh::quality::SMALL_DIHEDRAL.to_radians().tan();
        assert!((t - super::TAN_SMALL_DIHEDRAL).abs() <= 1e-16, "{t}");
        let t = 12.5f64.to_radians().tan();
        assert!((t - super::TAN_12_5).abs() <= 1e-16, "{t}");
        let t = super::LIFT_SWAP_DEG.to_radians().tan();
        assert!((t - super::TAN_LIFT).abs() <= 1e-16, "{t}");
    }

    /// What the count's search relies on: no angle under 12.5° by the
    /// tangent test means a min dihedral of at least 12°, also for the
    /// flat and needle tets of CAD parts.
    #[test]
    fn no_angle_under_12_5_by_tangent_means_at_least_12_degrees() {
        use crate::quality::{has_dihedral_under, min_dihedral_deg};
        let mut r = crate::test_rng(0x5eed_1234);
        let mut checked = 0;
        for i in 0..200_000 {
            // Regular-ish, flattened and stretched tets.
            let squash = [1.0, 0.3, 0.05, 1e-3][i % 4];
            let p: [[f64; 3]; 4] = std::array::from_fn(|_| [r(), r(), squash * r()]);
            if !has_dihedral_under(p, super::TAN_12_5) {
                checked += 1;
                assert!(min_dihedral_deg(p) >= 12.0, "{p:?}");
            }
        }
        assert!(checked > 1000, "{checked}");
    }
}

#[cfg(test)]
mod shortcut_tests {
    use super::*;
    use parafront_mesh::generate::box_mesh;

    /// A box of 6^3 cells with its inner points moved by up to 0.8 cells
    /// (each move kept where no tet inverts): slivers and needles.
    fn shaken_box(seed: u64) -> TetMesh {
        let n = 6;
        let mut m = box_mesh(n, n, n, [0.0; 3], [1.0; 3]);
        let mut r = crate::test_rng(seed);
        let h = 1.0 / n as f64;
        for p in 0..m.points.len() {
            let x = m.points[p];
            // On the boundary: within its face's plane, away from edges.
            let on = x.map(|c| c <= 0.0 || c >= 1.0);
            if on.iter().filter(|&&b| b).count() > 1 {
                continue;
            }
            m.points[p] = [0, 1, 2].map(|i| {
                if on[i] {
                    x[i]
                } else {
                    x[i] + 1.6 * h * (r() - 0.5)
                }
            });
            if m.points[p].iter().any(|c| !(0.0..=1.0).contains(c)) {
                m.points[p] = x;
                continue;
            }
            let ok = m.tets.iter().all(|t| {
                let q = t.map(|v| m.points[v.idx()]);
                parafront_geom::orient3d(q[0], q[1], q[2], q[3]) > 0.0
            });
            if !ok {
                m.points[p] = x;
            }
        }
        m
    }

    /// The idle memo and the compass steps cut short change nothing: the
    /// whole schedule gives the same mesh with them and without, and the
    /// memo did skip tries.
    #[test]
    fn the_shortcuts_give_the_same_mesh() {
        let mut skipped = 0;
        for seed in 1..=6u64 {
            let m0 = shaken_box(0x5ca1_ab1e ^ seed);
            let mut out = Vec::new();
            for shortcuts in [true, false] {
                let mut m = m0.clone();
                let mut st = ImproveStats::default();
                // Two points in three frozen, as a CAD part's surface
                // points are: tets under 10° stay for the passes on them.
                let frozen: Vec<bool> = (0..m.points.len()).map(|p| p % 3 != 0).collect();
                let mut imp = Improver::new(&mut m, &frozen).unwrap();
                imp.w.shortcuts = shortcuts;
                schedule(&mut imp, 2, &mut st, true);
                if shortcuts {
                    skipped += imp.idle_skips;
                } else {
                    assert_eq!(imp.idle_skips, 0);
                }
                imp.w.compact(true);
                m.check().unwrap();
                out.push((
                    m.points.clone(),
                    m.tets.clone(),
                    st.swap.done,
                    st.selective.done,
                ));
            }
            assert_eq!(out[0], out[1], "seed {seed}");
        }
        assert!(skipped > 100, "{skipped}");
    }
}

//! The front loop: AF1 (smallest face first), AF2 (ideal point, close
//! points, crossing checks), AF3 (add the tet), AF4 (sizes of new points),
//! AF5 (matching faces leave the front), and the recovery path for a front
//! that gets stuck.
use crate::grid::LooseGrid;
use crate::quality::candidate_score;
use crate::queue::MinQueue;
use crate::{RegionFilter, SizeMode, NO_PLACE};
pub use api::{
    FrontError, FrontInput, FrontOptions, FrontResult, FrontStats, Partial, RELEASE_FROM,
};
use parafront_geom::intersect::{shared_first, triangles_intersect};
use parafront_geom::*;
use parafront_mesh::{Marks, TET_FACES};
use rustc_hash::FxHashMap;

mod api;
mod candidates;
mod cavity;
mod check;
mod exhaustive;
mod faces;
mod fill;
mod free;
mod policy;
mod recover;
mod store;

use policy::Clearance;

/// Smallest mean ratio the front accepts: a flatter tet may be positive
/// only in exact arithmetic, and a solver reads it as inverted.
const SHAPE_FLOOR: f64 = 2e-3;
/// Close-point search radius on a first try, in units of the local size.
/// Measured on sphere_1e5: 1.0 gave 35k tets/s and 2.5 % under 10 degrees,
/// 0.7 gives 53k and 2.4 %, 0.5 gets stuck far more often.
const SEARCH_RADIUS: f64 = 0.7;

/// A tet taller than this many face edges (the DDG's first layer, at
/// `max_growth` 4) searches as wide as one this tall, in boxes around its
/// middle and its ideal point: the wider box held 102 near faces a query
/// instead of 82 on sphere_5e6's DDG, most of them surface faces. That
/// DDG: 9 % faster for as many tets (box2holes_5e6's 2-4 %; at 2.5 or
/// with no box above the ideal point, 10-50 % slower). The fine mesh
/// (`max_growth` 2) never reaches it.
const WIDE_SEARCH: f64 = 3.0;

/// Such a tall tet prefers an existing point this many times farther from
/// its ideal point than other tets do (and makes no new point that
/// close): the tall tets over neighbouring surface faces share their
/// apexes. DDGs (P = 8, 1 thread, paired runs): box2holes_5e6 364k -> 340k
/// tets, 15-19 % faster; sphere_5e6 200k -> 182k, 0-5 %. 1.4-1.8 are
/// alike; 2.0 is 50 % slower, 0.7 40 %.
const TALL_REUSE: f64 = 1.6;

/// Recovery rounds without fewer stuck faces before the front gives up: the
/// skull needs 14 (its stuck set goes 28, 68, 110, ... 48, 16, 0);
/// plate_holes 81 (its set wanders between 56 and 330 before it closes).
const STALL_ROUNDS: u32 = 100;
/// Marked points a tet needs to leave in a late recovery round.
const LATE_REMOVAL_POINTS: usize = 2;
/// A new tet's size is at most this multiple of its face's longest edge
/// (the default of `FrontOptions::max_growth`).
pub const MAX_GROWTH_PER_TET: f64 = 2.0;

/// Recovery rounds before the constrained fill takes over
/// (`FrontOptions::fill_after`). On the corpus: 4
/// closes round.stl in 6 s where 10 took 6 s and 200 failed; 1 and 2 fill
/// larger, harder cavities (the tray takes 40-70 s).
pub const DEFAULT_FILL_AFTER: u32 = 4;
/// Fills (each with its growth rounds) that leave a cavity open before
/// the front gives up: each costs seconds on a front that has them (a slot
/// under 10 times its width took minutes of recovery and fill rounds before
/// this bound; the pipeline then fills the whole region). No corpus or
/// hard input closes after a failed fill, so the first failure ends it:
/// with two (another recovery round between them) the slot at size 0.1
/// gave up after 4.0 s, with one after 3.5 s (one sitting).
const FILL_TRIES: u32 = 1;

/// A front whose first stall leaves at least this share of its input
/// faces' count stuck fills its cavities before any recovery round
/// (`FrontOptions::fill_at_stall`). The CAD parts of the corpus stall on
/// 68-139 % (tray, plate, hinge), the smooth ones and the bench surfaces
/// on 1-6 %, where a recovery round closes the few stuck faces in
/// milliseconds and the fill's tets are not the front's.
const STALL_FILL_SHARE: f64 = 0.25;

/// A first stall whose cavities the fill leaves open on at least this
/// share of the input faces' count hands the region's whole surface to the
/// fill, refined to the size field ([`Front::fill_region`], GDT's start):
/// the angle block's two open cavities hold 774 faces for its 704, and
/// cost four recovery rounds and a fill (3.1 s) where its whole surface
/// fills in 0.14 s; the idler's open cavity, 402 for 1,572, goes on to
/// recovery (0.9 s), its whole surface's fill failing in 1.4 s. So do small
/// inputs: the twisted square prism (12 faces) at size 0.1 recovered for
/// 3 s until the front gave up and the pipeline made the same fill (4.6 ->
/// 1.7 s; at 0.05 16 -> 10 s, at 0.02 160 -> 109 s).
const REGION_FILL_SHARE: f64 = 0.5;

/// A first stall with one cavity of this many times the input faces' count
/// goes to [`Front::fill_region`] at once, without filling its cavities
/// first: round.stl at size 0.4 stalls with one of 15,748 faces for its
/// 1,120, and the fill spent 4-10 s failing on it before the region's
/// surface filled in 0.3 s (at size 0.42: one of 9,332). By the cavity,
/// not the stuck faces: the tray at size 3 stalls on 19,706 faces for its
/// 4,520, in 143 cavities that the fill closes (93k tets in 18 s; its
/// whole surface refined, 276k in 46 s). The tray's largest cavities hold
/// 3.2-3.8 times its faces at sizes 2.5-3, some of them filled, the
/// plate's 4.1 at size 4, where both ways make one mesh.
const REGION_FIRST_SHARE: f64 = 6.0;

/// A front that stalls for the first time with fewer tets than this many
/// per input face hands its whole region to the fill
/// ([`Front::fill_early`]): round.stl stalls at 76 tets for 1,120 faces,
/// the tray at 6,272 for 4,520, where the fill would fail (0.7 s).
const EARLY_FILL_TETS: f64 = 0.5;
/// Inputs with fewer faces do not: their recovery costs milliseconds, and
/// the fill's split points cost quality (Schönhardt's prism: 8 tets at
/// 14.1° became 71 at 6.9°). Nor do they go to the region's fill before
/// their cavities' fill has failed ([`REGION_FIRST_SHARE`]): the boss
/// (28 faces) stalls with a cavity of 480 that the fill closes, and the
/// region's fill gave worse tets (1.9 % under 10° for 0.6 %).
const EARLY_FILL_MIN_FACES: usize = 512;

const NONE: u32 = u32::MAX;
/// How far a new edge keeps from front edges, in point clearances.
const EDGE_CLEARANCE: f64 = 2.0;

/// AF2.3's answer for one candidate tet.
enum Verdict {
    /// Free; with, per new face `i` (`TET_FACES[i]`), the near face it
    /// matches (AF5), or `NONE`.
    Free([u32; 3]),
    /// Near face `i` (its index in the near list) blocks it.
    Face(usize),
    /// A front point lies in it or too close.
    Point,
}

enum Outcome {
    Placed,
    Failed,
    Prohibited,
}

/// A front face. One record, not four arrays: the face popped from the
/// queue is anywhere in millions of ids, and each array cost a miss.
#[derive(Clone, Copy)]
struct Face {
    v: [u32; 3],
    /// The tet face behind it, `4t+f`, or `NONE` for an input face.
    owner: u32,
    /// Attempts so far (AF2 retries).
    tries: u8,
    alive: bool,
}

#[derive(Clone, Copy)]
struct Near {
    v: [u32; 3],
    id: u32,
    bb: Aabb,
    /// Its corners: gather loads them anyway, and each candidate tet
    /// would load them again from all over `pts`.
    p: [P3; 3],
}

/// The indices of the near faces whose boxes meet `b`, in order. The box
/// tests of 64 faces are done first, without branches: about half pass,
/// and a branch per face was mispredicted that often.
struct Overlapping<'n> {
    near: &'n [Near],
    b: Aabb,
    base: usize,
    next: usize,
    mask: u64,
}

impl<'n> Overlapping<'n> {
    #[inline]
    fn new(near: &'n [Near], b: Aabb) -> Self {
        Overlapping {
            near,
            b,
            base: 0,
            next: 0,
            mask: 0,
        }
    }
}

impl Iterator for Overlapping<'_> {
    type Item = usize;
    #[inline]
    fn next(&mut self) -> Option<usize> {
        while self.mask == 0 {
            if self.next >= self.near.len() {
                return None;
            }
            let end = (self.next + 64).min(self.near.len());
            let mut m = 0u64;
            for (j, nf) in self.near[self.next..end].iter().enumerate() {
                m |= (nf.bb.overlaps_nb(&self.b) as u64) << j;
            }
            self.base = self.next;
            self.next = end;
            self.mask = m;
        }
        let j = self.mask.trailing_zeros() as usize;
        self.mask &= self.mask - 1;
        Some(self.base + j)
    }
}

struct Front<'a> {
    pts: Vec<P3>,
    hp: Vec<f64>,
    n_input: usize,
    /// Every face ever made, by id (dead ones too: ids stay put).
    fv: store::Faces,
    /// Live faces by their sorted corners, built when recovery first needs
    /// it: AF5 finds a new tet's matching faces among AF2's near faces, so
    /// the front itself keeps no map (a hash update or two per face made).
    fmap: Option<FxHashMap<[u32; 3], u32>>,
    /// Live faces.
    n_front: usize,
    /// The most live faces since `FrontOptions::release` was last called.
    front_peak: usize,
    /// AF1's queue: `key << 32 | face`, the key an `f32` size (positive
    /// floats order as their bits), so one entry is 8 bytes.
    heap: MinQueue,
    fgrid: LooseGrid,
    tets: Vec<[u32; 4]>,
    neigh: Vec<u32>,
    talive: Vec<bool>,
    stuck: Vec<u32>,
    prohibited: Vec<u32>,
    /// Per point: 0 not asked yet, 1 inside the region, 2 outside.
    point_in: Vec<u8>,
    /// Per point asked: where the region filter located it
    /// ([`RegionFilter::locate`]), for queries near it.
    point_at: Vec<u32>,
    /// This try's new-point candidates that the region filter located, and
    /// where: the one committed keeps its place.
    new_at: Vec<(P3, u32)>,
    relax: u32,
    /// The input front, kept until the first recovery round (where the
    /// front may fill, not in a pass): the first stall may hand it whole to
    /// the fill ([`Front::fill_early`], while `early`), or to the fill and
    /// the refinement ([`REGION_FILL_SHARE`], [`REGION_FIRST_SHARE`]).
    input0: Vec<[u32; 3]>,
    /// The front has made too few tets for its input yet
    /// ([`EARLY_FILL_TETS`]).
    early: bool,
    /// Faces of the input front.
    n_input_faces: usize,
    opts: &'a FrontOptions,
    region: &'a dyn RegionFilter,
    size: SizeMode<'a>,
    stats: FrontStats,
    // Scratch buffers, reused for every face.
    near_f: Vec<Near>,
    near_p: Vec<u32>,
    cands: Vec<(f64, u32)>,
    /// The points the close-face search has seen (dedups corners of faces).
    seen: Marks,
}

/// Each of `g`'s ids' index in `tv`, or 4: by selects, not `position`
/// in a `map` (left out of line, once per near face).
#[inline(always)]
fn local_ids(g: [u32; 3], tv: [u32; 4]) -> [usize; 3] {
    let mut gl = [4usize; 3];
    for j in 0..3 {
        for i in (0..4).rev() {
            gl[j] = if g[j] == tv[i] { i } else { gl[j] };
        }
    }
    gl
}

#[inline]
fn sorted3(v: [u32; 3]) -> [u32; 3] {
    let mut k = v;
    k.sort_unstable();
    k
}

#[inline]
fn same_cycle(a: [u32; 3], b: [u32; 3]) -> bool {
    a == b || a == [b[1], b[2], b[0]] || a == [b[2], b[0], b[1]]
}

/// The L1 length of the box around `a` and `b`: a bound on the distance
/// between any two of their points.
#[inline]
fn span1(a: &Aabb, b: &Aabb) -> f64 {
    (0..3)
        .map(|k| a.max[k].max(b.max[k]) - a.min[k].min(b.min[k]))
        .sum()
}

#[inline]
fn heap_entry(key: f64, face: u32) -> u64 {
    ((key as f32).to_bits() as u64) << 32 | face as u64
}

#[inline]
fn box_dist2(b: &Aabb, p: P3) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        // Compare and select, as in `bbox`.
        let (lo, hi) = (b.min[k] - p[k], p[k] - b.max[k]);
        let d = if lo > hi { lo } else { hi };
        let d = if d > 0.0 { d } else { 0.0 };
        d2 += d * d;
    }
    d2
}

/// The box of `N >= 1` points, by compare and select (`minsd`, where
/// `f64::min` adds a NaN fix-up): the same box but for the sign of a zero.
#[inline(always)]
fn bbox<const N: usize>(p: [P3; N]) -> Aabb {
    let mut b = Aabb {
        min: p[0],
        max: p[0],
    };
    for x in &p[1..] {
        for (k, &c) in x.iter().enumerate() {
            b.min[k] = if c < b.min[k] { c } else { b.min[k] };
            b.max[k] = if c > b.max[k] { c } else { b.max[k] };
        }
    }
    b
}

fn tri_box(p: &[P3], v: [u32; 3]) -> Aabb {
    bbox(v.map(|i| p[i as usize]))
}

/// Fill the region bounded by `input.faces` (paper AF1-AF5).
pub fn advance(
    input: FrontInput,
    size: SizeMode<'_>,
    region: &dyn RegionFilter,
    opts: &FrontOptions,
) -> Result<FrontResult, FrontError> {
    if !opts.pass {
        check_closed(&input.faces)?;
    }
    let mut f = Front::new(input, size, region, opts);
    f.run()?;
    Ok(f.finish())
}

impl<'a> Front<'a> {
    /// The front of `input.faces`, each queued (AF1), no tet made yet.
    fn new(
        input: FrontInput,
        size: SizeMode<'a>,
        region: &'a dyn RegionFilter,
        opts: &'a FrontOptions,
    ) -> Front<'a> {
        let n = input.points.len();
        let bb = Aabb::from_points(&input.points);
        let hmin = input
            .point_size
            .iter()
            .copied()
            .filter(|h| *h > 0.0 && h.is_finite())
            .fold(f64::INFINITY, f64::min);
        let s0 = if hmin.is_finite() {
            hmin
        } else {
            bb.diagonal().max(1e-300) * 1e-3
        };
        let mut f = Front {
            pts: input.points,
            hp: input.point_size,
            n_input: n,
            fv: store::Faces::default(),
            fmap: None,
            n_front: 0,
            front_peak: 0,
            heap: MinQueue::default(),
            fgrid: LooseGrid::new(s0, bb.min),
            tets: Vec::new(),
            neigh: Vec::new(),
            talive: Vec::new(),
            stuck: Vec::new(),
            prohibited: Vec::new(),
            point_in: Vec::new(),
            point_at: Vec::new(),
            new_at: Vec::new(),
            relax: 0,
            input0: Vec::new(),
            early: false,
            n_input_faces: input.faces.len(),
            opts,
            region,
            size,
            stats: FrontStats::default(),
            near_f: Vec::new(),
            near_p: Vec::new(),
            cands: Vec::new(),
            seen: Marks::default(),
        };
        if let SizeMode::Growth(c) = size {
            // §5: initial face sizes are multiplied by the growth factor.
            for h in &mut f.hp {
                *h *= c;
            }
        }
        for &v in &input.faces {
            f.add_face(v, NONE);
        }
        if opts.fill && opts.fill_early && !opts.pass {
            f.early = input.faces.len() >= EARLY_FILL_MIN_FACES;
            f.input0 = input.faces;
        }
        f
    }
}

/// Every directed edge of a closed front appears as often as its reverse.
/// Once each is the usual case; a front left by parallel passes (§7) may
/// pinch, two gaps touching along an edge, and then uses it twice each way.
fn check_closed(faces: &[[u32; 3]]) -> Result<(), FrontError> {
    let mut e: Vec<(u32, u32)> = Vec::with_capacity(faces.len() * 3);
    for v in faces {
        for k in 0..3 {
            e.push((v[k], v[(k + 1) % 3]));
        }
    }
    e.sort_unstable();
    let mut i = 0;
    while i < e.len() {
        let mut j = i + 1;
        while j < e.len() && e[j] == e[i] {
            j += 1;
        }
        let (a, b) = e[i];
        let lo = e.partition_point(|x| *x < (b, a));
        let hi = e.partition_point(|x| *x <= (b, a));
        if hi - lo != j - i {
            return Err(FrontError::OpenFront { a, b, count: j - i });
        }
        i = j;
    }
    Ok(())
}

impl<'a> Front<'a> {
    fn face_key(&self, v: [u32; 3]) -> f64 {
        // AF1: the face forming the smallest element goes first.
        let h = (self.hp[v[0] as usize] + self.hp[v[1] as usize] + self.hp[v[2] as usize]) / 3.0;
        let p = |i: usize| self.pts[v[i] as usize];
        // The edge of an equilateral triangle of the same area: a needle
        // goes first, while the room above it is still free.
        let a2 = norm(tri_normal(p(0), p(1), p(2)));
        let e = (a2 * (2.0 / 3f64.sqrt())).sqrt();
        h.min(e)
    }

    /// The front faces (all but `skip`) whose boxes meet `q`, and the
    /// front points inside `q`. Front points are the corners of front
    /// faces, so one face query finds both.
    fn gather(&mut self, q: &Aabb, skip: u32, near_f: &mut Vec<Near>, near_p: &mut Vec<u32>) {
        let mut seen = std::mem::take(&mut self.seen);
        seen.clear(self.pts.len());
        self.fgrid.query(q, |g, w| {
            let p = w.map(|i| self.pts[i as usize]);
            let bb = bbox(p);
            if !bb.overlaps(q) {
                return;
            }
            for k in 0..3 {
                if seen.insert(w[k] as usize) && q.contains(p[k]) {
                    near_p.push(w[k]);
                }
            }
            if g != skip {
                near_f.push(Near { v: w, id: g, bb, p })
            }
        });
        self.seen = seen;
    }

    /// Calls `FrontOptions::release` once the front has halved since its
    /// peak: the faces and grid cells the front freed stayed resident
    /// inside the allocator, on top of the tets made since (a fine pass
    /// part's peak on sphere_5e6 at `--size 0.021`).
    #[inline]
    fn release_when_shrunk(&mut self) {
        let Some(release) = self.opts.release else {
            return;
        };
        if self.n_front > self.front_peak {
            self.front_peak = self.n_front;
        } else if self.front_peak >= RELEASE_FROM && 2 * self.n_front < self.front_peak {
            release();
            self.front_peak = self.n_front;
        }
    }

    fn run(&mut self) -> Result<(), FrontError> {
        let mut fewest_stuck = usize::MAX;
        let mut last_gain = 0;
        let mut failed_fills = 0;
        loop {
            while let Some(e) = self.heap.pop() {
                let (key, fid) = (f32::from_bits((e >> 32) as u32) as f64, e as u32);
                if !self.fv[fid as usize].alive {
                    continue;
                }
                match self.try_face(fid) {
                    Outcome::Placed => {
                        if self.pts.len() > self.opts.max_points {
                            return Err(FrontError::TooManyPoints(self.opts.max_points));
                        }
                        if self.early
                            && self.stats.tets as f64 > EARLY_FILL_TETS * self.input0.len() as f64
                        {
                            self.early = false;
                        }
                        self.release_when_shrunk();
                    }
                    Outcome::Prohibited => self.prohibited.push(fid),
                    Outcome::Failed => {
                        self.stats.retries += 1;
                        let t = &mut self.fv[fid as usize].tries;
                        *t += 1;
                        if *t < self.opts.tries_per_face {
                            // Later, when its surroundings have changed.
                            self.heap.push(heap_entry(key * 1.5, fid));
                        } else {
                            self.stuck.push(fid);
                        }
                    }
                }
            }
            self.stuck.retain(|&f| self.fv[f as usize].alive);
            if self.stuck.is_empty() {
                return Ok(());
            }
            if self.opts.pass && self.relax >= 1 {
                // §7: what a pass cannot close goes to the next pass, after
                // one round of removal and re-meshing, so that it hands over
                // no worse a front than it could make.
                self.prohibited.append(&mut self.stuck);
                return Ok(());
            }
            // Give up early when recovery stops making headway, rather than
            // spend every round on a front it cannot close.
            if self.stuck.len() < fewest_stuck {
                fewest_stuck = self.stuck.len();
                last_gain = self.relax;
            }
            let give_up =
                self.relax >= self.opts.recovery_rounds || self.relax >= last_gain + STALL_ROUNDS;
            // The fill every `fill_after` rounds, and where the front would
            // give up.
            let due = self.opts.fill_after > 0
                && self.relax >= self.opts.fill_after
                && self.relax.is_multiple_of(self.opts.fill_after);
            if self.opts.fill && (give_up || due) {
                let filled = self.fill_stalled(self.opts.fill_growth, false);
                debug_assert_eq!(self.check(), Ok(()), "after a fill");
                if filled {
                    continue;
                }
                failed_fills += 1;
            }
            if give_up || failed_fills >= FILL_TRIES {
                return Err(self.stuck_error());
            }
            // A front that stalls before it has made a tet for every other
            // input face (a surface of needles under a size that no tet on
            // them can meet) hands the whole region to the fill.
            if self.relax == 0 && self.early && self.fill_early() {
                continue;
            }
            // A first stall on much of the surface (CAD parts, whose long
            // faces leave thin cracks): the cavities the fill closes at
            // once need no recovery round (each cost as much as the front
            // before it); the others go on to recovery, and their failure
            // here does not count.
            let stuck_share = self.stuck.len() as f64 / self.n_input_faces as f64;
            if self.relax == 0
                && self.opts.fill
                && self.opts.fill_at_stall
                && !self.opts.pass
                && stuck_share >= STALL_FILL_SHARE
            {
                // One cavity of many times the region's own surface: the
                // cavities are not tried first.
                let whole_first = stuck_share >= REGION_FIRST_SHARE
                    && self.n_input_faces >= EARLY_FILL_MIN_FACES
                    && !self.input0.is_empty()
                    && self.largest_cavity() as f64
                        >= REGION_FIRST_SHARE * self.n_input_faces as f64;
                if !whole_first && self.fill_stalled(0, true) {
                    continue;
                }
                // The cavities it left hold much of the region: the
                // region's own surface, filled and refined, costs less than
                // their recovery.
                if (whole_first
                    || self.stuck.len() as f64 >= REGION_FILL_SHARE * self.n_input_faces as f64)
                    && !self.input0.is_empty()
                {
                    if self.opts.hand_over {
                        return Err(FrontError::HandOver);
                    }
                    if self.fill_region() {
                        continue;
                    }
                }
            }
            self.input0 = Vec::new();
            self.recover();
            debug_assert_eq!(self.check(), Ok(()), "after recovery round {}", self.relax);
        }
    }

    /// The error for a front that cannot be closed, at its first stuck face.
    fn stuck_error(&self) -> FrontError {
        let f = self.stuck[0];
        let v = self.fv[f as usize].v;
        let c = centroid3(
            self.pts[v[0] as usize],
            self.pts[v[1] as usize],
            self.pts[v[2] as usize],
        );
        let partial = self.opts.keep_partial.then(|| {
            Box::new(Partial {
                points: self.pts.clone(),
                tets: (0..self.tets.len())
                    .filter(|&t| self.talive[t])
                    .map(|t| self.tets[t])
                    .collect(),
                front: (0..self.fv.len())
                    .filter(|&f| self.fv[f].alive)
                    .map(|f| self.fv[f].v)
                    .collect(),
            })
        });
        FrontError::Stuck {
            rounds: self.relax,
            faces: self.stuck.len(),
            x: c[0],
            y: c[1],
            z: c[2],
            partial,
        }
    }

    /// Drop dead tets and unused new points; input points keep their ids.
    fn finish(self) -> FrontResult {
        // The search structures go first: the output is built in place, so
        // the peak is the front's own.
        drop((self.heap, self.fmap, self.fgrid, self.input0));
        drop((self.near_f, self.near_p, self.cands, self.seen, self.stuck));
        let front: Vec<[u32; 3]> = self
            .prohibited
            .iter()
            .filter(|&&f| self.fv[f as usize].alive)
            .map(|&f| self.fv[f as usize].v)
            .collect();
        drop(self.fv);
        use parafront_mesh::compact::{compact, keep_map, remap_face};
        let (mut tets, mut neigh, talive) = (self.tets, self.neigh, self.talive);
        let (tmap, _) = keep_map(talive.iter().copied());
        let mut used = vec![false; self.pts.len()];
        used[..self.n_input].iter_mut().for_each(|u| *u = true);
        for (tv, &alive) in tets.iter().zip(&talive) {
            if alive {
                for &p in tv {
                    used[p as usize] = true;
                }
            }
        }
        for f in &front {
            for &p in f {
                used[p as usize] = true;
            }
        }
        let (pmap, _) = keep_map(used);
        let (mut points, mut point_size) = (self.pts, self.hp);
        compact(&mut points, &pmap, 1);
        compact(&mut point_size, &pmap, 1);
        // In place: slot k <= t is free when tet t moves there.
        compact(&mut tets, &tmap, 1);
        for t in &mut tets {
            *t = t.map(|p| pmap[p as usize]);
        }
        compact(&mut neigh, &tmap, 4);
        for n in &mut neigh {
            *n = remap_face(*n, &tmap, NONE);
        }
        let mut stats = self.stats;
        stats.tets = tets.len();
        stats.new_points = points.len() - self.n_input;
        FrontResult {
            points,
            point_size,
            tets,
            // In place: `FaceRef` is a transparent `u32`, `NONE` its `NO_FACE`.
            neigh: neigh
                .into_iter()
                .map(parafront_mesh::FaceRef::from_raw)
                .collect(),
            front: front.iter().map(|f| f.map(|p| pmap[p as usize])).collect(),
            stats,
        }
    }
}

//! The parallel mesher of one closed front (paper §5 to §8): the DDG,
//! its balanced partition, the inside-out passes on shifted partitions
//! (pass 1 on DDG0, pass 2 with layers taken from higher neighbours,
//! pass 3 from lower ones, pass 4 serial) and the redistribution of the
//! pieces.
//!
//! Every part keeps its own points, tets and front (`Part`, in `part.rs`,
//! is private to this crate and only ever touched by the closure of its
//! own part); parts see each other's data only through the messages of a
//! [`Comm`]. A
//! process holds the parts `Comm::owned` gives (all of them with
//! `Threads`, a block of them per rank under MPI); the DDG's passes run
//! over the processes and every process then holds the whole DDG, its
//! partitions are replicated, and pass 4 runs on part 0's process, whose
//! choices reach the others by all-gather.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod check;
mod ddg_build;
mod packed;
mod part;
mod pass;
mod pockets;
mod reach;
mod redistribute;
mod schedule;
mod serial;

use part::*;
use pass::{front_left_per_tet, parallel_pass, seed_inner_parts};
use pockets::*;
use schedule::{Partitions, Passes, Recorder};
use serial::*;

pub use check::{check_pieces, PieceCheck, PieceCheckError};
pub use ddg_build::{build_ddg, DdgBuildStats};
pub use parafront_ddg::Partition;
pub use redistribute::{move_pieces, piece_boxes, shift_pieces, Piece};

use parafront_comm::Comm;
use parafront_ddg::{self as ddg, Ddg, Interfaces, Locator, PartFilter, Shift};
use parafront_front::{
    advance, Everywhere, FrontError, FrontInput, FrontOptions, RegionFilter, SizeMode,
};
use parafront_geom::{centroid3, orient3d, tet_volume6, Aabb, P3};
use parafront_mesh::FaceRef;
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use std::time::Instant;

/// Options of the parallel mesher.
#[derive(Clone, Debug)]
pub struct ParOptions {
    /// Number of parts (the paper's nproc).
    pub parts: usize,
    /// DDG growth factor `c_i` (§5).
    pub growth: f64,
    /// DDG layers moved across each wall in passes 2 and 3 (§7: 1 or 2).
    pub layers: usize,
    /// How the DDG is split (§6): METIS k-way or coordinate bisection.
    pub partition: ddg::Partition,
    /// Parallel passes that build the DDG (on convex cells, then a serial
    /// pass on what they leave: [`build_ddg`]); 0 builds it with the
    /// serial front.
    pub ddg_passes: usize,
    /// Recovery rounds of pass 4's front before the constrained fill takes
    /// over (`FrontOptions::fill_after`).
    pub fill_after: u32,
    /// Depth in mean surface edges (volume over area) under which a region
    /// skips the passes ([`PassError::Thin`]; 0: never).
    pub thin_depth: f64,
    /// Share of the volume left after pass 3 above which the region is
    /// meshed serially ([`PassError::Unsuited`]; 2: never).
    pub serial_from: f64,
    /// On deep fronts, the DDG's largest size as a share of a part's width
    /// (the cube root of its volume).
    pub ddg_cap: f64,
    /// Test hook: redistribution fails on this part ([`PassError::Injected`]).
    pub fail_part: Option<usize>,
    /// Merge the pieces into one mesh on part 0's process (true), or leave
    /// them where they are (a partitioned output, memory distributed).
    pub gather: bool,
    /// With `gather`: whether the caller keeps the pieces beside the
    /// merged mesh. Their tet numbers, owners and shared points are found
    /// only then (or without `gather`); a merged run whose improvement
    /// renumbers the mesh drops them.
    pub keep_pieces: bool,
    /// Hands freed memory back to the system (the CLI: glibc's
    /// `malloc_trim`), called once the DDG is split and after each part's
    /// front; `None` leaves it to the allocator.
    pub release: Option<fn()>,
}

pub use ddg_build::DDG_CAP;

/// Parallel passes of the DDG's build by default.
pub const DEFAULT_DDG_PASSES: usize = 2;

impl Default for ParOptions {
    fn default() -> Self {
        ParOptions {
            parts: 2,
            growth: ddg::DEFAULT_GROWTH,
            layers: 2,
            partition: ddg::Partition::default(),
            ddg_passes: DEFAULT_DDG_PASSES,
            fill_after: parafront_front::DEFAULT_FILL_AFTER,
            thin_depth: THIN_DEPTH,
            serial_from: SERIAL_FROM,
            ddg_cap: ddg_build::DDG_CAP,
            fail_part: None,
            gather: true,
            keep_pieces: true,
            release: None,
        }
    }
}

/// Keeps the entries of `v` whose flag in `gone` is false, in order.
pub(crate) fn retain_unflagged<T>(v: &mut Vec<T>, gone: &[bool]) {
    let mut k = 0;
    v.retain(|_| {
        k += 1;
        !gone[k - 1]
    });
}

/// Runs the release hook of [`ParOptions::release`], if there is one.
pub(crate) fn release(hook: Option<fn()>) {
    if let Some(f) = hook {
        f();
    }
}

/// Why the parallel mesher gave up on a region.
#[derive(Debug, thiserror::Error)]
pub enum PassError {
    /// The DDG could not be built (§5).
    #[error("domain-defining grid: {0}")]
    Ddg(#[from] ddg::DdgError),
    /// A part's front failed in one of the passes (§7).
    #[error("pass {pass}, part {part}: {source}")]
    Pass {
        /// The pass, 1 to 4.
        pass: u8,
        /// The part.
        part: usize,
        /// Why its front failed.
        source: FrontError,
    },
    /// Two points of the parts, with different global ids, at one place
    /// (redistribution, §8).
    #[error("redistribution: points {a} and {b} are both at {at:?}")]
    Coincident {
        /// One global id.
        a: u32,
        /// The other.
        b: u32,
        /// Where both are.
        at: P3,
    },
    /// A global point id that no part's tets use (redistribution, §8).
    #[error("redistribution: point {point} is in no tet of any part")]
    Unused {
        /// The global id.
        point: u32,
    },
    /// The DDG's passes left a face in more than two tets, or two tets
    /// on one side of a face.
    #[error("the DDG built in parallel: {0}")]
    DdgMerge(#[source] parafront_mesh::TopoError),
    /// Passes 1 to 3 left most of the region to the serial pass 4: a thin
    /// part, whose DDG has little interior to split.
    #[error(
        "passes 1 to 3 left {:.0} % of the volume to the serial pass 4 (a thin part: the walls between parts cross most of it)",
        100.0 * left
    )]
    Unsuited {
        /// The share of the volume left.
        left: f64,
    },
    /// A part held by another process failed (under MPI): every process
    /// stops with its message, or falls back to the serial front as the
    /// process holding the part does (which has the error itself).
    #[error("{message} (on another process: the one holding part {part})")]
    Remote {
        /// The part.
        part: usize,
        /// The part's error, as its process printed it.
        message: String,
        /// The error is a [`PassError::Pass`]: the region falls back to
        /// the serial front; else the run stops.
        pass_failed: bool,
    },
    /// The failure of the test hook `ParOptions::fail_part`.
    #[error("part {part}: the failure injected for the tests (fail_part)")]
    Injected {
        /// The part.
        part: usize,
    },
    /// The region is a thin plate before any pass runs (its volume over
    /// its area is under [`THIN_DEPTH`] mean surface edges): every such
    /// part of the corpus left 31-93 % to pass 4, after seconds to minutes.
    #[error(
        "a thin part, {depth:.2} surface edges deep (volume over area): the walls between parts would cross most of it"
    )]
    Thin {
        /// Volume over area, in mean surface edges.
        depth: f64,
    },
}

/// Depth, in mean surface edges, under which a region skips the passes
/// ([`PassError::Thin`]). The corpus's thin plates are 0.14-0.35 deep
/// (the tray, the plate with holes, the hinge, base_interface), every
/// other input 1.7 or more.
pub const THIN_DEPTH: f64 = 0.5;

/// What the passes did, for the summary and the benchmark table.
#[derive(Clone, Debug, Default)]
pub struct ParStats {
    /// Parts (the paper's nproc).
    pub parts: usize,
    /// Tets of the DDG (§5).
    pub ddg_tets: usize,
    /// Points of the DDG.
    pub ddg_points: usize,
    /// Of which on the surface.
    pub ddg_surface_points: usize,
    /// Its growth factor `c_i`.
    pub ddg_growth: f64,
    /// Wall seconds of the DDG (a failed try of its passes included).
    pub ddg_seconds: f64,
    /// CPU seconds (all threads) of the DDG and of the partition, where
    /// the system tells ([`process_cpu_seconds`]; 0 elsewhere): on a
    /// shared machine their share of a run's CPU time is steadier than
    /// their share of its wall time.
    pub ddg_cpu_seconds: f64,
    /// See `ddg_cpu_seconds`.
    pub partition_cpu_seconds: f64,
    /// With a DDG built by passes: what each pass made.
    pub ddg_build: Option<DdgBuildStats>,
    /// Wall seconds of the partition (§6): weights, split, shifts and the
    /// crossing partitions.
    pub partition_seconds: f64,
    /// Of which the split itself (RCB or METIS).
    pub split_seconds: f64,
    /// The split used, the DDG faces between parts, the fine faces
    /// expected on them, and the face-connected pieces of the most broken
    /// part (1: every part connected).
    pub partition: ddg::Partition,
    /// See `partition`.
    pub cut_faces: usize,
    /// See `partition`.
    pub cut_fine_faces: f64,
    /// See `partition`.
    pub max_components: usize,
    /// Max over mean of the predicted (DDG weight) load.
    pub predicted_imbalance: f64,
    /// Max over mean of the tets each part made in pass 1 to 3, and of the
    /// tets each part holds after redistribution.
    pub made_imbalance: f64,
    /// See `made_imbalance`.
    pub held_imbalance: f64,
    /// Tets of passes 1 to 3 removed to give pass 4 room.
    pub peeled_tets: usize,
    /// Tets made in passes 1 to 4 (those in the final mesh for 1 to 3).
    pub pass_tets: [usize; 4],
    /// Wall seconds of passes 1 to 4 (message building included).
    pub pass_seconds: [f64; 4],
    /// Per parallel pass run (1 to 3, then the crossing passes), each
    /// part's seconds inside the front.
    pub part_seconds: Vec<Vec<f64>>,
    /// Passes on a crossing partition after pass 3 (counted in pass 3).
    pub crossing_passes: usize,
    /// Parts off the surface that pass 1 started from a seed tet.
    pub seeds: usize,
    /// Wall seconds of the redistribution (§8).
    pub redistribute_seconds: f64,
}

impl ParStats {
    /// Seconds on the critical path if every part had its own core: each
    /// parallel pass takes as long as its slowest part.
    pub fn critical_path_seconds(&self) -> f64 {
        self.ddg_seconds
            + self.partition_seconds
            + self
                .part_seconds
                .iter()
                .map(|v| v.iter().cloned().fold(0.0, f64::max))
                .sum::<f64>()
            + self.pass_seconds[3]
            + self.redistribute_seconds
    }
}

/// CPU seconds this process has used so far, all threads together, from
/// `/proc/self/stat` (10 ms ticks); `None` where there is no such file.
pub fn process_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command (which may hold spaces): state is field 3,
    // utime and stime fields 14 and 15, in clock ticks (100 per second on
    // Linux).
    let rest = s.get(s.rfind(')')? + 1..)?;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ut: f64 = f.get(11)?.parse().ok()?;
    let st: f64 = f.get(12)?.parse().ok()?;
    Some((ut + st) / 100.0)
}

/// The merged mesh and the partitioned one.
#[derive(Clone, Debug, Default)]
pub struct ParOutput {
    /// Input points first (same ids), then the new points in global order.
    pub points: Vec<P3>,
    /// Tets in global order: by part after redistribution, then local order.
    pub tets: Vec<[u32; 4]>,
    /// Pass (1 to 4) that made each tet.
    pub tet_pass: Vec<u8>,
    /// The partitioned mesh, one piece per part held here.
    pub pieces: Vec<Piece>,
    /// The merged mesh's point count (on every process, with or without
    /// the merged mesh).
    pub n_points: u32,
    /// What the passes did.
    pub stats: ParStats,
}

/// The owned parts' results of one step, once every process knows that
/// all parts succeeded; else the first failure by part, as its own error
/// where the part is held and as [`PassError::Remote`] elsewhere (so that
/// every process stops, or falls back, alike).
fn agree<C: Comm, T>(
    comm: &C,
    pass: u8,
    local: Vec<Result<T, (usize, FrontError)>>,
) -> Result<Vec<T>, PassError> {
    let said = local
        .iter()
        .map(|r| r.as_ref().err().map(|(_, e)| e.to_string()))
        .collect();
    let Some((part, message)) = first_failure(comm, said) else {
        return Ok(local.into_iter().filter_map(Result::ok).collect());
    };
    if comm.holds(part) {
        if let Some(Err((_, source))) = local.into_iter().nth(part - comm.owned().start) {
            return Err(PassError::Pass { pass, part, source });
        }
    }
    Err(PassError::Remote {
        part,
        message,
        pass_failed: true,
    })
}

/// The first part, over all processes, whose entry of `said` (one per
/// owned part: its failure's message, or none) is a failure.
pub(crate) fn first_failure<C: Comm>(
    comm: &C,
    said: Vec<Option<String>>,
) -> Option<(usize, String)> {
    comm.all_gather(said)
        .into_iter()
        .enumerate()
        .find_map(|(part, m)| m.map(|m| (part, m)))
}

/// Where the parts may mesh in one pass (§7): a conservative owner for
/// each point, a box around each part's region (every front face meeting
/// it goes to the part as context) and the region filter of a part. The
/// passes of the fine mesh take their regions from the DDG; the passes
/// that build the DDG itself, before any DDG exists, take convex cells.
pub(crate) trait Regions: Sync {
    /// `Some(k)` when `p` lies inside part `k`'s region, off its walls.
    fn owner(&self, p: P3) -> Option<u32>;
    /// Per part, a box around its region.
    fn bounds(&self) -> Vec<Aabb>;
    /// Whether a front face with box `b`, which meets part `k`'s box, may
    /// come near its region: by default, yes.
    fn near(&self, _k: u32, _b: &Aabb) -> bool {
        true
    }
    /// The region filter of part `k`.
    fn filter(&self, k: u32) -> Box<dyn RegionFilter + '_>;
}

/// The regions of one DDG partition.
struct DdgRegions<'a> {
    d: &'a Ddg,
    loc: &'a Locator<'a>,
    walls: Interfaces,
    part_of: &'a [u32],
    cells: reach::PartCells,
    /// The DDG's face neighbours the filters walk, or none.
    neigh: &'a [FaceRef],
}

/// Whether this process lets the DDG's face neighbours go while its fronts
/// run: it holds only some of the parts (an MPI rank), whose passes set its
/// peak.
fn let_go_neigh<C: Comm>(comm: &C) -> bool {
    comm.owned().len() < comm.parts()
}

impl Regions for DdgRegions<'_> {
    fn owner(&self, p: P3) -> Option<u32> {
        self.loc.owner(p, self.part_of)
    }
    fn bounds(&self) -> Vec<Aabb> {
        let np = self
            .part_of
            .iter()
            .map(|&k| k as usize + 1)
            .max()
            .unwrap_or(0);
        let mut boxes = vec![Aabb::EMPTY; np];
        for (t, &k) in self.part_of.iter().enumerate() {
            boxes[k as usize] =
                boxes[k as usize].union(&Aabb::from_points(self.d.tet_points(t).iter()));
        }
        boxes
    }
    /// The face's box widened by its longest side (about the local size,
    /// the reach of the front's checks about a new point).
    fn near(&self, k: u32, b: &Aabb) -> bool {
        let ext = (0..3).map(|i| b.max[i] - b.min[i]).fold(0.0, f64::max);
        self.cells.meets(k, &b.inflated(ext))
    }
    fn filter(&self, k: u32) -> Box<dyn RegionFilter + '_> {
        Box::new(PartFilter::new(
            self.loc,
            &self.walls,
            self.part_of,
            k,
            self.neigh,
        ))
    }
}

/// Meshes the region bounded by `faces` (normals inward) on `comm.parts()`
/// parts. `size` is the fine size field; `point_size` the size at each
/// input point.
pub fn mesh_parallel<C: Comm>(
    points: &[P3],
    point_size: &[f64],
    faces: &[[u32; 3]],
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &ParOptions,
    comm: &C,
) -> Result<ParOutput, PassError> {
    mesh_parallel_around(points, point_size, faces, (&[], &[]), size, opts, comm)
}

/// [`mesh_parallel`] around a filled core: `core` are the outer faces of
/// tets made already (the lattice of §2's optimal space-filling tets),
/// their normals pointing out of the core into the space left, over
/// points that follow the surface's in `points`. The DDG and its partition
/// cover the region as `faces` bound it, the fronts start from both, and
/// no part is seeded (a part with no face lies inside the core). The
/// output holds every point of `points` in order. The core's tets
/// (`core_tets`: ids into `points`, a list for each part held, possibly
/// none) go into the pieces with the fronts', pass 0; a caller that adds
/// them to a merged mesh itself gives none.
pub fn mesh_parallel_around<C: Comm>(
    points: &[P3],
    point_size: &[f64],
    faces: &[[u32; 3]],
    core: (&[[u32; 3]], &[Vec<[u32; 4]>]),
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &ParOptions,
    comm: &C,
) -> Result<ParOutput, PassError> {
    passes_around(points, point_size, faces, core, size, opts, comm)?
        .redistribute(points, opts, comm)
}

/// The tets of the passes, each with the part it goes to, before §8's
/// redistribution: [`mesh_parallel_around`] in two steps, so that a
/// caller can free what only the passes needed (the size field: 7 MB of
/// each MPI rank's peak on sphere_5e6, which redistribution set) before
/// the tets move. The size field is not used after [`passes_around`].
pub struct Passed {
    parts: Vec<part::Part>,
    dst: Vec<redistribute::Dests>,
    next_gid: u32,
    rec: Recorder,
    t0: Instant,
}

/// [`mesh_parallel_around`] up to redistribution: the DDG, its
/// partition, and passes 1 to 4. The errors that send a region to the
/// serial front ([`PassError::Pass`], [`PassError::Unsuited`],
/// [`PassError::Thin`], a failed DDG, a remote pass failure) all come
/// from here; [`Passed::redistribute`] fails only as a run stopper.
pub fn passes_around<C: Comm>(
    points: &[P3],
    point_size: &[f64],
    faces: &[[u32; 3]],
    (core, core_tets): (&[[u32; 3]], &[Vec<[u32; 4]>]),
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &ParOptions,
    comm: &C,
) -> Result<Passed, PassError> {
    let np = comm.parts();
    let depth = ddg_build::depth(points, faces);
    if depth < opts.thin_depth {
        return Err(PassError::Thin { depth });
    }
    // §5 step 1: the DDG (built over the processes, then held by each:
    // it is small).
    let mut rec = Recorder::new(np);
    let t_ddg = Instant::now();
    // The surface's points only: the core's are no candidates for the DDG.
    let n_surface = faces.iter().flatten().max().map_or(0, |&v| v as usize + 1);
    let (d, built) = the_ddg(
        &points[..n_surface],
        &point_size[..n_surface],
        faces,
        depth,
        opts,
        comm,
    )?;
    rec.ddg(&d, built, t_ddg.elapsed().as_secs_f64());
    // §6 step 2: weights and the balanced split.
    let (loc, base) = split_ddg(&d, size, opts, (np, comm.owned().len() < np), &mut rec);
    // The DDG's build leaves its fronts' memory free in the allocator's
    // heaps; a process's peak comes later, in pass 1.
    release(opts.release);

    let all: Vec<[u32; 3]>;
    let faces = if core.is_empty() {
        faces
    } else {
        all = faces.iter().chain(core).copied().collect();
        &all[..]
    };
    let mut parts = seed_parts(comm.owned(), np, points, point_size, faces);
    let mut next_gid = points.len() as u32;
    if core.is_empty() {
        rec.st.seeds = seed_inner_parts(
            &mut parts,
            comm.owned(),
            (points, faces),
            &d,
            &loc,
            &base,
            size,
            &mut next_gid,
        );
    }
    // §7 step 3, passes 1 to 3 and the crossing passes.
    let mut on = Partitions::new(base);
    let passes = Passes {
        d: &d,
        loc: &loc,
        size,
        opts,
        comm,
    };
    passes.run(&mut parts, &mut on, &mut next_gid, &mut rec)?;
    rec.parallel_done();

    // A thin part leaves most of its volume to pass 4: then the serial
    // front on the whole region is both faster and the serial mesh.
    let left = left_fraction(&parts, comm, points, faces);
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!("before pass 4: {:.2} % of the volume left", 100.0 * left);
    }
    if left > opts.serial_from {
        return Err(PassError::Unsuited { left });
    }

    // Pass 4: what is left, serially on part 0.
    let t0 = Instant::now();
    let (made4, removed) = serial_pass(
        &mut parts,
        comm,
        Sizes::fine(size),
        &mut next_gid,
        &PASS4_ROUNDS,
        opts.fill_after,
    )?;
    rec.pass4(made4, removed, t0.elapsed().as_secs_f64());
    // Pass 4's front is freed: returned before redistribution's lists.
    release(opts.release);
    debug_check_parts(&parts, "pass 4");

    // §8 step 4.
    let t0 = Instant::now();
    part::add_core_tets(&mut parts, (points, point_size), core_tets);
    // Walks where the face neighbours are held; an MPI rank, which let
    // them go, does not rebuild them for this.
    let held = d.holds_neigh().then(|| d.neigh());
    let dst = redistribute::destinations(
        &parts,
        comm.owned().start,
        (&loc, held.as_deref().unwrap_or(&[])),
        &on.base,
    );
    drop(held);
    // The DDG, its locator and its partitions are done with before the
    // tets move: they were 30 MB of each MPI rank's peak on sphere_5e6,
    // which redistribution set. `redistribute` returns their memory to
    // the system, with what the caller frees before it.
    drop((on, loc));
    drop(d);
    Ok(Passed {
        parts,
        dst,
        next_gid,
        rec,
        t0,
    })
}

impl Passed {
    /// §8: the tets to their parts, the points numbered and shared. The
    /// output holds every point of `points` (the ones the passes were
    /// given) in order.
    pub fn redistribute<C: Comm>(
        self,
        points: &[P3],
        opts: &ParOptions,
        comm: &C,
    ) -> Result<ParOutput, PassError> {
        let Passed {
            parts,
            dst,
            next_gid,
            rec,
            t0,
        } = self;
        // What the caller freed since is returned before the tets move.
        release(opts.release);
        let sent = redistribute::send(parts, dst, comm);
        let out = redistribute::finish(sent, comm, points, next_gid, opts)?;
        let held = comm.all_gather(out.pieces.iter().map(|p| p.tets.len()).collect());
        let pass_tets = comm.all_reduce(
            out.pieces
                .iter()
                .map(|pc| {
                    let mut n = [0usize; 4];
                    // The core's tets (pass 0) are no pass's.
                    for &p in &pc.tet_pass {
                        if let Some(x) = (p as usize).checked_sub(1).and_then(|i| n.get_mut(i)) {
                            *x += 1;
                        }
                    }
                    n
                })
                .collect(),
            |a, b| [0, 1, 2, 3].map(|i| a[i] + b[i]),
        );
        Ok(rec.finish(out, held, pass_tets, t0.elapsed().as_secs_f64()))
    }
}

/// The DDG of the front: by `opts.ddg_passes` parallel passes, or by the
/// serial front when there are none or they fail, with their stats.
fn the_ddg<C: Comm>(
    points: &[P3],
    point_size: &[f64],
    faces: &[[u32; 3]],
    depth: f64,
    opts: &ParOptions,
    comm: &C,
) -> Result<(Ddg, Option<DdgBuildStats>), PassError> {
    if opts.ddg_passes > 0 {
        let (c, passes, cap) = (opts.growth, opts.ddg_passes, opts.ddg_cap);
        // Its passes run over the processes like the fine mesh's; every
        // process then holds the whole DDG (the same bytes everywhere).
        match ddg_build::build_ddg_at(points, faces, depth, c, passes, cap, comm) {
            Ok((d, bs)) => return Ok((d, Some(bs))),
            // The serial front gets another go (deterministic: the same
            // failure on any thread count).
            Err(e) => {
                if tracing::enabled!(tracing::Level::DEBUG) {
                    tracing::debug!("the DDG's passes failed ({e}); the serial front builds it");
                }
            }
        }
    }
    let d = ddg::build(
        points.to_vec(),
        point_size.to_vec(),
        faces.to_vec(),
        opts.growth,
    )
    .map_err(PassError::Ddg)?;
    Ok((d, None))
}

/// §6 step 2: the DDG's locator and the balanced split into `np` parts,
/// with their statistics; coarser bins where the process holds only
/// some of the parts (`shared`). The tet weights are not kept: the crossing
/// partition computes them again (1.6 MB of each MPI rank through the
/// passes on sphere_5e6 at 32 parts).
fn split_ddg<'d>(
    d: &'d Ddg,
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &ParOptions,
    (np, shared): (usize, bool),
    rec: &mut Recorder,
) -> (Locator<'d>, Vec<u32>) {
    let st = &mut rec.st;
    let t0 = Instant::now();
    let w = ddg::tet_weights(d, size);
    let t_w = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let part0 = ddg::partition(d, &w, size, np, opts.partition);
    let t_split = t1.elapsed().as_secs_f64();
    // The locator after METIS, not beside it: METIS's work space is gone
    // by then (on sphere_5e6 both together set each MPI rank's peak).
    let loc = if shared {
        Locator::with_bins(d, ddg::SHARED_PER_CELL)
    } else {
        Locator::new(d)
    };
    st.split_seconds = t_split;
    let t_rcb = t0.elapsed().as_secs_f64();
    st.predicted_imbalance = ddg::imbalance(&part0, &w, np);
    st.partition_seconds = t0.elapsed().as_secs_f64();
    st.partition = opts.partition;
    st.cut_faces = ddg::cut_faces(d, &part0);
    st.cut_fine_faces = ddg::cut_fine_faces(d, &part0, size);
    st.max_components = ddg::components(d, &part0, np)
        .into_iter()
        .max()
        .unwrap_or(0);
    rec.partitioned();
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!(
            "partition: weights {t_w:.3} s, split {t_split:.3} s (with the locator {t_rcb:.3} s, {:.1} MB)",
            loc.heap_bytes() as f64 * 1e-6
        );
    }
    (loc, part0)
}

/// How the passes' fronts size new tets: the field, and the tallest tet
/// over a face, in its longest edges (`FrontOptions::max_growth`).
#[derive(Clone, Copy)]
pub(crate) struct Sizes<'a> {
    pub(crate) field: &'a (dyn Fn(P3) -> f64 + Sync),
    pub(crate) max_growth: f64,
}

impl<'a> Sizes<'a> {
    /// The fine mesh's: the front's default growth.
    pub(crate) fn fine(field: &'a (dyn Fn(P3) -> f64 + Sync)) -> Sizes<'a> {
        Sizes {
            field,
            max_growth: parafront_front::MAX_GROWTH_PER_TET,
        }
    }
}

/// Share of the region's volume left after pass 3 above which the region
/// is meshed serially instead ([`PassError::Unsuited`];
/// `ParOptions::serial_from`).
pub const SERIAL_FROM: f64 = 0.25;

/// The share of the volume inside `faces` (the input front) that the
/// parts' fronts still enclose.
fn left_fraction<C: Comm>(parts: &[Part], comm: &C, points: &[P3], faces: &[[u32; 3]]) -> f64 {
    let Some(f0) = faces.first() else {
        return 0.0;
    };
    let o = points[f0[0] as usize];
    let vol6 = |pts: &[P3], fs: &[[u32; 3]]| -> f64 {
        fs.iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| pts[i as usize]);
                tet_volume6(o, a, b, c)
            })
            .sum()
    };
    let left = comm.all_reduce(
        parts.iter().map(|p| vol6(&p.pts, &p.front)).collect(),
        |a, b| a + b,
    );
    let all = vol6(points, faces);
    if all != 0.0 {
        left / all
    } else {
        0.0
    }
}

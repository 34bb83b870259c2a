//! The parallel mesher of one closed front (paper §5 to §8): the DDG,
//! its balanced partition, the inside-out passes on shifted partitions
//! (pass 1 on DDG0, pass 2 with layers taken from higher neighbours,
//! pass 3 from lower ones, pass 4 serial) and the redistribution of the
//! pieces.
//!
//! Every part keeps its own points, tets and front (`Part` is private to
//! this module and only ever touched by the closure of its own part); parts
//! see each other's data only through the messages of a [`Comm`].
#![forbid(unsafe_code)]

mod ddg_build;
mod pass;
mod pockets;
mod redistribute;
mod serial;

use pass::{front_left_per_tet, parallel_pass, seed_inner_parts};
use pockets::*;
use serial::*;

pub use ddg_build::{build_ddg, DdgBuildStats};
pub use parafront_ddg::Partition;
pub use redistribute::Piece;

use parafront_comm::Comm;
use parafront_ddg::{self as ddg, Ddg, Interfaces, Locator, PartFilter, Shift};
use parafront_front::{
    advance, Everywhere, FrontError, FrontInput, FrontOptions, RegionFilter, SizeMode,
};
use parafront_geom::{centroid3, orient3d, tet_volume6, Aabb, P3};
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
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum PassError {
    #[error("domain-defining grid: {0}")]
    Ddg(#[from] ddg::DdgError),
    #[error("pass {pass}, part {part}: {source}")]
    Pass {
        pass: u8,
        part: usize,
        source: FrontError,
    },
    #[error("redistribution: {0}")]
    Redistribute(String),
    /// Passes 1 to 3 left most of the region to the serial pass 4: a thin
    /// part, whose DDG has little interior to split.
    #[error(
        "passes 1 to 3 left {:.0} % of the volume to the serial pass 4 (a thin part: the walls between parts cross most of it)",
        100.0 * left
    )]
    Unsuited { left: f64 },
    /// The region is a thin plate before any pass runs (its volume over
    /// its area is under [`THIN_DEPTH`] mean surface edges): every such
    /// part of the corpus left 31-93 % to pass 4, after seconds to minutes.
    #[error(
        "a thin part, {depth:.2} surface edges deep (volume over area): the walls between parts would cross most of it"
    )]
    Thin { depth: f64 },
}

/// Depth, in mean surface edges, under which a region skips the passes
/// ([`PassError::Thin`]). The corpus's thin plates are 0.14-0.35 deep
/// (the tray, the plate with holes, the hinge, base_interface), every
/// other input 1.7 or more.
pub const THIN_DEPTH: f64 = 0.5;

/// What the passes did, for the summary and the benchmark table.
#[derive(Clone, Debug, Default)]
pub struct ParStats {
    pub parts: usize,
    pub ddg_tets: usize,
    pub ddg_points: usize,
    pub ddg_surface_points: usize,
    pub ddg_growth: f64,
    /// The DDG used the graded field (the per-face growth got stuck).
    pub ddg_graded: bool,
    pub ddg_seconds: f64,
    /// CPU seconds (all threads) of the DDG and of the partition, where
    /// the system tells ([`process_cpu_seconds`]; 0 elsewhere): on a
    /// shared machine their share of a run's CPU time is steadier than
    /// their share of its wall time.
    pub ddg_cpu_seconds: f64,
    pub partition_cpu_seconds: f64,
    /// With a DDG built by passes: what each pass made.
    pub ddg_build: Option<DdgBuildStats>,
    pub partition_seconds: f64,
    /// Of which the split itself (RCB or METIS).
    pub split_seconds: f64,
    /// The split used, the DDG faces between parts, the fine faces
    /// expected on them, and the face-connected pieces of the most broken
    /// part (1: every part connected).
    pub partition: ddg::Partition,
    pub cut_faces: usize,
    pub cut_fine_faces: f64,
    pub max_components: usize,
    /// Max over mean of the predicted (DDG weight) load.
    pub predicted_imbalance: f64,
    /// Max over mean of the tets each part made in pass 1 to 3, and of the
    /// tets each part holds after redistribution.
    pub made_imbalance: f64,
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
    pub pieces: Vec<Piece>,
    pub stats: ParStats,
}

/// A point as it travels in a message: its global id, where it is, its size.
#[derive(Clone, Copy, Debug)]
struct Rec {
    gid: u32,
    p: P3,
    h: f64,
}

/// A front face in a message: owned (the part advances it) or context
/// (the part only has to know it is there).
struct FaceMsg {
    owned: bool,
    v: [Rec; 3],
}

/// One part's local data.
#[derive(Default)]
struct Part {
    pts: Vec<P3>,
    size: Vec<f64>,
    gid: Vec<u32>,
    index: FxHashMap<u32, u32>,
    /// Local ids.
    tets: Vec<[u32; 4]>,
    tet_pass: Vec<u8>,
    /// The faces this part holds, local ids.
    front: Vec<[u32; 3]>,
    /// Global ids of the points of the faces that got stuck in its last
    /// front call (region rules allowed them, the front could not).
    stuck: Vec<u32>,
}

/// `np` empty parts, the input front on part 0 (the reader); pass 1 sends
/// it out.
fn seed_parts(np: usize, points: &[P3], point_size: &[f64], faces: &[[u32; 3]]) -> Vec<Part> {
    let mut parts: Vec<Part> = (0..np).map(|_| Part::default()).collect();
    for f in faces {
        let v = f.map(|i| {
            parts[0].local(Rec {
                gid: i,
                p: points[i as usize],
                h: point_size[i as usize],
            })
        });
        parts[0].front.push(v);
    }
    parts
}

impl Part {
    fn local(&mut self, r: Rec) -> u32 {
        if let Some(&i) = self.index.get(&r.gid) {
            return i;
        }
        let i = self.pts.len() as u32;
        self.pts.push(r.p);
        self.size.push(r.h);
        self.gid.push(r.gid);
        self.index.insert(r.gid, i);
        i
    }
    fn rec(&self, i: u32) -> Rec {
        Rec {
            gid: self.gid[i as usize],
            p: self.pts[i as usize],
            h: self.size[i as usize],
        }
    }
}

/// What one part's front call gave back, before new points get global ids.
struct Made {
    res: Option<parafront_front::FrontResult>,
    /// Global ids of the input points.
    input_gid: Vec<u32>,
    /// Input points inside this part (conservative assignment).
    input_ok: Vec<bool>,
    /// Per face of `res.front`: stuck rather than held by the region.
    stuck: Vec<bool>,
    seconds: f64,
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
    /// The region filter of part `k`.
    fn filter(&self, k: u32) -> Box<dyn RegionFilter + '_>;
}

/// The regions of one DDG partition.
struct DdgRegions<'a> {
    d: &'a Ddg,
    loc: &'a Locator,
    walls: Interfaces,
    part_of: &'a [u32],
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
    fn filter(&self, k: u32) -> Box<dyn RegionFilter + '_> {
        Box::new(PartFilter::new(self.loc, &self.walls, self.part_of, k))
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
    let np = comm.parts();
    let mut st = ParStats {
        parts: np,
        ..Default::default()
    };
    let depth = ddg_build::depth(points, faces);
    if depth < opts.thin_depth {
        return Err(PassError::Thin { depth });
    }
    // §5 step 1: the DDG (replicated: it is small).
    let cpu0 = process_cpu_seconds();
    let t_ddg = Instant::now();
    let built = if opts.ddg_passes > 0 {
        let (c, passes, cap) = (opts.growth, opts.ddg_passes, opts.ddg_cap);
        match ddg_build::build_ddg_at(points, faces, depth, c, passes, cap, comm) {
            Ok((d, bs)) => {
                st.ddg_build = Some(bs);
                Some(d)
            }
            // The serial front gets another go (deterministic: the same
            // failure on any thread count); `ddg_build` stays `None`.
            Err(e) => {
                if tracing::enabled!(tracing::Level::DEBUG) {
                    tracing::debug!("the DDG's passes failed ({e}); the serial front builds it");
                }
                None
            }
        }
    } else {
        None
    };
    let d = if let Some(d) = built {
        d
    } else {
        ddg::build(
            points.to_vec(),
            point_size.to_vec(),
            faces.to_vec(),
            opts.growth,
            ddg::DdgMode::default(),
        )
        .map_err(PassError::Ddg)?
    };
    st.ddg_tets = d.tets.len();
    st.ddg_points = d.points.len();
    st.ddg_surface_points = d.n_input;
    st.ddg_growth = d.growth;
    st.ddg_graded = d.mode == ddg::DdgMode::Graded;
    // A failed try of the passes included.
    st.ddg_seconds = t_ddg.elapsed().as_secs_f64();

    let cpu1 = process_cpu_seconds();
    // §6 step 2: weights and the balanced split.
    let t0 = Instant::now();
    // The locator alongside: METIS runs on one thread.
    let (loc, (w, part0, t_w, t_split)) = rayon::join(
        || Locator::new(&d),
        || {
            let w = ddg::tet_weights(&d, size);
            let t_w = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let part0 = ddg::partition(&d, &w, size, np, opts.partition);
            (w, part0, t_w, t1.elapsed().as_secs_f64())
        },
    );
    st.split_seconds = t_split;
    let t_rcb = t0.elapsed().as_secs_f64();
    st.predicted_imbalance = ddg::imbalance(&part0, &w, np);
    // Passes 2 and 3 shift it once pass 1 has shown where its front is
    // left (`order_for_shift`).
    let mut part0 = part0;
    let (mut part2, mut part3) = (Vec::new(), Vec::new());
    st.partition_seconds = t0.elapsed().as_secs_f64();
    st.partition = opts.partition;
    st.cut_faces = ddg::cut_faces(&d, &part0);
    st.cut_fine_faces = ddg::cut_fine_faces(&d, &part0, size);
    st.max_components = ddg::components(&d, &part0, np)
        .into_iter()
        .max()
        .unwrap_or(0);
    let cpu2 = process_cpu_seconds();
    if let (Some(a), Some(b), Some(c)) = (cpu0, cpu1, cpu2) {
        st.ddg_cpu_seconds = b - a;
        st.partition_cpu_seconds = c - b;
    }
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!(
            "partition: weights {t_w:.3} s, split {t_split:.3} s (with the locator {t_rcb:.3} s)"
        );
    }

    let mut parts = seed_parts(np, points, point_size, faces);
    let mut next_gid = points.len() as u32;
    st.seeds = seed_inner_parts(&mut parts, &d, &loc, &part0, size, &mut next_gid);
    let mut made_per_part = vec![0usize; np];

    // §7 step 3, passes 1 to 3; then, while the front left would make
    // pass 4 large, passes on a crossing partition (the other method and
    // its two shifts): what passes 2 and 3 leave sits where the walls of
    // both shifts meet, inside the crossing parts (P >= 32 on 1M tets).
    let mut crossing: Vec<Vec<u32>> = Vec::new();
    for j in 0..3 + MAX_CROSSING {
        if j >= 3 {
            let left = comm.all_reduce(parts.iter().map(|p| p.front.len()).collect(), |a, b| a + b);
            let made: usize = st.pass_tets.iter().sum();
            if (left as f64) < CROSSING_FROM * made as f64 {
                break;
            }
        }
        if j == 3 {
            let t = Instant::now();
            let method = match opts.partition {
                Partition::Rcb => Partition::Metis,
                Partition::Metis => Partition::Rcb,
            };
            crossing = vec![ddg::partition(&d, &w, size, np, method)];
            st.partition_seconds += t.elapsed().as_secs_f64();
        }
        if j == 1 || j == 4 {
            // Name the parts so that the next shift shares out what the
            // pass on the unshifted partition left, then shift it (§7
            // passes 2 and 3; the crossing partition likewise).
            let t = Instant::now();
            let left = front_left_per_tet(&parts, comm, &loc, d.tets.len());
            let base = if j == 1 { &mut part0 } else { &mut crossing[0] };
            let label = ddg::order_for_shift(&d, base, &left, opts.layers, np);
            for k in base.iter_mut() {
                *k = label[*k as usize];
            }
            let up = ddg::shifted(&d, base, Shift::FromHigher, opts.layers);
            let down = ddg::shifted(&d, base, Shift::FromLower, opts.layers);
            if tracing::enabled!(tracing::Level::DEBUG) {
                let loads = ddg::shift_loads(&d, base, &left, opts.layers, np);
                tracing::debug!(
                    "relabelled for pass {}: {:.3} s, front left per part {loads:?}",
                    j + 1,
                    t.elapsed().as_secs_f64()
                );
            }
            if j == 1 {
                let mut made = vec![0; np];
                for (k, &n) in made_per_part.iter().enumerate() {
                    made[label[k] as usize] = n;
                }
                made_per_part = made;
                (part2, part3) = (up, down);
            } else {
                crossing.extend([up, down]);
            }
            st.partition_seconds += t.elapsed().as_secs_f64();
        }
        // Partition work above counts in `partition_seconds`, not here.
        let t0 = Instant::now();
        let part_of: &[u32] = match j {
            0 => &part0,
            1 => &part2,
            2 => &part3,
            _ => &crossing[j - 3],
        };
        // The crossing passes count as pass 3.
        let label = j.min(2);
        let regions = DdgRegions {
            d: &d,
            loc: &loc,
            walls: Interfaces::new(&d, part_of),
            part_of,
        };
        let (tets, secs) = parallel_pass(
            &mut parts,
            comm,
            &regions,
            Sizes::fine(size),
            label as u8 + 1,
            &mut next_gid,
        )?;
        for (k, &n) in tets.iter().enumerate() {
            made_per_part[k] += n;
        }
        st.pass_tets[label] += tets.iter().sum::<usize>();
        st.part_seconds.push(secs);
        st.crossing_passes = j.saturating_sub(2);
        if tracing::enabled!(tracing::Level::DEBUG) {
            let fr: usize = parts.iter().map(|p| p.front.len()).sum();
            let stuck: usize = parts.iter().map(|p| p.stuck.len() / 3).sum();
            tracing::debug!(
                "pass {} tets {:?} front left {fr}, {stuck} stuck",
                if j < 3 {
                    format!("{}", j + 1)
                } else {
                    format!("3 (crossing {})", j - 2)
                },
                tets
            );
        }
        // Room for the next pass around what this one left stuck.
        let peeled = peel_stuck(&mut parts, comm);
        if tracing::enabled!(tracing::Level::DEBUG) {
            tracing::debug!(
                "after pass {}: {peeled} tets peeled around stuck faces",
                j + 1
            );
        }
        st.peeled_tets += peeled;
        st.pass_seconds[label] += t0.elapsed().as_secs_f64();
    }
    let mean = made_per_part.iter().sum::<usize>() as f64 / np as f64;
    st.made_imbalance = if mean > 0.0 {
        *made_per_part.iter().max().unwrap() as f64 / mean
    } else {
        1.0
    };

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
    st.pass_tets[3] = made4;
    st.peeled_tets += removed;
    st.pass_seconds[3] = t0.elapsed().as_secs_f64();

    // §8 step 4.
    let t0 = Instant::now();
    let out = redistribute::run(parts, comm, &loc, &part0, points, next_gid)?;
    st.redistribute_seconds = t0.elapsed().as_secs_f64();
    st.pass_tets = [0; 4];
    for &p in &out.tet_pass {
        st.pass_tets[p as usize - 1] += 1;
    }
    let held: Vec<usize> = out.pieces.iter().map(|p| p.tets.len()).collect();
    let mean = held.iter().sum::<usize>() as f64 / np as f64;
    st.held_imbalance = if mean > 0.0 {
        *held.iter().max().unwrap() as f64 / mean
    } else {
        1.0
    };
    Ok(ParOutput { stats: st, ..out })
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

/// Crossing passes after pass 3: one on a partition by the other method,
/// then one on each of its shifts.
const MAX_CROSSING: usize = 3;
/// A crossing pass runs while the front left has more faces than this
/// share of the tets made (pass 4 makes about a tet per face left).
const CROSSING_FROM: f64 = 0.0025;

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

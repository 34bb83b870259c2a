//! The pipeline: surface (validated) -> size field -> front, one material
//! region at a time -> checked `TetMesh`. Later stages (DDG, parallel
//! passes, redistribution, improvement) slot in between the front and the
//! check. The CLI is a thin layer over [`mesh_surface`].
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod auto_parts;
mod lattice;
mod parts;
mod pieces;
mod serial;
use lattice::{note_lattice, region_lattice};
use parts::{finish_pieces, mesh_parts, volume6};
use serial::{
    append_region, global_id, mesh_serial, region_points, serial_region, serial_region_mesh,
};
mod regions;
mod share;
mod summary;

pub use auto_parts::{
    auto_parts, estimate_for_parts, estimate_tets, AUTO_PARTS, DEFAULT_PART_TETS, MAX_AUTO_PARTS,
};
pub use parafront_ddg::Partition;
pub use regions::{material_regions, RegionFront};
pub use summary::{Stage, Summary};

use parafront_comm::Comm;
use parafront_ddg::DdgError;
use parafront_front::{advance, FrontError, FrontInput, FrontOptions, SizeMode};
use parafront_mesh::{CheckError, PointId, QualityReport, TetMesh, TopoError};
use parafront_passes::{passes_around, ParOptions, PassError, Passed};
pub use parafront_passes::{process_cpu_seconds, DDG_CAP, SERIAL_FROM, THIN_DEPTH};
use parafront_size::{SizeError, SizeField, SizeOptions, Sizing};
use parafront_surface::validate::{shells, validate, Report, Shell, ShellKind};
use parafront_surface::Surface;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Every option of `parafront mesh`, with documented defaults. The CLI
/// flags and a TOML file (`--config`) both map onto it.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshOptions {
    /// The size field (AG1): global `h`, `hmin`, `hmax`, `gradation`,
    /// sources, per-patch sizes, background grid.
    #[serde(default)]
    pub size: SizeOptions,
    /// Worker threads (0: all cores).
    #[serde(default)]
    pub threads: usize,
    /// Parts of the parallel mesher (the paper's nproc); 1 runs the serial
    /// front. With more, each region goes through the DDG, its partition
    /// and the inside-out passes (§5 to §8). [`AUTO_PARTS`] (0, the
    /// default) picks them from the estimated tet count: about one per
    /// `part_tets`, serial under one and a half ([`auto_parts`]); never
    /// from the threads, so the mesh does not depend on them.
    #[serde(default)]
    pub parts: usize,
    /// With `parts` auto: one part per this many estimated tets
    /// ([`DEFAULT_PART_TETS`]).
    #[serde(default = "default_part_tets")]
    pub part_tets: usize,
    /// DDG growth factor `c_i` (§5); 0 takes the default (1.6).
    #[serde(default)]
    pub ddg_growth: f64,
    /// How the DDG is split into parts (§6): `metis` or `rcb`.
    #[serde(default)]
    pub partition: parafront_ddg::Partition,
    /// Parallel passes that build the DDG (then a serial pass on what they
    /// leave); 0 builds it with the serial front; unset takes the default
    /// (`parafront_passes::DEFAULT_DDG_PASSES`).
    pub ddg_passes: Option<usize>,
    /// Skip the final validity check (not recommended; it is cheap).
    #[serde(default)]
    pub no_check: bool,
    /// Skip the quality report (`Summary::quality`): `parafront bench`
    /// times the meshing alone.
    #[serde(default)]
    pub no_quality: bool,
    /// The quality report also weighs every edge against the size field
    /// (its length over the target size at its midpoint:
    /// `QualityReport::edge_ratio`). Off by default: at 1e6 tets it took
    /// 0.2 of the report's 0.35 s on one thread.
    #[serde(default)]
    pub size_report: bool,
    /// When the front fails, keep its partial mesh and stuck faces in the
    /// error, for a debug dump (`parafront mesh --debug-dump`).
    #[serde(default)]
    pub debug_partial: bool,
    /// Counters the front updates, for a progress display (not an option
    /// a file can set).
    #[serde(skip)]
    pub progress: Option<std::sync::Arc<parafront_front::Progress>>,
    /// Inner bodies (shells inside material with outward normals) become
    /// regions of their own; without it every inner shell is a void.
    #[serde(default)]
    pub regions: bool,
    /// Mesh improvement level (§9): 0 off, 1 swaps and smoothing, 2
    /// (default) also collapse of very bad tets and selective movement, 3
    /// more passes. See `parafront_improve::ImproveOptions`.
    #[serde(default = "default_optimize")]
    pub optimize: u8,
    /// Parts improved in parallel (§9.5): 0 (default) one per 100k tets of
    /// a merged mesh, and each piece of a partitioned one as one part (the
    /// pieces are the parallel work already); 1 serial. See
    /// `parafront_improve::ImproveOptions::parts`.
    #[serde(default)]
    pub optimize_parts: usize,
    /// Recovery rounds of a stalled front before the constrained fill
    /// closes its cavities, and between the fill's tries; 0: only
    /// where the front would give up.
    #[serde(default = "default_fill_after")]
    pub fill_after: u32,
    /// Optimal space-filling tets (§2, `parafront_lattice`): a BCC lattice
    /// fills the interior where the size field is nearly uniform, and the
    /// front meshes only around it. The serial front only (one part).
    #[serde(default)]
    pub lattice: LatticeMode,
    /// Parallel mesher: depth in mean surface edges (volume over area)
    /// under which a region is meshed by the serial front instead (0:
    /// never). See `parafront_passes::ParOptions::thin_depth`.
    #[serde(default = "default_thin_depth")]
    pub thin_depth: f64,
    /// Parallel mesher: share of the volume left after pass 3 above which
    /// the region is meshed serially instead (2: never).
    #[serde(default = "default_serial_from")]
    pub serial_from: f64,
    /// Parallel mesher: the DDG's largest size on deep fronts, as a share
    /// of a part's width.
    #[serde(default = "default_ddg_cap")]
    pub ddg_cap: f64,
    /// Test hook (the MPI tests' failing rank): redistribution fails on
    /// this part, and every process must stop with its message. None by
    /// default.
    #[serde(default)]
    pub fail_part: Option<usize>,
    /// Merge the parts into one mesh (true, the default), or leave the mesh
    /// in its pieces, on the processes that made them (false: a `.pvtu`
    /// output, memory distributed under MPI). Off needs `parts` > 1 (auto
    /// gives 2 at least), turns the lattice off unless it is `On` (then its
    /// tets go into the pieces with the passes', §8) and improves the
    /// pieces where they lie (§9.5); the summary then has the pieces, and
    /// the mesh returned is empty.
    #[serde(default = "yes")]
    pub gather: bool,
    /// Called after each stage that frees much (the size field's build, the
    /// front or the passes, improvement), to hand freed memory back to the
    /// system: the cli passes glibc's `malloc_trim`. None by default.
    #[serde(skip)]
    pub release_memory: Option<fn()>,
}

impl MeshOptions {
    /// Tells the progress display, if any, what the run does now.
    pub(crate) fn note_phase(&self, p: parafront_front::Phase) {
        if let Some(pr) = &self.progress {
            pr.set_phase(p);
        }
    }

    /// Hands freed memory back, where [`MeshOptions::release_memory`] says how.
    pub(crate) fn release(&self) {
        if let Some(f) = self.release_memory {
            f();
        }
    }
}

fn yes() -> bool {
    true
}

fn default_part_tets() -> usize {
    DEFAULT_PART_TETS
}

fn default_thin_depth() -> f64 {
    ParOptions::default().thin_depth
}

fn default_serial_from() -> f64 {
    ParOptions::default().serial_from
}

fn default_ddg_cap() -> f64 {
    ParOptions::default().ddg_cap
}

fn default_fill_after() -> u32 {
    parafront_front::DEFAULT_FILL_AFTER
}

fn default_optimize() -> u8 {
    parafront_improve::ImproveOptions::default().level
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            size: SizeOptions::default(),
            threads: 0,
            parts: AUTO_PARTS,
            part_tets: DEFAULT_PART_TETS,
            ddg_growth: 0.0,
            partition: parafront_ddg::Partition::default(),
            ddg_passes: None,
            no_check: false,
            no_quality: false,
            size_report: false,
            debug_partial: false,
            progress: None,
            optimize: default_optimize(),
            optimize_parts: 0,
            regions: false,
            fill_after: default_fill_after(),
            lattice: LatticeMode::default(),
            thin_depth: default_thin_depth(),
            serial_from: default_serial_from(),
            ddg_cap: default_ddg_cap(),
            fail_part: None,
            gather: true,
            release_memory: None,
        }
    }
}

/// When the serial front leaves the interior to the lattice (§2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LatticeMode {
    /// When the size field has a largest size (`--size` or `--hmax`): the
    /// interior is then uniform. Under the default gradation alone the
    /// size doubles every few elements, each lattice level is a thin
    /// shell, and the lattice costs more than it saves (sphere_1e5: 3 % of
    /// the tets for 0.09 s).
    #[default]
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

impl std::str::FromStr for LatticeMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(LatticeMode::Auto),
            "on" => Ok(LatticeMode::On),
            "off" => Ok(LatticeMode::Off),
            _ => Err(format!("unknown lattice mode {s:?} (auto, on or off)")),
        }
    }
}

/// Why [`mesh_surface`] made no mesh; each names the region, stage or
/// element at fault.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The surface failed validation (AF5): its report.
    #[error("the surface is not valid for meshing:\n{0}")]
    InvalidSurface(Box<Report>),
    /// The size field could not be built (AG1).
    #[error("size field: {0}")]
    Size(#[from] SizeError),
    /// The serial front failed on a region (§4).
    #[error("region {region}: {source}")]
    Front {
        /// The region (as in the mesh).
        region: usize,
        /// Why the front failed.
        source: FrontError,
    },
    /// The parallel mesher failed on a region, where the serial front
    /// cannot take over (§5 to §8).
    #[error("region {region}: {source}")]
    Parallel {
        /// The region (as in the mesh).
        region: usize,
        /// Why the passes failed.
        source: PassError,
    },
    /// The mesh failed its final check.
    #[error("the generated mesh failed its check (this is a bug in parafront): {0}")]
    Check(#[from] CheckError),
    /// The partitioned mesh (`gather` off) failed its check where it lies.
    #[error("the generated mesh failed its check (this is a bug in parafront): {0}")]
    PieceCheck(#[from] parafront_passes::PieceCheckError),
    /// A partitioned output (`gather` off) that the options or the run do
    /// not allow.
    #[error("a partitioned output (.pvtu): {0}")]
    Partitioned(String),
    /// Parts left to the estimate (`AUTO_PARTS`) over several processes,
    /// which would each estimate alone.
    #[error("the parts are chosen in one process only: give --parts under MPI")]
    AutoPartsPerProcess,
    /// Improvement (§9) found the front's tets not face-adjacent.
    #[error("mesh improvement: {source}")]
    Improve {
        /// What is wrong with the tets.
        source: TopoError,
    },
    /// The final mesh's tets are not face-adjacent.
    #[error("the generated mesh failed its check (this is a bug in parafront): {source}")]
    Adjacency {
        /// What is wrong with the tets.
        source: TopoError,
    },
    /// A tet whose volume is positive exactly but not in floating point.
    #[error(
        "tet {tet} is positive only under exact arithmetic (its floating-point volume is not positive); \
         the front does not yet avoid such slivers"
    )]
    FloatVolume {
        /// The tet.
        tet: usize,
    },
}

/// Mesh the volume bounded by `s`. The result keeps the surface triangle
/// for triangle (its points come first, with their ids) and has passed
/// `check_against_surface` unless `no_check`. Runs on `opts.threads`
/// threads (a pool of its own when that differs from the current one).
pub fn mesh_surface(s: &Surface, opts: &MeshOptions) -> Result<(TetMesh, Summary), MeshError> {
    let comm = parafront_comm::Threads::new(opts.parts.max(1));
    mesh_surface_on(s, opts, &comm).map(|r| r.expect("one process holds every part"))
}

/// [`mesh_surface`] with the parts' messages going through `comm`, which
/// spreads `opts.parts` over processes (MPI): every process reads the
/// surface and builds the size field and the DDG (they are small), the
/// passes run on the parts each holds, and the mesh gathers on the process
/// of part 0, which improves and checks it and gets `Some`; the others get
/// `None` once the passes are done.
pub fn mesh_surface_on<C: Comm>(
    s: &Surface,
    opts: &MeshOptions,
    comm: &C,
) -> Result<Option<(TetMesh, Summary)>, MeshError> {
    let t = opts.threads;
    if t > 0 && t != rayon::current_num_threads() {
        if let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(t).build() {
            return pool.install(|| mesh_surface_here(s, opts, comm));
        }
    }
    mesh_surface_here(s, opts, comm)
}

fn mesh_surface_here<C: Comm>(
    s: &Surface,
    opts: &MeshOptions,
    comm: &C,
) -> Result<Option<(TetMesh, Summary)>, MeshError> {
    let pieces_only;
    let opts = if opts.gather {
        opts
    } else {
        // Parts left to the estimate are two at least for pieces (below).
        if opts.parts != AUTO_PARTS && opts.parts < 2 {
            return Err(MeshError::Partitioned(
                "it needs parts > 1 (--parts 2 or more)".into(),
            ));
        }
        // The lattice goes into the pieces when asked for (`On`), not by
        // default: the pieces' improvement leaves slivers the merged run's
        // mends in the thin layer between the surface and the lattice
        // (box2holes_1e5 at --size 0.05 --parts 8: min dihedral 14.6
        // against 22.1 merged and 20.0 without the lattice).
        pieces_only = MeshOptions {
            lattice: match opts.lattice {
                LatticeMode::On => LatticeMode::On,
                _ => LatticeMode::Off,
            },
            ..opts.clone()
        };
        &pieces_only
    };
    let mut sum = Summary {
        threads: rayon::current_num_threads(),
        ..Summary::default()
    };
    let t0 = Instant::now();
    let mut report = validate(s);
    if !report.is_valid() {
        return Err(MeshError::InvalidSurface(Box::new(report)));
    }
    // Inner shells are voids unless asked for regions: such a shell's
    // triangles are turned round, and the mesh keeps them so.
    let voided = if opts.regions {
        Vec::new()
    } else {
        bodies_in_material(&report.shells)
    };
    let turned;
    let s = if voided.is_empty() {
        s
    } else {
        let mut t = s.clone();
        for &k in &voided {
            for &f in &report.shells[k].tris {
                t.tris[f as usize].swap(1, 2);
            }
        }
        // Turning a shell changes only the shells' signs and kinds: the
        // rest of the validation stands, and runs again only to report a
        // shell that now has the wrong sign (a void inside a turned body).
        report.shells = shells(&t);
        if report.shells.iter().any(|sh| !sh.orientation_ok()) {
            return Err(MeshError::InvalidSurface(Box::new(validate(&t))));
        }
        turned = t;
        &turned
    };
    sum.voided_shells = voided;
    let fronts = material_regions(s, &report.shells);
    // Its shells' lists are in the fronts now: not held through the passes.
    drop(report);
    sum.push(Stage::Validate, t0.elapsed().as_secs_f64());

    let t0 = Instant::now();
    // Each process builds its parts' share of the field's octree (one
    // process: all of it).
    let sizing = Sizing::build_shared(s, &opts.size, None, &share::CommShare(comm))?;
    // `parts` auto: chosen here, where the field stands (its octree does
    // not depend on the parts on one process, the threads backend).
    let auto = if opts.parts == AUTO_PARTS {
        if comm.owned() != (0..comm.parts()) {
            return Err(MeshError::AutoPartsPerProcess);
        }
        let estimate = estimate_for_parts(s, &sizing, opts.part_tets);
        // Pieces need parts: a small job gets two rather than the serial
        // front (which makes no pieces).
        let parts = match auto_parts(estimate, opts.part_tets) {
            1 if !opts.gather => 2,
            p => p,
        };
        tracing::debug!(estimate, parts, "parts from the estimated tet count");
        sum.auto_parts = Some((parts, estimate));
        Some(parts)
    } else {
        None
    };
    sum.push(Stage::SizeField, t0.elapsed().as_secs_f64());
    opts.release();
    match auto {
        Some(parts) => {
            let chosen = MeshOptions {
                parts,
                ..opts.clone()
            };
            let threads = parafront_comm::Threads::new(parts);
            mesh_sized(s, fronts, sizing, &chosen, &threads, sum)
        }
        None => mesh_sized(s, fronts, sizing, opts, comm, sum),
    }
}

/// The rest of [`mesh_surface_here`] once the size field stands: the
/// front (serial, or the parts' passes), improvement, check and report.
fn mesh_sized<C: Comm>(
    s: &Surface,
    mut fronts: Vec<RegionFront>,
    sizing: Sizing,
    opts: &MeshOptions,
    comm: &C,
    mut sum: Summary,
) -> Result<Option<(TetMesh, Summary)>, MeshError> {
    let t0 = Instant::now();
    // The merged mesh starts from the surface where it is made: not on the
    // processes that only send their parts, nor anywhere in pieces mode.
    let merged_here = opts.parts < 2 || (opts.gather && comm.holds(0));
    let mut mesh = if merged_here {
        surface_mesh(s)
    } else {
        TetMesh::default()
    };
    let (lattice_inner, sizing) = if opts.parts > 1 {
        // Without a merged mesh, the field is kept only for the report
        // (sphere_5e6: 8 MB of every process, through the improvement).
        // Pieces are checked against each region's volume, taken now: the
        // fronts' faces go once their passes are done (sphere_5e6: 1.4 MB
        // of each MPI rank through redistribution and improvement). A
        // merged mesh is checked against the surface instead.
        let pieces_vol6 = (!opts.gather).then(|| volume6(s, &fronts));
        let (inner, sizing) = mesh_parts(
            s,
            &mut fronts,
            Some(sizing),
            opts,
            &mut mesh,
            &mut sum,
            comm,
            passes_around,
        )?;
        if let Some(vol6) = pieces_vol6 {
            return finish_pieces(s, (&fronts, vol6), sizing, opts, comm, &inner, sum).map(Some);
        }
        opts.release();
        if !comm.holds(0) {
            return Ok(None);
        }
        (inner, sizing)
    } else {
        let lat0 = sum.seconds(Stage::Lattice);
        let inner = mesh_serial(s, &fronts, &sizing, opts, &mut mesh, &mut sum)?;
        let lat = sum.seconds(Stage::Lattice) - lat0;
        sum.push(Stage::Front, t0.elapsed().as_secs_f64() - lat);
        (inner, Some(sizing))
    };
    opts.release();

    // The tets improvement set aside, and their report.
    let mut aside = None;
    if opts.optimize > 0 {
        opts.note_phase(parafront_front::Phase::Improving);
        // The report before improvement is the improvement's cost.
        let t0 = Instant::now();
        // The surface points (ids below s.points.len()) never move (§9.3),
        // nor do the lattice's inner points: their tets are already ideal.
        let io = parafront_improve::ImproveOptions {
            level: opts.optimize,
            parts: opts.optimize_parts,
        };
        let n_surface = s.points.len();
        let done = lattice::improve_around_lattice(&mut mesh, n_surface, &lattice_inner, &io, true)
            .map_err(|source| MeshError::Improve { source })?;
        sum.quality_before = done.before;
        sum.improve = Some(done.stats);
        aside = done.aside;
        sum.push(Stage::Improve, t0.elapsed().as_secs_f64());
        opts.release();
    }

    opts.note_phase(parafront_front::Phase::Checking);
    let t0 = Instant::now();
    // The check pairs the faces in its own table (three tets on a face, two
    // on one side), and compares the adjacency with it where improvement
    // kept one; where a lattice or --optimize 0 left none, none is built
    // for it (0.3 of 0.6 s on sphere_1e6 at --size 0.037). Without the check,
    // the adjacency's build is the conformity test.
    if opts.no_check {
        mesh.build_adjacency()
            .map_err(|source| MeshError::Adjacency { source })?;
    } else {
        let st = mesh.check_against_surface(&s.tris)?;
        // Exactly positive is not enough: a solver computes volumes in
        // floating point, and so does meshcheck.py. The check has the
        // smallest; the tet is looked for only when it is not positive.
        let flat = |t: &usize| {
            let p = mesh.tet_points(parafront_mesh::TetId::new(*t));
            parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]) <= 0.0
        };
        if st.min_volume <= 0.0 {
            if let Some(t) = (0..mesh.tets.len()).find(flat) {
                return Err(MeshError::FloatVolume { tet: t });
            }
        }
    }
    sum.push(Stage::Check, t0.elapsed().as_secs_f64());
    if !opts.no_quality {
        // With the run's size field: building it again for the report took
        // as long as the size field stage.
        let t0 = Instant::now();
        // A merged mesh keeps its field (`mesh_parts`).
        sum.quality = Some(match (&sizing, &aside) {
            (Some(f), _) if opts.size_report => QualityReport::with_size(&mesh, |p| f.size(p)),
            (_, Some(aside)) => lattice::report_after(&mesh, aside),
            _ => QualityReport::new(&mesh),
        });
        sum.push(Stage::Quality, t0.elapsed().as_secs_f64());
    }
    sum.tets = mesh.tets.len();
    sum.points = mesh.points.len();
    sum.regions = fronts.len();
    Ok(Some((mesh, sum)))
}

/// The inner bodies that are meshed as voids without `regions`: shells
/// with outward normals whose parent is material (a body floating in a
/// void stays a body).
pub fn bodies_in_material(shells: &[Shell]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..shells.len()).collect();
    order.sort_by_key(|&k| shells[k].depth);
    let mut material = vec![false; shells.len()];
    let mut out = Vec::new();
    for k in order {
        let sh = &shells[k];
        material[k] = match sh.parent {
            None => true,
            Some(p) if material[p as usize] => {
                if sh.kind == ShellKind::Inner {
                    out.push(k);
                }
                false
            }
            Some(_) => sh.kind == ShellKind::Inner,
        };
    }
    out.sort_unstable();
    out
}

/// A mesh of `s`'s points and boundary triangles, no tets yet.
fn surface_mesh(s: &Surface) -> TetMesh {
    TetMesh {
        points: s.points.clone(),
        bnd_tris: s.tris.iter().map(|t| t.map(PointId::from_raw)).collect(),
        bnd_patch: s.patch.clone(),
        ..Default::default()
    }
}

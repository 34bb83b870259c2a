//! The command line's flags: each subcommand's arguments, parsed by clap
//! into these structs (the defaults and help text a user sees).
use crate::surface_cmds::{HealArgs, HealTol};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "parafront",
    version,
    about = "Parallel advancing-front tetrahedral mesh generator (after Löhner 2014)"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) cmd: Cmd,
}

#[derive(Subcommand)]
pub(crate) enum Cmd {
    /// Mesh the built-in demo part (a block with a drilled hole, a void
    /// and an embedded sphere, its own region) and write it.
    Demo {
        /// Output mesh (.vtu, .msh, .mesh).
        #[arg(short, long, default_value = "demo.vtu")]
        output: PathBuf,
        /// Only validate the demo surface and write it (no volume mesh).
        #[arg(long)]
        check_only: bool,
        #[command(flatten)]
        mesh: MeshArgs,
        #[command(flatten)]
        write: WriteArgs,
    },
    /// Mesh the volume bounded by a closed surface (STL, OBJ, OFF, .msh, .mesh).
    Mesh {
        surface: PathBuf,
        /// Output mesh (.vtu, .msh, .mesh).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        mesh: MeshArgs,
        #[command(flatten)]
        heal: HealArgs,
        #[command(flatten)]
        write: WriteArgs,
    },
    /// Heal a surface that a float rounding left open (see `mesh --heal`)
    /// and write it (.stl, .obj, .off, .msh, .mesh, .vtu); nothing is
    /// written, exit 1, when it is still not valid.
    Heal {
        input: PathBuf,
        output: PathBuf,
        #[command(flatten)]
        tol: HealTol,
        #[command(flatten)]
        write: WriteArgs,
    },
    /// Validate a surface: open, non-manifold, inconsistent orientation,
    /// degenerate, duplicate and self-intersecting triangles; shell nesting.
    /// Exit status 0 when it can be meshed.
    Check { surface: PathBuf },
    /// Quality statistics of a tet mesh, optionally plotted (.svg or .png).
    Quality {
        mesh: PathBuf,
        #[arg(long)]
        plot: Option<PathBuf>,
        /// A mesh to compare with (e.g. the same run with --optimize 0):
        /// its summary is printed and its histograms drawn behind.
        #[arg(long)]
        before: Option<PathBuf>,
    },
    /// Time the mesher over parts and threads: a table like the paper's
    /// Tables 1 to 3, with the time per stage and pass, each pass's share
    /// of the tets, the load imbalance and the critical path.
    Bench {
        surface: PathBuf,
        /// Target element size.
        #[arg(long)]
        size: Option<f64>,
        /// Part counts to run, comma separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2,8")]
        parts: Vec<usize>,
        /// Thread counts to run, comma separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// DDG partition methods to run, comma separated (metis, rcb).
        #[arg(long, value_delimiter = ',', default_value = "metis")]
        partition: Vec<parafront_pipeline::Partition>,
        /// Parallel passes that build the DDG (0: the serial front).
        #[arg(long)]
        ddg_passes: Option<usize>,
    },
    /// Convert a tet mesh (.vtu, .msh, .mesh) or a surface (.stl, .obj,
    /// .off, .msh, .mesh; patch tags kept where the format holds them).
    /// A tet mesh written as .stl, .obj or .off gives its boundary.
    Convert {
        input: PathBuf,
        output: PathBuf,
        #[command(flatten)]
        write: WriteArgs,
    },
}

#[derive(Args)]
pub(crate) struct MeshArgs {
    /// Target element size (also the largest size).
    #[arg(long)]
    pub(crate) size: Option<f64>,
    /// Smallest element size.
    #[arg(long)]
    pub(crate) hmin: Option<f64>,
    /// Largest element size.
    #[arg(long)]
    pub(crate) hmax: Option<f64>,
    /// Growth limit of the size away from the surface and sources (>= 1).
    #[arg(long)]
    pub(crate) gradation: Option<f64>,
    /// Size options from a TOML file (sources, per-patch sizes, ...);
    /// the flags above override it.
    #[arg(long)]
    pub(crate) size_file: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub(crate) threads: Option<usize>,
    /// Mesh inner bodies (inner shells with outward normals) as regions
    /// of their own; without it every inner shell is a void.
    #[arg(long)]
    pub(crate) regions: bool,
    /// Parts of the parallel mesher (the paper's nproc): auto (about one
    /// per --part-tets estimated tets, the serial front under one and a
    /// half; chosen from the job, never from the threads, so the mesh
    /// does not depend on them), 1 (the serial front) or more
    #[arg(long, value_name = "auto|N", default_value = "auto", value_parser = parse_parts)]
    pub(crate) parts: usize,
    /// With --parts auto: about one part per this many estimated tets
    #[arg(long, value_name = "TETS", default_value_t = parafront_pipeline::DEFAULT_PART_TETS)]
    pub(crate) part_tets: usize,
    /// Growth factor of the domain-defining grid (§5).
    #[arg(long)]
    pub(crate) ddg_growth: Option<f64>,
    /// How the domain-defining grid is split into parts (§6): metis
    /// (k-way on its dual graph, parts connected) or rcb (coordinate
    /// bisection).
    #[arg(long, default_value = "metis")]
    pub(crate) partition: parafront_pipeline::Partition,
    /// Parallel passes that build the DDG before a serial pass closes it
    /// (0: the serial front builds it)
    #[arg(long)]
    pub(crate) ddg_passes: Option<usize>,
    /// With --parts > 1, also write the partitioned mesh: this .pvtu and
    /// one .vtu per part beside it.
    #[arg(long)]
    pub(crate) pvtu: Option<PathBuf>,
    /// Also plot the quality histograms to this file (.svg or .png);
    /// with improvement on, before and after.
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// Also report every edge's length over the target size at its
    /// midpoint (min, mean, max): how well the mesh meets the size field.
    #[arg(long)]
    pub(crate) size_report: bool,
    /// If the front cannot be closed, write what it made (tets) and the
    /// faces it left (triangles) to this file (.vtu, .msh or .mesh).
    #[arg(long)]
    pub(crate) debug_dump: Option<PathBuf>,
    /// Mesh improvement level (§9): 0 off, 1 swaps and smoothing, 2
    /// (default) also edge collapse and selective movement, 3 more passes.
    #[arg(long)]
    pub(crate) optimize: Option<u8>,
    /// Parts the improvement runs on in parallel (§9.5), interfaces
    /// frozen, then a second pass on shifted parts: 0 (default) one part
    /// per 100k tets of a merged mesh, and each piece of a partitioned one
    /// (--parts) as one part; 1 serial. The mesh depends on it, not on
    /// --threads.
    #[arg(long)]
    pub(crate) optimize_parts: Option<usize>,
    /// Recovery rounds of a stalled front before the constrained fill
    /// closes its cavities, and between the fill's tries; 0: only where the
    /// front would give up.
    #[arg(long, value_name = "ROUNDS", default_value_t = parafront_front::DEFAULT_FILL_AFTER)]
    pub(crate) fill_after: u32,
    /// Optimal space-filling tets (§2): the front (serial, or the passes
    /// of --parts) leaves the interior, where the size field is nearly
    /// uniform, to a BCC lattice of near-ideal tets and meshes only around
    /// it. auto: when the size field has a largest size (--size or
    /// --hmax); on; off. --pvtu turns it off (the merged run's tets are in no
    /// piece); -o x.pvtu only with on, which puts its tets into the pieces
    #[arg(long, value_name = "MODE", default_value = "auto")]
    pub(crate) lattice: parafront_pipeline::LatticeMode,
    /// With --parts > 1: a region less deep than this many mean surface
    /// edges (volume over area) is meshed by the serial front instead (0:
    /// never).
    #[arg(long, value_name = "EDGES", default_value_t = parafront_pipeline::THIN_DEPTH)]
    pub(crate) thin_depth: f64,
    /// With --parts > 1: a region whose passes 1 to 3 leave more than this
    /// share of its volume is meshed by the serial front instead (2: never).
    #[arg(long, value_name = "SHARE", default_value_t = parafront_pipeline::SERIAL_FROM)]
    pub(crate) serial_from: f64,
    /// With --parts > 1: the domain-defining grid's largest size on deep
    /// fronts, as a share of a part's width.
    #[arg(long, value_name = "SHARE", default_value_t = parafront_pipeline::DDG_CAP)]
    pub(crate) ddg_cap: f64,
    /// Test hook: redistribution fails on this part (the MPI tests'
    /// failing rank).
    #[arg(long, value_name = "PART", hide = true)]
    pub(crate) fail_part: Option<usize>,
}

#[derive(Args)]
pub(crate) struct WriteArgs {
    /// Gmsh output version: 4.1 or 2.2.
    #[arg(long, default_value = "4.1")]
    pub(crate) msh_version: String,
    /// Binary Gmsh output.
    #[arg(long)]
    pub(crate) binary: bool,
    /// Uncompressed VTU output.
    #[arg(long)]
    pub(crate) no_compress: bool,
}

/// `--parts`: `auto` (`parafront_pipeline::AUTO_PARTS`) or a count of
/// at least 1.
fn parse_parts(s: &str) -> Result<usize, String> {
    if s == "auto" {
        return Ok(parafront_pipeline::AUTO_PARTS);
    }
    match s.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("`{s}`: give auto or a count of 1 or more")),
    }
}

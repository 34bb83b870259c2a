//! What a run made and how long each stage took.
use parafront_mesh::QualityReport;
use parafront_passes::{ParStats, Piece};
use std::fmt;

/// A timed stage of a run, in [`Summary::stages`]. Its `Display` is the
/// name the CLI prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Surface validation and the material regions.
    Validate,
    /// The size field (AG1).
    SizeField,
    /// The serial front (§4), or the serial front of a region the parallel
    /// passes gave up.
    Front,
    /// §2's optimal space-filling tets: the lattice in the core of each
    /// region, before the front or the passes mesh around it.
    Lattice,
    /// The domain-defining grid (§5, step 1).
    Ddg,
    /// Its weights and balanced split, and the shifted partitions (§6,
    /// step 2).
    Partition,
    /// Pass 1 on the balanced partition (§7, step 3).
    Pass1,
    /// Pass 2, layers taken from higher neighbours.
    Pass2,
    /// Pass 3, layers taken from lower neighbours, and the crossing passes.
    Pass3,
    /// Pass 4: what is left, serially.
    Pass4,
    /// Redistribution of the pieces (§8, step 4).
    Redistribute,
    /// The parallel passes of a region, given up for the serial front.
    PassesGivenUp,
    /// Mesh improvement (§9).
    Improve,
    /// Adjacency and the validity check.
    Check,
    /// The quality report.
    Quality,
    /// Writing the mesh (the CLI's).
    Write,
}

impl Stage {
    /// The parallel stages, in the order of [`ParStats`]' seconds.
    pub(crate) const PARALLEL: [Stage; 7] = [
        Stage::Ddg,
        Stage::Partition,
        Stage::Pass1,
        Stage::Pass2,
        Stage::Pass3,
        Stage::Pass4,
        Stage::Redistribute,
    ];

    /// The name printed in the summary.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Validate => "validate",
            Stage::SizeField => "size field",
            Stage::Front => "front",
            Stage::Lattice => "lattice",
            Stage::Ddg => "ddg",
            Stage::Partition => "partition",
            Stage::Pass1 => "pass 1",
            Stage::Pass2 => "pass 2",
            Stage::Pass3 => "pass 3",
            Stage::Pass4 => "pass 4",
            Stage::Redistribute => "redistribute",
            Stage::PassesGivenUp => "passes given up",
            Stage::Improve => "improve",
            Stage::Check => "check",
            Stage::Quality => "quality",
            Stage::Write => "write",
        }
    }
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What a run made, for the summary line and the benchmark tables.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Threads the run had (`MeshOptions::threads`, or the pool's).
    pub threads: usize,
    /// With `MeshOptions::parts` auto: the parts chosen, and the tets
    /// estimated they were chosen from.
    pub auto_parts: Option<(usize, f64)>,
    /// Tets of the mesh returned.
    pub tets: usize,
    /// Points of the mesh returned.
    pub points: usize,
    /// Material regions meshed.
    pub regions: usize,
    /// (stage, seconds), in pipeline order; a stage may come more than
    /// once (the front of each region given up by the passes).
    pub stages: Vec<(Stage, f64)>,
    /// Recovery rounds of the serial front, summed over the regions.
    pub recovery_rounds: u32,
    /// Tets the serial front's recovery removed.
    pub tets_removed: usize,
    /// Cavities a stalled front handed to the constrained Delaunay fill,
    /// and the tets the fill made.
    pub cavities_filled: usize,
    /// See `cavities_filled`.
    pub fill_tets: usize,
    /// Cavities the fill was given and could not close; they grew, went
    /// to recovery, or gave way to the fill of their region's surface.
    pub fills_failed: usize,
    /// Tets and cubes of the optimal space-filling lattice (§2).
    pub lattice_tets: usize,
    /// See `lattice_tets`.
    pub lattice_cells: usize,
    /// Regions the front could not close at all, filled whole by the
    /// constrained fill of their surface instead, then refined to the size
    /// field by Delaunay insertion: valid, without the front's quality.
    /// Ids as in `Front` errors.
    pub regions_filled: Vec<usize>,
    /// Regions whose front stalled on much of their surface at its first
    /// stall, and that the fill of their whole surface, refined to the
    /// size field (GDT), meshed instead. Ids as in `Front` errors.
    pub regions_refined: Vec<usize>,
    /// Shells (ids as `parafront check` prints them) oriented as inner
    /// bodies and meshed as voids, without `regions`.
    pub voided_shells: Vec<usize>,
    /// Regions (ids as in the mesh) the parallel passes could not close,
    /// or left mostly to pass 4, meshed by the serial front instead, with
    /// the reason.
    pub serial_fallback: Vec<(usize, String)>,
    /// Quality of the front's mesh before improvement (when it ran).
    pub quality_before: Option<QualityReport>,
    /// Quality of the mesh returned, with edge lengths against the run's
    /// size field (unless `MeshOptions::no_quality`).
    pub quality: Option<QualityReport>,
    /// What improvement did, per operation (when it ran).
    pub improve: Option<parafront_improve::ImproveStats>,
    /// Per region, what the parallel passes did (empty with one part).
    pub parallel: Vec<ParStats>,
    /// The partitioned mesh, one piece per region and part, with global
    /// ids in the merged mesh's numbering: with more than one part, when
    /// the mesh stays in its pieces or improvement is off (improvement
    /// renumbers the merged mesh).
    pub pieces: Vec<Piece>,
    /// The parts of each region's pieces in `pieces` (0: none kept).
    pub piece_parts: usize,
}

impl Summary {
    /// Seconds of `stage`, summed over its entries (0 when it did not run).
    pub fn seconds(&self, stage: Stage) -> f64 {
        self.stages
            .iter()
            .filter(|s| s.0 == stage)
            .map(|s| s.1)
            .sum()
    }

    /// Seconds of every stage.
    pub fn total_seconds(&self) -> f64 {
        self.stages.iter().map(|s| s.1).sum()
    }

    /// Records `seconds` of `stage`.
    pub fn push(&mut self, stage: Stage, seconds: f64) {
        self.stages.push((stage, seconds));
    }
}

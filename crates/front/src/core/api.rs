//! The front's public types: its options, input, result, counters and
//! errors.
use super::{DEFAULT_FILL_AFTER, MAX_GROWTH_PER_TET};
use parafront_geom::P3;

/// Tuning of the front. The defaults are what the serial mesher uses.
#[derive(Clone, Debug)]
pub struct FrontOptions {
    /// Attempts on one face before it waits for recovery.
    pub tries_per_face: u8,
    /// Removal-and-remesh rounds before giving up (step 5 of the issue).
    pub recovery_rounds: u32,
    /// Stop with an error past this many points (runaway guard).
    pub max_points: usize,
    /// Report progress every this many tets (0: never).
    pub progress_every: usize,
    /// Where to report it.
    pub progress: Option<std::sync::Arc<crate::Progress>>,
    /// A parallel pass (§7): the input front may be open (a part's share
    /// of the global front), and faces that get stuck are handed back in
    /// `FrontResult::front` for a later pass instead of being recovered.
    /// The front handed over must still contain every face that bounds the
    /// region (faces the filter rejects are held, not advanced): the front
    /// never crosses a face it does not know, and an open front bounds
    /// nothing.
    pub pass: bool,
    /// On failure, hand back the partial mesh and the stuck front in
    /// `FrontError::Stuck` (step 5.4: a debug dump when asked).
    pub keep_partial: bool,
    /// A new tet's size is at most this multiple of its face's longest
    /// edge: sizes then grow geometrically, and a small face under a large
    /// size (CAD needles) keeps a local search. The DDG allows more.
    pub max_growth: f64,
    /// Hand a stalled front's cavities to the constrained Delaunay fill
    /// instead of failing. Off, the front stops with
    /// `FrontError::Stuck` where the fill would start.
    pub fill: bool,
    /// Times a cavity the fill cannot close is grown by the tets behind
    /// its faces before the front gives up (fewer when a growth round
    /// closes no cavity).
    pub fill_growth: u32,
    /// Recovery rounds before the fill takes over, and between its tries
    /// (a stalled region costs a few rounds, not minutes); 0: only
    /// where the front would give up. Where the fill cannot close a cavity
    /// yet, recovery goes on.
    pub fill_after: u32,
    /// A front that stalls for the first time before it has made a tet
    /// for every other input face hands its whole input to the fill
    /// (edges split first); where that fails, recovery goes on. For a
    /// region's surface; a gap left by the passes (§7) is thin by nature.
    pub fill_early: bool,
    /// Where the first stall's fill leaves cavities on much of the region
    /// (`REGION_FILL_SHARE`), return [`FrontError::HandOver`] instead of
    /// filling the input whole here: for an input that holds a lattice
    /// (§2), whose tets the caller adds.
    pub hand_over: bool,
    /// At the front's first stall, when it leaves many faces stuck, fill
    /// the cavities (no growth rounds) before any recovery round; those
    /// the fill cannot close go on to recovery. Not in a parallel pass
    /// (§7), whose front is open.
    pub fill_at_stall: bool,
    /// Called once the live front has shrunk to half its largest size
    /// since the last call (from [`RELEASE_FROM`] faces): the caller hands
    /// the memory of the faces and grid cells freed since back to the
    /// system (the CLI: glibc's `malloc_trim`). It must not touch the
    /// mesh; none by default.
    pub release: Option<fn()>,
}

/// The live front, in faces, below which [`FrontOptions::release`] is not
/// called: a smaller front frees too little to be worth a call.
pub const RELEASE_FROM: usize = 1 << 15;

impl Default for FrontOptions {
    fn default() -> Self {
        FrontOptions {
            tries_per_face: 3,
            recovery_rounds: 200,
            max_points: u32::MAX as usize - 1,
            progress_every: 4096,
            progress: None,
            pass: false,
            keep_partial: false,
            max_growth: MAX_GROWTH_PER_TET,
            fill: true,
            fill_growth: 4,
            fill_after: DEFAULT_FILL_AFTER,
            fill_early: false,
            hand_over: false,
            fill_at_stall: true,
            release: None,
        }
    }
}

/// A closed front to fill.
pub struct FrontInput {
    /// The points the faces index; they keep their ids in the result, and
    /// the new points follow them.
    pub points: Vec<P3>,
    /// Size at each point (AG3).
    pub point_size: Vec<f64>,
    /// Triangles with right-hand normals pointing into the region to mesh.
    pub faces: Vec<[u32; 3]>,
}

/// What the front did (AF1 to AF5), for reports.
#[derive(Clone, Debug, Default)]
pub struct FrontStats {
    /// Tets in the result.
    pub tets: usize,
    /// Points in the result beyond the input: the new points (AF2.1) and
    /// the fill's Steiner points.
    pub new_points: usize,
    /// Faces that failed to get a tet and went back to the queue or to the
    /// stuck list (AF5).
    pub retries: usize,
    /// Recovery rounds run (AF5: removal around the stuck faces and re-meshing).
    pub recovery_rounds: u32,
    /// Tets removed again, by recovery and by growing the fill's cavities.
    pub tets_removed: usize,
    /// Pockets closed by coning to an inner point (recovery's last resort).
    pub pockets_filled: usize,
    /// Cavities closed by the constrained Delaunay fill, and its tets.
    pub cavities_filled: usize,
    /// Tets the constrained Delaunay fill made.
    pub fill_tets: usize,
    /// Cavities the fill was given and could not close (each then grew,
    /// went to recovery, or gave way to the region's fill).
    pub fills_failed: usize,
    /// Regions whose whole surface the fill closed and refined to the
    /// size field (GDT, §2) in place of the front (0 or 1 for one front).
    pub regions_refined: usize,
}

/// What the front made.
#[derive(Debug)]
pub struct FrontResult {
    /// Input points first, in input order, then the new points.
    pub points: Vec<P3>,
    /// Size (target edge length) at each point of `points`: the input's, then
    /// each new point's (AF4).
    pub point_size: Vec<f64>,
    /// Positively oriented tets.
    pub tets: Vec<[u32; 4]>,
    /// The tet across each face, `neigh[4t+f]` (or `NO_FACE`).
    pub neigh: Vec<parafront_mesh::FaceRef>,
    /// Faces the region filter kept from being advanced, and in pass mode
    /// the faces that got stuck (pass hand-over).
    pub front: Vec<[u32; 3]>,
    /// What the front did.
    pub stats: FrontStats,
}

/// What the front had made when it gave up: its points, its tets and the
/// faces still in the front, in one numbering.
#[derive(Debug, Default)]
pub struct Partial {
    /// Every point so far: the input's first, in input order, then the new ones.
    pub points: Vec<P3>,
    /// The live tets, positively oriented.
    pub tets: Vec<[u32; 4]>,
    /// The faces still in the front, normals pointing into the unmeshed region.
    pub front: Vec<[u32; 3]>,
}

/// Why the front did not finish.
#[derive(Debug, thiserror::Error)]
pub enum FrontError {
    /// Recovery (AF5) and the fill could not close the front.
    #[error("the front could not be closed after {rounds} recovery rounds: {faces} faces stuck near ({x:.6e}, {y:.6e}, {z:.6e})")]
    Stuck {
        /// Recovery rounds run.
        rounds: u32,
        /// Faces stuck at the end.
        faces: usize,
        /// x of the first stuck face's centroid.
        x: f64,
        /// y of the first stuck face's centroid.
        y: f64,
        /// z of the first stuck face's centroid.
        z: f64,
        /// With `FrontOptions::keep_partial`.
        partial: Option<Box<Partial>>,
    },
    #[error(
        "the front is not closed: edge ({a}, {b}) is used by {count} faces with this direction"
    )]
    /// The input front is not closed (checked outside pass mode): directed
    /// edge `a`-`b` is used by `count` faces and its reverse by a different
    /// number.
    OpenFront {
        /// The edge's first point.
        a: u32,
        /// The edge's second point.
        b: u32,
        /// Faces that use the edge from `a` to `b`.
        count: usize,
    },
    /// More points than `FrontOptions::max_points` (the limit given): a size
    /// field or a front running away.
    #[error("more than {0} points: the size field or the front is running away")]
    TooManyPoints(usize),
    /// With `FrontOptions::hand_over`: the first stall left cavities on
    /// much of the region, which its surface's whole fill, refined, would
    /// mesh better; the input holds a lattice whose tets are the caller's,
    /// so the caller fills the surface (the lattice's points as seeds).
    #[error("the front stalled on much of the region: its surface is to be filled whole")]
    HandOver,
}

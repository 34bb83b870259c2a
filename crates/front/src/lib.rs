//! The scalar advancing front (paper §4, AF1 to AF5).
//!
//! One core that every later stage reuses: the serial mesher, the
//! domain-defining grid (a size override, §5), every parallel pass (a
//! region filter, §7), and refilling holes after smoothing (§9.3).
//!
//! Input is a closed front: triangles whose right-hand normals point into
//! the region to mesh, and a size per point (AG3). Output is the tets,
//! their `4t+f` adjacency (kept as tets are made, not rebuilt), the new
//! points and whatever front a region filter left behind.

#![warn(missing_docs)]
mod core;
mod grid;
mod quality;
mod queue;

pub use crate::core::{
    advance, FrontError, FrontInput, FrontOptions, FrontResult, FrontStats, Partial,
    DEFAULT_FILL_AFTER, MAX_GROWTH_PER_TET, RELEASE_FROM,
};

use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};

/// Counters a front updates as it works, for a progress display on another
/// thread, and the run's phase, which the pipeline sets. Relaxed atomics:
/// a display needs no ordering.
#[derive(Debug, Default)]
pub struct Progress {
    tets: AtomicU64,
    front: AtomicU64,
    rounds: AtomicU64,
    fills: AtomicU64,
    phase: AtomicU8,
}

/// What a run is doing, for a progress display: after the front, the
/// improvement (§9) and the final check can take as long as it did (a CAD
/// part whose region went to the fill: 12-40 s of improvement).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// The front, its fills, the DDG and the passes.
    Meshing,
    /// Mesh improvement (§9).
    Improving,
    /// The validity check of the result.
    Checking,
}

impl Progress {
    /// The run's phase.
    pub fn phase(&self) -> Phase {
        match self.phase.load(Ordering::Relaxed) {
            1 => Phase::Improving,
            2 => Phase::Checking,
            _ => Phase::Meshing,
        }
    }
    /// Sets the run's phase (the pipeline, as it goes).
    pub fn set_phase(&self, p: Phase) {
        self.phase.store(p as u8, Ordering::Relaxed);
    }
    /// Tets made so far (recovery's removals are not subtracted).
    pub fn tets(&self) -> u64 {
        self.tets.load(Ordering::Relaxed)
    }
    /// Faces in the front now.
    pub fn front(&self) -> u64 {
        self.front.load(Ordering::Relaxed)
    }
    /// Recovery rounds so far.
    pub fn rounds(&self) -> u64 {
        self.rounds.load(Ordering::Relaxed)
    }
    /// Constrained fills started so far.
    pub fn fills(&self) -> u64 {
        self.fills.load(Ordering::Relaxed)
    }
    pub(crate) fn note_fill(&self) {
        self.fills.fetch_add(1, Ordering::Relaxed);
    }
    pub(crate) fn set(&self, tets: u64, front: u64, rounds: u64) {
        self.tets.store(tets, Ordering::Relaxed);
        self.front.store(front, Ordering::Relaxed);
        self.rounds.store(rounds, Ordering::Relaxed);
    }
}

use parafront_geom::P3;

/// Where a pass may mesh (paper §7). The front skips faces whose points,
/// edges or ideal point fall outside, and drops close points outside.
pub trait RegionFilter: Sync {
    /// Whether `p` lies inside the region (by default everywhere).
    fn point_ok(&self, _p: P3) -> bool {
        true
    }
    /// The segment `a`-`b` stays inside (the paper's neighbour-to-neighbour
    /// traversal through the DDG).
    fn edge_ok(&self, _a: P3, _b: P3) -> bool {
        true
    }
    /// [`RegionFilter::point_ok`], and a place that holds `p` alone (a
    /// cell of the filter's own, [`NO_PLACE`] when it has none): a later
    /// query near `p` tries it first (`near`, places of nearby points), and
    /// [`RegionFilter::edge_ok_at`] decides by it. The answer does not
    /// depend on `near`.
    fn locate(&self, p: P3, _near: &[u32]) -> (bool, u32) {
        (self.point_ok(p), NO_PLACE)
    }
    /// [`RegionFilter::edge_ok`] for ends located at places `pa` and `pb`.
    fn edge_ok_at(&self, a: P3, _pa: u32, b: P3, _pb: u32) -> bool {
        self.edge_ok(a, b)
    }
}

/// No place known ([`RegionFilter::locate`]).
pub const NO_PLACE: u32 = u32::MAX;

/// No restriction: the serial mesher.
pub struct Everywhere;
impl RegionFilter for Everywhere {}

/// How a new point gets its size (AF4).
#[derive(Clone, Copy)]
pub enum SizeMode<'a> {
    /// From the size field at the new point.
    Field(&'a (dyn Fn(P3) -> f64 + Sync)),
    /// DDG (§5): the mean size of the removed face's points times `c`.
    Growth(f64),
}

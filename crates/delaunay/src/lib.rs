//! The Delaunay kernel, and the constrained fill of a cavity the front
//! cannot close (AF5's last resort).
//!
//! The paper's §2 names the two scalar methods, the advancing front and the
//! generalized Delaunay triangulation (GDT). This crate is the second's
//! kernel: a tet store with `4t+f` adjacency ([`Triangulation`]), point
//! insertion by Bowyer-Watson with exact predicates and a symbolic
//! perturbation of the in-sphere test (so cospherical and coplanar points
//! need no special case), 2-3 flips and edge removal, and a `check()` of
//! validity and of the Delaunay property.
//!
//! [`fill_cavity`] builds on it: given a closed triangulated surface (a
//! stalled front's cavity), it returns tets that fill it exactly and keep
//! every surface triangle. It triangulates the cavity's points, recovers the
//! missing faces by flips, and keeps the tets inside. Where flips stall it
//! tries the cone from the kernel's deepest point, then a search (a front
//! with exact validity and no quality rules that can step back, adding
//! Steiner points strictly inside the cavity at its dead ends), then the
//! conforming fill (the missing edges split in the triangulation, the
//! split points then moved off the surface into the cavity, after Si and
//! Gärtner), then Steiner points in the triangulation. A whole region
//! (`FillOptions::segments_first`) is filled in TetGen's order, in one
//! triangulation: its edges recovered by flips and kept, an edge flips
//! cannot recover split at a point inserted without undoing what is kept
//! (a constrained Bowyer-Watson cavity), then its faces, then the split
//! points moved inside.
//!
//! [`refine_to_size`] is GDT's next step: it refines a filled region to a
//! size field by Bowyer-Watson insertion of seeds (a lattice) and of
//! circumcentres, never across the region's boundary.
#![forbid(unsafe_code)]
#![warn(missing_docs)]
mod check;
mod conform;
mod constrained;
mod fill;
mod flips;
mod predicates;
mod recover;
mod refine;
mod relocate;
mod search;
mod segments;
mod tri;

pub use check::CheckError;
pub use fill::{fill_cavity, Fill, FillError, FillMethod, FillOptions};
pub use flips::Flip;
pub use predicates::{is_flat, FLAT};
pub use refine::{refine_fill, refine_to_size, RefineError, RefineOptions, Refined};
pub use tri::{InsertError, Triangulation, NONE, TET_FACES};

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
//! Gärtner), then Steiner points in the triangulation. A front that
//! stalls on its whole input asks for the conforming fill alone, its
//! edges split first until each piece is a Delaunay edge
//! (`FillOptions::segments_first`): flips on thousands of faces cost
//! seconds, and a surface of needles needs less than a point per face.
//!
//! [`refine_to_size`] is GDT's next step: it refines a filled region to a
//! size field by Bowyer-Watson insertion of seeds (a lattice) and of
//! circumcentres, never across the region's boundary.
#![forbid(unsafe_code)]
#![warn(missing_docs)]
mod check;
mod conform;
mod fill;
mod flips;
mod predicates;
mod recover;
mod refine;
mod search;
mod tri;

pub use check::CheckError;
pub use fill::{fill_cavity, Fill, FillError, FillMethod, FillOptions};
pub use flips::Flip;
pub use refine::{refine_to_size, RefineError, RefineOptions, Refined};
pub use tri::{InsertError, Triangulation, NONE, TET_FACES};

//! The tetrahedral mesh store.
//!
//! Struct of arrays with typed `u32` ids: `tets[t]` holds four point ids,
//! `neigh[4t+f]` the face across face `f` (opposite vertex `f`) as
//! `4t'+f'`, and `region[t]` a region id. Topology (tets, neigh) never needs
//! coordinates; geometry (points) is a separate array.
//!
//! Orientation: every tet `abcd` has `orient3d(a,b,c,d) > 0`, and face `f`
//! listed by [`TET_FACES`] has its right-hand normal pointing out of the tet.
//!
//! - `build_adjacency`, `boundary_faces`: pairing faces by a sorted table,
//!   built in slices of vertex id.
//! - `check`, `check_against_surface`: all invariants, exact orientation.
//! - [`quality`]: dihedral angles, radius and mean ratio, edge length vs size.
//! - [`generate`]: structured box meshes for tests.
//! - [`Marks`]: an index set that empties in O(1), for the walks.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod adjacency;
mod angles;
mod check;
pub mod compact;
mod faces;
pub mod generate;
pub mod ids;
mod marks;
mod problem;
pub mod quality;
mod slices;
mod tetmesh;

pub use adjacency::{face_neighbours, TopoError, MAX_TETS};
pub use check::{CheckStats, SAMPLES, VOLUME_RTOL};
pub use ids::{FaceRef, PointId, TetId, NO_FACE};
pub use marks::Marks;
pub use problem::{CheckError, MeshProblem, ProblemKind};
pub use quality::{QualityReport, TetQuality};
pub use tetmesh::{TetMesh, TET_FACES};

//! The tetrahedral mesh store.
//!
//! Struct of arrays with typed `u32` ids: `tets[t]` holds four point ids,
//! `neigh[4t+f]` the face across face `f` (opposite vertex `f`) as
//! `4t'+f'`, and `region[t]` a region id. Topology (tets, neigh) never needs
//! coordinates; geometry (points) is a separate array.
//!
//! Orientation: every tet `abcd` has `orient3d(a,b,c,d) > 0`, and face `f`
//! listed by [`TET_FACES`] has its right-hand normal pointing out of the tet.

pub mod ids;
mod tetmesh;

pub use ids::{FaceRef, PointId, TetId, NO_FACE};
pub use tetmesh::{TetMesh, TET_FACES};

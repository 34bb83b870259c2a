//! What a failed check reports: each problem with the ids and coordinates
//! involved ([`MeshProblem`]), its kind, and the [`CheckError`] that keeps
//! the first [`SAMPLES`](crate::SAMPLES) of each kind and counts the rest.
use crate::ids::*;
use parafront_geom::P3;
use std::fmt;
use thiserror::Error;

/// The kinds of [`MeshProblem`], for counting and matching.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ProblemKind {
    /// See [`MeshProblem::ArrayLength`].
    ArrayLength,
    /// See [`MeshProblem::NonFinitePoint`].
    NonFinitePoint,
    /// See [`MeshProblem::PointOutOfRange`].
    PointOutOfRange,
    /// See [`MeshProblem::RepeatedVertex`].
    RepeatedVertex,
    /// See [`MeshProblem::NotPositive`].
    NotPositive,
    /// See [`MeshProblem::FaceInManyTets`].
    FaceInManyTets,
    /// See [`MeshProblem::FaceSameSide`].
    FaceSameSide,
    /// See [`MeshProblem::NeighWrong`].
    NeighWrong,
    /// See [`MeshProblem::BadInputTriangle`].
    BadInputTriangle,
    /// See [`MeshProblem::MissingBoundaryFace`].
    MissingBoundaryFace,
    /// See [`MeshProblem::ExtraBoundaryFace`].
    ExtraBoundaryFace,
    /// See [`MeshProblem::FlippedBoundaryFace`].
    FlippedBoundaryFace,
    /// See [`MeshProblem::DuplicateInputTriangle`].
    DuplicateInputTriangle,
    /// See [`MeshProblem::VolumeMismatch`].
    VolumeMismatch,
}
/// Number of kinds.
pub(crate) const NK: usize = ProblemKind::VolumeMismatch as usize + 1;

struct Pt(P3);
impl fmt::Display for Pt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {}, {})", self.0[0], self.0[1], self.0[2])
    }
}
struct Pts<'a>(&'a [P3]);
impl fmt::Display for Pts<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, p) in self.0.iter().enumerate() {
            if i > 0 {
                write!(f, " ")?;
            }
            write!(f, "{}", Pt(*p))?;
        }
        Ok(())
    }
}
fn ids<T: fmt::Display>(v: &[T]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// One thing wrong with a mesh, with the ids and coordinates involved.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum MeshProblem {
    /// A per-tet or per-face array whose length does not fit the tets.
    #[error("array {name} has length {len}, expected {expected}")]
    ArrayLength {
        /// The array's name.
        name: &'static str,
        /// Its length.
        len: usize,
        /// The length it should have.
        expected: String,
    },
    /// A point with a NaN or infinite coordinate.
    #[error("point {point} has a non-finite coordinate {}", Pt(*coords))]
    NonFinitePoint {
        /// The point.
        point: PointId,
        /// Its coordinates.
        coords: P3,
    },
    /// A tet naming a point past the end of `points`.
    #[error("tet {tet} uses point {point}, but there are only {n_points} points")]
    PointOutOfRange {
        /// The tet.
        tet: TetId,
        /// The point it names.
        point: PointId,
        /// Points in the mesh.
        n_points: usize,
    },
    /// A tet naming one point twice.
    #[error("tet {tet} repeats a vertex: ({})", ids(verts))]
    RepeatedVertex {
        /// The tet.
        tet: TetId,
        /// Its points.
        verts: [PointId; 4],
    },
    /// A tet whose exact orientation is not positive.
    #[error(
        "tet {tet} ({}) is {} (6*volume = {volume6:e}): {}",
        ids(verts), if *flat { "flat" } else { "inverted" }, Pts(coords)
    )]
    NotPositive {
        /// The tet.
        tet: TetId,
        /// Its points.
        verts: [PointId; 4],
        /// Their coordinates.
        coords: [P3; 4],
        /// Floating-point six times volume (the sign decision is exact).
        volume6: f64,
        /// Zero volume exactly, rather than negative.
        flat: bool,
    },
    /// A face in more than two tets.
    #[error("face ({}) belongs to {} tets: {}", ids(face), tets.len(), ids(tets))]
    FaceInManyTets {
        /// The face's points.
        face: [PointId; 3],
        /// The tets that have it.
        tets: Vec<TetId>,
    },
    /// Two tets on the same side of their shared face.
    #[error(
        "tets {} and {} both see face ({}) from the same side (overlap or inversion)",
        tets[0], tets[1], ids(face)
    )]
    FaceSameSide {
        /// The face's points.
        face: [PointId; 3],
        /// The two tets.
        tets: [TetId; 2],
    },
    /// A `neigh` entry that does not name the tet across the face.
    #[error(
        "neigh of face {} of tet {} ({}) is {}, expected {}",
        face.local(), face.tet(), ids(verts), fref(*found), fref(*expected)
    )]
    NeighWrong {
        /// The face.
        face: FaceRef,
        /// Its points.
        verts: [PointId; 3],
        /// What `neigh` holds.
        found: FaceRef,
        /// What it should hold.
        expected: FaceRef,
    },
    /// An input triangle that cannot be compared with the mesh.
    #[error("input triangle {tri} ({}) {why}", ids(verts))]
    BadInputTriangle {
        /// The triangle.
        tri: usize,
        /// Its points.
        verts: [u32; 3],
        /// What is wrong with it.
        why: &'static str,
    },
    /// An input triangle that is not a face of one tet on the boundary.
    #[error(
        "input triangle {tri} ({}) is not a mesh boundary face: {why}; at {}",
        ids(verts),
        Pts(coords)
    )]
    MissingBoundaryFace {
        /// The triangle.
        tri: usize,
        /// Its points.
        verts: [u32; 3],
        /// Their coordinates.
        coords: [P3; 3],
        /// Why it is not a boundary face.
        why: String,
    },
    /// A face of one tet, or between regions, that no input triangle gives.
    #[error(
        "face {} of tet {} ({}) is {} but no input triangle; at {}",
        face.local(), face.tet(), ids(verts),
        match regions { Some(r) => format!("an interface between regions {} and {}", r[0], r[1]), None => "on the boundary".into() },
        Pts(coords)
    )]
    ExtraBoundaryFace {
        /// The face.
        face: FaceRef,
        /// Its points.
        verts: [PointId; 3],
        /// Their coordinates.
        coords: [P3; 3],
        /// The two regions when the face lies between two tets.
        regions: Option<[u32; 2]>,
    },
    /// An input triangle whose mesh face is turned the other way.
    #[error(
        "input triangle {tri} ({}) is reversed: the mesh boundary face {} of tet {} is ({})",
        ids(verts), face.local(), face.tet(), ids(mesh_verts)
    )]
    FlippedBoundaryFace {
        /// The triangle.
        tri: usize,
        /// Its points.
        verts: [u32; 3],
        /// The mesh face.
        face: FaceRef,
        /// The mesh face's points, in the tet's order.
        mesh_verts: [PointId; 3],
    },
    /// Input triangles that give one face more often than it bounds tets.
    #[error(
        "input triangles {} are the same face ({}) one time too many",
        ids(tris),
        ids(verts)
    )]
    DuplicateInputTriangle {
        /// The triangles.
        tris: Vec<usize>,
        /// Their points.
        verts: [u32; 3],
    },
    /// Tet volumes that do not add up to the volume the triangles enclose.
    #[error(
        "tet volumes sum to {mesh}, but the triangles enclose {surface} (relative difference {rel:e})"
    )]
    VolumeMismatch {
        /// The tets' volume.
        mesh: f64,
        /// The volume the triangles enclose.
        surface: f64,
        /// Their relative difference.
        rel: f64,
    },
}

fn fref(f: FaceRef) -> String {
    if f.is_none() {
        "none (boundary)".into()
    } else {
        format!("face {} of tet {}", f.local(), f.tet())
    }
}

impl MeshProblem {
    /// Its [`ProblemKind`].
    pub fn kind(&self) -> ProblemKind {
        use MeshProblem as P;
        use ProblemKind as K;
        match self {
            P::ArrayLength { .. } => K::ArrayLength,
            P::NonFinitePoint { .. } => K::NonFinitePoint,
            P::PointOutOfRange { .. } => K::PointOutOfRange,
            P::RepeatedVertex { .. } => K::RepeatedVertex,
            P::NotPositive { .. } => K::NotPositive,
            P::FaceInManyTets { .. } => K::FaceInManyTets,
            P::FaceSameSide { .. } => K::FaceSameSide,
            P::NeighWrong { .. } => K::NeighWrong,
            P::BadInputTriangle { .. } => K::BadInputTriangle,
            P::MissingBoundaryFace { .. } => K::MissingBoundaryFace,
            P::ExtraBoundaryFace { .. } => K::ExtraBoundaryFace,
            P::FlippedBoundaryFace { .. } => K::FlippedBoundaryFace,
            P::DuplicateInputTriangle { .. } => K::DuplicateInputTriangle,
            P::VolumeMismatch { .. } => K::VolumeMismatch,
        }
    }
}

/// A mesh that failed its check: the first few problems of each kind, and
/// how many of each kind there were.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckError {
    /// Up to [`SAMPLES`](crate::SAMPLES) problems of each kind, in element
    /// order per kind.
    pub problems: Vec<MeshProblem>,
    /// Number of problems found, per kind, for kinds that occurred.
    pub counts: Vec<(ProblemKind, usize)>,
}

impl CheckError {
    /// How many problems of kind `k` were found.
    pub fn count(&self, k: ProblemKind) -> usize {
        self.counts
            .iter()
            .find(|c| c.0 == k)
            .map(|c| c.1)
            .unwrap_or(0)
    }
    /// The kept problems of kind `k`.
    pub fn of_kind(&self, k: ProblemKind) -> impl Iterator<Item = &MeshProblem> {
        self.problems.iter().filter(move |p| p.kind() == k)
    }
}

impl fmt::Display for CheckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let total: usize = self.counts.iter().map(|c| c.1).sum();
        write!(f, "mesh check failed with {total} problems (")?;
        for (i, (k, n)) in self.counts.iter().enumerate() {
            write!(f, "{}{n} {k:?}", if i > 0 { ", " } else { "" })?;
        }
        write!(f, ")")?;
        for p in &self.problems {
            write!(f, "\n  - {p}")?;
        }
        Ok(())
    }
}
impl std::error::Error for CheckError {}

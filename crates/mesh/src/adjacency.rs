//! Face adjacency (`neigh[4t+f]`) from the sorted face table, and the
//! boundary faces it leaves unpaired.
use crate::faces::*;
use crate::ids::*;
use crate::tetmesh::{TetMesh, TET_FACES};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering::Relaxed};
use thiserror::Error;

/// Why the tets do not form a valid face adjacency.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TopoError {
    /// More tets than face references `4t+f` can number.
    #[error("{n} tets: too many for u32 face references (at most {max})", max = MAX_TETS)]
    TooManyTets {
        /// The tets.
        n: usize,
    },
    /// A tet naming one point twice.
    #[error("tet {tet} lists point {point} twice: {verts:?}")]
    RepeatedVertex {
        /// The tet.
        tet: TetId,
        /// The point it repeats.
        point: PointId,
        /// Its points.
        verts: [PointId; 4],
    },
    /// A face in three or more tets.
    #[error(
        "face ({}, {}, {}) belongs to {} tets {:?}; a face may belong to at most two{}",
        face[0], face[1], face[2], tets.len(), tets.iter().map(|t| t.raw()).collect::<Vec<_>>(),
        more_msg(*more)
    )]
    FaceInManyTets {
        /// The face's points.
        face: [PointId; 3],
        /// The tets that have it.
        tets: Vec<TetId>,
        /// Other bad faces found besides this one.
        more: usize,
    },
    /// Two tets on the same side of their shared face.
    #[error(
        "tets {} and {} both see face ({}, {}, {}) from the same side (they overlap, or one is inverted){}",
        tets[0], tets[1], face[0], face[1], face[2], more_msg(*more)
    )]
    FaceSameSide {
        /// The face's points.
        face: [PointId; 3],
        /// The two tets.
        tets: [TetId; 2],
        /// Other bad faces found besides this one.
        more: usize,
    },
}

fn more_msg(more: usize) -> String {
    if more == 0 {
        String::new()
    } else {
        format!(" ({more} more bad faces)")
    }
}

/// The most tets whose face references `4t+f` fit below [`NO_FACE`].
pub const MAX_TETS: usize = (u32::MAX / 4) as usize;

impl TetMesh {
    /// Fills `neigh` from `tets`: faces with the same three vertices are
    /// paired, faces found once get [`NO_FACE`]. Fails, leaving `neigh`
    /// empty, when a tet repeats a vertex, a face belongs to three or more
    /// tets, or two tets see a face from the same side.
    pub fn build_adjacency(&mut self) -> Result<(), TopoError> {
        self.neigh.clear();
        self.neigh = face_neighbours(&self.tets)?;
        Ok(())
    }

    /// Faces with no tet on the other side, in tet order. Uses `neigh` when
    /// built, else pairs the faces itself (a face found once is boundary).
    pub fn boundary_faces(&self) -> Vec<FaceRef> {
        if self.neigh.len() == 4 * self.tets.len() {
            return (0..self.neigh.len())
                .into_par_iter()
                .filter(|&i| self.neigh[i].is_none())
                .map(|i| FaceRef::from_raw(i as u32))
                .collect();
        }
        let mut out: Vec<FaceRef> = Vec::new();
        for_each_key_slice(&self.tets, |keys, _| {
            out.par_extend(group_chunks(keys).par_iter().flat_map_iter(|chunk| {
                let mut v = Vec::new();
                for_each_group(chunk, |g| {
                    if g.len() == 1 {
                        v.push(FaceRef::from_raw(low(g[0])));
                    }
                });
                v
            }));
        });
        out.par_sort_unstable();
        out
    }

    /// The boundary faces as triangles, outward from the mesh.
    pub fn boundary_triangles(&self) -> Vec<[PointId; 3]> {
        self.boundary_faces()
            .par_iter()
            .map(|&f| self.face_points(f))
            .collect()
    }

    /// Point ids of face `f`, outward from its tet.
    #[inline]
    pub fn face_points(&self, f: FaceRef) -> [PointId; 3] {
        let t = &self.tets[f.tet().idx()];
        TET_FACES[f.local()].map(|l| t[l])
    }
}

/// The face neighbours of `tets`: faces with the same three vertices are
/// paired (`4t+f` across face `f`, the face opposite corner `f`), faces
/// found once get [`NO_FACE`]. Fails when a tet repeats a vertex, a face
/// belongs to three or more tets, or two tets see a face from the same
/// side. The one adjacency builder of the workspace: the mesh's and the
/// merged DDG's.
pub fn face_neighbours(tets: &[[PointId; 4]]) -> Result<Vec<FaceRef>, TopoError> {
    let n = tets.len();
    if n > MAX_TETS {
        return Err(TopoError::TooManyTets { n });
    }
    if let Some(t) = tets.par_iter().position_first(has_repeat) {
        let verts = tets[t];
        let point = (0..4)
            .find_map(|i| (0..i).find(|&j| verts[j] == verts[i]).map(|j| verts[j]))
            .unwrap_or_default();
        return Err(TopoError::RepeatedVertex {
            tet: TetId::new(t),
            point,
            verts,
        });
    }
    let neigh: Vec<AtomicU32> = (0..4 * n)
        .into_par_iter()
        .map(|_| AtomicU32::new(NO_FACE.raw()))
        .collect();
    let bad = AtomicUsize::new(0);
    // First bad group of each chunk; slices and their chunks are in key
    // order, so the reported one is the same on every run.
    let mut first_bad: Option<TopoError> = None;
    for_each_key_slice(tets, |keys, _| {
        let first = group_chunks(keys)
            .par_iter()
            .map(|chunk| {
                let mut first = None;
                for_each_group(chunk, |g| match g.len() {
                    1 => {}
                    2 => {
                        let (a, b) = (low(g[0]), low(g[1]));
                        if face_parity(tets, a) == face_parity(tets, b) {
                            bad.fetch_add(1, Relaxed);
                            first.get_or_insert_with(|| TopoError::FaceSameSide {
                                face: unpack_triple(g[0]).map(PointId::from_raw),
                                tets: [FaceRef::from_raw(a).tet(), FaceRef::from_raw(b).tet()],
                                more: 0,
                            });
                        } else {
                            neigh[a as usize].store(b, Relaxed);
                            neigh[b as usize].store(a, Relaxed);
                        }
                    }
                    _ => {
                        bad.fetch_add(1, Relaxed);
                        first.get_or_insert_with(|| TopoError::FaceInManyTets {
                            face: unpack_triple(g[0]).map(PointId::from_raw),
                            tets: g.iter().map(|&k| FaceRef::from_raw(low(k)).tet()).collect(),
                            more: 0,
                        });
                    }
                });
                first
            })
            .collect::<Vec<_>>()
            .into_iter()
            .flatten()
            .next();
        if first_bad.is_none() {
            first_bad = first;
        }
    });
    if let Some(mut e) = first_bad {
        let others = bad.into_inner() - 1;
        match &mut e {
            TopoError::FaceInManyTets { more, .. } | TopoError::FaceSameSide { more, .. } => {
                *more = others
            }
            _ => {}
        }
        return Err(e);
    }
    Ok(neigh
        .into_iter()
        .map(|a| FaceRef::from_raw(a.into_inner()))
        .collect())
}

//! Validity and the Delaunay property, checked exactly.
use crate::predicates::in_sphere_sos;
use crate::tri::{Triangulation, NONE, TET_FACES};
use parafront_geom::orient3d;

/// What [`Triangulation::check`] found wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CheckError {
    /// Live tet `.0` is not positively oriented (exactly).
    #[error("tet {0} is not positive")]
    NotPositive(u32),
    /// Face `.1` of tet `.0` links to a neighbour face that does not link back.
    #[error("tet {0} face {1}: its neighbour does not point back")]
    Asymmetric(u32, usize),
    /// Face `.1` of tet `.0` and its neighbour's face have different corners.
    #[error("tet {0} face {1}: the neighbour's face has other corners")]
    Mismatch(u32, usize),
    /// Tet `.0` links to a dead tet.
    #[error("tet {0} links to a dead tet")]
    DeadLink(u32),
    /// Face `.1` of tet `.0` is not locally Delaunay: the neighbour's apex lies
    /// inside the tet's circumsphere (under the symbolic perturbation).
    #[error("tet {0} face {1}: the neighbour's apex is inside its circumsphere")]
    NotDelaunay(u32, usize),
    /// `.0` faces have no neighbour; exactly the bounding tet's four should.
    #[error("{0} faces lie on the bounding hull, a closed hull has 4")]
    OpenHull(usize),
}

impl Triangulation {
    /// Every live tet positive under the exact predicate, adjacency
    /// symmetric, shared faces with the same corners, and only the bounding
    /// tet's four faces without a neighbour.
    pub fn check(&self) -> Result<(), CheckError> {
        let mut open = 0;
        for t in self.live_tets() {
            let p = self.tet_points(t);
            if orient3d(p[0], p[1], p[2], p[3]) <= 0.0 {
                return Err(CheckError::NotPositive(t));
            }
            let tv = self.tet(t);
            for f in 0..4 {
                let nb = self.neighbour(t, f);
                if nb == NONE {
                    open += 1;
                    continue;
                }
                let (u, g) = (nb >> 2, (nb & 3) as usize);
                if !self.is_alive(u) {
                    return Err(CheckError::DeadLink(t));
                }
                if self.neighbour(u, g) != 4 * t + f as u32 {
                    return Err(CheckError::Asymmetric(t, f));
                }
                let mut a = TET_FACES[f].map(|k| tv[k]);
                let uv = self.tet(u);
                let mut b = TET_FACES[g].map(|k| uv[k]);
                a.sort_unstable();
                b.sort_unstable();
                if a != b {
                    return Err(CheckError::Mismatch(t, f));
                }
            }
        }
        if open != 4 {
            return Err(CheckError::OpenHull(open));
        }
        Ok(())
    }

    /// Every interior face is locally Delaunay under the symbolic
    /// perturbation: no tet's neighbour has its apex inside the tet's
    /// circumsphere. Holds after insertions; flips may break it.
    pub fn check_delaunay(&self) -> Result<(), CheckError> {
        for t in self.live_tets() {
            for f in 0..4 {
                let nb = self.neighbour(t, f);
                if nb == NONE {
                    continue;
                }
                let apex = self.tet(nb >> 2)[(nb & 3) as usize];
                if in_sphere_sos(
                    self.tet(t),
                    self.tet_points(t),
                    apex,
                    self.pts[apex as usize],
                ) {
                    return Err(CheckError::NotDelaunay(t, f));
                }
            }
        }
        Ok(())
    }
}

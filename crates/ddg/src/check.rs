//! The DDG's consistency check, for the tests and debug builds: every tet
//! positive under the exact predicate, and the adjacency symmetric, each
//! link one face seen from its two sides.
use crate::Ddg;
use parafront_geom::orient3d;
use parafront_mesh::TET_FACES;

/// What [`Ddg::check`] found wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DdgCheckError {
    /// The DDG's arrays disagree in length, or a tet names a missing point.
    #[error("the DDG's arrays are inconsistent: {0}")]
    Shape(&'static str),
    /// Tet `t` is not positive.
    #[error("DDG tet {0} is not positive")]
    NotPositive(u32),
    /// Tet face `4t+f` and its neighbour do not name each other.
    #[error("DDG tet face {0} and its neighbour do not name each other")]
    Asymmetric(u32),
    /// Tet face `4t+f` and its neighbour's face are not one face turned.
    #[error("DDG tet face {0} and its neighbour's face are not one face seen from both sides")]
    Mismatch(u32),
}

impl Ddg {
    /// Check the DDG (see the module's doc).
    pub fn check(&self) -> Result<(), DdgCheckError> {
        if self.neigh.len() != 4 * self.tets.len() {
            return Err(DdgCheckError::Shape("neigh is not 4 per tet"));
        }
        let np = self.points.len();
        for (t, tv) in self.tets.iter().enumerate() {
            if tv.iter().any(|&p| p as usize >= np) {
                return Err(DdgCheckError::Shape("a tet names a missing point"));
            }
            let p = tv.map(|i| self.points[i as usize]);
            if !(orient3d(p[0], p[1], p[2], p[3]) > 0.0) {
                return Err(DdgCheckError::NotPositive(t as u32));
            }
            for f in 0..4 {
                let fr = (4 * t + f) as u32;
                let nb = self.neigh[fr as usize];
                if nb.is_none() {
                    continue;
                }
                let u = nb.tet().idx();
                if u >= self.tets.len() || self.neigh[nb.idx()].raw() != fr {
                    return Err(DdgCheckError::Asymmetric(fr));
                }
                let w = TET_FACES[f].map(|k| tv[k]);
                let x = TET_FACES[nb.local()].map(|k| self.tets[u][k]);
                let turned = [x[0], x[2], x[1]];
                let same = w == turned
                    || w == [turned[1], turned[2], turned[0]]
                    || w == [turned[2], turned[0], turned[1]];
                if !same {
                    return Err(DdgCheckError::Mismatch(fr));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_built_ddg_passes_and_each_fault_is_named() {
        let s = parafront_surface::generate::icosphere([0.0; 3], 1.0, 2);
        // The front's faces point into the region: the triangles turned.
        let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let d = crate::build(s.points.clone(), s.mean_edge_lengths(), faces, 1.6)
            .expect("the DDG of a sphere");
        assert!(d.tets.len() > 100);
        assert_eq!(d.check(), Ok(()));
        let fr = d
            .neigh
            .iter()
            .position(|n| !n.is_none())
            .expect("inner faces");
        let mut bad = d.clone();
        bad.neigh[fr] = parafront_mesh::NO_FACE;
        assert_eq!(
            bad.check(),
            Err(DdgCheckError::Asymmetric(d.neigh[fr].raw()))
        );
        let mut bad = d.clone();
        bad.tets[0].swap(0, 1);
        assert!(matches!(
            bad.check(),
            Err(DdgCheckError::NotPositive(0) | DdgCheckError::Mismatch(_))
        ));
        let mut bad = d.clone();
        bad.neigh.pop();
        assert!(matches!(bad.check(), Err(DdgCheckError::Shape(_))));
    }
}

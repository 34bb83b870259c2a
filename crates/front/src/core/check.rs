//! The front's own consistency check, run after every recovery round and
//! every fill in debug builds (so in the tests): the tets' adjacency is
//! symmetric, each live front face is the open face of the tet that owns
//! it, and the live-face count is right.
use super::*;

/// What [`Front::check`] found wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrontCheckError {
    /// Tet face `4t+f` names a dead tet, or one that does not name it back.
    #[error("tet face {0} and its neighbour do not name each other")]
    Asymmetric(u32),
    /// Tet face `4t+f` and its neighbour's face differ, or face one way.
    #[error("tet face {0} and its neighbour's face are not one face seen from both sides")]
    Mismatch(u32),
    /// Live front face `id`'s owner is dead, closed, or another face.
    #[error("front face {0} is not the open face of the tet that owns it")]
    Owner(u32),
    /// Live front faces counted, and the count the front keeps.
    #[error("{counted} live front faces, but the front counts {kept}")]
    Count { counted: usize, kept: usize },
}

impl Front<'_> {
    /// Check the front's invariants (see the module's doc).
    pub(super) fn check(&self) -> Result<(), FrontCheckError> {
        for t in 0..self.tets.len() {
            if !self.talive[t] {
                continue;
            }
            let tv = self.tets[t];
            for f in 0..4 {
                let fr = (4 * t + f) as u32;
                let nb = self.neigh[fr as usize];
                if nb == NONE {
                    continue;
                }
                let u = (nb >> 2) as usize;
                if !self.talive[u] || self.neigh[nb as usize] != fr {
                    return Err(FrontCheckError::Asymmetric(fr));
                }
                let w = TET_FACES[f].map(|k| tv[k]);
                let x = TET_FACES[(nb & 3) as usize].map(|k| self.tets[u][k]);
                if !same_cycle(w, [x[0], x[2], x[1]]) {
                    return Err(FrontCheckError::Mismatch(fr));
                }
            }
        }
        let mut counted = 0;
        for (id, face) in self.fv.iter().enumerate() {
            if !face.alive {
                continue;
            }
            counted += 1;
            let o = face.owner;
            if o == NONE {
                continue; // an input face
            }
            let t = (o >> 2) as usize;
            let ok = self.talive[t]
                && self.neigh[o as usize] == NONE
                && same_cycle(face.v, TET_FACES[(o & 3) as usize].map(|k| self.tets[t][k]));
            if !ok {
                return Err(FrontCheckError::Owner(id as u32));
            }
        }
        if counted != self.n_front {
            return Err(FrontCheckError::Count {
                counted,
                kept: self.n_front,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Everywhere, FrontInput};

    /// A unit cube's front, faces turned inward.
    fn cube() -> FrontInput {
        let points: Vec<P3> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64])
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let c = [0.5; 3];
        let faces = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .map(|[a, b, d]: [u32; 3]| {
                let p = [a, b, d].map(|i| points[i as usize]);
                if orient3d(p[0], p[1], p[2], c) > 0.0 {
                    [a, b, d]
                } else {
                    [a, d, b]
                }
            })
            .collect();
        FrontInput {
            point_size: vec![0.5; 8],
            points,
            faces,
        }
    }

    #[test]
    fn a_sound_front_passes_and_each_fault_is_named() {
        let opts = FrontOptions::default();
        let mut f = Front::new(cube(), SizeMode::Growth(1.0), &Everywhere, &opts);
        assert_eq!(f.check(), Ok(()));
        // Two tets, so that one inner face links them.
        let mut placed = 0;
        for id in 0..12 {
            if f.fv[id].alive && matches!(f.try_face(id as u32), Outcome::Placed) {
                placed += 1;
            }
            if placed == 2 {
                break;
            }
        }
        assert_eq!(placed, 2);
        assert_eq!(f.check(), Ok(()));
        let fr = (0..f.neigh.len()).find(|&i| f.neigh[i] != NONE);
        let owned = (0..f.fv.len()).find(|&i| f.fv[i].alive && f.fv[i].owner != NONE);
        // A one-sided link.
        if let Some(fr) = fr {
            let keep = f.neigh[fr];
            f.neigh[keep as usize] = NONE;
            assert_eq!(f.check(), Err(FrontCheckError::Asymmetric(fr as u32)));
            f.neigh[keep as usize] = fr as u32;
            assert_eq!(f.check(), Ok(()));
        }
        // A front face whose owner's face is closed.
        let id = owned.expect("the tets opened faces");
        let o = f.fv[id].owner;
        f.fv[id].owner = 4 * (o >> 2) + (o + 1) % 4;
        assert!(matches!(f.check(), Err(FrontCheckError::Owner(_))));
        f.fv[id].owner = o;
        // A miscount.
        f.n_front += 1;
        assert_eq!(
            f.check(),
            Err(FrontCheckError::Count {
                counted: f.n_front - 1,
                kept: f.n_front
            })
        );
    }
}

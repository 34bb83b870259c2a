//! The DDG's face neighbours, which an MPI rank lets go while its §7
//! fronts run, rebuilt from the tets when next asked. The partitions,
//! their shifts and walls (§6, §7) read them, and the point location
//! walks them where they are held; on an MPI rank they were 3.3 MB of a
//! peak set by the fronts (sphere_5e6, 4 ranks).
use crate::Ddg;
use parafront_mesh::{face_neighbours, FaceRef, PointId};
use std::ops::Deref;
use std::sync::{PoisonError, RwLock, RwLockReadGuard};

/// `neigh[4t+f]`, the tet across face `f` of tet `t` (or `NO_FACE`), as
/// held: empty once let go ([`Ddg::let_go_neigh`]).
#[derive(Debug, Default)]
pub struct Adjacency(RwLock<Vec<FaceRef>>);

impl From<Vec<FaceRef>> for Adjacency {
    fn from(neigh: Vec<FaceRef>) -> Adjacency {
        Adjacency(RwLock::new(neigh))
    }
}

impl Clone for Adjacency {
    fn clone(&self) -> Adjacency {
        Adjacency::from(self.read().clone())
    }
}

impl Adjacency {
    fn read(&self) -> RwLockReadGuard<'_, Vec<FaceRef>> {
        self.0.read().unwrap_or_else(PoisonError::into_inner)
    }

    /// The table as held, for the tests that break it.
    pub fn get_mut(&mut self) -> &mut Vec<FaceRef> {
        self.0.get_mut().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The DDG's face neighbours, held for as long as this lives:
/// [`Ddg::neigh`].
pub struct Neigh<'a>(RwLockReadGuard<'a, Vec<FaceRef>>);

impl Deref for Neigh<'_> {
    type Target = [FaceRef];
    fn deref(&self) -> &[FaceRef] {
        &self.0
    }
}

impl Ddg {
    /// The face neighbours, `neigh[4t+f]` (or `NO_FACE`); rebuilt from
    /// the tets where they were let go. The same table either way: a face
    /// of a conforming mesh has one tet on each side.
    pub fn neigh(&self) -> Neigh<'_> {
        let held = self.adjacency.read();
        if !held.is_empty() || self.tets.is_empty() {
            return Neigh(held);
        }
        drop(held);
        {
            let mut w = self
                .adjacency
                .0
                .write()
                .unwrap_or_else(PoisonError::into_inner);
            if w.is_empty() {
                let typed: &[[PointId; 4]] = bytemuck::cast_slice(&self.tets);
                *w = face_neighbours(typed).expect("the DDG's faces paired when it was built");
            }
        }
        Neigh(self.adjacency.read())
    }

    /// Frees the face neighbours until [`neigh`](Self::neigh) is next
    /// asked (the fronts then locate points without walks).
    pub fn let_go_neigh(&self) {
        let mut w = self
            .adjacency
            .0
            .write()
            .unwrap_or_else(PoisonError::into_inner);
        *w = Vec::new();
    }

    /// Whether the face neighbours are held now.
    pub fn holds_neigh(&self) -> bool {
        !self.adjacency.read().is_empty() || self.tets.is_empty()
    }
}

#[cfg(test)]
mod tests {
    /// A let-go table is rebuilt as it was, and held again until let go.
    #[test]
    fn the_neighbours_come_back_as_they_were() {
        let d = crate::ddg_of(&parafront_surface::generate::icosphere([0.0; 3], 1.0, 2));
        let before = d.neigh().to_vec();
        assert_eq!(before.len(), 4 * d.tets.len());
        assert!(d.holds_neigh());
        d.let_go_neigh();
        assert!(!d.holds_neigh());
        assert_eq!(&*d.neigh(), &before[..]);
        assert!(d.holds_neigh());
        assert_eq!(d.clone().neigh().to_vec(), before);
    }
}

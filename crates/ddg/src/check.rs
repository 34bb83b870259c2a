//! The DDG's consistency check, for the tests and debug builds: it is a
//! tet mesh, so `TetMesh::check` says whether every tet is positive under
//! the exact predicate and its `neigh` pairs each face with the one tet
//! that has it from the other side.
use crate::Ddg;
use parafront_mesh::{CheckError, PointId, TetMesh};

impl Ddg {
    /// Check the DDG (see the module's doc).
    pub fn check(&self) -> Result<(), CheckError> {
        let mesh = TetMesh {
            points: self.points.clone(),
            tets: self.tets.iter().map(|t| t.map(PointId::from_raw)).collect(),
            neigh: self.neigh().to_vec(),
            ..TetMesh::default()
        };
        mesh.check().map(|_| ())
    }
}

#[cfg(test)]
mod tests {
    use parafront_mesh::{ProblemKind, NO_FACE};

    #[test]
    fn a_built_ddg_passes_and_each_fault_is_named() {
        let d = crate::ddg_of(&parafront_surface::generate::icosphere([0.0; 3], 1.0, 2));
        assert!(d.tets.len() > 100);
        assert!(d.check().is_ok());
        let fr = d
            .neigh()
            .iter()
            .position(|n| !n.is_none())
            .expect("inner faces");
        let mut bad = d.clone();
        bad.adjacency.get_mut()[fr] = NO_FACE;
        let e = bad.check().unwrap_err();
        assert!(e.count(ProblemKind::NeighWrong) >= 1, "{e}");
        let mut bad = d.clone();
        bad.tets[0].swap(0, 1);
        let e = bad.check().unwrap_err();
        assert!(e.count(ProblemKind::NotPositive) >= 1, "{e}");
        let mut bad = d.clone();
        bad.adjacency.get_mut().pop();
        let e = bad.check().unwrap_err();
        assert!(e.count(ProblemKind::ArrayLength) >= 1, "{e}");
    }
}

//! Random closed surfaces mesh with default options (issue 20): radially
//! perturbed spheres (star-shaped), and spheres whose corners are pulled
//! onto a neighbour (needle triangles up to 1:10^5). Every one must give a
//! mesh that keeps the surface and fills it exactly.
use parafront_pipeline::{mesh_surface, LatticeMode, MeshOptions};
use parafront_surface::generate::icosphere;
use parafront_surface::validate::validate;
use parafront_surface::Surface;
use proptest::prelude::*;

fn meshes(s: &Surface) -> Result<(), TestCaseError> {
    meshes_with(s, &MeshOptions::default()).map(|_| ())
}

/// The mesh keeps the surface and fills it exactly; the tets the lattice
/// made.
fn meshes_with(s: &Surface, o: &MeshOptions) -> Result<usize, TestCaseError> {
    prop_assume!(validate(s).is_valid());
    let (m, sum) =
        mesh_surface(s, o).map_err(|e| TestCaseError::fail(format!("meshing failed: {e}")))?;
    m.check_against_surface(&s.tris)
        .map_err(|e| TestCaseError::fail(format!("invalid mesh: {e}")))?;
    let v = s.signed_volume();
    prop_assert!(
        (m.volume() - v).abs() <= 1e-9 * v.abs(),
        "volume {} of {v}",
        m.volume()
    );
    Ok(sum.lattice_tets)
}

/// Every corner of `s` (a sphere about the origin) at `radius[i]` of its
/// distance.
fn scaled(mut s: Surface, radius: &[f64]) -> Surface {
    for (i, p) in s.points.iter_mut().enumerate() {
        let r = radius[i % radius.len()];
        *p = p.map(|x| x * r);
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn random_star_shaped_surfaces_mesh(
        radius in prop::collection::vec(0.3f64..1.0, 42),
        subdiv in 1u32..4,
    ) {
        meshes(&scaled(icosphere([0.0; 3], 1.0, subdiv), &radius))?;
    }

    /// The lattice (§2) against a bumpy surface, at sizes near its
    /// edges'. (A surface much coarser than the size, or spikier, stalls
    /// the front with or without the lattice: issue 20.)
    #[test]
    fn bumpy_spheres_mesh_with_the_lattice(
        radius in prop::collection::vec(0.85f64..1.0, 42),
        h in 0.06f64..0.1,
    ) {
        let mut o = MeshOptions { lattice: LatticeMode::On, ..MeshOptions::default() };
        o.size.h = Some(h);
        let lat = meshes_with(&scaled(icosphere([0.0; 3], 1.0, 4), &radius), &o)?;
        prop_assert!(lat > 0);
    }

    /// Corners pulled to within `t` of a neighbour along their edge.
    #[test]
    fn spheres_with_needle_triangles_mesh(
        pulls in prop::collection::vec((0usize..1000, -5.0f64..-1.0), 1..8),
    ) {
        let mut s = icosphere([0.0; 3], 1.0, 1);
        for (k, e) in pulls {
            let t = s.tris[k % s.tris.len()];
            let (a, b) = (t[0] as usize, t[1] as usize);
            let f = 1.0 - 10f64.powf(e);
            let (pa, pb) = (s.points[a], s.points[b]);
            s.points[a] = [0, 1, 2].map(|i| pa[i] + f * (pb[i] - pa[i]));
        }
        meshes(&s)?;
    }
}

//! Random perturbations of a box mesh, then improvement: the result is
//! always a valid mesh of the same box, its worst tet no worse, and the
//! same input gives the same output.
use parafront_geom::{orient3d, tet_volume6, P3};
use parafront_improve::quality::quality;
use parafront_improve::{improve, ImproveOptions};
use parafront_mesh::generate::box_mesh;
use parafront_mesh::TetMesh;
use proptest::prelude::*;

fn worst(m: &TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|t| quality(t.map(|x| m.points[x.idx()])))
        .fold(f64::INFINITY, f64::min)
}

fn positive(m: &TetMesh) -> bool {
    m.tets.iter().all(|t| {
        let p = t.map(|x| m.points[x.idx()]);
        orient3d(p[0], p[1], p[2], p[3]) > 0.0 && tet_volume6(p[0], p[1], p[2], p[3]) > 0.0
    })
}

/// A 4x4x4 box with its interior points moved by `d` (in cell sizes),
/// each move kept only if no tet inverts.
fn perturbed(d: &[P3]) -> TetMesh {
    let n = 4;
    let mut m = box_mesh(n, n, n, [0.0; 3], [1.0; 3]);
    let h = 1.0 / n as f64;
    let mut k = 0;
    for p in 0..m.points.len() {
        let x = m.points[p];
        if x.iter().any(|&c| c <= 0.0 || c >= 1.0) {
            continue;
        }
        let old = x;
        let dd = d[k % d.len()];
        k += 1;
        m.points[p] = [0, 1, 2].map(|i| x[i] + h * dd[i]);
        if !positive(&m) {
            m.points[p] = old;
        }
    }
    m
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn improving_a_perturbed_box_keeps_it_valid(
        d in prop::collection::vec(prop::array::uniform3(-0.45f64..0.45), 27),
        level in 1u8..=3,
        parts in 1usize..=3,
    ) {
        let m0 = perturbed(&d);
        let tris = |m: &TetMesh| -> Vec<[u32; 3]> {
            m.bnd_tris.iter().map(|t| t.map(|p| p.raw())).collect()
        };
        m0.check_against_surface(&tris(&m0)).unwrap();
        let vol0 = 1.0;
        let mut m = m0.clone();
        let st = improve(&mut m, &[], &ImproveOptions { level, parts }).unwrap();
        m.check_against_surface(&tris(&m)).unwrap();
        prop_assert!(positive(&m));
        let vol: f64 = m.tets.iter().map(|t| {
            let p = t.map(|x| m.points[x.idx()]);
            tet_volume6(p[0], p[1], p[2], p[3]) / 6.0
        }).sum();
        prop_assert!((vol - vol0).abs() <= 1e-12 * vol0);
        prop_assert!(worst(&m) >= worst(&m0), "{} < {}", worst(&m), worst(&m0));
        // The boundary triangles are the same, point for point (ids may
        // shift when a collapse removes a point with a lower id).
        let coords = |m: &TetMesh| -> Vec<[P3; 3]> {
            m.bnd_tris.iter().map(|t| t.map(|p| m.points[p.idx()])).collect()
        };
        prop_assert_eq!(coords(&m), coords(&m0));
        prop_assert_eq!(st.tets_after, m.tets.len());
        let mut again = m0.clone();
        improve(&mut again, &[], &ImproveOptions { level, parts }).unwrap();
        prop_assert_eq!(&again.tets, &m.tets);
        prop_assert_eq!(&again.points, &m.points);
    }
}

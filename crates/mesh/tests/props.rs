//! Property tests: checks and quality under affine and similarity maps.
use parafront_geom::P3;
use parafront_mesh::generate::box_mesh_two_regions;
use parafront_mesh::quality::tet_quality;
use parafront_mesh::*;
use proptest::prelude::*;

type Mat = [[f64; 3]; 3];

fn apply(a: &Mat, t: P3, p: P3) -> P3 {
    [0, 1, 2].map(|i| a[i][0] * p[0] + a[i][1] * p[1] + a[i][2] * p[2] + t[i])
}

fn det(a: &Mat) -> f64 {
    parafront_geom::dot(a[0], parafront_geom::cross(a[1], a[2]))
}

/// A rotation from a (not necessarily unit) quaternion.
fn rotation(q: [f64; 4]) -> Mat {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|v| v / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn tris_of(m: &TetMesh) -> Vec<[u32; 3]> {
    m.bnd_tris.iter().map(|t| t.map(|p| p.raw())).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn affine_maps_keep_the_mesh_valid(
        n in (1usize..4, 1usize..4, 1usize..4),
        split in 0usize..4,
        a in prop::array::uniform3(prop::array::uniform3(-2.0f64..2.0)),
        t in prop::array::uniform3(-1e3f64..1e3),
    ) {
        // Well-conditioned maps only: rounding may not flip a tet.
        let d = det(&a);
        let fro: f64 = a.iter().flatten().map(|x| x * x).sum();
        prop_assume!(d > 0.05 * fro.powf(1.5));
        let mut m = box_mesh_two_regions(n.0, n.1, n.2, [0.0; 3], [1.0; 3], split.min(n.0));
        let before = m.check_against_surface(&tris_of(&m)).unwrap();
        for p in &mut m.points {
            *p = apply(&a, t, *p);
        }
        let s = m.check_against_surface(&tris_of(&m)).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(s.n_boundary_faces, before.n_boundary_faces);
        prop_assert!((s.volume - d).abs() < 1e-9 * d.max(1.0), "{} vs det {}", s.volume, d);
        // A reflection turns every tet inside out.
        for p in &mut m.points {
            p[0] = -p[0];
        }
        let e = m.check().unwrap_err();
        prop_assert_eq!(e.count(ProblemKind::NotPositive), m.tets.len());
    }

    #[test]
    fn quality_is_similarity_invariant(
        p in prop::array::uniform4(prop::array::uniform3(-1.0f64..1.0)),
        q in prop::array::uniform4(-1.0f64..1.0),
        s in -3.0f64..3.0,
        t in prop::array::uniform3(-100.0f64..100.0),
    ) {
        let v6 = parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]);
        prop_assume!(v6.abs() > 1e-2);
        prop_assume!(q.iter().map(|x| x * x).sum::<f64>() > 1e-3);
        let mut p = p;
        if v6 < 0.0 {
            p.swap(0, 1);
        }
        let r = rotation(q);
        let k = 10f64.powf(s);
        let a = r.map(|row| row.map(|x| x * k));
        prop_assert!(det(&a) > 0.0);
        let q0 = tet_quality(p);
        let q1 = tet_quality(p.map(|x| apply(&a, t, x)));
        let tol = 1e-7;
        prop_assert!((q0.radius_ratio - q1.radius_ratio).abs() < tol, "{:?} {:?}", q0, q1);
        prop_assert!((q0.mean_ratio - q1.mean_ratio).abs() < tol, "{:?} {:?}", q0, q1);
        prop_assert!((q0.min_dihedral - q1.min_dihedral).abs() < 1e-5, "{:?} {:?}", q0, q1);
        prop_assert!((q0.max_dihedral - q1.max_dihedral).abs() < 1e-5, "{:?} {:?}", q0, q1);
        prop_assert!((q1.volume - q0.volume * k * k * k).abs() < 1e-9 * q1.volume.abs());
        prop_assert!(q0.radius_ratio > 0.0 && q0.radius_ratio <= 1.0 + 1e-12);
        prop_assert!(q0.mean_ratio > 0.0 && q0.mean_ratio <= 1.0 + 1e-12);
    }
}

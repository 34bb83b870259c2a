//! check(), check_against_surface() and build_adjacency() on box meshes,
//! intact and corrupted in each way the checks are meant to catch.
use parafront_mesh::generate::{box_mesh, box_mesh_two_regions, INTERFACE_PATCH};
use parafront_mesh::*;

fn tris_of(m: &TetMesh) -> Vec<[u32; 3]> {
    m.bnd_tris.iter().map(|t| t.map(|p| p.raw())).collect()
}

fn unit_box(n: usize) -> TetMesh {
    box_mesh(n, n, n, [0.0; 3], [1.0; 3])
}

/// The id of the grid point (i, j, k) of an n^3 box.
fn grid_pt(n: usize, i: usize, j: usize, k: usize) -> PointId {
    PointId::new(i + (n + 1) * (j + (n + 1) * k))
}

#[test]
fn box_meshes_pass_both_checks() {
    for (nx, ny, nz) in [(1, 1, 1), (2, 3, 4), (5, 5, 5), (7, 1, 3)] {
        let (lo, hi) = ([-1.5, 2.0, 10.0], [3.0, 2.5, 17.25]);
        let m = box_mesh(nx, ny, nz, lo, hi);
        let s = m.check().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.n_tets, 6 * nx * ny * nz);
        assert_eq!(s.n_points, (nx + 1) * (ny + 1) * (nz + 1));
        assert_eq!(s.n_unused_points, 0);
        assert_eq!(s.n_regions, 1);
        assert_eq!(s.n_interface_faces, 0);
        let nb = 4 * (nx * ny + ny * nz + nx * nz);
        assert_eq!(s.n_boundary_faces, nb);
        assert_eq!(2 * s.n_interior_faces + nb, 4 * s.n_tets);
        let vol = 4.5 * 0.5 * 7.25;
        assert!((s.volume - vol).abs() < 1e-12 * vol, "{}", s.volume);
        assert!(s.min_volume > 0.0);
        assert_eq!(s.surface_volume, None);

        assert_eq!(m.bnd_tris.len(), nb);
        assert_eq!(m.bnd_patch.len(), nb);
        let s2 = m
            .check_against_surface(&tris_of(&m))
            .unwrap_or_else(|e| panic!("{e}"));
        assert!((s2.surface_volume.unwrap() - vol).abs() < 1e-12 * vol);
        // Each side gets 2 triangles per cell face, all on that side, outward.
        for p in 0..6u32 {
            let (d, top) = ((p / 2) as usize, p % 2 == 1);
            let cells = [ny * nz, nx * nz, nx * ny][d];
            let on: Vec<_> = (0..nb).filter(|&i| m.bnd_patch[i] == p).collect();
            assert_eq!(on.len(), 2 * cells, "patch {p}");
            for i in on {
                let c = m.bnd_tris[i].map(|q| m.points[q.idx()]);
                let want = if top { hi[d] } else { lo[d] };
                assert!(c.iter().all(|x| x[d] == want));
                let n = parafront_geom::tri_normal(c[0], c[1], c[2]);
                assert_eq!(n[d] > 0.0, top, "patch {p} triangle {i} not outward");
            }
        }
    }
}

#[test]
fn adjacency_is_symmetric_and_boundary_matches() {
    let m = box_mesh(3, 2, 4, [0.0; 3], [1.0; 3]);
    assert_eq!(m.neigh.len(), 4 * m.tets.len());
    for (i, &n) in m.neigh.iter().enumerate() {
        let f = FaceRef::from_raw(i as u32);
        if n.is_none() {
            continue;
        }
        assert_eq!(m.neigh[n.raw() as usize], f);
        let mut a = m.face_points(f);
        let mut b = m.face_points(n);
        b.reverse();
        a.sort();
        b.sort();
        assert_eq!(a, b);
        assert_ne!(f.tet(), n.tet());
    }
    let mut bt = m.boundary_triangles();
    let mut want = m.bnd_tris.clone();
    bt.sort();
    want.sort();
    assert_eq!(bt, want);
    // Without neigh the face table gives the same boundary.
    let mut m2 = m.clone();
    m2.neigh.clear();
    assert_eq!(m2.boundary_faces(), m.boundary_faces());
}

#[test]
fn two_region_box() {
    let m = box_mesh_two_regions(4, 2, 3, [0.0; 3], [2.0, 1.0, 1.0], 1);
    let s = m
        .check_against_surface(&tris_of(&m))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.n_regions, 2);
    assert_eq!(s.n_interface_faces, 2 * 2 * 3);
    assert!((s.volume - 2.0).abs() < 1e-12);
    assert!((s.surface_volume.unwrap() - 2.0).abs() < 1e-12);
    let iface: Vec<_> = (0..m.bnd_tris.len())
        .filter(|&i| m.bnd_patch[i] == INTERFACE_PATCH)
        .collect();
    assert_eq!(iface.len(), 12);
    for &i in &iface {
        let c = m.bnd_tris[i].map(|q| m.points[q.idx()]);
        assert!(c.iter().all(|x| x[0] == 0.5));
        assert!(parafront_geom::tri_normal(c[0], c[1], c[2])[0] > 0.0);
    }
    // Interface triangles may come in either orientation, or both.
    let mut t = tris_of(&m);
    for &i in &iface[..3] {
        t[i].swap(0, 1);
    }
    m.check_against_surface(&t)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut t2 = tris_of(&m);
    t2.extend(iface.iter().map(|&i| {
        let mut r = tris_of(&m)[i];
        r.swap(1, 2);
        r
    }));
    m.check_against_surface(&t2)
        .unwrap_or_else(|e| panic!("{e}"));
    // Dropping one is an interface face with no triangle.
    let mut t3 = tris_of(&m);
    let gone = t3.remove(iface[0]);
    let e = m.check_against_surface(&t3).unwrap_err();
    assert_eq!(e.count(ProblemKind::ExtraBoundaryFace), 1, "{e}");
    match e.of_kind(ProblemKind::ExtraBoundaryFace).next().unwrap() {
        MeshProblem::ExtraBoundaryFace { verts, regions, .. } => {
            let mut v = verts.map(|p| p.raw());
            let mut g = gone;
            v.sort();
            g.sort();
            assert_eq!(v, g);
            assert!(matches!(regions, Some(r) if r.contains(&0) && r.contains(&1)));
        }
        p => panic!("{p}"),
    }
    // Collapsing the regions makes the interface triangles interior faces.
    let mut one = m.clone();
    one.region.iter_mut().for_each(|r| *r = 0);
    let e = one.check_against_surface(&tris_of(&m)).unwrap_err();
    assert_eq!(e.count(ProblemKind::MissingBoundaryFace), 12, "{e}");
    assert!(e.to_string().contains("inside region 0"), "{e}");
}

#[test]
fn flipped_tet() {
    let mut m = unit_box(3);
    let t = 40;
    m.tets[t].swap(0, 1);
    let e = m.check().unwrap_err();
    assert_eq!(e.count(ProblemKind::NotPositive), 1, "{e}");
    match e.of_kind(ProblemKind::NotPositive).next().unwrap() {
        MeshProblem::NotPositive {
            tet, flat, coords, ..
        } => {
            assert_eq!(*tet, TetId::from_raw(t as u32));
            assert!(!flat);
            assert_eq!(*coords, m.tet_points(TetId::from_raw(t as u32)));
        }
        p => panic!("{p}"),
    }
    // Its faces are now seen from the same side as its neighbours see them.
    assert!(e.count(ProblemKind::FaceSameSide) >= 1, "{e}");
    assert!(e.to_string().contains("tet 40"), "{e}");
    assert!(m.clone().build_adjacency().is_err());
}

#[test]
fn many_flipped_tets_are_all_counted_and_some_listed() {
    let mut m = unit_box(4);
    for t in (0..m.tets.len()).step_by(37) {
        m.tets[t].swap(2, 3);
    }
    let n = m.tets.len().div_ceil(37);
    let e = m.check().unwrap_err();
    assert_eq!(e.count(ProblemKind::NotPositive), n);
    let listed: Vec<_> = e.of_kind(ProblemKind::NotPositive).collect();
    assert_eq!(listed.len(), SAMPLES);
    // The first ones, in tet order.
    for (i, p) in listed.iter().enumerate() {
        assert!(matches!(p, MeshProblem::NotPositive { tet, .. } if tet.idx() == 37 * i));
    }
}

#[test]
fn duplicated_tet() {
    let mut m = unit_box(2);
    m.neigh.clear();
    m.tets.push(m.tets[5]);
    m.region.push(0);
    let e = m.check().unwrap_err();
    // Its interior faces are in 3 tets, its boundary faces twice on one side.
    assert!(e.count(ProblemKind::FaceInManyTets) >= 1, "{e}");
    assert_eq!(
        e.count(ProblemKind::FaceInManyTets) + e.count(ProblemKind::FaceSameSide),
        4
    );
    assert_eq!(e.count(ProblemKind::NotPositive), 0);
    let r = m.clone().build_adjacency().unwrap_err();
    let s = r.to_string();
    assert!(
        s.contains("5") && s.contains(&(m.tets.len() - 1).to_string()),
        "{s}"
    );
    assert!(m.neigh.is_empty());
}

#[test]
fn missing_tet_makes_a_hole() {
    let mut m = unit_box(3);
    // Drop a tet at the box centre, away from the boundary.
    let c = grid_pt(3, 1, 1, 1);
    let t = m.tets.iter().position(|t| t[0] == c).unwrap();
    m.tets.remove(t);
    m.region.remove(t);
    // neigh no longer matches the tet count.
    let e = m.check().unwrap_err();
    assert_eq!(e.count(ProblemKind::ArrayLength), 1, "{e}");
    m.neigh.clear();
    // A mesh with a cavity is valid on its own...
    let s = m.check().unwrap();
    assert_eq!(s.n_boundary_faces, 6 * 9 * 2 + 4);
    // ...but not against the box surface.
    let e = m.check_against_surface(&tris_of(&m)).unwrap_err();
    assert_eq!(e.count(ProblemKind::ExtraBoundaryFace), 4, "{e}");
    assert_eq!(e.count(ProblemKind::VolumeMismatch), 1, "{e}");
    match e.of_kind(ProblemKind::VolumeMismatch).next().unwrap() {
        MeshProblem::VolumeMismatch { mesh, surface, .. } => {
            assert!((surface - 1.0).abs() < 1e-12);
            assert!((mesh - (1.0 - 1.0 / 27.0 / 6.0)).abs() < 1e-12);
        }
        p => panic!("{p}"),
    };
}

#[test]
fn face_in_three_tets() {
    let mut m = unit_box(2);
    // A tet on an interior face: now three tets share that face.
    let f = (0..m.neigh.len())
        .map(|i| FaceRef::from_raw(i as u32))
        .find(|&f| !m.neigh[f.raw() as usize].is_none())
        .unwrap();
    let v = m.face_points(f);
    let p = m.push_point([5.0, 5.0, 5.0]);
    let mut t = [v[0], v[1], v[2], p];
    let c = t.map(|q| m.points[q.idx()]);
    if parafront_geom::orient3d(c[0], c[1], c[2], c[3]) < 0.0 {
        t.swap(0, 1);
    }
    let nt = m.push_tet(t, 0);
    assert!(m.neigh.is_empty());
    let e = m.check().unwrap_err();
    assert_eq!(e.count(ProblemKind::FaceInManyTets), 1, "{e}");
    match e.of_kind(ProblemKind::FaceInManyTets).next().unwrap() {
        MeshProblem::FaceInManyTets { tets, face } => {
            assert_eq!(tets.len(), 3);
            assert!(tets.contains(&f.tet()) && tets.contains(&nt));
            let mut a = v;
            a.sort();
            assert_eq!(*face, a);
        }
        p => panic!("{p}"),
    }
    match m.build_adjacency() {
        Err(TopoError::FaceInManyTets { tets, .. }) => assert_eq!(tets.len(), 3),
        r => panic!("{r:?}"),
    }
}

#[test]
fn boundary_triangle_removed_reversed_or_added() {
    let m = unit_box(2);
    let tris = tris_of(&m);
    let mut t = tris.clone();
    let gone = t.remove(7);
    let e = m.check_against_surface(&t).unwrap_err();
    assert_eq!(e.count(ProblemKind::ExtraBoundaryFace), 1, "{e}");
    match e.of_kind(ProblemKind::ExtraBoundaryFace).next().unwrap() {
        MeshProblem::ExtraBoundaryFace {
            verts,
            regions,
            coords,
            ..
        } => {
            assert_eq!(verts.map(|p| p.raw()), gone);
            assert_eq!(*regions, None);
            assert_eq!(*coords, gone.map(|p| m.points[p as usize]));
        }
        p => panic!("{p}"),
    }

    let mut t = tris.clone();
    t[3].swap(0, 2);
    let e = m.check_against_surface(&t).unwrap_err();
    assert_eq!(e.count(ProblemKind::FlippedBoundaryFace), 1, "{e}");
    assert!(matches!(
        e.of_kind(ProblemKind::FlippedBoundaryFace).next().unwrap(),
        MeshProblem::FlippedBoundaryFace { tri: 3, .. }
    ));

    let mut t = tris.clone();
    t.push(tris[0]);
    let e = m.check_against_surface(&t).unwrap_err();
    assert_eq!(e.count(ProblemKind::DuplicateInputTriangle), 1, "{e}");

    // An interior face listed as boundary.
    let f = (0..m.neigh.len()).find(|&i| !m.neigh[i].is_none()).unwrap();
    let mut t = tris.clone();
    t.push(m.face_points(FaceRef::from_raw(f as u32)).map(|p| p.raw()));
    let e = m.check_against_surface(&t).unwrap_err();
    assert_eq!(e.count(ProblemKind::MissingBoundaryFace), 1, "{e}");

    // A triangle no tet has, and malformed ones.
    let mut t = tris.clone();
    t.push([0, 13, 26]);
    t.push([0, 0, 1]);
    t.push([0, 1, 99]);
    let e = m.check_against_surface(&t).unwrap_err();
    assert_eq!(e.count(ProblemKind::MissingBoundaryFace), 1, "{e}");
    assert!(e.to_string().contains("no tet has this face"), "{e}");
    assert_eq!(e.count(ProblemKind::BadInputTriangle), 2, "{e}");
}

#[test]
fn moved_point_inverts_tets_and_breaks_volume() {
    let mut m = unit_box(2);
    let c = grid_pt(2, 1, 1, 1);
    m.points[c.idx()] = [1.7, 0.5, 0.5];
    let e = m.check_against_surface(&tris_of(&m)).unwrap_err();
    let n_inv = m
        .tets
        .iter()
        .filter(|t| {
            let p = t.map(|q| m.points[q.idx()]);
            parafront_geom::orient3d(p[0], p[1], p[2], p[3]) <= 0.0
        })
        .count();
    assert!(n_inv > 0);
    assert_eq!(e.count(ProblemKind::NotPositive), n_inv, "{e}");
    // The inverted tets cover space twice: |volumes| add up to too much.
    assert_eq!(e.count(ProblemKind::VolumeMismatch), 1, "{e}");
    assert!(e.of_kind(ProblemKind::NotPositive).all(|p| match p {
        MeshProblem::NotPositive { verts, .. } => verts.contains(&c),
        _ => false,
    }));
    assert!(e.to_string().contains("1.7"), "{e}");

    // Moving the point onto a face plane of its tets makes some flat.
    let mut m = unit_box(2);
    m.points[c.idx()] = [1.0, 0.5, 0.5];
    let e = m.check().unwrap_err();
    assert!(
        e.of_kind(ProblemKind::NotPositive)
            .any(|p| matches!(p, MeshProblem::NotPositive { flat: true, .. })),
        "{e}"
    );

    // A boundary point moved outward, tets still positive: volumes agree.
    let mut m = unit_box(2);
    m.points[grid_pt(2, 2, 2, 2).idx()] = [1.2, 1.1, 1.3];
    let s = m.check_against_surface(&tris_of(&m)).unwrap();
    assert!(s.volume > 1.0);
    assert!((s.volume - s.surface_volume.unwrap()).abs() < 1e-12);
}

#[test]
fn bad_ids_nan_and_corrupt_neigh() {
    let mut m = unit_box(2);
    m.tets[3][2] = PointId::from_raw(1000);
    m.tets[4][1] = m.tets[4][0];
    m.points[0][1] = f64::NAN;
    let e = m.check().unwrap_err();
    assert_eq!(e.count(ProblemKind::PointOutOfRange), 1, "{e}");
    assert_eq!(e.count(ProblemKind::RepeatedVertex), 1, "{e}");
    assert_eq!(e.count(ProblemKind::NonFinitePoint), 1, "{e}");
    let s = e.to_string();
    assert!(s.contains("tet 3 uses point 1000"), "{s}");
    assert!(s.contains("tet 4 repeats"), "{s}");
    assert!(matches!(
        m.clone().build_adjacency(),
        Err(TopoError::RepeatedVertex { tet, .. }) if tet == TetId::new(4)
    ));

    let mut m = unit_box(2);
    let (a, b) = (1usize, 6usize);
    m.neigh.swap(a, b);
    let e = m.check().unwrap_err();
    assert!(e.count(ProblemKind::NeighWrong) >= 2, "{e}");
    assert!(e.of_kind(ProblemKind::NeighWrong).all(|p| match p {
        MeshProblem::NeighWrong { face, .. } =>
            [a, b].contains(&(face.raw() as usize)) || [a, b].iter().any(|&x| m.neigh[x] == *face),
        _ => false,
    }));

    let mut m = unit_box(1);
    m.region.pop();
    assert_eq!(m.check().unwrap_err().count(ProblemKind::ArrayLength), 1);
}

#[test]
fn empty_mesh_is_valid() {
    let mut m = TetMesh::default();
    m.build_adjacency().unwrap();
    let s = m.check_against_surface(&[]).unwrap();
    assert_eq!(s.n_tets, 0);
    assert_eq!(s.surface_volume, Some(0.0));
    assert!(m.boundary_faces().is_empty());
}

/// Process CPU seconds (Linux /proc), to time phases on a busy machine.
fn cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let f: Vec<&str> = s
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let tick = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}

/// Timing on a large box: `cargo test -p parafront-mesh --test check -- --ignored --nocapture`.
#[test]
#[ignore]
fn large_box_timing() {
    let n: usize = std::env::var("PARAFRONT_BOX_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(95);
    let time = |name: &str, f: &mut dyn FnMut()| {
        let (t, c) = (std::time::Instant::now(), cpu_s());
        f();
        println!("{name}: {:.2?} wall, {:.2} s cpu", t.elapsed(), cpu_s() - c);
    };
    let mut m = TetMesh::default();
    time("box_mesh", &mut || {
        m = box_mesh(n, n, n, [0.0; 3], [1.0; 3])
    });
    println!(
        "box {n}^3: {} tets, {} threads",
        m.tets.len(),
        rayon::current_num_threads()
    );
    time("build_adjacency", &mut || m.build_adjacency().unwrap());
    time("check", &mut || {
        m.check().unwrap();
    });
    let tris = tris_of(&m);
    time("check_against_surface", &mut || {
        m.check_against_surface(&tris).unwrap();
    });
    time("quality report", &mut || {
        quality::QualityReport::new(&m);
    });
    time("quality report with size", &mut || {
        quality::QualityReport::with_size(&m, |_| 1.0 / n as f64);
    });
    // Worst case for memory locality: points and tets in random order.
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = |k: usize| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % k as u64) as usize
    };
    let mut perm: Vec<usize> = (0..m.points.len()).collect();
    for i in (1..perm.len()).rev() {
        perm.swap(i, rnd(i + 1));
    }
    let mut pts = vec![[0.0; 3]; m.points.len()];
    for (i, &p) in perm.iter().enumerate() {
        pts[p] = m.points[i];
    }
    m.points = pts;
    for t in &mut m.tets {
        *t = t.map(|p| PointId::new(perm[p.idx()]));
    }
    for i in (1..m.tets.len()).rev() {
        m.tets.swap(i, rnd(i + 1));
    }
    m.neigh.clear();
    println!("shuffled:");
    time("build_adjacency", &mut || m.build_adjacency().unwrap());
    time("check", &mut || {
        m.check().unwrap();
    });
    time("quality report", &mut || {
        quality::QualityReport::new(&m);
    });
}

/// A box large enough that the face table is built in several slices:
/// the adjacency matches a plain pairing, and corruptions anywhere in the
/// id range are all found.
#[test]
fn large_box_across_slices_of_the_face_table() {
    use std::collections::HashMap;
    let n = 24;
    let mut m = unit_box(n);
    assert!(4 * m.tets.len() > 4 * (1 << 16));
    let s = m.check_against_surface(&tris_of(&m)).unwrap();
    assert_eq!(s.n_boundary_faces, 2 * 6 * n * n);
    assert!((s.surface_volume.unwrap() - 1.0).abs() < 1e-12);

    // build_adjacency against a hash-map pairing of the sorted triples.
    let mut by: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for i in 0..4 * m.tets.len() as u32 {
        let mut v = m.face_points(FaceRef::from_raw(i)).map(|p| p.raw());
        v.sort();
        by.entry(v).or_default().push(i);
    }
    m.build_adjacency().unwrap();
    for fs in by.values() {
        match fs[..] {
            [a] => assert!(m.neigh[a as usize].is_none()),
            [a, b] => {
                assert_eq!(m.neigh[a as usize], FaceRef::from_raw(b));
                assert_eq!(m.neigh[b as usize], FaceRef::from_raw(a));
            }
            _ => panic!("{fs:?}"),
        }
    }
    assert_eq!(m.boundary_faces().len(), 2 * 6 * n * n);

    // Input triangles dropped and flipped at both ends and the middle.
    let tris = tris_of(&m);
    let last = tris.len() - 1;
    let mut t = tris.clone();
    for i in [last, tris.len() / 2, 0] {
        t.remove(i);
    }
    let mid = t.len() / 2;
    t[mid].swap(0, 1);
    t[last - 4].swap(1, 2);
    let e = m.check_against_surface(&t).unwrap_err();
    assert_eq!(e.count(ProblemKind::ExtraBoundaryFace), 3, "{e}");
    assert_eq!(e.count(ProblemKind::FlippedBoundaryFace), 2, "{e}");
    assert_eq!(e.count(ProblemKind::VolumeMismatch), 1, "{e}");

    // Tets at both ends of the id range duplicated: each face of each in
    // three tets, or twice from one side.
    let mut d = m.clone();
    d.neigh.clear();
    for t in [0, d.tets.len() - 1] {
        d.tets.push(d.tets[t]);
        d.region.push(0);
    }
    let e = d.check().unwrap_err();
    assert_eq!(
        e.count(ProblemKind::FaceInManyTets) + e.count(ProblemKind::FaceSameSide),
        8,
        "{e}"
    );
    match d.build_adjacency() {
        Err(TopoError::FaceInManyTets { more, .. } | TopoError::FaceSameSide { more, .. }) => {
            assert_eq!(more, 7)
        }
        r => panic!("{r:?}"),
    }

    // A point id near u32::MAX: reported, and the slices' histogram does
    // not grow with it (it is counted with the largest ids).
    let mut b = m.clone();
    b.neigh.clear();
    b.tets[1000][2] = PointId::from_raw(u32::MAX - 5);
    let e = b.check().unwrap_err();
    assert_eq!(e.count(ProblemKind::PointOutOfRange), 1, "{e}");
    assert!(b.clone().build_adjacency().is_ok());
    let q = QualityReport::with_size(&b, |_| 1.0);
    assert_eq!(q.n_skipped, 1);
}

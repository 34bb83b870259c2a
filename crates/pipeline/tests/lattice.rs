//! Optimal space-filling tets (§2, issue 21): with a largest size the
//! interior is a BCC lattice and the front meshes only around it; the mesh
//! is valid, keeps the surface, does not depend on the thread count, and
//! its lattice tets are the ideal ones.
use parafront_mesh::quality::QualityReport;
use parafront_pipeline::{mesh_surface, LatticeMode, MeshOptions};
use parafront_size::SizeOptions;
use parafront_surface::{generate, Surface};

fn run(
    s: &Surface,
    h: f64,
    lattice: LatticeMode,
    threads: usize,
) -> (parafront_mesh::TetMesh, usize) {
    run_parts(s, h, lattice, threads, 1)
}

fn run_parts(
    s: &Surface,
    h: f64,
    lattice: LatticeMode,
    threads: usize,
    parts: usize,
) -> (parafront_mesh::TetMesh, usize) {
    let o = MeshOptions {
        parts,
        size: SizeOptions {
            h: Some(h),
            ..SizeOptions::default()
        },
        lattice,
        threads,
        // Inner bodies as regions: the mesh then keeps every input
        // triangle as given (the default turns them round, as voids).
        regions: true,
        ..MeshOptions::default()
    };
    let (m, sum) = mesh_surface(s, &o).unwrap_or_else(|e| panic!("meshing failed: {e}"));
    assert!(
        sum.serial_fallback.is_empty(),
        "passes given up: {:?}",
        sum.serial_fallback
    );
    m.check_against_surface(&s.tris)
        .unwrap_or_else(|e| panic!("invalid mesh: {e}"));
    assert_eq!(QualityReport::new(&m).n_inverted, 0);
    (m, sum.lattice_tets)
}

fn volume(m: &parafront_mesh::TetMesh) -> f64 {
    (0..m.tets.len())
        .map(|t| {
            let p = m.tet_points(parafront_mesh::TetId::new(t));
            parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]) / 6.0
        })
        .sum()
}

#[test]
fn a_sphere_at_a_uniform_size_is_mostly_lattice() {
    let s = generate::icosphere([0.0; 3], 1.0, 4);
    let (m, lat) = run(&s, 0.08, LatticeMode::Auto, 2);
    assert!(lat * 3 > m.tets.len(), "{lat} of {}", m.tets.len());
    // The volume is the polyhedron's, whatever the lattice took.
    let (off, none) = run(&s, 0.08, LatticeMode::Off, 2);
    assert_eq!(none, 0);
    assert!((volume(&m) - volume(&off)).abs() < 1e-9 * volume(&off));
    // Better elements than the front alone.
    let (q, qo) = (QualityReport::new(&m), QualityReport::new(&off));
    assert!(
        q.radius_ratio.mean > qo.radius_ratio.mean,
        "{} {}",
        q.radius_ratio.mean,
        qo.radius_ratio.mean
    );
    assert!(q.min_dihedral.min > 10.0, "{}", q.min_dihedral.min);
}

#[test]
fn the_lattice_mesh_does_not_depend_on_threads() {
    let s = generate::demo_part();
    let (a, la) = run(&s, 0.6, LatticeMode::On, 1);
    let (b, lb) = run(&s, 0.6, LatticeMode::On, 2);
    assert!(la > 0);
    assert_eq!(la, lb);
    assert_eq!(a.tets, b.tets);
    assert_eq!(a.points, b.points);
}

#[test]
fn auto_leaves_the_graded_default_to_the_front() {
    let s = generate::icosphere([0.0; 3], 1.0, 3);
    let (m, lat) = mesh_surface(&s, &MeshOptions::default())
        .map(|(m, s)| (m, s.lattice_tets))
        .unwrap();
    assert_eq!(lat, 0);
    assert!(!m.tets.is_empty());
}

/// The lattice fits the passes as it fits the serial front (issue 21):
/// the passes mesh the layer between it and the surface, the mesh is
/// valid, the same on any thread count, and about the serial one's size.
#[test]
fn the_passes_mesh_around_the_lattice() {
    let s = generate::icosphere([0.0; 3], 1.0, 4);
    let (serial, ls) = run(&s, 0.06, LatticeMode::Auto, 2);
    let (a, la) = run_parts(&s, 0.06, LatticeMode::Auto, 1, 4);
    let (b, lb) = run_parts(&s, 0.06, LatticeMode::Auto, 2, 4);
    assert!(la > 0 && la == ls && la == lb, "{la} {ls} {lb}");
    assert!(la * 3 > a.tets.len(), "{la} of {}", a.tets.len());
    assert_eq!(a.tets, b.tets);
    assert_eq!(a.points, b.points);
    let (n, m) = (a.tets.len() as f64, serial.tets.len() as f64);
    assert!((n - m).abs() < 0.1 * m, "{n} tets against {m} serially");
    assert!((volume(&a) - volume(&serial)).abs() < 1e-9 * volume(&serial));
    assert!(QualityReport::new(&a).min_dihedral.min > 10.0);
}

/// The summary's quality of a lattice run adds the report of the tets
/// improvement set aside to that of the others: it is the final mesh's,
/// counts and extremes exactly, means to rounding; the report before
/// improvement counts the front's mesh.
#[test]
fn the_reported_quality_is_the_meshs_own() {
    let s = generate::icosphere([0.0; 3], 1.0, 4);
    let o = MeshOptions {
        size: SizeOptions {
            h: Some(0.08),
            ..SizeOptions::default()
        },
        lattice: LatticeMode::On,
        ..MeshOptions::default()
    };
    let (m, sum) = mesh_surface(&s, &o).unwrap();
    assert!(sum.lattice_tets * 3 > m.tets.len());
    let (got, want) = (sum.quality.expect("a report"), QualityReport::new(&m));
    assert_eq!(got.n_tets, want.n_tets);
    assert_eq!(got.n_inverted, want.n_inverted);
    assert_eq!(got.dihedral_hist, want.dihedral_hist);
    assert_eq!(got.min_dihedral_hist, want.min_dihedral_hist);
    assert_eq!(got.max_dihedral_hist, want.max_dihedral_hist);
    assert_eq!(got.radius_ratio_hist, want.radius_ratio_hist);
    assert_eq!(got.mean_ratio_hist, want.mean_ratio_hist);
    assert_eq!(got.share_min_dihedral_below, want.share_min_dihedral_below);
    for (a, b) in [
        (got.min_dihedral, want.min_dihedral),
        (got.max_dihedral, want.max_dihedral),
        (got.radius_ratio, want.radius_ratio),
        (got.mean_ratio, want.mean_ratio),
    ] {
        assert_eq!((a.min, a.max, a.count), (b.min, b.max, b.count));
        assert!(
            (a.mean - b.mean).abs() <= 1e-12 * b.mean.abs(),
            "{a:?} {b:?}"
        );
    }
    let before = sum.quality_before.expect("improvement ran");
    let st = sum.improve.expect("improvement ran");
    assert_eq!(before.n_tets, st.tets_before);
    assert_eq!(before.dihedral_hist.total(), 6 * st.tets_before as u64);
}

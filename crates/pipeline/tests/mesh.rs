//! The whole pipeline on generated surfaces: the result keeps the surface,
//! fills it exactly, is deterministic, and its tets are far from flat.
use parafront_mesh::quality::QualityReport;
use parafront_pipeline::{mesh_surface, MeshOptions, Stage};
use parafront_surface::{generate, Surface};

fn mesh(s: &Surface) -> parafront_mesh::TetMesh {
    mesh_with(s, &MeshOptions::default())
}

/// Inner bodies as regions of their own (`--regions`).
fn mesh_regions(s: &Surface) -> parafront_mesh::TetMesh {
    mesh_with(
        s,
        &MeshOptions {
            regions: true,
            ..MeshOptions::default()
        },
    )
}

fn mesh_with(s: &Surface, o: &MeshOptions) -> parafront_mesh::TetMesh {
    let o = &MeshOptions {
        size_report: true,
        ..o.clone()
    };
    let (m, summary) = mesh_surface(s, o).unwrap_or_else(|e| panic!("meshing failed: {e}"));
    assert_eq!(summary.tets, m.tets.len());
    m.check_against_surface(&s.tris)
        .unwrap_or_else(|e| panic!("invalid mesh: {e}"));
    // The front never makes a tet flatter than its shape floor (mean ratio
    // 2e-3), so no tet is flat in floating point. (Only a pocket walled in
    // by close input faces may go lower; these smooth inputs have none.)
    let q = QualityReport::new(&m);
    assert_eq!(q.n_inverted, 0);
    // The summary's report is of this mesh, with edge lengths against the
    // run's size field: most edges within a factor two of it.
    let sq = summary
        .quality
        .as_ref()
        .expect("the summary has a quality report");
    assert_eq!(sq.n_tets, m.tets.len());
    assert_eq!(sq.min_dihedral.min, q.min_dihedral.min);
    assert_eq!(sq.n_inverted, 0);
    let er = sq
        .edge_ratio
        .expect("size_report: the run's size field gives edge ratios");
    assert!(er.mean > 0.5 && er.mean < 2.0, "mean edge/size {}", er.mean);
    assert!(
        q.mean_ratio.min >= 1.9e-3,
        "min mean ratio {}",
        q.mean_ratio.min
    );
    m
}

fn sphere_void_body() -> (Surface, Surface, Surface) {
    let outer = generate::icosphere([0.0; 3], 2.0, 3);
    let void = generate::icosphere([0.9, 0.0, 0.0], 0.5, 2).flipped();
    let body = generate::icosphere([-0.8, 0.2, 0.1], 0.6, 2);
    (outer, void, body)
}

#[test]
fn sphere_with_a_void_and_an_embedded_body() {
    let (mut s, void, body) = sphere_void_body();
    s.append(&void);
    s.append(&body);
    let m = mesh_regions(&s);
    let mut r = m.region.clone();
    r.sort_unstable();
    r.dedup();
    assert_eq!(r.len(), 2, "the outer material and the embedded body");
    let v = m.volume();
    assert!((v - s.signed_volume() + body.signed_volume()).abs() < 1e-9 * v);
}

#[test]
fn inner_bodies_are_voids_by_default() {
    // Without `regions` an inner shell bounds a hole whichever way it
    // faces; the mesh keeps its triangles, turned to face the hole.
    let (mut s, void, body) = sphere_void_body();
    s.append(&void);
    s.append(&body);
    let (m, sum) = mesh_surface(&s, &MeshOptions::default()).unwrap();
    assert_eq!(sum.voided_shells.len(), 1);
    assert_eq!(sum.regions, 1);
    assert!(m.region.iter().all(|&r| r == m.region[0]));
    let (mut turned, void, body) = sphere_void_body();
    turned.append(&void);
    turned.append(&body.flipped());
    m.check_against_surface(&turned.tris).unwrap();
    assert!(m.check_against_surface(&s.tris).is_err());
    let v = m.volume();
    assert!((v - turned.signed_volume()).abs() < 1e-9 * v, "{v}");
}

#[test]
fn thin_torus() {
    // A coarse tube: 2 to 3 tets across, where fronts from every side meet.
    let s = generate::torus([0.0; 3], 2.0, 0.3, 40, 8);
    mesh(&s);
}

#[test]
fn demo_part_is_deterministic() {
    let s = generate::demo_part();
    let a = mesh_regions(&s);
    let b = mesh_regions(&s);
    assert_eq!(a.tets, b.tets);
    assert_eq!(a.points, b.points);
}

/// CAD needles (fans from the plate's corners to a hole's rim, 0.3-1.4
/// degree angles): no tet on them is far from flat, so only validity and
/// the exact fill are asserted. The front of session 4 stopped on the
/// 5 x 64 plate with 338 faces stuck.
#[test]
fn needle_plates_mesh() {
    for (t, rim) in [(5.0, 64), (1.0, 128), (10.0, 32)] {
        let s = generate::needle_plate(t, rim);
        let (m, summary) = mesh_surface(&s, &MeshOptions::default())
            .unwrap_or_else(|e| panic!("plate {t} x {rim}: meshing failed: {e}"));
        m.check_against_surface(&s.tris)
            .unwrap_or_else(|e| panic!("plate {t} x {rim}: invalid mesh: {e}"));
        let v: f64 = m.volume();
        assert!(
            (v - s.signed_volume()).abs() < 1e-9 * v,
            "plate {t} x {rim}: volume {v} against {}",
            s.signed_volume()
        );
        assert_eq!(QualityReport::new(&m).n_inverted, 0);
        println!(
            "plate {t} x {rim}: {} tets, {} recovery rounds",
            m.tets.len(),
            summary.recovery_rounds
        );
    }
}

/// A thin plate would leave most of its volume to pass 4 (every wall
/// between parts crosses it): it is meshed by the serial front, so the mesh
/// is the serial one, and the summary says why. Its depth (volume over
/// area, 0.03 edges) says so before the DDG; with that test off
/// (`thin_depth: 0`), the share its passes leave says so after
/// them. A thick body keeps its passes. (At 1.0 thick, the plate's
/// pockets now close in the passes, whose fronts fill the cavities of a
/// first stall, and pass 4 gets nothing.)
#[test]
fn thin_plates_skip_the_passes() {
    let s = generate::needle_plate(0.5, 64);
    let par = MeshOptions {
        parts: 8,
        ..MeshOptions::default()
    };
    let (serial, _) = mesh_surface(&s, &MeshOptions::default()).unwrap();
    for (thin_depth, why) in [(None, "surface edges deep"), (Some(0.0), "of the volume")] {
        let o = MeshOptions {
            thin_depth: thin_depth.unwrap_or(par.thin_depth),
            ..par.clone()
        };
        let (m, summary) = mesh_surface(&s, &o).unwrap();
        m.check_against_surface(&s.tris).unwrap();
        assert_eq!(summary.serial_fallback.len(), 1, "{summary:?}");
        let msg = &summary.serial_fallback[0].1;
        assert!(msg.contains(why), "{msg}");
        assert_eq!(m.tets, serial.tets);
        assert_eq!(m.points, serial.points);
    }

    let ball = generate::icosphere([0.0; 3], 1.0, 3);
    let (m, summary) = mesh_surface(&ball, &par).unwrap();
    m.check_against_surface(&ball.tris).unwrap();
    assert!(summary.serial_fallback.is_empty());
    assert_eq!(summary.parallel.len(), 1);
}

/// `no_quality` (the benchmarks) leaves the report out, and its time too;
/// the mesh is the same.
#[test]
fn no_quality_skips_the_report_only() {
    let s = generate::icosphere([0.0; 3], 1.0, 2);
    let (m0, s0) = mesh_surface(&s, &MeshOptions::default()).unwrap();
    let o = MeshOptions {
        no_quality: true,
        ..MeshOptions::default()
    };
    let (m1, s1) = mesh_surface(&s, &o).unwrap();
    assert!(s0.quality.is_some() && s0.seconds(Stage::Quality) > 0.0);
    assert!(s1.quality.is_none());
    assert!(s1.stages.iter().all(|st| st.0 != Stage::Quality));
    assert_eq!(m0.tets, m1.tets);
    // Edge lengths against the size field only when asked, and the rest
    // of the report the same.
    let q0 = s0.quality.unwrap();
    assert!(q0.edge_ratio.is_none() && q0.edge_ratio_hist.is_none());
    let o = MeshOptions {
        size_report: true,
        ..MeshOptions::default()
    };
    let (m2, s2) = mesh_surface(&s, &o).unwrap();
    assert_eq!(m0.tets, m2.tets);
    let q2 = s2.quality.unwrap();
    let e = q2.edge_ratio.unwrap();
    assert!(
        e.count > m2.tets.len() && e.mean > 0.5 && e.mean < 2.0,
        "{e:?}"
    );
    assert_eq!(q2.edge_ratio_hist.unwrap().total() as usize, e.count);
    assert_eq!(q0.radius_ratio, q2.radius_ratio);
}

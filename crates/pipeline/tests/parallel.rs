//! `parts > 1`: the parallel mesher through the pipeline, on a part with
//! several regions (a void and an embedded body) and on a torus.
use parafront_mesh::TetId;
use parafront_pipeline::{mesh_surface, MeshOptions};
use parafront_surface::generate;

fn opts(parts: usize, h: f64) -> MeshOptions {
    // Generation only: improvement changes the mesh after the passes. No
    // lattice: its tets are in no piece (tests/lattice.rs has the passes
    // around one).
    let mut o = MeshOptions {
        parts,
        optimize: 0,
        regions: true,
        lattice: parafront_pipeline::LatticeMode::Off,
        ..MeshOptions::default()
    };
    o.size.h = Some(h);
    o
}

#[test]
fn the_demo_part_on_2_and_4_parts() {
    let s = generate::demo_part();
    let (m1, _) = mesh_surface(&s, &opts(1, 1.2)).unwrap();
    for parts in [2, 4] {
        let (m, sum) =
            mesh_surface(&s, &opts(parts, 1.2)).unwrap_or_else(|e| panic!("{parts} parts: {e}"));
        // mesh_surface checked it; check again here, independently of the flag.
        m.check_against_surface(&s.tris).unwrap();
        for t in 0..m.tets.len() {
            let p = m.tet_points(TetId::new(t));
            assert!(parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]) > 0.0);
        }
        assert_eq!(sum.parallel.len(), sum.regions);
        let made: usize = sum
            .parallel
            .iter()
            .map(|p| p.pass_tets.iter().sum::<usize>())
            .sum();
        assert_eq!(made, m.tets.len());
        assert_eq!(sum.pieces.len(), parts * sum.regions);
        let dev = (m.tets.len() as f64 / m1.tets.len() as f64 - 1.0).abs();
        assert!(
            dev < 0.10,
            "{parts} parts: {} tets, serial {}",
            m.tets.len(),
            m1.tets.len()
        );
    }
}

#[test]
fn the_threads_option_is_honoured_and_leaves_the_mesh_alone() {
    // `MeshOptions::threads` sizes the run's pool (the CLI's --threads);
    // for fixed parts the mesh is the same on any number of threads.
    let s = generate::torus([0.0; 3], 2.0, 0.7, 24, 10);
    let run = |threads: usize| {
        let o = MeshOptions {
            threads,
            ..opts(4, 0.35)
        };
        mesh_surface(&s, &o).unwrap()
    };
    let (m1, s1) = run(1);
    let (m3, s3) = run(3);
    assert_eq!((s1.threads, s3.threads), (1, 3));
    assert!(m1.tets.len() > 1000, "{} tets", m1.tets.len());
    assert_eq!(m1.tets, m3.tets);
    assert_eq!(m1.points, m3.points);
}

#[test]
fn auto_parts_follow_the_estimate_not_the_threads() {
    // `parts` auto (the default) with one part per 1,500 estimated tets:
    // the torus gets several parts, the same mesh as those parts given
    // outright, on 1 thread or 3; under a part per million tets it stays
    // serial.
    let s = generate::torus([0.0; 3], 2.0, 0.7, 24, 10);
    let run = |parts: usize, part_tets: usize, threads: usize| {
        let o = MeshOptions {
            threads,
            part_tets,
            ..opts(parts, 0.35)
        };
        mesh_surface(&s, &o).unwrap()
    };
    let (m1, s1) = run(parafront_pipeline::AUTO_PARTS, 1_500, 1);
    let (parts, estimate) = s1.auto_parts.expect("parts chosen");
    assert!(parts > 1, "{parts} parts for {estimate} tets");
    assert_eq!(parts, parafront_pipeline::auto_parts(estimate, 1_500));
    assert_eq!(s1.parallel.len(), 1);
    assert_eq!(s1.parallel[0].parts, parts);
    // The estimate is the front's count before improvement (`opts`
    // leaves it off), within half on this coarse torus (5,299 for 3,892;
    // within 2 % on sphere_1e6 and torus_1e6).
    let err = estimate / m1.tets.len() as f64 - 1.0;
    assert!(
        err.abs() < 0.5,
        "{estimate} estimated, {} made",
        m1.tets.len()
    );
    let (m3, _) = run(parafront_pipeline::AUTO_PARTS, 1_500, 3);
    assert_eq!(m1.tets, m3.tets);
    assert_eq!(m1.points, m3.points);
    let (given, sg) = run(parts, 1_500, 2);
    assert!(sg.auto_parts.is_none());
    assert_eq!(m1.tets, given.tets);
    let (serial, ss) = run(parafront_pipeline::AUTO_PARTS, 1_000_000, 2);
    assert_eq!(ss.auto_parts.map(|a| a.0), Some(1));
    assert!(ss.parallel.is_empty());
    let (one, _) = run(1, 1_500, 2);
    assert_eq!(serial.tets, one.tets);
}

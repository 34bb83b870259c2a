//! The front fills closed surfaces; the result passes the mesh check.
use parafront_front::*;
use parafront_geom::*;
use parafront_mesh::{PointId, TetMesh};
use parafront_surface::{generate, Surface};

fn fill(s: &Surface, h: f64) -> (TetMesh, FrontStats) {
    let input = FrontInput {
        points: s.points.clone(),
        point_size: s.mean_edge_lengths(),
        faces: s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect(),
    };
    let field = move |_p: P3| h;
    let r = advance(
        input,
        SizeMode::Field(&field),
        &Everywhere,
        &FrontOptions::default(),
    )
    .expect("front closes");
    assert!(r.front.is_empty());
    let mut m = TetMesh {
        points: r.points,
        tets: r.tets.iter().map(|t| t.map(PointId)).collect(),
        region: vec![0; r.tets.len()],
        ..Default::default()
    };
    m.neigh = r
        .neigh
        .iter()
        .map(|&f| parafront_mesh::FaceRef(f))
        .collect();
    let stats = m
        .check_against_surface(&s.tris)
        .unwrap_or_else(|e| panic!("invalid mesh: {e}"));
    let _ = stats;
    // The adjacency the front kept equals the one rebuilt from scratch.
    let kept = m.neigh.clone();
    m.build_adjacency().unwrap();
    assert_eq!(kept, m.neigh);
    (m, r.stats)
}

#[test]
fn fills_a_cube() {
    let s = generate::voxels([0.0; 3], 1.0, [1, 1, 1], |_, _, _| true);
    let (m, _) = fill(&s, 1.0);
    assert!(m.tets.len() >= 5, "{}", m.tets.len());
}

#[test]
fn fills_a_voxel_block() {
    let s = generate::voxels([0.0; 3], 0.25, [6, 5, 4], |i, j, _| !(i == 2 && j == 2));
    let (m, st) = fill(&s, 0.25);
    eprintln!(
        "block: {} tets, {} new points, {:?}",
        m.tets.len(),
        st.new_points,
        st
    );
}

#[test]
fn fills_an_icosphere() {
    let s = generate::icosphere([0.0; 3], 1.0, 3);
    let (m, st) = fill(&s, 0.15);
    eprintln!("sphere: {} tets, {:?}", m.tets.len(), st);
    assert!(st.new_points > 0);
}

#[test]
fn fills_a_torus() {
    let s = generate::torus([0.0; 3], 2.0, 0.6, 32, 12);
    let (m, st) = fill(&s, 0.3);
    eprintln!("torus: {} tets, {:?}", m.tets.len(), st);
}

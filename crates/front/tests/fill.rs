//! The front fills closed surfaces; the result passes the mesh check.
use parafront_front::*;
use parafront_geom::*;
use parafront_mesh::{PointId, TetMesh};
use parafront_surface::{generate, Surface};

fn fill(s: &Surface, h: f64) -> (TetMesh, FrontStats) {
    fill_with(s, h, &FrontOptions::default())
}

/// [`fill`] under `opts`.
fn fill_with(s: &Surface, h: f64, opts: &FrontOptions) -> (TetMesh, FrontStats) {
    let input = FrontInput {
        points: s.points.clone(),
        point_size: s.mean_edge_lengths(),
        faces: s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect(),
    };
    let field = move |_p: P3| h;
    let r = advance(input, SizeMode::Field(&field), &Everywhere, opts).expect("front closes");
    assert!(r.front.is_empty());
    let mut m = TetMesh {
        points: r.points,
        tets: r.tets.iter().map(|t| t.map(PointId::from_raw)).collect(),
        region: vec![0; r.tets.len()],
        ..Default::default()
    };
    m.neigh = r.neigh.clone();
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

/// §7 hand-over: a pass meshes only where x < 0.1 and returns the rest of
/// the front; a serial pass closes that front; the union is the mesh.
#[test]
fn a_pass_hands_its_front_to_the_next() {
    struct HalfSpace;
    impl RegionFilter for HalfSpace {
        fn point_ok(&self, p: P3) -> bool {
            p[0] < 0.1
        }
    }
    let s = generate::icosphere([0.0; 3], 1.0, 3);
    let field = |_p: P3| 0.15;
    let pass = FrontOptions {
        pass: true,
        ..FrontOptions::default()
    };
    // The part sees the whole front, so nothing it makes can cross a face
    // it may not advance; the filter holds those back (§7).
    let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let r1 = advance(
        FrontInput {
            points: s.points.clone(),
            point_size: s.mean_edge_lengths(),
            faces,
        },
        SizeMode::Field(&field),
        &HalfSpace,
        &pass,
    )
    .expect("an open front is allowed in a pass");
    assert!(r1.tets.len() > 100, "pass 1 made {} tets", r1.tets.len());
    for t in &r1.tets {
        for &p in t {
            assert!(r1.points[p as usize][0] < 0.1, "pass 1 left its region");
        }
    }
    let rest = r1.front.clone();
    let r2 = advance(
        FrontInput {
            points: r1.points.clone(),
            point_size: r1.point_size.clone(),
            faces: rest,
        },
        SizeMode::Field(&field),
        &Everywhere,
        &FrontOptions::default(),
    )
    .expect("the remaining front is closed and closes");
    assert!(r2.front.is_empty());
    let mut m = TetMesh {
        points: r2.points,
        tets: r1
            .tets
            .iter()
            .chain(&r2.tets)
            .map(|t| t.map(PointId::from_raw))
            .collect(),
        region: vec![0; r1.tets.len() + r2.tets.len()],
        ..Default::default()
    };
    m.build_adjacency().unwrap();
    m.check_against_surface(&s.tris)
        .unwrap_or_else(|e| panic!("invalid mesh: {e}"));
}

/// Step 5.4: a front that gives up hands back what it made, and that is
/// consistent: the tets' open faces are the input faces it never covered
/// plus exactly the faces it left in the front.
#[test]
fn a_failed_front_hands_back_its_partial_mesh() {
    let s = generate::torus([0.0; 3], 2.0, 0.6, 32, 12);
    let field = |_p: P3| 0.3;
    let opts = FrontOptions {
        recovery_rounds: 0,
        keep_partial: true,
        // The constrained fill would close it (issue 20).
        fill: false,
        ..FrontOptions::default()
    };
    let input: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let err = advance(
        FrontInput {
            points: s.points.clone(),
            point_size: s.mean_edge_lengths(),
            faces: input.clone(),
        },
        SizeMode::Field(&field),
        &Everywhere,
        &opts,
    )
    .expect_err("no recovery: this torus gets stuck in the first pass");
    let FrontError::Stuck {
        faces,
        partial: Some(p),
        ..
    } = err
    else {
        panic!("expected Stuck with a partial mesh, got {err}");
    };
    assert!(!p.tets.is_empty() && !p.front.is_empty());
    assert_eq!(p.front.len(), faces);
    let sorted = |mut f: [u32; 3]| {
        f.sort_unstable();
        f
    };
    // Faces used once by the tets, with the input faces they cover removed.
    let mut count = std::collections::HashMap::new();
    for t in &p.tets {
        for f in parafront_mesh::TET_FACES {
            *count.entry(sorted(f.map(|k| t[k]))).or_insert(0) += 1;
        }
    }
    let mut open: std::collections::HashSet<[u32; 3]> = count
        .into_iter()
        .filter(|e| e.1 == 1)
        .map(|e| e.0)
        .collect();
    let mut uncovered = Vec::new();
    for f in &input {
        if !open.remove(&sorted(*f)) {
            uncovered.push(sorted(*f));
        }
    }
    let mut expect: Vec<[u32; 3]> = open.into_iter().chain(uncovered).collect();
    let mut got: Vec<[u32; 3]> = p.front.iter().map(|f| sorted(*f)).collect();
    expect.sort_unstable();
    got.sort_unstable();
    assert_eq!(got, expect);
}

/// Issue 3's quality target before any improvement: on a smooth surface,
/// under 1 % of the tets have a dihedral angle under 10°. New points and
/// new edges keep clear of the front, so fronts meeting leave no slabs.
#[test]
fn a_smooth_sphere_has_few_slivers_before_improvement() {
    let s = generate::icosphere([0.0; 3], 1.0, 4);
    let (m, _) = fill(&s, 0.1);
    let bad = m
        .tets
        .iter()
        .filter(|t| {
            let p = t.map(|i| m.points[i.raw() as usize]);
            parafront_mesh::quality::dihedral_angles(p)
                .iter()
                .any(|&a| a < 10.0)
        })
        .count();
    let share = bad as f64 / m.tets.len() as f64;
    eprintln!("sphere: {} tets, {bad} under 10 deg", m.tets.len());
    assert!(m.tets.len() > 10_000, "{} tets", m.tets.len());
    assert!(share < 0.01, "{:.2} % of tets under 10 deg", 100.0 * share);
}

/// The hinge (a CAD part of needle triangles, 1,212 faces) under its own
/// edge lengths: the front stalls on most of its faces at once. The fill
/// at that first stall closes every cavity, so no recovery round runs;
/// without it, recovery takes rounds. Both meshes are valid.
#[test]
fn a_first_stall_on_most_faces_is_filled_without_recovery() {
    use parafront_surface::read::{read_surface_bytes, Format};
    let text = include_str!("../../delaunay/tests/data/hinge_surface.obj");
    // Its faces point inward, as the front takes them.
    let s = read_surface_bytes("hinge.obj", text.as_bytes(), Format::Obj)
        .expect("OBJ")
        .flipped();
    let stats: Vec<FrontStats> = [true, false]
        .into_iter()
        .map(|fill_at_stall| {
            let opts = FrontOptions {
                fill_at_stall,
                ..FrontOptions::default()
            };
            let (m, st) = fill_with(&s, 5.0, &opts);
            eprintln!(
                "fill at stall {fill_at_stall}: {} tets, {st:?}",
                m.tets.len()
            );
            st
        })
        .collect();
    assert_eq!(stats[0].recovery_rounds, 0, "{:?}", stats[0]);
    assert!(stats[0].cavities_filled > 0, "{:?}", stats[0]);
    assert!(stats[1].recovery_rounds > 0, "{:?}", stats[1]);
}

/// `FrontOptions::release` runs once a large front has halved, and leaves
/// the mesh as it was: a slab one cube thick, whose 81,000 faces start
/// the front over [`RELEASE_FROM`] and close as its cubes fill.
#[test]
fn the_release_hook_runs_as_a_large_front_shrinks_and_changes_nothing() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    fn count() {
        CALLS.fetch_add(1, Ordering::Relaxed);
    }
    let s = generate::voxels([0.0; 3], 1.0, [200, 100, 1], |_, _, _| true);
    assert!(s.tris.len() > 2 * RELEASE_FROM, "{}", s.tris.len());
    let (plain, _) = fill(&s, 1.0);
    let (hooked, _) = fill_with(
        &s,
        1.0,
        &FrontOptions {
            release: Some(count),
            ..FrontOptions::default()
        },
    );
    let calls = CALLS.load(Ordering::Relaxed);
    assert!((1..=8).contains(&calls), "{calls} calls");
    assert_eq!(plain.points, hooked.points);
    assert_eq!(plain.tets, hooked.tets);
}

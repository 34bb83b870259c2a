//! Each local operation of §9 on a tiny hand-built configuration: the
//! result must be a valid mesh with the same boundary and volume, and the
//! outcome the one the geometry calls for.
use parafront_geom::{orient3d, tet_volume6, P3};
use parafront_improve::quality::{min_dihedral_deg, quality};
use parafront_improve::{Improver, Outcome};
use parafront_mesh::{PointId, TetMesh};

/// A mesh from points and tets (each flipped to positive), with its
/// boundary as `bnd_tris`.
fn mesh(points: Vec<P3>, tets: &[[u32; 4]]) -> TetMesh {
    let mut m = TetMesh {
        points,
        ..Default::default()
    };
    for t in tets {
        let mut v = t.map(PointId::from_raw);
        let p = v.map(|x| m.points[x.idx()]);
        if orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
            v.swap(2, 3);
        }
        m.push_tet(v, 0);
    }
    m.build_adjacency().unwrap();
    m.bnd_tris = m.boundary_triangles();
    m.bnd_patch = vec![0; m.bnd_tris.len()];
    m
}

fn tris(m: &TetMesh) -> Vec<[u32; 3]> {
    m.bnd_tris.iter().map(|t| t.map(|p| p.raw())).collect()
}

fn worst(m: &TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|t| quality(t.map(|x| m.points[x.idx()])))
        .fold(f64::INFINITY, f64::min)
}

/// Valid, boundary as before, volume as before, every tet positive in
/// floating point too.
fn assert_same_domain(m: &TetMesh, tris: &[[u32; 3]], vol: f64) {
    m.check_against_surface(tris).unwrap();
    assert!((m.volume() - vol).abs() <= 1e-12 * vol.abs());
    for t in &m.tets {
        let p = t.map(|x| m.points[x.idx()]);
        assert!(tet_volume6(p[0], p[1], p[2], p[3]) > 0.0);
    }
}

/// Ring `n` points on the unit circle at z = 0 and the edge's ends at
/// z = -h (point n) and z = +h (point n+1): `n` tets around that edge.
fn ring_mesh(n: usize, h: f64) -> TetMesh {
    let mut pts: Vec<P3> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            // Uneven radii, so the best triangulation is unique.
            let r = 1.0 + 0.07 * (i % 3) as f64;
            [r * a.cos(), r * a.sin(), 0.0]
        })
        .collect();
    pts.push([0.0, 0.0, -h]);
    pts.push([0.0, 0.0, h]);
    let (d, e) = (n as u32, n as u32 + 1);
    let tets: Vec<[u32; 4]> = (0..n as u32)
        .map(|i| [d, e, i, (i + 1) % n as u32])
        .collect();
    mesh(pts, &tets)
}

#[test]
fn two_three_swap_of_two_flat_tets() {
    // Two flat tets on a wide triangle; the edge between the apexes
    // pierces it, so three tets around that edge are far better.
    let s = 3f64.sqrt() / 2.0;
    let pts = vec![
        [1.0, 0.0, 0.0],
        [-0.5, s, 0.0],
        [-0.5, -s, 0.0],
        [0.0, 0.0, -0.3],
        [0.0, 0.0, 0.3],
    ];
    let mut m = mesh(pts, &[[0, 1, 2, 4], [0, 2, 1, 3]]);
    let (tr, vol, q0) = (tris(&m), m.volume(), worst(&m));
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    // Tet 0's face opposite its apex (point 4).
    let f = imp.mesh().tets[0]
        .iter()
        .position(|p| p.raw() == 4)
        .unwrap();
    assert_eq!(imp.swap_face(0, f), Outcome::Done);
    imp.finish();
    assert_eq!(m.tets.len(), 3);
    assert_same_domain(&m, &tr, vol);
    assert!(worst(&m) > q0);
    // Every new tet holds the new edge 3-4.
    assert!(m
        .tets
        .iter()
        .all(|t| t.contains(&PointId::from_raw(3)) && t.contains(&PointId::from_raw(4))));
}

#[test]
fn three_two_swap_of_a_long_edge() {
    // Three tets around a long edge: two tets on the triangle are better.
    let mut m = ring_mesh(3, 1.5);
    let (tr, vol, q0) = (tris(&m), m.volume(), worst(&m));
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert_eq!(
        imp.remove_edge(0, PointId::from_raw(3), PointId::from_raw(4)),
        Outcome::Done
    );
    imp.finish();
    assert_eq!(m.tets.len(), 2);
    assert_same_domain(&m, &tr, vol);
    assert!(worst(&m) > q0);
    // And the 2-3 swap back would be worse, so it is refused.
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    let f = imp.mesh().tets[0]
        .iter()
        .position(|p| p.raw() == 3 || p.raw() == 4)
        .unwrap();
    assert_eq!(imp.swap_face(0, f), Outcome::NotBetter);
}

/// Worst quality of the best triangulation of the ring, by trying every
/// triangulation (Catalan many).
fn brute_best(pts: &[P3], n: usize, a: P3, b: P3) -> f64 {
    fn rec(pts: &[P3], a: P3, b: P3, i: usize, j: usize) -> f64 {
        if j - i < 2 {
            return f64::INFINITY;
        }
        (i + 1..j)
            .map(|k| {
                let t =
                    quality([pts[i], pts[k], pts[j], b]).min(quality([pts[i], pts[j], pts[k], a]));
                t.min(rec(pts, a, b, i, k)).min(rec(pts, a, b, k, j))
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }
    rec(pts, a, b, 0, n - 1)
}

#[test]
fn edge_removal_of_rings_of_five_and_six() {
    for n in [5, 6] {
        let mut m = ring_mesh(n, 2.0);
        let (tr, vol, q0) = (tris(&m), m.volume(), worst(&m));
        let best = brute_best(&m.points[..n], n, m.points[n], m.points[n + 1]);
        assert!(best > q0, "n={n}: the ring test case should be improvable");
        let mut imp = Improver::new(&mut m, &[]).unwrap();
        let (d, e) = (PointId::from_raw(n as u32), PointId::from_raw(n as u32 + 1));
        assert_eq!(imp.remove_edge(0, d, e), Outcome::Done, "n={n}");
        imp.finish();
        assert_eq!(m.tets.len(), 2 * n - 4, "n={n}");
        assert_same_domain(&m, &tr, vol);
        // The dynamic programme finds the optimal triangulation.
        assert!(
            (worst(&m) - best).abs() < 1e-12,
            "n={n}: {} vs {best}",
            worst(&m)
        );
        assert!(!m.tets.iter().any(|t| t.contains(&d) && t.contains(&e)));
    }
}

#[test]
fn edge_removal_refused_when_not_better() {
    // A short edge with a ring of 4: its 4 tets beat any 4 without it.
    let mut m = ring_mesh(4, 0.7);
    let before = m.tets.clone();
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert_eq!(
        imp.remove_edge(0, PointId::from_raw(4), PointId::from_raw(5)),
        Outcome::NotBetter
    );
    // A boundary edge (on the ring) is constrained.
    assert_eq!(
        imp.remove_edge(0, PointId::from_raw(0), PointId::from_raw(1)),
        Outcome::Constrained
    );
    imp.finish();
    assert_eq!(m.tets, before);
}

/// Point 0 inside a dented octahedron (the dent at point 3 pulls the
/// equator in between points 1 and 2), plus two tets filling the dent
/// outside, which join 1 and 2 by an edge around the outside of 0's ball.
fn dented_ball() -> TetMesh {
    let pts = vec![
        [0.0, 0.0, 0.0],  // 0: a, the free interior point
        [1.0, -1.0, 0.0], // 1: b
        [1.0, 1.0, 0.0],  // 2: c
        [0.3, 0.0, 0.0],  // 3: m, the dent
        [0.0, 0.0, 1.0],  // 4: top
        [0.0, 0.0, -1.0], // 5: bottom
        [-1.0, 0.0, 0.0], // 6: w
    ];
    let eq = [1, 3, 2, 6];
    let mut tets = Vec::new();
    for i in 0..4 {
        let (x, y) = (eq[i], eq[(i + 1) % 4]);
        tets.push([0, x, y, 4]);
        tets.push([0, x, y, 5]);
    }
    tets.push([1, 3, 2, 4]);
    tets.push([1, 3, 2, 5]);
    let m = mesh(pts, &tets);
    m.check().unwrap();
    m
}

#[test]
fn collapse_refused_by_the_link_condition() {
    let mut m = dented_ball();
    let before = m.clone();
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert!(imp.is_free(PointId::from_raw(0)));
    assert!(!imp.is_free(PointId::from_raw(1)));
    // 0 and 1 share the neighbour 2, but 0-1-2 is no triangle.
    assert_eq!(
        imp.collapse(PointId::from_raw(0), PointId::from_raw(1)),
        Outcome::LinkCondition
    );
    // 1 is on the boundary: it may not disappear.
    assert_eq!(
        imp.collapse(PointId::from_raw(1), PointId::from_raw(0)),
        Outcome::Frozen
    );
    imp.finish();
    assert_eq!(m.tets, before.tets);
    assert_eq!(m.points, before.points);
}

#[test]
fn collapse_of_a_point_next_to_another() {
    // A free point very close to the dent point: collapsing it onto the
    // dent point removes its bad tets.
    let mut m = dented_ball();
    m.points[0] = [0.25, 0.0, 0.0];
    m.check().unwrap();
    let (tr, vol, q0) = (tris(&m), m.volume(), worst(&m));
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert_eq!(
        imp.collapse(PointId::from_raw(0), PointId::from_raw(3)),
        Outcome::Done
    );
    imp.finish();
    // Point 0 is gone: the others move down one id.
    assert_eq!(m.points.len(), 6);
    let tr: Vec<[u32; 3]> = tr.iter().map(|t| t.map(|p| p - 1)).collect();
    assert_same_domain(&m, &tr, vol);
    assert!(worst(&m) > q0);
}

#[test]
fn move_refused_when_it_would_invert() {
    let mut m = dented_ball();
    let before = m.clone();
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    // Past the dent point: the tets on the dent would turn inside out.
    assert_eq!(
        imp.move_point(PointId::from_raw(0), [0.5, 0.0, 0.0]),
        Outcome::Inverted
    );
    // Boundary points never move.
    assert_eq!(
        imp.move_point(PointId::from_raw(4), [0.0, 0.0, 0.9]),
        Outcome::Frozen
    );
    assert_eq!(imp.smooth_point(PointId::from_raw(4)), Outcome::Frozen);
    imp.finish();
    assert_eq!(m.points, before.points);
}

#[test]
fn smoothing_raises_the_worst_tet() {
    // The free point pushed next to the top: smoothing pulls it back.
    let mut m = dented_ball();
    m.points[0] = [-0.05, 0.0, 0.9];
    m.check().unwrap();
    let (tr, vol, q0) = (tris(&m), m.volume(), worst(&m));
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert_eq!(imp.smooth_point(PointId::from_raw(0)), Outcome::Done);
    imp.finish();
    assert_same_domain(&m, &tr, vol);
    assert!(worst(&m) > q0);
    assert!(m.points[0][2] < 0.9);
}

fn min_dihedral(m: &TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|t| min_dihedral_deg(t.map(|x| m.points[x.idx()])))
        .fold(f64::INFINITY, f64::min)
}

fn under_10(m: &TetMesh) -> usize {
    m.tets
        .iter()
        .filter(|t| min_dihedral_deg(t.map(|x| m.points[x.idx()])) < 10.0)
        .count()
}

/// Three tets from the tray (issue 5), shifted: the foot of a 3.175 high
/// wall (points 0, 4, 5 at y = 0, 1, 2 at the top) and a point 12 away on
/// the top face. Every tet is under 10° and no swap helps; one new point
/// near the short edges gives tets that are all over 10°.
fn wall_foot() -> TetMesh {
    let pts = vec![
        [0.0, 0.0, 0.0],
        [-0.3068, 3.175, 0.3068],
        [0.0, 3.175, 0.0],
        [-5.0453, 3.175, -10.69362],
        [0.3554, 0.0, -0.24888],
        [-0.3068, 0.0, 0.3068],
    ];
    mesh(pts, &[[0, 1, 2, 3], [4, 2, 3, 0], [0, 5, 1, 3]])
}

#[test]
fn insertion_of_a_point_at_a_wall_foot() {
    let mut m = wall_foot();
    let (tr, vol, d0) = (tris(&m), m.volume(), min_dihedral(&m));
    assert_eq!(under_10(&m), 3);
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    // The three share edge 0-3; neither its removal nor a face swap helps.
    assert_ne!(
        imp.remove_edge(0, PointId::from_raw(0), PointId::from_raw(3)),
        Outcome::Done
    );
    for t in 0..3 {
        for f in 0..4 {
            assert_ne!(imp.swap_face(t, f), Outcome::Done);
        }
    }
    assert_eq!(imp.insert_point(0, false), Outcome::Done);
    assert!(imp.is_free(PointId::from_raw(6)));
    imp.finish();
    m.check().unwrap();
    // The same boundary (every old point is on it), one more point.
    assert_same_domain(&m, &tr, vol);
    assert_eq!(m.points.len(), 7);
    assert!(m.tets.iter().all(|t| t.contains(&PointId::from_raw(6))));
    assert_eq!(under_10(&m), 0);
    assert!(min_dihedral(&m) > d0);
}

#[test]
fn insertion_refused_when_nothing_gets_better() {
    // The regular-ish tets of a ring: none under 10°, nothing to gain.
    let mut m = ring_mesh(5, 1.0);
    assert_eq!(under_10(&m), 0);
    let before = m.clone();
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert_eq!(imp.insert_point(0, false), Outcome::NotBetter);
    assert_eq!(imp.insert_point(99, false), Outcome::NotFound);
    imp.finish();
    assert_eq!(m.tets, before.tets);
    assert_eq!(m.points, before.points);
}

#[test]
fn swap_for_the_dihedral_angles() {
    // Two flat tets on a wide triangle, both under 10°: the 2-3 swap
    // leaves none under 10°.
    let s = 3f64.sqrt() / 2.0;
    let pts = vec![
        [1.0, 0.0, 0.0],
        [-0.5, s, 0.0],
        [-0.5, -s, 0.0],
        [0.0, 0.0, -0.06],
        [0.0, 0.0, 0.06],
    ];
    let mut m = mesh(pts, &[[0, 1, 2, 4], [0, 2, 1, 3]]);
    let (tr, vol, d0) = (tris(&m), m.volume(), min_dihedral(&m));
    assert_eq!(under_10(&m), 2);
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert_eq!(imp.swap_for_dihedral(0), Outcome::Done);
    // Now nothing under 10° is left around tet 0.
    assert_eq!(imp.swap_for_dihedral(0), Outcome::NotBetter);
    imp.finish();
    m.check().unwrap();
    assert_eq!(m.tets.len(), 3);
    assert_same_domain(&m, &tr, vol);
    assert_eq!(under_10(&m), 0);
    assert!(min_dihedral(&m) > d0);
}

#[test]
fn swap_that_lifts_the_min_dihedral() {
    // Two tets on a wide triangle at about 17°, none under 10°: the count
    // swap has nothing to do, the lift swap makes the three tets around
    // the apexes' edge, whose min dihedral is higher; then nothing lifts.
    let s = 3f64.sqrt() / 2.0;
    let pts = vec![
        [1.0, 0.0, 0.0],
        [-0.5, s, 0.0],
        [-0.5, -s, 0.0],
        [0.0, 0.0, -0.15],
        [0.0, 0.0, 0.15],
    ];
    let mut m = mesh(pts, &[[0, 1, 2, 4], [0, 2, 1, 3]]);
    let (tr, vol, d0) = (tris(&m), m.volume(), min_dihedral(&m));
    assert_eq!(under_10(&m), 0);
    assert!(d0 < 18.0, "{d0}");
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    assert_eq!(imp.swap_for_dihedral(0), Outcome::NotBetter);
    assert_eq!(imp.swap_for_min_dihedral(0), Outcome::Done);
    assert_eq!(imp.swap_for_min_dihedral(0), Outcome::NotBetter);
    assert_eq!(imp.swap_for_min_dihedral(99), Outcome::NotFound);
    imp.finish();
    m.check().unwrap();
    assert_eq!(m.tets.len(), 3);
    assert_same_domain(&m, &tr, vol);
    assert!(
        min_dihedral(&m) > d0 + 1.0,
        "{} against {d0}",
        min_dihedral(&m)
    );
}

/// Point 0 inside an octahedron (points 1-6 at +-1 on the axes): the
/// eight tets of its ball.
fn octahedron_ball(c: P3) -> TetMesh {
    let mut pts = vec![c];
    for k in 0..3 {
        for s in [1.0, -1.0] {
            let mut p = [0.0; 3];
            p[k] = s;
            pts.push(p);
        }
    }
    let mut tets = Vec::new();
    for x in [1, 2] {
        for y in [3, 4] {
            for z in [5, 6] {
                tets.push([0, x, y, z]);
            }
        }
    }
    mesh(pts, &tets)
}

#[test]
fn lift_moves_the_free_point_of_a_tet_no_swap_or_point_lifts() {
    // Off centre, the ball's worst tet is at about 14°, none under 10°:
    // no swap or new point lifts it, but moving the point back does.
    let mut m = octahedron_ball([0.25, 0.25, 0.3]);
    let (tr, vol, d0) = (tris(&m), m.volume(), min_dihedral(&m));
    assert!(d0 > 10.0 && d0 < 15.0, "{d0}");
    let mut imp = Improver::new(&mut m, &[]).unwrap();
    let st = imp.lift_worst();
    imp.finish();
    assert_eq!((st.swap.done, st.insert.done), (0, 0));
    assert!(st.selective.done >= 1);
    assert_eq!((m.tets.len(), m.points.len()), (8, 7));
    assert_same_domain(&m, &tr, vol);
    // The centre's ball is eight tets of 54.7° at best.
    assert!(min_dihedral(&m) > 50.0, "{}", min_dihedral(&m));
    assert!(
        m.points[0].iter().all(|x| x.abs() < 0.05),
        "{:?}",
        m.points[0]
    );
}

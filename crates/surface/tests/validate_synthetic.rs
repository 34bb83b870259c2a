//! `validate` on surfaces built here: valid shapes and nestings, and one
//! broken variant per defect class, checking class, count and ids.
use parafront_surface::validate::{regions, shells, validate, Class, Item, Region, ShellKind};
use parafront_surface::Surface;

type P3 = [f64; 3];

fn surf(points: Vec<P3>, tris: Vec<[u32; 3]>) -> Surface {
    Surface::one_patch(points, tris)
}

fn merge(parts: &[Surface]) -> Surface {
    let mut s = surf(Vec::new(), Vec::new());
    for p in parts {
        let off = s.points.len() as u32;
        s.points.extend_from_slice(&p.points);
        s.tris.extend(p.tris.iter().map(|t| t.map(|v| v + off)));
        s.patch.extend_from_slice(&p.patch);
    }
    s
}

fn flip(mut s: Surface) -> Surface {
    for t in &mut s.tris {
        t.swap(1, 2);
    }
    s
}

/// Axis-aligned cube, outward; vertex `x + 2y + 4z` is corner (x, y, z).
fn cube(lo: P3, h: f64) -> Surface {
    let points = (0..8)
        .map(|i| [0, 1, 2].map(|k| lo[k] + h * ((i >> k) & 1) as f64))
        .collect();
    let quads = [
        [0, 2, 3, 1], // z = lo
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let tris = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    surf(points, tris)
}

use parafront_surface::generate::icosphere;

fn torus(rr: f64, r: f64, n: u32, m: u32) -> Surface {
    let mut pts = Vec::new();
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for j in 0..m {
            let v = std::f64::consts::TAU * j as f64 / m as f64;
            let w = rr + r * v.cos();
            pts.push([w * u.cos(), w * u.sin(), r * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    let s = surf(pts, tris);
    if s.signed_volume() < 0.0 {
        flip(s)
    } else {
        s
    }
}

fn classes(r: &parafront_surface::validate::Report) -> Vec<Class> {
    r.problems.iter().map(|p| p.class).collect()
}

#[test]
fn builders_are_outward() {
    assert!((cube([0.0; 3], 2.0).signed_volume() - 8.0).abs() < 1e-12);
    assert!(icosphere([0.0; 3], 1.0, 2).signed_volume() > 4.0);
    assert!(torus(2.0, 0.5, 24, 12).signed_volume() > 9.0);
}

#[test]
fn valid_single_shells() {
    for s in [
        cube([0.0; 3], 1.0),
        icosphere([1.0, 2.0, 3.0], 2.0, 3),
        torus(2.0, 0.5, 32, 16),
    ] {
        let r = validate(&s);
        assert!(r.is_valid(), "{r}");
        assert!(r.problems.is_empty(), "{r}");
        assert_eq!(r.shells.len(), 1);
        let sh = &r.shells[0];
        assert_eq!(sh.tris.len(), s.tris.len());
        assert_eq!((sh.depth, sh.parent, sh.kind), (0, None, ShellKind::Outer));
        assert!((sh.volume - s.signed_volume()).abs() < 1e-9 * sh.volume.abs());
        assert!(r.to_string().contains("valid"));
    }
}

#[test]
fn nested_cubes_void_and_inner_body() {
    let s = merge(&[
        cube([0.0; 3], 4.0),
        flip(cube([1.0; 3], 2.0)),
        cube([1.5; 3], 1.0),
    ]);
    let r = validate(&s);
    assert!(r.is_valid(), "{r}");
    let got: Vec<_> = r
        .shells
        .iter()
        .map(|sh| (sh.tris[0], sh.depth, sh.parent, sh.kind))
        .collect();
    assert_eq!(
        got,
        vec![
            (0, 0, None, ShellKind::Outer),
            (12, 1, Some(0), ShellKind::Void),
            (24, 2, Some(1), ShellKind::Inner),
        ]
    );
    assert!((r.shells[1].volume + 8.0).abs() < 1e-12);
    assert_eq!(shells(&s), r.shells);
    assert_eq!(
        regions(&r.shells),
        vec![
            Region {
                outer: 0,
                voids: vec![1]
            },
            Region {
                outer: 2,
                voids: vec![]
            }
        ]
    );
}

#[test]
fn sphere_with_two_voids_and_a_separate_body() {
    let s = merge(&[
        icosphere([0.0; 3], 3.0, 3),
        flip(icosphere([1.0, 0.0, 0.0], 0.5, 2)),
        flip(icosphere([-1.0, 0.3, 0.2], 0.7, 2)),
        torus(2.0, 0.5, 24, 12),
    ]);
    // Move the torus out of the sphere: a separate outer shell.
    let mut s = s;
    let first_torus = s.points.len() - 24 * 12;
    for p in &mut s.points[first_torus..] {
        p[2] += 10.0;
    }
    let r = validate(&s);
    assert!(r.is_valid(), "{r}");
    let kinds: Vec<_> = r.shells.iter().map(|sh| (sh.depth, sh.kind)).collect();
    assert_eq!(
        kinds,
        vec![
            (0, ShellKind::Outer),
            (1, ShellKind::Void),
            (1, ShellKind::Void),
            (0, ShellKind::Outer)
        ]
    );
    assert_eq!(r.shells[1].parent, Some(0));
    assert_eq!(r.shells[2].parent, Some(0));
    assert_eq!(regions(&r.shells).len(), 2);
    assert_eq!(regions(&r.shells)[0].voids, vec![1, 2]);
}

#[test]
fn open_surface() {
    let mut s = cube([0.0; 3], 1.0);
    s.tris.remove(0); // [0, 2, 3]
    s.patch.pop();
    let r = validate(&s);
    assert!(!r.is_valid());
    assert_eq!(classes(&r), vec![Class::OpenEdge]);
    let p = r.problem(Class::OpenEdge).unwrap();
    assert_eq!(p.count, 3);
    let mut edges: Vec<[u32; 2]> = p
        .examples
        .iter()
        .map(|e| match e {
            Item::Edge { v, tris, .. } => {
                assert_eq!(tris.len(), 1);
                *v
            }
            _ => panic!("not an edge"),
        })
        .collect();
    edges.sort();
    assert_eq!(edges, vec![[0, 2], [0, 3], [2, 3]]);
    assert_eq!(r.shells[0].kind, ShellKind::NotClosed);
    let text = r.to_string();
    assert!(text.contains("open (boundary) edges"), "{text}");
    assert!(text.contains("edge 0-2 (0, 0, 0) (0, 1, 0)"), "{text}");
}

#[test]
fn one_flipped_triangle() {
    let mut s = cube([0.0; 3], 1.0);
    s.tris[4].swap(1, 2); // [0, 1, 5] -> [0, 5, 1]
    let r = validate(&s);
    assert_eq!(classes(&r), vec![Class::InconsistentEdge]);
    let p = r.problem(Class::InconsistentEdge).unwrap();
    assert_eq!(p.count, 3);
    for e in &p.examples {
        let Item::Edge { tris, .. } = e else {
            panic!("not an edge")
        };
        assert!(tris.contains(&4), "{tris:?}");
    }
}

#[test]
fn duplicate_triangle() {
    let mut s = cube([0.0; 3], 1.0);
    s.tris.push([3, 0, 2]); // same set as triangle 0
    s.patch.push(0);
    let r = validate(&s);
    assert_eq!(
        classes(&r),
        vec![Class::NonManifoldEdge, Class::DuplicateTriangle]
    );
    let p = r.problem(Class::DuplicateTriangle).unwrap();
    assert_eq!(p.count, 1);
    assert!(matches!(p.examples[0], Item::TriPair { t: [0, 12], .. }));
    assert_eq!(r.count(Class::NonManifoldEdge), 3);
}

#[test]
fn pinched_vertex_two_cubes_at_a_corner() {
    let mut s = merge(&[cube([0.0; 3], 1.0), cube([1.0; 3], 1.0)]);
    // Weld the second cube's corner 0 (= (1,1,1)) onto the first's vertex 7.
    for t in &mut s.tris[12..] {
        for v in t.iter_mut() {
            if *v == 8 {
                *v = 7;
            }
        }
    }
    let r = validate(&s);
    assert_eq!(
        classes(&r),
        vec![Class::PinchedVertex, Class::UnreferencedVertex]
    );
    let p = r.problem(Class::PinchedVertex).unwrap();
    assert_eq!(p.count, 1);
    assert_eq!(
        p.examples[0],
        Item::Vertex {
            v: 7,
            p: [1.0; 3],
            fans: 2
        }
    );
    assert_eq!(r.count(Class::UnreferencedVertex), 1);
    assert_eq!(r.shells.len(), 2);
}

#[test]
fn non_manifold_edge_two_cubes_on_an_edge() {
    let mut s = merge(&[cube([0.0; 3], 1.0), cube([1.0, 1.0, 0.0], 1.0)]);
    // Second cube's corners (1,1,0) and (1,1,1) are ids 8 and 12: weld onto 3, 7.
    for t in &mut s.tris[12..] {
        for v in t.iter_mut() {
            *v = match *v {
                8 => 3,
                12 => 7,
                x => x,
            };
        }
    }
    let r = validate(&s);
    assert_eq!(
        classes(&r),
        vec![Class::NonManifoldEdge, Class::UnreferencedVertex]
    );
    let p = r.problem(Class::NonManifoldEdge).unwrap();
    assert_eq!(p.count, 1);
    let Item::Edge { v, tris, .. } = &p.examples[0] else {
        panic!()
    };
    assert_eq!((*v, tris.len()), ([3, 7], 4));
    assert_eq!(r.shells.len(), 1);
    assert_eq!(r.shells[0].kind, ShellKind::NotClosed);
}

fn tet(a: P3, b: P3, c: P3, d: P3) -> Surface {
    surf(
        vec![a, b, c, d],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

#[test]
fn zero_area_in_a_closed_surface() {
    // Tet with edge ab split by m on one side only, closed by the flat
    // triangle (a, m, b).
    let pts = vec![
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        [0.0, 0.0, 2.0],
        [1.0, 0.0, 0.0],
    ];
    let (a, b, c, d, m) = (0, 1, 2, 3, 4);
    let s = surf(
        pts,
        vec![
            [a, c, m],
            [m, c, b],
            [a, b, d],
            [a, d, c],
            [b, c, d],
            [a, m, b],
        ],
    );
    let r = validate(&s);
    let p = r.problem(Class::ZeroArea).unwrap();
    assert_eq!(p.count, 1);
    assert!(matches!(p.examples[0], Item::Tri { t: 5, .. }));
    // The split leaves T-junctions: [a,c,m] and [m,c,b] lie along [a,b,d]'s
    // edge ab, which is more than a shared vertex.
    let si = r.problem(Class::SelfIntersection).unwrap();
    assert_eq!(si.count, 2);
    let pairs: Vec<[u32; 2]> = si
        .examples
        .iter()
        .map(|e| match e {
            Item::TriPair { t, .. } => *t,
            _ => panic!(),
        })
        .collect();
    assert_eq!(pairs, vec![[0, 2], [1, 2]]);
    assert_eq!(
        r.count(Class::OpenEdge) + r.count(Class::InconsistentEdge),
        0
    );

    // Repeated vertex ids.
    let mut s = cube([0.0; 3], 1.0);
    s.tris.push([5, 5, 6]);
    let r = validate(&s);
    let p = r.problem(Class::ZeroArea).unwrap();
    assert_eq!(p.count, 1);
    assert!(matches!(
        p.examples[0],
        Item::Tri {
            t: 12,
            v: [5, 5, 6],
            ..
        }
    ));
}

#[test]
fn self_intersecting_tets() {
    let big = tet(
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [0.0, 4.0, 0.0],
        [0.0, 0.0, 4.0],
    );
    // Apex inside the big tet, base below its bottom face.
    let small = surf(
        vec![
            [0.5, 0.5, -1.0],
            [2.0, 0.5, -1.0],
            [0.5, 2.0, -1.0],
            [1.0, 1.0, 0.5],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    assert!(big.signed_volume() > 0.0 && small.signed_volume() > 0.0);
    let s = merge(&[big, small]);
    let r = validate(&s);
    assert_eq!(classes(&r), vec![Class::SelfIntersection]);
    let p = r.problem(Class::SelfIntersection).unwrap();
    assert_eq!(p.count, 3);
    let pairs: Vec<[u32; 2]> = p
        .examples
        .iter()
        .map(|e| match e {
            Item::TriPair { t, .. } => *t,
            _ => panic!(),
        })
        .collect();
    assert_eq!(pairs, vec![[0, 5], [0, 6], [0, 7]]);
    assert!(r.to_string().contains("triangles 0 [0, 2, 1] and 5"));
}

#[test]
fn coplanar_overlap_is_a_self_intersection() {
    // Two unit cubes offset by half along x: their z = 0 faces overlap in
    // the plane, and side faces cut through each other.
    let s = merge(&[cube([0.0; 3], 1.0), cube([0.5, 0.0, 0.0], 1.0)]);
    let r = validate(&s);
    assert!(r.count(Class::SelfIntersection) > 0);
    let p = r.problem(Class::SelfIntersection).unwrap();
    // Bottom faces (tris 0,1 and 12,13) overlap in the plane z = 0.
    assert!(p
        .examples
        .iter()
        .any(|e| matches!(e, Item::TriPair { t: [0, 12], .. })
            || matches!(e, Item::TriPair { t: [0, 13], .. })
            || matches!(e, Item::TriPair { t: [1, 12], .. })
            || matches!(e, Item::TriPair { t: [1, 13], .. })));
}

#[test]
fn inside_out_and_wrongly_oriented_void() {
    let r = validate(&flip(cube([0.0; 3], 1.0)));
    assert_eq!(classes(&r), vec![Class::WrongShellOrientation]);
    let p = r.problem(Class::WrongShellOrientation).unwrap();
    assert_eq!(p.count, 1);
    let Item::Shell {
        shell,
        first_tri,
        volume,
        depth,
    } = p.examples[0]
    else {
        panic!()
    };
    assert_eq!((shell, first_tri, depth), (0, 0, 0));
    assert!((volume + 1.0).abs() < 1e-12);
    assert!(r.to_string().contains("inside-out"));

    // A body with outward normals inside material is an embedded body.
    let s = merge(&[cube([0.0; 3], 4.0), cube([1.0; 3], 2.0)]);
    let r = validate(&s);
    assert!(r.is_valid(), "{r}");
    assert_eq!(r.shells[1].kind, ShellKind::Inner);

    // A cavity inside a cavity is inside-out.
    let s = merge(&[
        cube([0.0; 3], 4.0),
        flip(cube([1.0; 3], 2.0)),
        flip(cube([1.5; 3], 1.0)),
    ]);
    let r = validate(&s);
    let p = r.problem(Class::WrongShellOrientation).unwrap();
    assert_eq!(p.count, 1);
    assert!(matches!(
        p.examples[0],
        Item::Shell {
            shell: 2,
            first_tri: 24,
            depth: 2,
            ..
        }
    ));
}

#[test]
fn unreferenced_vertex_is_a_warning() {
    let mut s = cube([0.0; 3], 1.0);
    s.points.push([9.0, 9.0, 9.0]);
    let r = validate(&s);
    assert!(r.is_valid());
    assert_eq!(classes(&r), vec![Class::UnreferencedVertex]);
    assert!(matches!(
        r.problem(Class::UnreferencedVertex).unwrap().examples[0],
        Item::Vertex { v: 8, .. }
    ));
    assert!(r.to_string().contains("warning"));
}

#[test]
fn bad_input_does_not_panic() {
    let mut s = cube([0.0; 3], 1.0);
    s.tris.push([0, 1, 99]);
    let r = validate(&s);
    assert_eq!(classes(&r), vec![Class::BadIndex]);
    assert!(shells(&s).is_empty());

    let mut s = cube([0.0; 3], 1.0);
    s.points[3][1] = f64::NAN;
    let r = validate(&s);
    assert_eq!(classes(&r), vec![Class::NonFinite]);
    assert_eq!(r.count(Class::NonFinite), 1);

    // An empty surface, or points without triangles (an OBJ cut short),
    // is its own error, not a valid surface with nothing in it.
    let r = validate(&Surface::default());
    assert_eq!(classes(&r), vec![Class::NoTriangles]);
    assert!(!r.is_valid() && r.shells.is_empty());
    let mut s = cube([0.0; 3], 1.0);
    s.tris.clear();
    s.patch.clear();
    let r = validate(&s);
    assert_eq!(classes(&r), vec![Class::NoTriangles]);
    assert!(r.to_string().contains("8 points and no triangles"), "{r}");
}

#[test]
fn many_examples_are_capped() {
    let mut s = icosphere([0.0; 3], 1.0, 2);
    for t in &mut s.tris {
        t.swap(1, 2);
    }
    for t in s.tris.iter_mut().step_by(2) {
        t.swap(1, 2);
    }
    let r = validate(&s);
    let p = r.problem(Class::InconsistentEdge).unwrap();
    assert!(p.count > 10);
    assert_eq!(p.examples.len(), 10);
    assert!(r
        .to_string()
        .contains(&format!("... and {} more", p.count - 10)));
}

#[test]
fn large_sphere_is_fast() {
    let s = icosphere([0.0; 3], 1.0, 7); // 327 680 triangles
    let t0 = std::time::Instant::now();
    let r = validate(&s);
    let dt = t0.elapsed().as_secs_f64();
    println!("validate {} triangles: {:.3} s", s.tris.len(), dt);
    assert!(r.is_valid(), "{r}");
    assert!(dt < 10.0, "took {dt} s");
}

#[test]
fn thousand_voids_nest_quickly() {
    let mut parts = vec![cube([0.0; 3], 21.0)];
    for i in 0..10 {
        for j in 0..10 {
            for k in 0..10 {
                let lo = [
                    1.0 + 2.0 * i as f64,
                    1.0 + 2.0 * j as f64,
                    1.0 + 2.0 * k as f64,
                ];
                parts.push(flip(cube(lo, 1.0)));
            }
        }
    }
    // One inner body in the first void.
    parts.push(cube([1.25; 3], 0.5));
    let s = merge(&parts);
    let t0 = std::time::Instant::now();
    let r = validate(&s);
    println!("1002 shells: {:.3} s", t0.elapsed().as_secs_f64());
    assert!(r.is_valid(), "{r}");
    assert_eq!(r.shells.len(), 1002);
    assert_eq!((r.shells[0].depth, r.shells[0].kind), (0, ShellKind::Outer));
    for sh in &r.shells[1..1001] {
        assert_eq!(
            (sh.depth, sh.parent, sh.kind),
            (1, Some(0), ShellKind::Void)
        );
    }
    let body = &r.shells[1001];
    assert_eq!(
        (body.depth, body.parent, body.kind),
        (2, Some(1), ShellKind::Inner)
    );
    let reg = regions(&r.shells);
    assert_eq!(reg.len(), 2);
    assert_eq!(reg[0].voids.len(), 1000);
}

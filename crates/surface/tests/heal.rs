//! Healing on dirty surfaces made in code: closed parts whose vertices along
//! a seam were written twice, the copies 1 ulp off. Every heal is checked
//! with `heal::check`; the corpus's dirty files run when PARAFRONT_GEOMETRY
//! is set.
use parafront_geom::P3;
use parafront_surface::generate::{icosphere, voxels};
use parafront_surface::heal::{check, heal, HealOptions, Healed};
use parafront_surface::validate::{validate, Class};
use parafront_surface::Surface;

/// One ulp away from `x`, away from zero.
fn ulp(x: f64) -> f64 {
    f64::from_bits(x.to_bits() + 1)
}

/// `s` with the vertices that triangles on `side` share with the others
/// written again for the `side` triangles, moved by `jitter`; the vertices
/// `keep` names stay shared (a seam that ends there pinches them).
fn unweld(
    s: &Surface,
    side: impl Fn(&[u32; 3]) -> bool,
    jitter: impl Fn(P3) -> P3,
    keep: impl Fn(u32) -> bool,
) -> Surface {
    let n = s.points.len();
    let (mut on, mut off) = (vec![false; n], vec![false; n]);
    for t in &s.tris {
        let flag = if side(t) { &mut on } else { &mut off };
        for &v in t {
            flag[v as usize] = true;
        }
    }
    let mut d = s.clone();
    let mut copy = vec![u32::MAX; n];
    for v in 0..n {
        if on[v] && off[v] && !keep(v as u32) {
            copy[v] = d.points.len() as u32;
            d.points.push(jitter(s.points[v]));
        }
    }
    for t in d.tris.iter_mut() {
        if side(t) {
            *t = t.map(|v| {
                if copy[v as usize] != u32::MAX {
                    copy[v as usize]
                } else {
                    v
                }
            });
        }
    }
    d
}

fn healed(s: &Surface, o: &HealOptions) -> Healed {
    let h = heal(s, o);
    check(s, &h, o).unwrap_or_else(|e| panic!("heal broke its promise: {e}"));
    h
}

fn centroid_x(s: &Surface, t: &[u32; 3]) -> f64 {
    t.iter().map(|&v| s.points[v as usize][0]).sum::<f64>() / 3.0
}

#[test]
fn seam_of_one_ulp_closes_back_to_the_original() {
    let s = icosphere([0.3, -1.7, 2.0], 1.5, 3);
    assert!(validate(&s).is_valid());
    let d = unweld(
        &s,
        |t| centroid_x(&s, t) > 0.3,
        |p| [ulp(p[0]), p[1], ulp(p[2])],
        |_| false,
    );
    let r = validate(&d);
    assert!(r.count(Class::OpenEdge) > 20, "{r}");
    let h = healed(&d, &HealOptions::default());
    let seam = d.points.len() - s.points.len();
    assert_eq!(h.report.vertices_merged, seam);
    assert_eq!(h.report.tris_dropped(), 0);
    assert_eq!(h.report.shells_flipped, 0);
    assert!(h.report.max_distance > 0.0 && h.report.max_distance < 1e-15);
    // The copies came last: the original comes back exactly.
    assert_eq!(h.surface, s);
}

#[test]
fn seam_ending_at_a_shared_vertex_removes_the_pinch() {
    let s = icosphere([0.0; 3], 1.0, 2);
    let top = (0..s.points.len() as u32)
        .max_by(|&a, &b| s.points[a as usize][2].total_cmp(&s.points[b as usize][2]))
        .unwrap();
    // A quarter: its seam runs pole to pole; the top pole stays shared.
    let quarter = |t: &[u32; 3]| {
        let c = t.map(|v| s.points[v as usize]);
        c.iter().map(|p| p[0]).sum::<f64>() > 0.0 && c.iter().map(|p| p[1]).sum::<f64>() > 0.0
    };
    let d = unweld(&s, quarter, |p| p.map(ulp), |v| v == top);
    let r = validate(&d);
    assert!(r.count(Class::PinchedVertex) >= 1, "{r}");
    let h = healed(&d, &HealOptions::default());
    assert!(h.report.vertices_merged > 0);
    let r = validate(&h.surface);
    assert!(r.is_valid(), "{r}");
    assert_eq!(h.surface, s);
}

/// A wedge 1e-12 thick: its vertical edges are real and far shorter than
/// any absolute tolerance; the seams along both caps are 1 ulp off.
fn thin_wedge(eps: f64) -> Surface {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, eps],
        [1.0, 0.0, eps],
        [0.0, 1.0, eps],
    ];
    let t = vec![
        [0, 2, 1],
        [3, 4, 5],
        [0, 1, 4],
        [0, 4, 3],
        [1, 2, 5],
        [1, 5, 4],
        [2, 0, 3],
        [2, 3, 5],
    ];
    Surface::one_patch(p, t)
}

#[test]
fn real_short_edges_are_kept_whatever_the_tolerance() {
    let s = thin_wedge(1e-12);
    assert!(validate(&s).is_valid(), "{}", validate(&s));
    // The two caps written apart from the sides.
    let d = unweld(
        &s,
        |t| t == &[0, 2, 1] || t == &[3, 4, 5],
        |p| [p[0], ulp(p[1]), p[2]],
        |_| false,
    );
    assert_eq!(validate(&d).count(Class::OpenEdge), 12);
    let h = healed(&d, &HealOptions::default());
    assert_eq!(h.report.vertices_merged, 6);
    assert_eq!(h.surface, s);
    // A tolerance twice the shortest edge would reach across the 1e-12
    // edges: they are edges, so they are never collapsed.
    let wide = HealOptions { rel_tol: 2.0 };
    let h = heal(&d, &wide);
    assert_eq!(h.surface, s);
    for t in &h.surface.tris {
        assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    }
}

#[test]
fn a_gap_of_a_few_ulps_that_is_not_open_is_left_alone() {
    // Two closed cubes 3 ulps apart: nothing is open, nothing merges.
    let a = voxels([0.0; 3], 1.0, [1, 1, 1], |_, _, _| true);
    let x = ulp(ulp(ulp(1.0)));
    let b = voxels([x, 0.0, 0.0], 1.0, [1, 1, 1], |_, _, _| true);
    let mut s = a.clone();
    s.append(&b);
    let h = healed(&s, &HealOptions::default());
    assert!(!h.report.changed());
    assert_eq!(h.surface, s);

    // A dirty sphere under a closed cube whose corner is 2 ulps from the
    // top seam vertex: the seam closes, the cube's corner stays its own.
    let ball = icosphere([0.0; 3], 1.0, 2);
    let d0 = unweld(
        &ball,
        |t| centroid_x(&ball, t) > 0.0,
        |p| p.map(ulp),
        |_| false,
    );
    let seam_v = d0.points[ball.points.len()..]
        .iter()
        .copied()
        .max_by(|a, b| a[2].total_cmp(&b[2]))
        .unwrap();
    let corner = [ulp(ulp(seam_v[0])), seam_v[1], seam_v[2]];
    let cube = voxels(corner, 0.5, [1, 1, 1], |_, _, _| true);
    let mut d = d0.clone();
    d.append(&cube);
    let h = healed(&d, &HealOptions::default());
    let n_ball = ball.points.len();
    // Each cube corner keeps a point of its own.
    for v in d0.points.len()..d.points.len() {
        let m = h.point_map[v];
        let with: Vec<usize> = (0..d.points.len())
            .filter(|&u| h.point_map[u] == m)
            .collect();
        assert_eq!(with, vec![v], "cube corner {v} merged");
    }
    assert_eq!(h.report.vertices_merged, d0.points.len() - n_ball);
    let r = validate(&h.surface);
    assert!(r.is_valid(), "{r}");
}

#[test]
fn real_holes_stay_open_and_valid_surfaces_unchanged() {
    let s = icosphere([0.0; 3], 1.0, 2);
    let mut holed = s.clone();
    holed.tris.remove(5);
    holed.patch.remove(5);
    let h = healed(&holed, &HealOptions::default());
    assert!(!h.report.changed());
    assert_eq!(h.report.open_edges, 3);
    assert_eq!(h.surface, holed);
    let h = healed(&s, &HealOptions::default());
    assert_eq!((h.surface, h.report.open_edges), (s, 0));
}

/// A unit cube whose top face (patch 5) is cut off and written again once
/// per entry of `lids`, each time with its own 1-ulp copies of the corners
/// (`true`: turned to face into the part).
fn cube_with_lids(lids: &[bool]) -> (Surface, Surface) {
    let s = voxels([0.0; 3], 1.0, [1, 1, 1], |_, _, _| true);
    let top: Vec<usize> = (0..s.tris.len()).filter(|&t| s.patch[t] == 5).collect();
    let mut d = s.clone();
    d.tris.retain(|t| !top.iter().any(|&i| s.tris[i] == *t));
    d.patch = vec![0; d.tris.len()];
    for (i, &turned) in lids.iter().enumerate() {
        let mut copy = std::collections::HashMap::new();
        for &t in &top {
            let c = s.tris[t].map(|v| {
                *copy.entry(v).or_insert_with(|| {
                    let mut q = s.points[v as usize];
                    for _ in 0..=i {
                        q = q.map(ulp);
                    }
                    d.points.push(q);
                    d.points.len() as u32 - 1
                })
            });
            d.tris.push(if turned { [c[0], c[2], c[1]] } else { c });
            d.patch.push(5);
        }
    }
    let mut s = s;
    s.patch = s
        .patch
        .iter()
        .map(|&p| if p == 5 { 5 } else { 0 })
        .collect();
    (s, d)
}

#[test]
fn merge_made_copies_are_dropped() {
    // The lid written twice: merged, the two copies coincide and one goes.
    let (_, d) = cube_with_lids(&[false, false]);
    assert!(!validate(&d).is_valid());
    let h = healed(&d, &HealOptions::default());
    assert_eq!(h.report.vertices_merged, 8);
    assert_eq!(h.report.tris_duplicate, 2);
    assert_eq!(h.report.tris_degenerate, 0);
    let r = validate(&h.surface);
    assert!(r.is_valid(), "{r}");
    assert_eq!(h.surface.tris.len(), 12);
}

#[test]
fn a_turned_lid_is_turned_back() {
    let (s, d) = cube_with_lids(&[true]);
    assert_eq!(validate(&d).count(Class::OpenEdge), 8);
    let h = healed(&d, &HealOptions::default());
    assert_eq!(h.report.vertices_merged, 4);
    assert_eq!((h.report.shells_flipped, h.report.tris_flipped), (1, 2));
    let r = validate(&h.surface);
    assert!(r.is_valid(), "{r}");
    assert!((h.surface.signed_volume() - s.signed_volume()).abs() < 1e-12);
}

#[test]
fn bad_input_comes_back_unchanged() {
    let mut s = icosphere([0.0; 3], 1.0, 1);
    s.tris.push([0, 1, 999]);
    s.patch.push(0);
    let h = heal(&s, &HealOptions::default());
    assert_eq!(h.surface, s);
    let mut s = icosphere([0.0; 3], 1.0, 1);
    s.points[0][0] = f64::NAN;
    assert!(!heal(&s, &HealOptions::default()).report.changed());
    let e = Surface::default();
    assert_eq!(heal(&e, &HealOptions::default()).surface, e);
}

#[test]
fn corpus_dirty_files_heal_to_valid_surfaces() {
    let Some(dir) = std::env::var_os("PARAFRONT_GEOMETRY") else {
        println!("PARAFRONT_GEOMETRY unset: corpus test skipped");
        return;
    };
    let dir = std::path::PathBuf::from(dir);
    for (file, open, pinched) in [
        ("dirty/angle_block.STL", 166, 33),
        ("dirty/idler_riser.STL", 44, 1),
    ] {
        let s = parafront_surface::read::read_surface(&dir.join(file)).unwrap();
        let r = validate(&s);
        assert_eq!(r.count(Class::OpenEdge), open, "{file}");
        assert_eq!(r.count(Class::PinchedVertex), pinched, "{file}");
        let h = healed(&s, &HealOptions::default());
        println!("{file}: {}", h.report);
        let r = validate(&h.surface);
        assert!(r.is_valid(), "{file}: {r}");
        assert_eq!(h.surface.tris.len(), s.tris.len(), "{file}");
    }
    for file in [
        "invalid/stanford-bunny.obj",
        "invalid/teapot.stl",
        "invalid/shared.STL",
        "invalid/cow.obj",
        "invalid/wingnut.obj",
    ] {
        let s = parafront_surface::read::read_surface(&dir.join(file)).unwrap();
        let h = healed(&s, &HealOptions::default());
        let r = validate(&h.surface);
        println!("{file}: {}", h.report);
        assert!(!r.is_valid(), "{file} healed to valid");
    }
}

#[test]
fn random_seams_on_a_torus_close_back_exactly() {
    use parafront_surface::generate::torus;
    let s = torus([1.0, -2.0, 0.5], 3.0, 0.75, 24, 12);
    assert!(validate(&s).is_valid());
    // A small LCG: seams along random planes, each copy 1 to 3 ulps off
    // along each axis, up or down.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        seed >> 33
    };
    for _ in 0..8 {
        let (a, b) = (next() % 7, next() % 5);
        let side = |t: &[u32; 3]| {
            let c = t.map(|v| s.points[v as usize]);
            let x: f64 = c
                .iter()
                .map(|p| p[0] * (a as f64 - 3.0) + p[1] * (b as f64 - 2.0))
                .sum();
            x > 0.0
        };
        let steps: Vec<i64> = (0..3).map(|_| (next() % 7) as i64 - 3).collect();
        let jitter = |p: P3| {
            let mut q = p;
            for k in 0..3 {
                let bits = q[k].to_bits() as i64 + steps[k];
                q[k] = f64::from_bits(bits as u64);
            }
            q
        };
        let d = unweld(&s, side, jitter, |_| false);
        let h = healed(&d, &HealOptions::default());
        assert_eq!(h.report.vertices_merged, d.points.len() - s.points.len());
        assert_eq!(h.surface, s, "steps {steps:?}");
    }
}

//! Hard surfaces built in code (issue 20): needles, thin slots, tiny
//! features beside large faces, twisted prisms. Each must mesh with default
//! options and with a size far above its smallest edge, keep its surface
//! and fill it exactly.
use parafront_pipeline::{mesh_surface, MeshOptions};
use parafront_surface::Surface;

type P3 = [f64; 3];

fn surface(points: Vec<P3>, tris: Vec<[u32; 3]>) -> Surface {
    let n = tris.len();
    let mut s = Surface {
        points,
        tris,
        patch: vec![0; n],
        ..Default::default()
    };
    if s.signed_volume() < 0.0 {
        s = s.flipped();
    }
    s
}

/// A `k`-sided frustum along z, `len` long, radii `r0` at z = 0 and `r1`
/// at the top; caps fanned from one corner (needle triangles on the sides
/// and caps alike).
fn frustum(k: usize, len: f64, r0: f64, r1: f64, twist: f64) -> Surface {
    let mut p = Vec::new();
    for (z, r, t) in [(0.0, r0, 0.0), (len, r1, twist)] {
        for i in 0..k {
            let a = t + i as f64 * std::f64::consts::TAU / k as f64;
            p.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    let k32 = k as u32;
    let mut t = Vec::new();
    for i in 0..k32 {
        let j = (i + 1) % k32;
        t.push([i, j, j + k32]);
        t.push([i, j + k32, i + k32]);
    }
    for i in 1..k32 - 1 {
        t.push([0, i + 1, i]);
        t.push([k32, k32 + i, k32 + i + 1]);
    }
    surface(p, t)
}

/// A box 1 x 1 x 1 with a slot `gap` wide cut down into it to depth 0.9.
fn slotted_box(gap: f64) -> Surface {
    let prof: Vec<[f64; 2]> = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.5 + gap / 2.0, 1.0],
        [0.5 + gap / 2.0, 0.1],
        [0.5 - gap / 2.0, 0.1],
        [0.5 - gap / 2.0, 1.0],
        [0.0, 1.0],
    ];
    let n = prof.len() as u32;
    let mut p = Vec::new();
    for y in [0.0, 1.0] {
        for q in &prof {
            p.push([q[0], y, q[1]]);
        }
    }
    let cap = [
        [0, 1, 4],
        [0, 4, 5],
        [1, 2, 3],
        [1, 3, 4],
        [0, 5, 6],
        [0, 6, 7],
    ];
    let mut t = Vec::new();
    for c in cap {
        t.push(c);
        t.push([c[0] + n, c[2] + n, c[1] + n]);
    }
    for k in 0..n {
        let (a, b) = (k, (k + 1) % n);
        t.push([a, a + n, b + n]);
        t.push([a, b + n, b]);
    }
    // Cap orientation follows the sides': fix by the volume's sign.
    surface(p, t)
}

fn smallest_edge(s: &Surface) -> f64 {
    let d = |a: u32, b: u32| {
        let (p, q) = (s.points[a as usize], s.points[b as usize]);
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    s.tris
        .iter()
        .flat_map(|t| [d(t[0], t[1]), d(t[1], t[2]), d(t[2], t[0])])
        .fold(f64::INFINITY, f64::min)
}

/// Default options, then `--size` 10 and 100 times the smallest edge.
fn meshes(name: &str, s: &Surface) {
    let e = smallest_edge(s);
    meshes_at(name, s, &[None, Some(10.0 * e), Some(100.0 * e)]);
}

fn meshes_at(name: &str, s: &Surface, sizes: &[Option<f64>]) {
    for &h in sizes {
        let mut o = MeshOptions::default();
        o.size.h = h;
        let (m, sum) =
            mesh_surface(s, &o).unwrap_or_else(|err| panic!("{name}, size {h:?}: {err}"));
        m.check_against_surface(&s.tris)
            .unwrap_or_else(|err| panic!("{name}, size {h:?}: invalid mesh: {err}"));
        let v = s.signed_volume();
        assert!(
            (m.volume() - v).abs() <= 1e-9 * v,
            "{name}: volume {} of {v}",
            m.volume()
        );
        println!(
            "{name} size {h:?}: {} tets, {} cavities filled ({} tets)",
            m.tets.len(),
            sum.cavities_filled,
            sum.fill_tets
        );
    }
}

#[test]
fn needle_frustums() {
    for aspect in [1000.0, 2500.0, 5000.0] {
        // Tip 1/aspect of the length, base twice as wide.
        let r = 0.5 / aspect;
        meshes(
            &format!("frustum 1:{aspect}"),
            &frustum(6, 1.0, 2.0 * r, r, 0.0),
        );
    }
}

/// A `k`-sided rod of radius `r` and length `len`, its sides cut into
/// `segs` rings, its caps fanned from their centres.
fn rod(k: usize, r: f64, len: f64, segs: usize) -> Surface {
    let mut p = Vec::new();
    for s in 0..=segs {
        let z = len * s as f64 / segs as f64;
        for i in 0..k {
            let a = i as f64 * std::f64::consts::TAU / k as f64;
            p.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    let (c0, c1) = (p.len() as u32, p.len() as u32 + 1);
    p.push([0.0, 0.0, 0.0]);
    p.push([0.0, 0.0, len]);
    let (k32, s32) = (k as u32, segs as u32);
    let at = |s: u32, i: u32| s * k32 + i % k32;
    let mut t = Vec::new();
    for s in 0..s32 {
        for i in 0..k32 {
            t.push([at(s, i), at(s, i + 1), at(s + 1, i + 1)]);
            t.push([at(s, i), at(s + 1, i + 1), at(s + 1, i)]);
        }
    }
    for i in 0..k32 {
        t.push([c0, at(0, i + 1), at(0, i)]);
        t.push([c1, at(s32, i), at(s32, i + 1)]);
    }
    surface(p, t)
}

#[test]
fn thin_rod_is_closed_by_the_fill() {
    // The thin rod of issue 20 (r 0.02, length 20, side triangles 5 long:
    // aspect 3000): recovery alone never closed it; the fill does.
    let s = rod(8, 0.02, 20.0, 4);
    let (m, sum) = mesh_surface(&s, &MeshOptions::default()).expect("the rod meshes");
    m.check_against_surface(&s.tris).expect("valid");
    assert!(sum.cavities_filled > 0 && sum.fill_tets > 0, "the fill ran");
    meshes("rod", &s);
}

#[test]
fn twisted_prisms() {
    // Schönhardt: a triangular prism twisted so that no tetrahedralization
    // of its six corners exists; and a twisted square prism.
    meshes("schonhardt", &frustum(3, 1.0, 1.0, 1.0, 0.5));
    meshes("twisted square prism", &frustum(4, 1.0, 1.0, 1.0, 0.6));
}

#[test]
fn thin_slots() {
    for gap in [1e-2, 1e-3] {
        meshes_at(&format!("slot {gap}"), &slotted_box(gap), &[None]);
    }
}

/// Under a size 10 times the slot's width the front stalls beside the slot
/// in thin, folded, nearly flat cavities (6V ~ 1e-4 of the slot's scale)
/// that neither the flips nor the search close; after three failed fills the
/// pipeline fills the whole region from its surface (valid, coarse). The
/// 0.1 % slot at size 0.01 is a run of minutes (a million-tet front before
/// it stalls): ignored for CI; `slot_under_ten_times_its_width` is the
/// quick case.
#[test]
#[ignore = "minutes: a million-tet front before the region fill (run with --ignored)"]
fn thin_slots_under_a_large_size() {
    for gap in [1e-2, 1e-3] {
        meshes(&format!("slot {gap}"), &slotted_box(gap));
    }
}

#[test]
fn slot_under_ten_times_its_width() {
    // The front cannot close it: the region is filled whole, and the mesh
    // is valid.
    let s = slotted_box(1e-2);
    let mut o = MeshOptions::default();
    o.size.h = Some(0.1);
    let (m, sum) = mesh_surface(&s, &o).expect("the slot meshes");
    m.check_against_surface(&s.tris).expect("valid");
    assert_eq!(sum.regions_filled, vec![1], "the whole-region fill ran");
    let v = s.signed_volume();
    assert!((m.volume() - v).abs() <= 1e-9 * v);
}

/// The unit box with a cubic boss `e` wide and high at the centre of its
/// top face (a feature `e` of the part beside faces of 1).
fn boss_box(e: f64) -> Surface {
    let mut p: Vec<P3> = Vec::new();
    for z in [0.0, 1.0] {
        for y in [0.0, 1.0] {
            for x in [0.0, 1.0] {
                p.push([x, y, z]);
            }
        }
    }
    let c = |x: u32, y: u32, z: u32| x + 2 * y + 4 * z;
    let mut t: Vec<[u32; 3]> = Vec::new();
    let quad = |t: &mut Vec<[u32; 3]>, a: u32, b: u32, cc: u32, d: u32| {
        t.push([a, b, cc]);
        t.push([a, cc, d]);
    };
    quad(&mut t, c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0));
    quad(&mut t, c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1));
    quad(&mut t, c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1));
    quad(&mut t, c(1, 1, 0), c(0, 1, 0), c(0, 1, 1), c(1, 1, 1));
    quad(&mut t, c(0, 1, 0), c(0, 0, 0), c(0, 0, 1), c(0, 1, 1));
    let (lo, hi) = (0.5 - e / 2.0, 0.5 + e / 2.0);
    let ring = |z: f64| [[lo, lo, z], [hi, lo, z], [hi, hi, z], [lo, hi, z]];
    let inner: Vec<u32> = ring(1.0)
        .iter()
        .map(|&q| {
            p.push(q);
            p.len() as u32 - 1
        })
        .collect();
    let top: Vec<u32> = ring(1.0 + e)
        .iter()
        .map(|&q| {
            p.push(q);
            p.len() as u32 - 1
        })
        .collect();
    let outer = [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)];
    for k in 0..4 {
        let k1 = (k + 1) % 4;
        t.push([outer[k], outer[k1], inner[k1]]);
        t.push([outer[k], inner[k1], inner[k]]);
        quad(&mut t, inner[k], inner[k1], top[k1], top[k]);
    }
    quad(&mut t, top[0], top[1], top[2], top[3]);
    surface(p, t)
}

#[test]
fn tiny_feature_beside_large_faces() {
    // A boss 1e-4 of the part on a face of 1, at the default size.
    meshes_at("boss 1e-4", &boss_box(1e-4), &[None]);
}

/// The same boss under a given size: the surface growth once dropped the
/// box's seeds (sizes above the cap) and built its tree on the boss alone,
/// so every point outside it got the boss's 1e-4, and the front ran away.
#[test]
fn tiny_feature_under_a_given_size() {
    meshes_at("boss 1e-4", &boss_box(1e-4), &[Some(0.5), Some(0.1)]);
}

//! The size field's components and their composition.
mod common;
use common::*;
use parafront_geom::dist;
use parafront_mesh::{PointId, TetMesh};
use parafront_size::*;
use parafront_surface::Surface;
use proptest::prelude::*;
use std::collections::BTreeMap;

fn exact(seeds: &[([f64; 3], f64)], c: f64, p: [f64; 3]) -> f64 {
    seeds
        .iter()
        .map(|&(x, h)| h + c * dist(p, x))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn constant_field() {
    let sz = Sizing::constant(0.3).unwrap();
    let mut rng = Rng(7);
    for _ in 0..100 {
        assert_eq!(sz.size(rng.in_box(-10.0, 10.0)), 0.3);
    }
    assert!(matches!(
        Sizing::constant(-1.0),
        Err(SizeError::Invalid { .. })
    ));
    assert!(matches!(
        Sizing::build(&Surface::default(), &SizeOptions::default(), None),
        Err(SizeError::NoSize)
    ));
}

#[test]
fn point_source_core_then_linear_growth() {
    let o = SizeOptions {
        gradation: 1.5,
        sources: vec![SourceSpec::Point {
            center: [1.0, 2.0, 3.0],
            h0: 0.1,
            r0: 0.5,
            growth: None,
        }],
        ..Default::default()
    };
    let sz = Sizing::build(&Surface::default(), &o, None).unwrap();
    let at = |d: f64| sz.size([1.0 + d * 0.6, 2.0 - d * 0.8, 3.0]);
    assert_eq!(at(0.0), 0.1);
    assert_eq!(at(0.49), 0.1);
    for d in [0.6, 1.0, 2.5, 7.0] {
        assert!((at(d) - (0.1 + 0.5 * (d - 0.5))).abs() < 1e-12, "d={d}");
    }
}

#[test]
fn segment_sphere_box_sources() {
    let src = |s: SourceSpec| Source::new(&s, 1.2);
    let seg = src(SourceSpec::Segment {
        a: [0.0; 3],
        b: [2.0, 0.0, 0.0],
        h0: 0.1,
        r0: 0.0,
        growth: Some(2.0),
    });
    assert_eq!(seg.size([1.0, 0.0, 0.0]), 0.1);
    assert!((seg.size([1.0, 3.0, 0.0]) - 3.1).abs() < 1e-12);
    assert!((seg.size([-1.0, 0.0, 0.0]) - 1.1).abs() < 1e-12);
    let sph = src(SourceSpec::Sphere {
        center: [0.0; 3],
        radius: 1.0,
        h0: 0.1,
        r0: 0.1,
        growth: None,
    });
    assert_eq!(sph.size([0.0, 0.0, 1.05]), 0.1);
    assert!((sph.size([0.0, 0.0, 0.0]) - (0.1 + 0.2 * 0.9)).abs() < 1e-12);
    assert!((sph.size([0.0, 3.0, 0.0]) - (0.1 + 0.2 * 1.9)).abs() < 1e-12);
    let bx = src(SourceSpec::Box {
        min: [0.0; 3],
        max: [1.0; 3],
        h0: 0.2,
        r0: 0.0,
        growth: Some(1.5),
    });
    assert_eq!(bx.size([0.5, 0.9, 0.1]), 0.2);
    assert!((bx.size([2.0, 0.5, 0.5]) - 0.7).abs() < 1e-12);
    assert!((bx.size([2.0, 2.0, 1.0]) - (0.2 + 0.5 * 2f64.sqrt())).abs() < 1e-12);
}

#[test]
fn icosphere_growth_matches_edges_and_exact_formula() {
    let s = icosphere(4, 1.0); // 2562 points
    let o = SizeOptions::default();
    let sz = Sizing::build(&s, &o, None).unwrap();
    let mean = s.mean_edge_lengths();
    let seeds: Vec<_> = s.points.iter().cloned().zip(mean.iter().cloned()).collect();
    let c = o.gradation - 1.0;
    let ps = sz.surface_point_sizes();
    let mut equal = 0;
    for (i, &p) in s.points.iter().enumerate() {
        let e = exact(&seeds, c, p);
        // The field at a surface point: its own size unless a finer
        // neighbour's growth is smaller (then exactly that).
        assert!(
            (ps[i] - e).abs() <= 1e-12 * e,
            "point {i}: {} vs exact {e}",
            ps[i]
        );
        assert!(ps[i] <= mean[i] * (1.0 + 1e-12));
        if (ps[i] - mean[i]).abs() <= 1e-12 * mean[i] {
            equal += 1;
        }
    }
    assert!(
        equal > s.points.len() * 9 / 10,
        "only {equal} points keep their edge length"
    );
    // Grows towards the centre, never above the exact formula by > 2%.
    let h_surf = mean.iter().cloned().fold(0.0, f64::max);
    let centre = sz.size([0.0; 3]);
    assert!(centre > 2.0 * h_surf, "centre {centre} vs surface {h_surf}");
    let mut rng = Rng(11);
    let mut worst: f64 = 0.0;
    for _ in 0..5000 {
        let p = rng.in_box(-1.0, 1.0);
        if dist(p, [0.0; 3]) > 1.0 {
            continue;
        }
        let (v, e) = (sz.size(p), exact(&seeds, c, p));
        worst = worst.max(v / e - 1.0);
        assert!(v <= e * 1.03, "at {p:?}: {v} > exact {e}");
    }
    println!("icosphere worst over-estimate {worst:.4}");
    // Along a radius the size rises monotonically (up to 1%).
    let mut last = 0.0;
    for k in 0..=20 {
        let v = sz.size([0.0, 0.0, 1.0 - k as f64 * 0.05]);
        assert!(v >= last * 0.99, "not growing inward at step {k}");
        last = v;
    }
}

#[test]
fn thin_gap_keeps_the_fine_size() {
    // A big coarse sphere and a tiny fine one just outside it: in the small
    // one the size must stay small, not grow from the big one's faces. The
    // gap between them is outside the domain, where the field is coarse
    // (no size is asked for there): the points are inside a sphere.
    let mut s = icosphere(2, 1.0);
    let small = icosphere(3, 0.05);
    let off = s.points.len() as u32;
    s.points
        .extend(small.points.iter().map(|p| [p[0] + 1.1, p[1], p[2]]));
    s.tris.extend(small.tris.iter().map(|t| t.map(|v| v + off)));
    s.patch.extend(small.patch.iter());
    let sz = Sizing::build(&s, &SizeOptions::default(), None).unwrap();
    let g = sz.growth().unwrap();
    for p in [
        [0.99, 0.01, 0.0],
        [0.97, 0.0, 0.01],
        [0.95, 0.01, 0.0],
        [1.1, 0.0, 0.0],
        [1.1, 0.03, 0.0],
        [1.13, 0.0, 0.0],
        [1.1, 0.0, -0.04],
    ] {
        let (v, e) = (sz.size(p), g.exact(p));
        assert!(
            v <= e * 1.03 && v >= e * 0.8,
            "at {p:?}: {v} vs exact {e}, leaf {:?}",
            g.leaf_of(p)
        );
    }
}

/// The torus `torus(60, 24, 0.8, 0.3)` and its points as seeds, each
/// with its mean edge length.
fn torus_seeds() -> (Surface, Vec<([f64; 3], f64)>) {
    let s = torus(60, 24, 0.8, 0.3);
    let h = s.mean_edge_lengths();
    let seeds = s.points.iter().copied().zip(h).collect();
    (s, seeds)
}

/// A point inside the torus `torus(60, 24, 0.8, 0.3)` (its tube radius
/// 0.3 less the facets' sag), from tube coordinates in `[0, 1)`.
fn in_torus(x: [f64; 3]) -> [f64; 3] {
    let (u, v, r) = (
        x[0] * std::f64::consts::TAU,
        x[1] * std::f64::consts::TAU,
        0.29 * x[2],
    );
    let rho = 0.8 + r * v.cos();
    [rho * u.cos(), rho * u.sin(), r * v.sin()]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    /// The octree over the whole cube (no surface given) is Lipschitz to
    /// its tolerances everywhere.
    #[test]
    fn growth_is_lipschitz(a in prop::array::uniform3(-1.2f64..1.2), b in prop::array::uniform3(-1.2f64..1.2), t in 0.0f64..1.0) {
        use std::sync::OnceLock;
        static G: OnceLock<(SurfaceGrowth, f64)> = OnceLock::new();
        let (g, c) = G.get_or_init(|| {
            let (_, seeds) = torus_seeds();
            let c = SizeOptions::default().gradation - 1.0;
            (SurfaceGrowth::new(&seeds, c), c)
        });
        // Far pairs and close pairs (b pulled towards a).
        let b2 = [a[0] + (b[0] - a[0]) * t * t, a[1] + (b[1] - a[1]) * t * t, a[2] + (b[2] - a[2]) * t * t];
        for q in [b, b2] {
            let (fa, fq) = (g.size(a), g.size(q));
            let allowed = 1.5 * c * dist(a, q) + 0.02 * fa.max(fq);
            prop_assert!((fa - fq).abs() <= allowed, "|f({:?})={} - f({:?})={}| > {}", a, fa, q, fq, allowed);
        }
    }

    /// The size field of a surface is Lipschitz inside it, where the
    /// fronts bound a new point's size from a neighbour's (outside, the
    /// octree is coarse).
    #[test]
    fn the_size_field_is_lipschitz_inside(a in prop::array::uniform3(0.0f64..1.0), b in prop::array::uniform3(0.0f64..1.0), t in 0.0f64..1.0) {
        use std::sync::OnceLock;
        static SZ: OnceLock<Sizing> = OnceLock::new();
        let sz = SZ.get_or_init(|| Sizing::build(&torus(60, 24, 0.8, 0.3), &SizeOptions::default(), None).unwrap());
        let c = sz.gradation() - 1.0;
        // Far pairs and close pairs (b pulled towards a in tube
        // coordinates, so that both stay inside).
        let b2 = [a[0] + (b[0] - a[0]) * t * t, a[1] + (b[1] - a[1]) * t * t, a[2] + (b[2] - a[2]) * t * t];
        let pa = in_torus(a);
        for q in [in_torus(b), in_torus(b2)] {
            let (fa, fq) = (sz.size(pa), sz.size(q));
            let allowed = 1.5 * c * dist(pa, q) + 0.02 * fa.max(fq);
            prop_assert!((fa - fq).abs() <= allowed, "|f({:?})={} - f({:?})={}| > {}", pa, fa, q, fq, allowed);
        }
    }
}

#[test]
fn patch_sizes_refine_their_points() {
    // Torus: patch 1 = outer half. Its points get 0.01; patch 0 keeps edges.
    let s = torus(60, 24, 1.0, 0.3);
    let mean = s.mean_edge_lengths();
    let mut ps = BTreeMap::new();
    ps.insert("1".to_string(), 0.01);
    ps.insert("0".to_string(), 10.0); // larger than the edges: no effect
    let o = SizeOptions {
        patch_sizes: ps,
        ..Default::default()
    };
    let sz = Sizing::build(&s, &o, None).unwrap();
    let mut in_patch = vec![false; s.points.len()];
    for (t, tri) in s.tris.iter().enumerate() {
        if s.patch[t] == 1 {
            for &v in tri {
                in_patch[v as usize] = true;
            }
        }
    }
    let seeds: Vec<_> = s
        .points
        .iter()
        .enumerate()
        .map(|(i, &p)| (p, if in_patch[i] { 0.01 } else { mean[i] }))
        .collect();
    let c = o.gradation - 1.0;
    let mut far_from_patch = 0;
    for (i, &p) in s.points.iter().enumerate() {
        let v = sz.surface_point_sizes()[i];
        if in_patch[i] {
            assert!((v - 0.01).abs() < 1e-12, "patch point {i}: {v}");
        } else {
            // Grown from the fine patch where it is close, else the edges.
            let e = exact(&seeds, c, p);
            // A point dominated by the patch's growth may sit in a far leaf:
            // within its 2% interpolation tolerance, never below.
            assert!(
                v >= e * (1.0 - 1e-12) && v <= e * 1.02,
                "point {i}: {v} vs {e}"
            );
            if (v - mean[i]).abs() < 1e-12 {
                far_from_patch += 1;
            }
        }
    }
    assert!(
        far_from_patch > 0,
        "patch 0 points should keep their edge length"
    );
}

/// Box [0,2]^3 as 2x2x2 cubes, each cut into 6 Kuhn tets (positive volume).
fn box_mesh() -> TetMesh {
    let mut m = TetMesh::default();
    let id = |i: usize, j: usize, k: usize| (i + 3 * j + 9 * k) as u32;
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..3 {
                m.points.push([i as f64, j as f64, k as f64]);
            }
        }
    }
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..2 {
                for p in perms {
                    let mut c = [i, j, k];
                    let mut v = vec![id(c[0], c[1], c[2])];
                    for ax in p {
                        c[ax] += 1;
                        v.push(id(c[0], c[1], c[2]));
                    }
                    let pt = |x: u32| m.points[x as usize];
                    if parafront_geom::orient3d(pt(v[0]), pt(v[1]), pt(v[2]), pt(v[3])) < 0.0 {
                        v.swap(2, 3);
                    }
                    m.tets.push([v[0], v[1], v[2], v[3]].map(PointId::from_raw));
                }
            }
        }
    }
    m
}

#[test]
fn background_grid_is_exact_for_linear_fields() {
    let m = box_mesh();
    let lin = |p: [f64; 3]| 0.5 + 0.1 * p[0] + 0.2 * p[1] + 0.05 * p[2];
    let sizes: Vec<f64> = m.points.iter().map(|&p| lin(p)).collect();
    let bg = BackgroundGrid::new(&m, &sizes).unwrap();
    let mut rng = Rng(3);
    let mut hint = 0;
    for _ in 0..2000 {
        let p = rng.in_box(0.0, 2.0);
        let v = bg.size_with(p, &mut hint).expect("inside");
        assert!((v - lin(p)).abs() < 1e-12, "{v} vs {}", lin(p));
        assert!((bg.size(p) - lin(p)).abs() < 1e-12);
    }
    assert_eq!(bg.size_with([2.5, 1.0, 1.0], &mut hint), None);
    assert_eq!(bg.size([-0.1, 1.0, 1.0]), f64::INFINITY);

    // Through Sizing: the background is one component, not imposed outside.
    let o = SizeOptions {
        h: Some(0.6),
        ..Default::default()
    };
    let sz = Sizing::build(&Surface::default(), &o, Some((m.clone(), sizes))).unwrap();
    assert!((sz.size([0.0, 0.0, 0.0]) - 0.5).abs() < 1e-12);
    assert_eq!(sz.size([1.5, 1.5, 1.5]), 0.6);
    assert_eq!(sz.size([5.0, 0.0, 0.0]), 0.6);
    let mut cur = SizeCursor::default();
    assert!((sz.size_with([0.5, 0.0, 0.0], &mut cur) - 0.55).abs() < 1e-12);

    // Bad grids are typed errors.
    assert!(matches!(
        BackgroundGrid::new(&m, &[1.0]),
        Err(SizeError::Background { .. })
    ));
    let mut neg = vec![1.0; m.points.len()];
    neg[4] = -1.0;
    let e = BackgroundGrid::new(&m, &neg).unwrap_err().to_string();
    assert!(e.contains("point 4"), "{e}");
}

#[test]
fn clamps_and_global_cap() {
    let s = icosphere(2, 1.0);
    let o = SizeOptions {
        h: Some(0.3),
        hmin: 0.25,
        ..Default::default()
    };
    let sz = Sizing::build(&s, &o, None).unwrap();
    assert_eq!(sz.size([0.0; 3]), 0.3);
    for &v in sz.surface_point_sizes() {
        assert!((0.25..=0.3).contains(&v), "{v}");
    }
    // Coincident points: zero edge lengths are an error unless hmin > 0.
    let bad = Surface {
        points: vec![[0.0; 3]; 3],
        tris: vec![[0, 1, 2]],
        patch: vec![0],
        patch_names: vec![],
    };
    let e = Sizing::build(&bad, &SizeOptions::default(), None)
        .err()
        .unwrap();
    assert!(matches!(e, SizeError::ZeroSize { point: 0, .. }), "{e}");
    let o = SizeOptions {
        hmin: 0.1,
        ..Default::default()
    };
    assert_eq!(
        Sizing::build(&bad, &o, None).unwrap().size([1.0, 0.0, 0.0]),
        0.1
    );
    let oob = Surface {
        points: vec![[0.0; 3]],
        tris: vec![[0, 1, 2]],
        patch: vec![],
        patch_names: vec![],
    };
    let e = Sizing::build(&oob, &SizeOptions::default(), None)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("triangle 0"), "{e}");
}

#[test]
fn toml_example_parses_every_key() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sizes.toml");
    let o = SizeOptions::from_toml_file(&path).unwrap();
    assert_eq!(o.h, Some(0.5));
    assert_eq!((o.hmin, o.hmax, o.gradation), (0.001, 2.0, 1.25));
    assert!(o.surface_growth);
    assert_eq!(
        o.background.as_deref(),
        Some(std::path::Path::new("background.vtu"))
    );
    assert_eq!(o.patch_size_map().unwrap().get(&3), Some(&0.01));
    let kinds: Vec<_> = o.sources.iter().map(|s| s.kind()).collect();
    assert_eq!(kinds, ["point", "segment", "sphere", "box"]);
    assert_eq!(
        o.sources[0],
        SourceSpec::Point {
            center: [0.0; 3],
            h0: 0.01,
            r0: 0.1,
            growth: Some(1.3)
        }
    );
    // Round trip.
    let back = SizeOptions::from_toml_str(&o.to_toml_string(), "roundtrip").unwrap();
    assert_eq!(back, o);
    // Defaults.
    let d = SizeOptions::from_toml_str("", "empty.toml").unwrap();
    assert_eq!(d, SizeOptions::default());
    assert_eq!(d.hmax, f64::INFINITY);
}

#[test]
fn toml_errors_name_file_line_and_key() {
    let e = SizeOptions::from_toml_str("h = 0.1\ngradaton = 1.3\n", "sizes.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("sizes.toml:") && e.contains("line 2") && e.contains("gradaton"),
        "{e}"
    );
    let e = SizeOptions::from_toml_str("hmin = \"small\"\n", "a.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 1") && e.contains("hmin"), "{e}");
    let e = SizeOptions::from_toml_str("[[sources]]\nkind = \"cone\"\nh0 = 1.0\n", "b.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("cone") && e.contains("line"), "{e}");
    let e = SizeOptions::from_toml_str(
        "[[sources]]\nkind = \"point\"\ncenter = [0,0,0]\nh0 = 1.0\nradius = 2.0\n",
        "c.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("radius"), "{e}");
    let e = SizeOptions::from_toml_str(
        "[[sources]]\nkind = \"point\"\ncenter = [0,0,0]\nh0 = -1.0\n",
        "d.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("sources[0] (point) h0") && e.contains("-1"),
        "{e}"
    );
    let e = SizeOptions::from_toml_str("gradation = 0.9\n", "e.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("gradation"), "{e}");
    let e = SizeOptions::from_toml_str("[patch_sizes]\nwall = 0.1\n", "f.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("wall"), "{e}");
}

#[test]
fn no_growth_is_the_smallest_surface_size() {
    let s = icosphere(2, 1.0);
    let o = SizeOptions {
        gradation: 1.0,
        ..Default::default()
    };
    let sz = Sizing::build(&s, &o, None).unwrap();
    let hmin = s
        .mean_edge_lengths()
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    assert!((sz.size([0.0; 3]) - hmin).abs() < 1e-12);
    assert!((sz.size([5.0, 0.0, 0.0]) - hmin).abs() < 1e-12);
}

/// A capped growth is `min(f, cap)` to the octree's tolerances, and drops
/// what the cap hides: the seeds at the cap and the cells above it.
#[test]
fn a_capped_growth_is_the_capped_field_and_smaller() {
    let (_, seeds) = torus_seeds();
    let hmean = seeds.iter().map(|s| s.1).sum::<f64>() / seeds.len() as f64;
    let c = 0.3;
    let full = SurfaceGrowth::new(&seeds, c);
    for cap in [0.9 * hmean, 1.5 * hmean, 4.0 * hmean] {
        let capped = SurfaceGrowth::with_cap(&seeds, c, cap);
        assert!(capped.stats().nodes <= full.stats().nodes);
        if cap < hmean {
            assert!(capped.stats().seeds < seeds.len());
            assert!(capped.stats().nodes < full.stats().nodes / 4);
        }
        for i in 0..2000 {
            // Points in and around the torus, deterministic.
            let t = i as f64 * 0.618_034;
            let p = [
                1.3 * (t * 1.7).sin(),
                1.3 * (t * 2.3).cos(),
                0.5 * (t * 3.1).sin(),
            ];
            let e = exact(&seeds, c, p).min(cap);
            let v = capped.size(p);
            assert!(
                v <= cap && v <= e * 1.03 && v >= e * 0.8,
                "cap {cap}, at {p:?}: {v} vs {e}"
            );
            assert_eq!(capped.exact(p), e);
        }
    }
}

/// Seeds at or above the cap are dropped, but the growth still covers the
/// surface's box: a small feature's seeds alone once made the tree, and a
/// point outside it got the feature's size (a unit box with a 1e-4 boss
/// under a size of 0.5 was meshed at 1e-4 everywhere).
#[test]
fn capped_growth_covers_the_dropped_seeds_box() {
    use parafront_size::SurfaceGrowth;
    let mut seeds = vec![([0.0, 0.0, 0.0], 1.1), ([1.0, 1.0, 1.0], 1.1)];
    for k in 0..8 {
        let d = |b: usize| if k >> b & 1 == 1 { 1e-4 } else { 0.0 };
        seeds.push(([0.5 + d(0), 0.5 + d(1), 1.0 + d(2)], 1e-4));
    }
    let capped = SurfaceGrowth::with_cap(&seeds, 0.2, 0.5);
    let free = SurfaceGrowth::with_cap(&seeds, 0.2, f64::INFINITY);
    for p in [
        [0.0, 0.0, 0.0],
        [0.5, 0.5, 0.5],
        [1.0, 0.0, 1.0],
        [0.9, 0.9, 0.1],
    ] {
        let want = free.size(p).min(0.5);
        let got = capped.size(p);
        assert!(
            (got - want).abs() <= 1e-9 * want,
            "at {p:?}: {got} vs {want}"
        );
        assert!(got > 0.05, "at {p:?}: {got}");
    }
}

/// Given the surface, the octree leaves the cube outside it coarse: it has
/// fewer nodes, and inside the torus it answers exactly as the full octree
/// does (the cells there are built the same way).
#[test]
fn the_domain_octree_is_the_full_one_inside_and_smaller() {
    let (s, seeds) = torus_seeds();
    let c = 0.3;
    let full = SurfaceGrowth::new(&seeds, c);
    let dom = SurfaceGrowth::in_domain(&seeds, c, f64::INFINITY, &s.points, &s.tris);
    assert!(
        (dom.stats().nodes as f64) < 0.9 * full.stats().nodes as f64,
        "{} nodes against {}",
        dom.stats().nodes,
        full.stats().nodes
    );
    let mut inside = 0;
    for i in 0..20_000 {
        let t = i as f64 * 0.618_034;
        let p = [
            1.2 * (t * 1.7).sin(),
            1.2 * (t * 2.3).cos(),
            0.35 * (t * 3.1).sin(),
        ];
        // Inside the tube of radius 0.3 about the circle of radius 0.8.
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        if (rho - 0.8).hypot(p[2]) < 0.29 {
            inside += 1;
            assert_eq!(dom.size(p), full.size(p), "at {p:?}");
        }
    }
    assert!(inside > 1000, "{inside}");
}

//! `validate` on the shared corpus (skipped when PARAFRONT_GEOMETRY is
//! unset). Expected values are those of /work/shared/geometry/manifest.json.
use parafront_surface::read::read_surface;
use parafront_surface::validate::{validate, Class, Report, ShellKind};
use std::path::{Path, PathBuf};

fn corpus() -> Option<PathBuf> {
    match std::env::var_os("PARAFRONT_GEOMETRY") {
        Some(d) => Some(PathBuf::from(d)),
        None => {
            println!("PARAFRONT_GEOMETRY unset: corpus test skipped");
            None
        }
    }
}

fn check(dir: &Path, file: &str) -> Report {
    let s = read_surface(&dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let t0 = std::time::Instant::now();
    let r = validate(&s);
    println!(
        "{file}: {} triangles, validate {:.3} s",
        s.tris.len(),
        t0.elapsed().as_secs_f64()
    );
    r
}

/// (file, triangles, volume, [(triangles, depth, signed volume)] per shell
/// when there are several).
const VALID: &[(&str, usize, f64)] = &[
    ("valid/spot.obj", 5856, 0.7183),
    ("valid/fertility.off", 9000, 4.322e5),
    ("valid/fandisk.off", 14454, 20.27),
    ("valid/hinge.stl", 1212, 6336.0),
    ("valid/1002_tray_bottom.STL", 4520, 3.479e5),
    ("valid/plate_holes.STL", 1252, 7.674e5),
    ("valid/base_interface_gmsh.stl", 28488, 1.258e6),
    ("valid/discrete_voids.obj", 3008, 0.8614),
    ("valid/skull.obj", 100002, 563.4),
    ("valid/boot.obj", 39906, 0.002548),
];

#[test]
fn valid_files_are_valid() {
    let Some(dir) = corpus() else { return };
    for &(file, ntri, vol) in VALID {
        let r = check(&dir, file);
        assert!(r.is_valid(), "{file}:\n{r}");
        assert!(r.problems.is_empty(), "{file}:\n{r}");
        assert_eq!(r.n_tris, ntri, "{file}");
        let total: f64 = r.shells.iter().map(|s| s.volume).sum();
        assert!((total - vol).abs() < 1e-3 * vol, "{file}: volume {total}");
        if file == "valid/discrete_voids.obj" {
            continue;
        }
        assert_eq!(r.shells.len(), 1, "{file}");
        assert_eq!(r.shells[0].kind, ShellKind::Outer, "{file}");
    }
}

#[test]
fn discrete_voids_nesting() {
    let Some(dir) = corpus() else { return };
    let r = check(&dir, "valid/discrete_voids.obj");
    assert!(r.is_valid(), "{r}");
    // manifest.json shell_nesting: (triangles, depth, signed volume).
    let mut want = vec![
        (2446, 0, 0.8750000000000001),
        (112, 1, -0.0027277587806371676),
        (112, 1, -0.002728938178319837),
        (112, 1, -0.00272815183284638),
        (110, 1, -0.0027259828301812255),
        (116, 1, -0.0027365867033561898),
    ];
    let mut got: Vec<(usize, u32, f64)> = r
        .shells
        .iter()
        .map(|s| (s.tris.len(), s.depth, s.volume))
        .collect();
    let key = |a: &(usize, u32, f64), b: &(usize, u32, f64)| a.2.total_cmp(&b.2);
    want.sort_by(key);
    got.sort_by(key);
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert_eq!((g.0, g.1), (w.0, w.1));
        assert!((g.2 - w.2).abs() < 1e-9 * w.2.abs(), "{g:?} vs {w:?}");
    }
    let outer = r.shells.iter().position(|s| s.depth == 0).unwrap() as u32;
    for s in r.shells.iter().filter(|s| s.depth == 1) {
        assert_eq!((s.kind, s.parent), (ShellKind::Void, Some(outer)));
    }
    let regions = parafront_surface::validate::regions(&r.shells);
    assert_eq!(regions.len(), 1);
    assert_eq!(regions[0].voids.len(), 5);
}

#[test]
fn bunny_is_open() {
    let Some(dir) = corpus() else { return };
    let r = check(&dir, "invalid/stanford-bunny.obj");
    assert!(!r.is_valid());
    assert_eq!(r.count(Class::OpenEdge), 223, "{r}");
    assert_eq!(r.count(Class::UnreferencedVertex), 1113, "{r}");
    for c in [
        Class::NonManifoldEdge,
        Class::PinchedVertex,
        Class::InconsistentEdge,
        Class::SelfIntersection,
        Class::ZeroArea,
    ] {
        assert_eq!(r.count(c), 0, "{c:?}\n{r}");
    }
}

#[test]
fn cow_is_pinched_and_self_intersecting() {
    let Some(dir) = corpus() else { return };
    let r = check(&dir, "invalid/cow.obj");
    assert_eq!(r.count(Class::PinchedVertex), 1, "{r}");
    assert_eq!(r.count(Class::SelfIntersection), 81, "{r}");
    assert_eq!(r.count(Class::OpenEdge), 0);
    assert_eq!(r.count(Class::NonManifoldEdge), 0);
    assert_eq!(r.count(Class::InconsistentEdge), 0);
    println!("{r}");
}

#[test]
fn wingnut_self_intersects() {
    let Some(dir) = corpus() else { return };
    let r = check(&dir, "invalid/wingnut.obj");
    assert_eq!(r.count(Class::SelfIntersection), 3, "{r}");
    assert_eq!(
        r.problems.iter().map(|p| p.class).collect::<Vec<_>>(),
        vec![Class::SelfIntersection]
    );
}

/// The generated benchmark surfaces (`$PARAFRONT_GEOMETRY/../bench`): all
/// valid, with the manifest's volume; prints shells and timings.
#[test]
fn bench_surfaces_are_valid() {
    let Some(dir) = corpus() else { return };
    let bench = dir.join("../bench");
    if !bench.is_dir() {
        println!("no bench directory next to PARAFRONT_GEOMETRY: skipped");
        return;
    }
    // (file, triangles, volume) from bench/manifest.json.
    let cases: &[(&str, usize, f64)] = &[
        ("sphere_5e6.stl", 118506, 4.188790204786391),
        ("box2holes_5e6.stl", 214164, 4.727654975296132),
        ("torus_1e6.stl", 64188, 2.4180530782668916),
    ];
    for &(file, ntri, vol) in cases {
        let r = check(&bench, file);
        assert!(r.is_valid(), "{file}:\n{r}");
        assert_eq!(r.n_tris, ntri);
        let total: f64 = r.shells.iter().map(|s| s.volume).sum();
        assert!((total - vol).abs() < 0.02 * vol, "{file}: volume {total}");
        let kinds: Vec<_> = r.shells.iter().map(|s| (s.depth, s.kind)).collect();
        println!("  shells {:?}", kinds);
    }
}

/// spheres27: a box holding 27 spheres. The stored file gives the spheres
/// outward normals (positive volume), so they read as 27 bodies embedded
/// in the box (regions of their own), not as voids; the surface is valid.
#[test]
fn bench_spheres27_nesting() {
    let Some(dir) = corpus() else { return };
    let bench = dir.join("../bench");
    if !bench.join("spheres27_1e6.stl").is_file() {
        println!("no spheres27_1e6.stl: skipped");
        return;
    }
    let r = check(&bench, "spheres27_1e6.stl");
    assert_eq!(r.shells.len(), 28);
    let outer: Vec<usize> = (0..28).filter(|&i| r.shells[i].depth == 0).collect();
    assert_eq!(outer.len(), 1);
    for (i, s) in r.shells.iter().enumerate() {
        if i != outer[0] {
            assert_eq!((s.depth, s.kind), (1, ShellKind::Inner));
            assert_eq!(s.parent, Some(outer[0] as u32));
        }
    }
    assert!(r.is_valid(), "{r}");
}

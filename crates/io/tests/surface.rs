//! Surfaces written in every surface format and read back by the surface
//! readers: the same points (bit for bit), triangles (turned the same way)
//! and tags where the format holds them; and Gmsh's own reader (the gmsh
//! Python module, skipped when missing) finds our named physical groups.

mod common;
use common::*;
use parafront_io::*;
use parafront_surface::generate::voxels;
use parafront_surface::read::read_surface;
use parafront_surface::Surface;

/// Two unit cells of voxels with patch tags 0..5 (by side), coordinates
/// using all their bits, and names on some patches.
fn part(base: u32) -> Surface {
    let mut s = voxels([0.1, -0.3, 1e-7], 1.0 / 3.0, [2, 1, 1], |_, _, _| true);
    for p in s.points.iter_mut() {
        p[1] += (p[0] * 7.0).sin() * 1e-3;
    }
    for t in s.patch.iter_mut() {
        *t += base;
    }
    s.patch_names = vec![(base, "x low".into()), (base + 5, "lid".into())];
    s
}

/// Triangles as coordinate bits (rotated to start at the least corner,
/// orientation kept) with their tags, sorted: equal whatever the numbering.
fn canon(s: &Surface) -> Vec<([[u64; 3]; 3], u32)> {
    let mut v: Vec<_> = s
        .tris
        .iter()
        .zip(&s.patch)
        .map(|(t, &tag)| {
            let c = t.map(|i| s.points[i as usize].map(f64::to_bits));
            let k = (0..3).min_by_key(|&k| c[k]).unwrap();
            ([c[k], c[(k + 1) % 3], c[(k + 2) % 3]], tag)
        })
        .collect();
    v.sort();
    v
}

fn name_of(s: &Surface, tag: u32) -> Option<&str> {
    s.patch_names
        .iter()
        .find(|(t, _)| *t == tag)
        .map(|(_, n)| n.as_str())
}

#[test]
fn surfaces_round_trip_in_every_format() {
    let d = scratch("surface");
    for base in [0, 1] {
        let s = part(base);
        for (name, o) in [
            ("a.stl", WriteOptions::default()),
            ("a.obj", WriteOptions::default()),
            ("a.off", WriteOptions::default()),
            ("a41.msh", WriteOptions::default()),
            (
                "b41.msh",
                WriteOptions {
                    binary: true,
                    ..Default::default()
                },
            ),
            (
                "a22.msh",
                WriteOptions {
                    msh_version: MshVersion::V22,
                    ..Default::default()
                },
            ),
            ("a.mesh", WriteOptions::default()),
        ] {
            let p = d.join(format!("{base}{name}"));
            write_surface(&p, &s, &o).unwrap();
            let r = read_surface(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            let ext = name.rsplit('.').next().unwrap();
            // What each format holds: OFF no tags; STL and OBJ groups
            // numbered from 0 in tag order; Gmsh groups from 1.
            let mut want = s.clone();
            match ext {
                "off" => want.patch.fill(0),
                "stl" | "obj" => want.patch.iter_mut().for_each(|t| *t -= base),
                "msh" if base == 0 => want.patch.iter_mut().for_each(|t| *t += 1),
                _ => {}
            }
            assert_eq!(canon(&r), canon(&want), "{}", p.display());
            if ext == "stl" {
                // Welded exactly: the same points, maybe in another order.
                let mut a: Vec<_> = r.points.iter().map(|p| p.map(f64::to_bits)).collect();
                let mut b: Vec<_> = s.points.iter().map(|p| p.map(f64::to_bits)).collect();
                a.sort();
                b.sort();
                assert_eq!(a, b);
            } else {
                assert_eq!(r.points, s.points, "{}", p.display());
                assert_eq!(r.tris.len(), s.tris.len());
            }
            if matches!(ext, "stl" | "obj" | "msh") {
                let lid = want.patch[s.patch.iter().position(|&t| t == base + 5).unwrap()];
                let low = want.patch[s.patch.iter().position(|&t| t == base).unwrap()];
                assert_eq!(name_of(&r, lid), Some("lid"), "{}", p.display());
                assert_eq!(name_of(&r, low), Some("x low"), "{}", p.display());
            }
        }
    }
}

#[test]
fn bad_surfaces_are_errors() {
    let d = scratch("surface-bad");
    let mut s = part(0);
    s.tris[3][1] = 999;
    let e = write_surface(&d.join("x.stl"), &s, &WriteOptions::default()).unwrap_err();
    assert!(e.to_string().contains("triangle 3"), "{e}");
    let s = part(0);
    let e = write_surface(&d.join("x.ply"), &s, &WriteOptions::default()).unwrap_err();
    assert!(e.to_string().contains("unknown surface format"), "{e}");
    assert!(listing(&d).is_empty());
}

/// The gmsh module reads our .msh files: physical groups (dim, tag, name)
/// and the element count of each.
#[test]
fn gmsh_reads_our_physical_groups() {
    let ok = std::process::Command::new("python3")
        .args(["-c", "import gmsh"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        eprintln!("gmsh_reads_our_physical_groups: skipped: python3 with gmsh not found");
        return;
    }
    const GROUPS: &str = r#"
import sys, gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
for dim, tag in sorted(gmsh.model.getPhysicalGroups()):
    n = 0
    for e in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
        _, tags, _ = gmsh.model.mesh.getElements(dim, e)
        n += sum(len(t) for t in tags)
    print(dim, tag, repr(gmsh.model.getPhysicalName(dim, tag)), n)
gmsh.finalize()
"#;
    let d = scratch("gmsh");
    let m = cube_mesh(2, |c| [0, 3][c % 2]);
    let count = |tags: &[u32], t: u32| tags.iter().filter(|&&x| x == t).count();
    for v in [MshVersion::V41, MshVersion::V22] {
        for binary in [false, true] {
            let p = d.join(format!("{v:?}{binary}.msh"));
            let o = WriteOptions {
                msh_version: v,
                binary,
                region_names: vec![(3, "steel".into())],
                patch_names: vec![(10, "x0".into())],
                ..Default::default()
            };
            write_mesh(&p, &m, &o).unwrap();
            let got: Vec<String> = python(GROUPS, &[p.to_str().unwrap()])
                .lines()
                .map(str::to_string)
                .collect();
            // Patches 10..16 kept; regions 0 and 3 go out as 1 and 4.
            let mut want: Vec<String> = (10..16)
                .map(|t| {
                    let n = if t == 10 {
                        "x0".to_string()
                    } else {
                        format!("patch {t}")
                    };
                    format!("2 {t} '{n}' {}", count(&m.bnd_patch, t))
                })
                .collect();
            want.push(format!("3 1 'region 0' {}", count(&m.region, 0)));
            want.push(format!("3 4 'steel' {}", count(&m.region, 3)));
            assert_eq!(got, want, "{}", p.display());
        }
    }
}

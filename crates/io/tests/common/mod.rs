//! Test helpers: a hand-made tet mesh and scratch directories.
#![allow(dead_code)]

use parafront_geom::orient3d;
use parafront_mesh::{PointId, TetMesh, TET_FACES};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// `n`^3 cubes, each split into 6 tets along its main diagonal (conforming
/// across cubes), points nudged off the grid so coordinates use all their
/// bits. Boundary faces are outward with patch 10 + cube side (0..6);
/// region is `region(cube index)`.
pub fn cube_mesh(n: usize, region: impl Fn(usize) -> u32) -> TetMesh {
    let id = |i: usize, j: usize, k: usize| (i * (n + 1) + j) * (n + 1) + k;
    let mut m = TetMesh::default();
    for i in 0..=n {
        for j in 0..=n {
            for k in 0..=n {
                let h = (id(i, j, k) as f64 * 0.7).sin() * 1e-3;
                let mut p = [i as f64 / 3.0, j as f64 * 0.1, k as f64 * 1.1];
                // Interior points move; boundary points stay on the box faces.
                for (c, &q) in [i, j, k].iter().enumerate() {
                    if q > 0 && q < n {
                        p[c] += h * (c as f64 + 1.0);
                    }
                }
                m.points.push(p);
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
    let mut cube = 0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                for pm in perms {
                    let mut c = [i, j, k];
                    let mut t = [PointId::from_raw(id(c[0], c[1], c[2]) as u32); 4];
                    for s in 0..3 {
                        c[pm[s]] += 1;
                        t[s + 1] = PointId::from_raw(id(c[0], c[1], c[2]) as u32);
                    }
                    let p = |v: PointId| m.points[v.idx()];
                    if orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) < 0.0 {
                        t.swap(2, 3);
                    }
                    assert!(orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) > 0.0);
                    m.tets.push(t);
                    m.region.push(region(cube));
                }
                cube += 1;
            }
        }
    }
    let mut count: HashMap<[u32; 3], (usize, [PointId; 3])> = HashMap::new();
    for t in &m.tets {
        for f in TET_FACES {
            let tri = [t[f[0]], t[f[1]], t[f[2]]];
            let mut key = tri.map(|p| p.raw());
            key.sort_unstable();
            count.entry(key).or_insert((0, tri)).0 += 1;
        }
    }
    let mut bnd: Vec<[PointId; 3]> = count
        .values()
        .filter(|(c, _)| *c == 1)
        .map(|(_, t)| *t)
        .collect();
    bnd.sort();
    let hi = [n as f64 / 3.0, n as f64 * 0.1, n as f64 * 1.1];
    for t in bnd {
        let ps: Vec<[f64; 3]> = t.iter().map(|p| m.points[p.idx()]).collect();
        let side = (0..3)
            .find_map(|c| {
                if ps.iter().all(|p| p[c] == 0.0) {
                    Some(2 * c)
                } else if ps.iter().all(|p| p[c] == hi[c]) {
                    Some(2 * c + 1)
                } else {
                    None
                }
            })
            .expect("boundary face on a box side");
        m.bnd_tris.push(t);
        m.bnd_patch.push(10 + side as u32);
    }
    assert_eq!(m.bnd_tris.len(), 12 * n * n);
    m
}

/// A fresh empty scratch directory under the system temp dir, removed
/// with its files when the test is done with it (dropped).
pub fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("parafront-io-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

/// A scratch directory; it goes when this does.
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Names of the files in `d`, sorted.
pub fn listing(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Asserts two meshes hold the same points (bit for bit), cells and tags.
pub fn assert_same(a: &TetMesh, b: &TetMesh) {
    assert_eq!(a.points.len(), b.points.len(), "point count");
    for (i, (p, q)) in a.points.iter().zip(&b.points).enumerate() {
        assert_eq!(
            p.map(f64::to_bits),
            q.map(f64::to_bits),
            "point {i}: {p:?} vs {q:?}"
        );
    }
    assert_eq!(a.tets, b.tets, "tets");
    assert_eq!(a.region, b.region, "regions");
    assert_eq!(a.bnd_tris, b.bnd_tris, "boundary triangles");
    assert_eq!(a.bnd_patch, b.bnd_patch, "patches");
}

/// The mesh with tets stably grouped by region (the Gmsh 4.1 element order).
pub fn grouped_by_region(m: &TetMesh) -> TetMesh {
    let mut g = m.clone();
    let mut order: Vec<usize> = (0..m.tets.len()).collect();
    order.sort_by_key(|&t| m.region[t]);
    g.tets = order.iter().map(|&t| m.tets[t]).collect();
    g.region = order.iter().map(|&t| m.region[t]).collect();
    let mut order: Vec<usize> = (0..m.bnd_tris.len()).collect();
    order.sort_by_key(|&t| m.bnd_patch[t]);
    g.bnd_tris = order.iter().map(|&t| m.bnd_tris[t]).collect();
    g.bnd_patch = order.iter().map(|&t| m.bnd_patch[t]).collect();
    g
}

/// True when `python3 -c "import meshio"` works; prints a skip note if not.
pub fn have_meshio(test: &str) -> bool {
    let ok = std::process::Command::new("python3")
        .args(["-c", "import meshio, numpy"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        eprintln!("{test}: skipped: python3 with meshio and numpy not found");
    }
    ok
}

/// Runs an inline Python script with arguments; returns its stdout.
pub fn python(script: &str, args: &[&str]) -> String {
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .expect("run python3");
    assert!(
        out.status.success(),
        "python failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// `m` with its tags as the Gmsh writer writes them: per kind, shifted by
/// 1 when one of them is 0 (Gmsh groups start at 1).
pub fn gmsh_tags(m: &TetMesh) -> TetMesh {
    let shift = |t: &[u32]| -> Vec<u32> {
        let s = t.contains(&0) as u32;
        t.iter().map(|&x| x + s).collect()
    };
    let mut g = m.clone();
    g.region = shift(&m.region);
    g.bnd_patch = shift(&m.bnd_patch);
    g
}

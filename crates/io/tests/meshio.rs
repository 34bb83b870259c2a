//! Cross-checks with Python: meshio reads every format we write (and we
//! read what meshio writes), and shared/tools/meshcheck.py accepts our
//! output. Skipped with a message when python3 + meshio are missing.

mod common;
use common::*;
use parafront_io::*;
use parafront_mesh::{TetMesh, TET_FACES};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Prints, per cell type: count, sum of 0-based ids, sum of tag, sum of
/// tag * (sum of the cell's ids) (pairs tags with cells, order-free).
const SUMMARY: &str = r#"
import sys, warnings
import numpy as np, meshio
warnings.simplefilter("ignore")
m = meshio.read(sys.argv[1])
keys = {"tetra": sys.argv[2], "triangle": sys.argv[3]}
print("points", len(m.points), repr(float(np.sum(m.points, dtype=np.float64))))
for ty in ("tetra", "triangle"):
    n = ids = tags = pair = 0
    for i, c in enumerate(m.cells):
        if c.type != ty:
            continue
        d = c.data.astype(np.int64)
        t = np.asarray(m.cell_data[keys[ty]][i]).astype(np.int64).ravel()
        n += len(d); ids += int(d.sum()); tags += int(t.sum()); pair += int((t * d.sum(axis=1)).sum())
    print(ty, n, ids, tags, pair)
for k in sys.argv[4:]:
    if k in m.point_data:
        print("point", k, repr(float(np.nansum(m.point_data[k]))))
    else:
        for i, c in enumerate(m.cells):
            print("cell", k, c.type, repr(float(np.nansum(np.asarray(m.cell_data[k][i], dtype=np.float64)))))
"#;

/// The summary lines SUMMARY prints, computed from our mesh.
fn expect(m: &TetMesh) -> Vec<String> {
    let mut out = vec![format!("points {}", m.points.len())];
    let mut line = |ty: &str, cells: Vec<Vec<u32>>, tags: &[u32]| {
        let ids: u64 = cells.iter().flatten().map(|&i| i as u64).sum();
        let tsum: u64 = tags.iter().map(|&t| t as u64).sum();
        let pair: u64 = cells
            .iter()
            .zip(tags)
            .map(|(c, &t)| t as u64 * c.iter().map(|&i| i as u64).sum::<u64>())
            .sum();
        out.push(format!("{ty} {} {ids} {tsum} {pair}", cells.len()));
    };
    line(
        "tetra",
        m.tets
            .iter()
            .map(|t| t.iter().map(|p| p.raw()).collect())
            .collect(),
        &m.region,
    );
    line(
        "triangle",
        m.bnd_tris
            .iter()
            .map(|t| t.iter().map(|p| p.raw()).collect())
            .collect(),
        &m.bnd_patch,
    );
    out
}

fn summary(path: &Path, tet_key: &str, tri_key: &str, extra: &[&str]) -> Vec<String> {
    let mut args = vec![path.to_str().unwrap(), tet_key, tri_key];
    args.extend_from_slice(extra);
    // meshio prints stray blank lines and warnings: keep only ours.
    let keep = ["points ", "tetra ", "triangle ", "point ", "cell "];
    python(SUMMARY, &args)
        .lines()
        .filter(|l| keep.iter().any(|k| l.starts_with(k)))
        .map(str::to_string)
        .collect()
}

/// Checks the coordinate sum (second field of "points") closely, the rest exactly.
fn check(path: &Path, m: &TetMesh, got: &[String]) {
    let want = expect(m);
    let pts: Vec<&str> = got[0].split(' ').collect();
    assert_eq!(
        format!("{} {}", pts[0], pts[1]),
        want[0],
        "{}",
        path.display()
    );
    let s: f64 = pts[2].parse().unwrap();
    let ours: f64 = m.points.iter().flatten().sum();
    assert!(
        (s - ours).abs() <= 1e-12 * ours.abs().max(1.0),
        "{}: coordinate sum {s} vs {ours}",
        path.display()
    );
    assert_eq!(&got[1..3], &want[1..3], "{}", path.display());
}

fn mesh() -> TetMesh {
    cube_mesh(3, |c| [7, 0, 3][c % 3])
}

#[test]
fn meshio_reads_our_files() {
    if !have_meshio("meshio_reads_our_files") {
        return;
    }
    let d = scratch("meshio-read");
    let m = mesh();
    for (name, o) in [
        (
            "raw.vtu",
            WriteOptions {
                compress: false,
                ..Default::default()
            },
        ),
        ("zlib.vtu", WriteOptions::default()),
        (
            "i32.vtu",
            WriteOptions {
                vtu_int64: false,
                ..Default::default()
            },
        ),
    ] {
        let p = d.join(name);
        write_mesh(&p, &m, &o).unwrap();
        check(&p, &m, &summary(&p, "region", "patch", &[]));
    }
    for v in [MshVersion::V41, MshVersion::V22] {
        for binary in [false, true] {
            let p = d.join(format!("{v:?}{binary}.msh"));
            let o = WriteOptions {
                msh_version: v,
                binary,
                region_names: vec![(3, "r3".into())],
                patch_names: vec![(11, "side 11".into())],
                ..Default::default()
            };
            write_mesh(&p, &m, &o).unwrap();
            // Region 0 is there: Gmsh groups start at 1, so all shift.
            let g = gmsh_tags(&m);
            check(&p, &g, &summary(&p, "gmsh:physical", "gmsh:physical", &[]));
            check(
                &p,
                &g,
                &summary(&p, "gmsh:geometrical", "gmsh:geometrical", &[]),
            );
        }
    }
    let p = d.join("m.mesh");
    write_mesh(&p, &m, &WriteOptions::default()).unwrap();
    check(&p, &m, &summary(&p, "medit:ref", "medit:ref", &[]));
}

#[test]
fn meshio_reads_extra_arrays() {
    if !have_meshio("meshio_reads_extra_arrays") {
        return;
    }
    let d = scratch("meshio-fields");
    let m = mesh();
    let size: Vec<f64> = m.points.iter().map(|p| p[0]).collect();
    let qual: Vec<f64> = (0..m.tets.len()).map(|t| t as f64 * 0.5).collect();
    let part: Vec<i32> = (0..m.tets.len() + m.bnd_tris.len())
        .map(|c| c as i32 % 4)
        .collect();
    let vec3: Vec<f64> = m.points.iter().flatten().copied().collect();
    let mut piece = Piece::new(&m);
    piece
        .point_fields
        .push(Field::scalar("size", FieldData::F64(&size)));
    piece.point_fields.push(Field {
        name: "coords",
        ncomp: 3,
        data: FieldData::F64(&vec3),
    });
    piece
        .cell_fields
        .push(Field::scalar("quality", FieldData::F64(&qual)));
    piece
        .cell_fields
        .push(Field::scalar("part", FieldData::I32(&part)));
    let p = d.join("f.vtu");
    write_vtu(&p, &piece, &WriteOptions::default()).unwrap();
    let got = summary(
        &p,
        "region",
        "patch",
        &["size", "coords", "quality", "part"],
    );
    check(&p, &m, &got);
    let val = |prefix: &str| -> f64 {
        let l = got
            .iter()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("{prefix} in {got:?}"));
        l.rsplit(' ').next().unwrap().parse().unwrap()
    };
    assert_eq!(val("point size "), size.iter().sum::<f64>());
    assert!((val("point coords ") - vec3.iter().sum::<f64>()).abs() < 1e-9);
    assert_eq!(val("cell quality tetra "), qual.iter().sum::<f64>());
    assert_eq!(
        val("cell quality triangle "),
        0.0,
        "triangles padded with NaN"
    );
    let nt = m.tets.len();
    assert_eq!(
        val("cell part tetra ") as i64,
        part[..nt].iter().map(|&x| x as i64).sum::<i64>()
    );
    assert_eq!(
        val("cell part triangle ") as i64,
        part[nt..].iter().map(|&x| x as i64).sum::<i64>()
    );
}

/// meshio writes VTU (ascii, base64 inline, zlib), msh 2.2/4.1 and Medit;
/// read_mesh reads them back to the same mesh.
#[test]
fn we_read_meshio_files() {
    if !have_meshio("we_read_meshio_files") {
        return;
    }
    let d = scratch("meshio-write");
    let m = mesh();
    let src = d.join("src.vtu");
    write_mesh(
        &src,
        &m,
        &WriteOptions {
            compress: false,
            ..Default::default()
        },
    )
    .unwrap();
    let script = r#"
import sys, warnings
import numpy as np, meshio
warnings.simplefilter("ignore")
src, out = sys.argv[1], sys.argv[2]
m = meshio.read(src)
reg = [np.asarray(x) for x in m.cell_data["region"]]
pat = [np.asarray(x) for x in m.cell_data["patch"]]
tag = [r if c.type == "tetra" else p for c, r, p in zip(m.cells, reg, pat)]
cells = [(c.type, c.data) for c in m.cells]
# meshio's 4.1 writer needs node entities when there are two cell types.
dim_tags = {"gmsh:dim_tags": np.array([[3, 1]] * len(m.points))}
def mk(cd, pd={}):
    return meshio.Mesh(m.points, cells, cell_data=cd, point_data=pd)
mk({"region": reg, "patch": pat}).write(out + "/ascii.vtu", binary=False)
mk({"region": reg, "patch": pat}).write(out + "/b64.vtu", compression=None)
mk({"region": reg, "patch": pat}).write(out + "/zlib.vtu", compression="zlib")
g = {"gmsh:physical": tag, "gmsh:geometrical": tag}
mk(g).write(out + "/a22.msh", file_format="gmsh22", binary=False)
mk(g).write(out + "/b22.msh", file_format="gmsh22", binary=True)
mk(g, dim_tags).write(out + "/a41.msh", file_format="gmsh", binary=False)
mk(g, dim_tags).write(out + "/b41.msh", file_format="gmsh", binary=True)
mk({"medit:ref": tag}).write(out + "/m.mesh")
"#;
    python(script, &[src.to_str().unwrap(), d.to_str().unwrap()]);
    for name in ["b64.vtu", "zlib.vtu", "a22.msh", "b22.msh", "m.mesh"] {
        let r = read_mesh(&d.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_same(&m, &r);
    }
    // meshio's 4.1 writer puts a whole cell block in one entity and drops
    // per-element tags: compare geometry and cells only.
    for name in ["a41.msh", "b41.msh"] {
        let mut r = read_mesh(&d.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(r.tets.len(), m.tets.len());
        r.region.clone_from(&m.region);
        r.bnd_patch.clone_from(&m.bnd_patch);
        assert_same(&m, &r);
    }
    // meshio's ascii VTU rounds coordinates: compare all but the last bits.
    let r = read_mesh(&d.join("ascii.vtu")).unwrap();
    assert_eq!(
        (&r.tets, &r.region, &r.bnd_tris, &r.bnd_patch),
        (&m.tets, &m.region, &m.bnd_tris, &m.bnd_patch)
    );
    for (p, q) in m.points.iter().zip(&r.points) {
        for k in 0..3 {
            assert!(
                (p[k] - q[k]).abs() <= 1e-9 * p[k].abs().max(1.0),
                "{p:?} vs {q:?}"
            );
        }
    }
}

fn meshcheck() -> Option<PathBuf> {
    let p = match std::env::var_os("PARAFRONT_SHARED") {
        Some(s) => PathBuf::from(s).join("tools/meshcheck.py"),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/tools/meshcheck.py"),
    };
    if p.is_file() {
        Some(p)
    } else {
        eprintln!(
            "meshcheck: skipped: {} not found (set PARAFRONT_SHARED)",
            p.display()
        );
        None
    }
}

/// The boundary triangles plus the faces between regions, as a mesh with
/// no tets (a surface file for meshcheck).
fn surface_of(m: &TetMesh) -> TetMesh {
    let mut s = TetMesh {
        points: m.points.clone(),
        bnd_tris: m.bnd_tris.clone(),
        bnd_patch: m.bnd_patch.clone(),
        ..Default::default()
    };
    let mut seen: HashMap<[u32; 3], (usize, usize)> = HashMap::new();
    for (t, tet) in m.tets.iter().enumerate() {
        for (f, lf) in TET_FACES.iter().enumerate() {
            let mut k = lf.map(|i| tet[i].raw());
            k.sort_unstable();
            if let Some(&(t0, f0)) = seen.get(&k) {
                if m.region[t0] != m.region[t] {
                    s.bnd_tris.push(TET_FACES[f0].map(|i| m.tets[t0][i]));
                    s.bnd_patch.push(99);
                }
            } else {
                seen.insert(k, (t, f));
            }
        }
    }
    s
}

#[test]
fn meshcheck_accepts_our_output() {
    if !have_meshio("meshcheck_accepts_our_output") {
        return;
    }
    let Some(mc) = meshcheck() else { return };
    let d = scratch("meshcheck");
    let one = cube_mesh(3, |_| 1);
    let two = cube_mesh(3, |c| (c / 9) as u32); // three slabs of cubes
    for (tag, m) in [("one", &one), ("two", &two)] {
        let surf = d.join(format!("{tag}-surface.mesh"));
        let s = surface_of(m);
        if tag == "two" {
            assert!(s.bnd_tris.len() > m.bnd_tris.len(), "interfaces found");
        }
        write_medit(&surf, &s).unwrap();
        for (name, o) in [
            ("zlib.vtu", WriteOptions::default()),
            ("a41.msh", WriteOptions::default()),
            (
                "b22.msh",
                WriteOptions {
                    msh_version: MshVersion::V22,
                    binary: true,
                    ..Default::default()
                },
            ),
            ("m.mesh", WriteOptions::default()),
        ] {
            let p = d.join(format!("{tag}-{name}"));
            write_mesh(&p, m, &o).unwrap();
            let out = std::process::Command::new("python3")
                .arg(&mc)
                .arg(&p)
                .arg("--surface")
                .arg(&surf)
                .output()
                .expect("run meshcheck");
            let text = String::from_utf8_lossy(&out.stdout);
            assert_eq!(
                out.status.code(),
                Some(0),
                "{}:\n{text}{}",
                p.display(),
                String::from_utf8_lossy(&out.stderr)
            );
            let regions = text
                .lines()
                .find(|l| l.starts_with("regions "))
                .map(|l| l.split_whitespace().last());
            let want = if tag == "two" { Some(Some("3")) } else { None };
            assert_eq!(regions, want, "{text}");
        }
    }
    // And it does reject a broken mesh: one tet flipped.
    let mut bad = one.clone();
    bad.tets[4].swap(0, 1);
    let p = d.join("bad.vtu");
    write_mesh(&p, &bad, &WriteOptions::default()).unwrap();
    let st = std::process::Command::new("python3")
        .arg(&mc)
        .arg(&p)
        .arg("--quiet")
        .status()
        .unwrap();
    assert_eq!(st.code(), Some(1));
}

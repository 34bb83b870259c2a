//! Every writer, read back by `read_mesh`: same points (bit for bit), cells
//! and tags; atomic writes; PVTU; malformed input gives errors, not panics.

mod common;
use common::*;
use parafront_io::*;
use parafront_mesh::{PointId, TetMesh};
use std::path::Path;

fn opts(f: impl FnOnce(&mut WriteOptions)) -> WriteOptions {
    let mut o = WriteOptions::default();
    f(&mut o);
    o
}

/// Regions interleaved (cube parity), so grouping by entity shows.
fn mesh() -> TetMesh {
    let mut m = cube_mesh(3, |c| [7, 0, 3][c % 3]);
    // Values whose shortest text is long or uses exponents.
    m.points[0] = [1e-300, -0.0, 5e-324];
    m
}

#[test]
fn vtu_round_trips_bit_exact() {
    let d = scratch("vtu");
    let m = mesh();
    for (name, o) in [
        ("raw.vtu", opts(|o| o.compress = false)),
        ("zlib.vtu", opts(|_| {})),
        ("zlib9.vtu", opts(|o| o.compress_level = 9)),
        ("int32.vtu", opts(|o| o.vtu_int64 = false)),
    ] {
        let p = d.join(name);
        write_mesh(&p, &m, &o).unwrap();
        let r = read_mesh(&p).unwrap();
        assert_same(&m, &r);
    }
    // Compression does something on this mesh.
    let raw = std::fs::metadata(d.join("raw.vtu")).unwrap().len();
    let z = std::fs::metadata(d.join("zlib.vtu")).unwrap().len();
    assert!(z < raw, "compressed {z} vs raw {raw}");
    assert_eq!(
        listing(&d).len(),
        4,
        "no temp files left: {:?}",
        listing(&d)
    );
}

#[test]
fn vtu_large_arrays_span_several_blocks() {
    let d = scratch("vtu-big");
    let m = cube_mesh(20, |c| c as u32 % 5);
    // 21^3 points * 24 bytes is several 32 KiB blocks.
    assert!(m.points.len() * 24 > 4 * 32768);
    for c in [false, true] {
        let p = d.join(format!("big{c}.vtu"));
        write_mesh(&p, &m, &opts(|o| o.compress = c)).unwrap();
        assert_same(&m, &read_mesh(&p).unwrap());
    }
}

#[test]
fn msh_round_trips_all_versions() {
    let d = scratch("msh");
    let m = mesh();
    for v in [MshVersion::V41, MshVersion::V22] {
        for b in [false, true] {
            let p = d.join(format!("{v:?}-{b}.msh"));
            let o = opts(|o| {
                o.msh_version = v;
                o.binary = b;
                o.region_names = vec![(7, "steel".into()), (0, "air".into())];
                o.patch_names = vec![(10, "x0".into())];
            });
            write_mesh(&p, &m, &o).unwrap();
            let r = read_mesh(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            // 4.1 groups elements by entity; 2.2 keeps the order. Region
            // 0 is there, so the regions come back shifted by 1.
            let want = if v == MshVersion::V41 {
                grouped_by_region(&m)
            } else {
                m.clone()
            };
            assert_same(&gmsh_tags(&want), &r);
            let text = String::from_utf8_lossy(&std::fs::read(&p).unwrap()).into_owned();
            for name in [
                "3 8 \"steel\"",
                "3 1 \"air\"",
                "3 4 \"region 3\"",
                "2 10 \"x0\"",
                "2 11 \"patch 11\"",
            ] {
                assert!(text.contains(name), "{name} not in {}", p.display());
            }
        }
    }
}

#[test]
fn medit_round_trips() {
    let d = scratch("medit");
    let m = mesh();
    let p = d.join("m.mesh");
    write_mesh(&p, &m, &WriteOptions::default()).unwrap();
    assert_same(&m, &read_mesh(&p).unwrap());
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.starts_with("MeshVersionFormatted 2"));
    assert!(text.trim_end().ends_with("End"));
}

#[test]
fn format_from_extension() {
    assert_eq!(Format::from_path(Path::new("a/b.VTU")), Some(Format::Vtu));
    assert_eq!(Format::from_path(Path::new("b.msh")), Some(Format::Msh));
    assert_eq!(Format::from_path(Path::new("b.mesh")), Some(Format::Medit));
    assert_eq!(Format::from_path(Path::new("b.stl")), None);
    let d = scratch("ext");
    let e = write_mesh(&d.join("x.stl"), &mesh(), &WriteOptions::default()).unwrap_err();
    assert!(matches!(e, IoError::UnknownFormat { .. }), "{e}");
    assert!(listing(&d).is_empty());
}

#[test]
fn failed_writes_leave_nothing() {
    let d = scratch("atomic");
    let mut m = mesh();
    m.region.pop();
    for ext in ["vtu", "msh", "mesh"] {
        let p = d.join(format!("bad.{ext}"));
        let e = write_mesh(&p, &m, &WriteOptions::default()).unwrap_err();
        assert!(e.to_string().contains("region ids"), "{e}");
    }
    let mut m = mesh();
    m.tets[5][2] = PointId::from_raw(m.points.len() as u32);
    let e = write_mesh(&d.join("bad.vtu"), &m, &WriteOptions::default()).unwrap_err();
    assert!(e.to_string().contains("tet 5"), "{e}");
    assert!(listing(&d).is_empty(), "{:?}", listing(&d));

    // A writer failing half-way: old file kept, temp file removed.
    let p = d.join("keep.txt");
    std::fs::write(&p, "old").unwrap();
    let e = write_atomic(&p, |w| {
        use std::io::Write;
        w.write_all(b"partial")?;
        Err(std::io::Error::other("disk full"))
    })
    .unwrap_err();
    assert!(e.to_string().contains("disk full") && e.to_string().contains("keep.txt"));
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
    assert_eq!(listing(&d), vec!["keep.txt"]);

    // Missing directory: an error naming the file.
    let e = write_mesh(
        &d.join("no/such/dir.vtu"),
        &mesh(),
        &WriteOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(e, IoError::Io { .. }) && e.to_string().contains("dir.vtu"),
        "{e}"
    );
}

#[test]
fn pvtu_writes_parts_and_index() {
    let d = scratch("pvtu");
    let a = cube_mesh(2, |_| 1);
    let b = cube_mesh(1, |_| 2);
    let gid_a: Vec<i64> = (0..a.points.len() as i64).collect();
    let gid_b: Vec<i64> = (100..100 + b.points.len() as i64).collect();
    let ghost_a = vec![0u8; a.tets.len()];
    let ghost_b = vec![1u8; b.tets.len()];
    let piece = |m: &'static TetMesh, g: &'static [i64], h: &'static [u8]| Piece {
        mesh: m,
        point_fields: vec![Field::scalar("GlobalPointIds", FieldData::I64(g))],
        cell_fields: vec![Field::scalar("vtkGhostType", FieldData::U8(h))],
    };
    let (a, b): (&'static TetMesh, &'static TetMesh) =
        (Box::leak(Box::new(a)), Box::leak(Box::new(b)));
    let (gid_a, gid_b) = (gid_a.leak(), gid_b.leak());
    let (ghost_a, ghost_b) = (ghost_a.leak(), ghost_b.leak());
    let p = d.join("part.pvtu");
    let parts = write_pvtu(
        &p,
        &[piece(a, gid_a, ghost_a), piece(b, gid_b, ghost_b)],
        &WriteOptions::default(),
    )
    .unwrap();
    assert_eq!(listing(&d), vec!["part.pvtu", "part_0.vtu", "part_1.vtu"]);
    assert_eq!(parts, vec![d.join("part_0.vtu"), d.join("part_1.vtu")]);
    assert_same(a, &read_mesh(&parts[0]).unwrap());
    assert_same(b, &read_mesh(&parts[1]).unwrap());
    let idx = std::fs::read_to_string(&p).unwrap();
    for s in [
        "type=\"PUnstructuredGrid\"",
        "<Piece Source=\"part_0.vtu\"/>",
        "<Piece Source=\"part_1.vtu\"/>",
        "GlobalIds=\"GlobalPointIds\"",
        "Name=\"vtkGhostType\"",
        "Name=\"region\"",
    ] {
        assert!(idx.contains(s), "{s} missing in\n{idx}");
    }

    // Parts with different arrays: an error, and nothing of the call left.
    let d2 = scratch("pvtu-bad");
    let e = write_pvtu(
        &d2.join("x.pvtu"),
        &[piece(a, gid_a, ghost_a), Piece::new(b)],
        &WriteOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("part 1"), "{e}");
    assert!(listing(&d2).is_empty(), "{:?}", listing(&d2));

    // A field of the wrong length is refused before any file is made.
    let short = [1.0f64; 3];
    let mut bad = Piece::new(a);
    bad.point_fields
        .push(Field::scalar("size", FieldData::F64(&short)));
    let e = write_vtu(&d2.join("y.vtu"), &bad, &WriteOptions::default()).unwrap_err();
    assert!(e.to_string().contains("\"size\""), "{e}");
    assert!(listing(&d2).is_empty());
}

#[test]
fn read_errors_name_the_problem() {
    let d = scratch("readerr");
    let m = mesh();
    let p = d.join("m.vtu");
    write_mesh(&p, &m, &WriteOptions::default()).unwrap();
    let full = std::fs::read(&p).unwrap();

    let bad = d.join("bad.vtu");
    std::fs::write(&bad, &full[..full.len() / 2]).unwrap();
    let e = read_mesh(&bad).unwrap_err();
    assert!(e.to_string().contains("bad.vtu"), "{e}");

    let text =
        String::from_utf8_lossy(&full).replace("UnstructuredGrid\" version", "PolyData\" version");
    std::fs::write(&bad, text.as_bytes()).unwrap();
    // Lossy text damages the binary part; the type check comes first anyway.
    assert!(read_mesh(&bad)
        .unwrap_err()
        .to_string()
        .contains("PolyData"));

    let e = read_mesh(&d.join("missing.msh")).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }), "{e}");

    std::fs::write(d.join("t.msh"), "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 4 2 0 0 1 2 3 4\n$EndElements\n").unwrap();
    let e = read_mesh(&d.join("t.msh")).unwrap_err();
    assert!(e.to_string().contains("t.msh"), "{e}");
}

#[test]
fn corrupt_vtu_never_panics() {
    let d = scratch("fuzz");
    let m = cube_mesh(1, |_| 0);
    for (k, compress) in [false, true].into_iter().enumerate() {
        let p = d.join(format!("m{k}.vtu"));
        write_mesh(&p, &m, &opts(|o| o.compress = compress)).unwrap();
        let full = std::fs::read(&p).unwrap();
        let q = d.join("c.vtu");
        let start = full
            .windows(13)
            .position(|w| w == b"<AppendedData")
            .unwrap();
        for cut in (0..full.len()).step_by(7) {
            std::fs::write(&q, &full[..cut]).unwrap();
            let _ = read_mesh(&q);
        }
        // Flip bytes in the binary part: headers, sizes, zlib streams.
        for i in (start..full.len()).step_by(3) {
            let mut b = full.clone();
            b[i] ^= 0xA5;
            std::fs::write(&q, &b).unwrap();
            if let Ok(r) = read_mesh(&q) {
                // Whatever was read is in range.
                assert!(r.tets.iter().flatten().all(|p| p.idx() < r.points.len()));
            }
        }
    }
}

#[test]
fn reads_base64_appended_big_endian_vtu() {
    // Made with Python's struct/base64; meshio reads the same values.
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data_b64be.vtu");
    let m = read_mesh(&p).unwrap();
    assert_eq!(
        m.points,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.5]
        ]
    );
    assert_eq!(m.tets, vec![[0, 1, 2, 3].map(PointId::from_raw)]);
    assert_eq!(m.region, vec![4]);
    assert_eq!(m.bnd_tris, vec![[0, 2, 1].map(PointId::from_raw)]);
    assert_eq!(m.bnd_patch, vec![9]);
}

const ASCII_VTU: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="5" NumberOfCells="3">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">
          0 0 0  1 0 0  0 1 0  0 0 1  0.1 0.2 0.30000000000000004
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">4 0 1 2 3 0 2 1</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">1 5 8</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">1 10 5</DataArray>
      </Cells>
      <CellData>
        <DataArray type="Int32" Name="medit:ref" format="ascii">0 2 3</DataArray>
      </CellData>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;

#[test]
fn reads_ascii_vtu_and_rejects_other_cells() {
    let d = scratch("ascii-vtu");
    let p = d.join("a.vtu");
    std::fs::write(&p, ASCII_VTU).unwrap();
    let m = read_mesh(&p).unwrap();
    assert_eq!(m.points.len(), 5);
    assert_eq!(m.points[4][2].to_bits(), (0.1f64 + 0.2).to_bits());
    // The vertex cell is skipped; tags come from medit:ref.
    assert_eq!((m.tets.len(), m.region.clone()), (1, vec![2]));
    assert_eq!(
        (m.bnd_tris.clone(), m.bnd_patch.clone()),
        (vec![[0, 2, 1].map(PointId::from_raw)], vec![3])
    );

    std::fs::write(&p, ASCII_VTU.replace("1 10 5", "1 12 5")).unwrap();
    let e = read_mesh(&p).unwrap_err().to_string();
    assert!(
        e.contains("a.vtu") && e.contains("cell 1") && e.contains("type 12"),
        "{e}"
    );

    std::fs::write(&p, ASCII_VTU.replace("4 0 1 2 3 0 2 1", "4 0 1 2 9 0 2 1")).unwrap();
    let e = read_mesh(&p).unwrap_err().to_string();
    assert!(e.contains("cell 1 refers to point 9"), "{e}");

    std::fs::write(&p, ASCII_VTU.replace("0.1 0.2", "0.1 x")).unwrap();
    let e = read_mesh(&p).unwrap_err().to_string();
    assert!(e.contains("\"x\" is not a number"), "{e}");
}

mod prop {
    use super::*;
    use proptest::prelude::*;

    fn finite() -> impl Strategy<Value = f64> {
        any::<u64>()
            .prop_map(f64::from_bits)
            .prop_filter("finite", |x| x.is_finite())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Any finite coordinates survive every writer bit for bit (ascii
        /// writers print the shortest round-trip text).
        #[test]
        fn coordinates_round_trip(xs in proptest::collection::vec(finite(), 12), r in 0u32..1000, t in 0u32..1000) {
            let d = scratch("prop");
            let m = TetMesh {
                points: xs.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
                tets: vec![[0, 1, 2, 3].map(PointId::from_raw)],
                region: vec![r],
                bnd_tris: vec![[0, 2, 1].map(PointId::from_raw)],
                bnd_patch: vec![t],
                ..Default::default()
            };
            for (name, o) in [
                ("a.vtu", WriteOptions::default()),
                ("a.msh", WriteOptions::default()),
                ("b.msh", opts(|o| o.binary = true)),
                ("c.msh", opts(|o| o.msh_version = MshVersion::V22)),
                ("a.mesh", WriteOptions::default()),
            ] {
                let p = d.join(name);
                write_mesh(&p, &m, &o).unwrap();
                let want = if name.ends_with(".msh") { gmsh_tags(&m) } else { m.clone() };
                assert_same(&want, &read_mesh(&p).unwrap());
            }
        }
    }
}

/// `u32` ids plus an offset are written as the `Int64` array of their
/// sums, byte for byte, cell arrays padded over the triangles alike.
#[test]
fn ids_from_u32_write_as_their_int64_sums() {
    let d = scratch("i64from");
    let m = mesh();
    let ids: Vec<u32> = (0..m.points.len() as u32).map(|i| 7 * i).collect();
    let cells: Vec<u32> = (0..m.tets.len() as u32).rev().collect();
    let wide = |v: &[u32], o: i64| v.iter().map(|&x| o + x as i64).collect::<Vec<i64>>();
    let (ids64, cells64) = (wide(&ids, 0), wide(&cells, 1 << 40));
    let write = |name: &str, p: FieldData, c: FieldData| {
        let piece = Piece {
            mesh: &m,
            point_fields: vec![Field::scalar("GlobalPointIds", p)],
            cell_fields: vec![Field::scalar("GlobalCellIds", c)],
        };
        let path = d.join(name);
        write_vtu(&path, &piece, &WriteOptions::default()).unwrap();
        std::fs::read(&path).unwrap()
    };
    let a = write("a.vtu", FieldData::I64(&ids64), FieldData::I64(&cells64));
    let b = write(
        "b.vtu",
        FieldData::I64From(&ids, 0),
        FieldData::I64From(&cells, 1 << 40),
    );
    assert!(!m.bnd_tris.is_empty(), "the cell arrays are padded");
    assert_eq!(a, b);
}

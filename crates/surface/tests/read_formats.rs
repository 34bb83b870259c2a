//! Every reader on small hand-written (or test-written) files: counts,
//! exact coordinates, tags and names; and the error messages.

mod read_common;

use parafront_surface::read::{
    self, medit, msh, read_surface, read_surface_bytes, Format, Loc, ReadError, VolumeData,
};
use parafront_surface::Surface;
use read_common::*;

type Tri = [[f64; 3]; 3];

fn coords(s: &Surface) -> Vec<Tri> {
    s.tris
        .iter()
        .map(|t| t.map(|i| s.points[i as usize]))
        .collect()
}

fn expected_coords() -> Vec<Tri> {
    T.iter().map(|t| t.map(|i| P[i as usize])).collect()
}

fn read(name: &str, b: &[u8], f: Format) -> Surface {
    read_surface_bytes(name, b, f).unwrap_or_else(|e| panic!("{e}"))
}

fn err(name: &str, b: &[u8], f: Format) -> ReadError {
    match read_surface_bytes(name, b, f) {
        Ok(s) => panic!("{name}: expected an error, read {} triangles", s.tris.len()),
        Err(e) => e,
    }
}

fn replace(b: &[u8], from: &str, to: &str) -> Vec<u8> {
    let s = String::from_utf8(b.to_vec()).unwrap();
    assert!(s.contains(from), "sample lacks {from:?}");
    s.replacen(from, to, 1).into_bytes()
}

// ---- STL ----

#[test]
fn stl_ascii_solids_become_patches_and_weld_exactly() {
    let s = read("a.stl", &stl_ascii(), Format::Stl);
    assert_eq!(
        s.points,
        vec![
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0]
        ]
    );
    assert_eq!(s.tris, vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [2, 1, 3]]);
    assert_eq!(s.patch, vec![0, 0, 1, 1]);
    assert_eq!(
        s.patch_names,
        vec![(0, "Left side".to_string()), (1, "right".to_string())]
    );
    assert!(s.points[0][0].is_sign_positive(), "-0 welded to +0");
}

#[test]
fn stl_ascii_no_tolerance_weld() {
    // 1 and 1+ulp must stay two points.
    let b = replace(
        &stl_ascii(),
        "vertex 1.0 0 0",
        "vertex 1.0000000000000002 0 0",
    );
    let s = read("a.stl", &b, Format::Stl);
    assert_eq!(s.points.len(), 5);
    assert_eq!(s.points[4], [1.0000000000000002, 0.0, 0.0]);
}

#[test]
fn stl_binary_starting_with_solid_round_trips() {
    let b = stl_binary();
    assert!(b.starts_with(b"solid"));
    let s = read("b.stl", &b, Format::Stl);
    assert_eq!(s.points.len(), 4, "point 4 is not in any triangle");
    assert_eq!(s.tris.len(), 4);
    assert_eq!(coords(&s), expected_coords());
    assert_eq!(s.patch, vec![0; 4]);
}

#[test]
fn stl_errors() {
    let e = err("a.stl", &stl_ascii()[..300], Format::Stl);
    assert!(e.to_string().starts_with("a.stl:"), "{e}");
    let b = replace(&stl_ascii(), "vertex 0 0 1e0", "vertex 0 nan 1");
    assert_eq!(
        err("a.stl", &b, Format::Stl).to_string(),
        "a.stl:21: vertex coordinate is not finite (NaN)"
    );
    let b = replace(&stl_ascii(), "vertex 0 0 1e0", "vertex 0 1e999 1");
    assert_eq!(err("a.stl", &b, Format::Stl).loc(), Loc::Line(21));
    let b = replace(
        &stl_ascii(),
        "    endloop\r\n",
        "      vertex 0 0 0\r\n    endloop\r\n",
    );
    assert_eq!(
        err("a.stl", &b, Format::Stl).to_string(),
        "a.stl:23: facet has more than 3 vertices"
    );
    let mut b = stl_ascii();
    let at = b.windows(8).position(|w| w == b"endsolid").unwrap();
    b[at..at + 2].copy_from_slice(b"\xff\xfe");
    assert!(err("a.stl", &b, Format::Stl)
        .to_string()
        .starts_with("a.stl:16: unexpected"));
    // Binary: truncated by a byte, and a NaN in triangle 1, vertex 2.
    let b = stl_binary();
    let e = err("b.stl", &b[..b.len() - 1], Format::Stl);
    assert!(e.to_string().contains("header says 4 triangles"), "{e}");
    let mut b = stl_binary();
    let at = 84 + 50 + 12 + 24;
    b[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let e = err("b.stl", &b, Format::Stl);
    assert_eq!(e.loc(), Loc::Byte(at));
    assert!(
        e.to_string()
            .starts_with("b.stl: byte 170: triangle 1 vertex 2"),
        "{e}"
    );
    let e = err("tiny.stl", b"\x00\x01", Format::Stl);
    assert!(e.to_string().contains("truncated"), "{e}");
    let e = err("empty.stl", b"", Format::Stl);
    assert!(e.to_string().starts_with("empty.stl"), "{e}");
}

// ---- OBJ ----

#[test]
fn obj_quads_groups() {
    let s = read("cube.obj", &obj_cube(), Format::Obj);
    assert_eq!(s.points.len(), 8);
    assert_eq!(s.points[6], [1.0, 1.0, 1.0]);
    assert_eq!(s.tris.len(), 12);
    assert_eq!(&s.tris[..2], &[[0, 3, 2], [0, 2, 1]]);
    assert_eq!(s.tris[11], [4, 6, 7]);
    let mut want = vec![0, 0];
    want.extend([1; 8]);
    want.extend([2, 2]);
    assert_eq!(s.patch, want);
    let names: Vec<_> = s
        .patch_names
        .iter()
        .map(|(t, n)| (*t, n.as_str()))
        .collect();
    assert_eq!(names, vec![(0, "bottom"), (1, "sides"), (2, "top")]);
}

#[test]
fn obj_face_syntaxes_and_negative_indices() {
    let s = read("mixed.obj", &obj_mixed(), Format::Obj);
    assert_eq!(s.points, P[..4].to_vec());
    assert_eq!(s.tris, T.to_vec());
    assert_eq!(s.patch, vec![0; 4]);
    assert!(s.patch_names.is_empty());
}

#[test]
fn obj_errors() {
    let b = replace(&obj_cube(), "f 4 1 5 8", "f 4 1 9 8");
    assert_eq!(
        err("cube.obj", &b, Format::Obj).to_string(),
        "cube.obj:16: face index 9 out of range (file has 8 vertices)"
    );
    let b = replace(&obj_cube(), "f 4 1 5 8", "f 4 0 5 8");
    assert!(err("cube.obj", &b, Format::Obj)
        .to_string()
        .starts_with("cube.obj:16: face index 0 out of range"));
    let b = replace(&obj_cube(), "f 4 1 5 8", "f 4 -9 5 8");
    assert_eq!(err("cube.obj", &b, Format::Obj).loc(), Loc::Line(16));
    let b = replace(&obj_cube(), "f 4 1 5 8", "f 4 1");
    assert_eq!(
        err("cube.obj", &b, Format::Obj).to_string(),
        "cube.obj:16: face has 2 vertices, needs 3"
    );
    let b = replace(&obj_cube(), "v 1 1 1", "v 1 inf 1");
    assert_eq!(
        err("cube.obj", &b, Format::Obj).to_string(),
        "cube.obj:8: vertex 7 coordinate 1 is not finite (inf)"
    );
    let b = replace(&obj_cube(), "v 1 1 1", "v 1 x 1");
    assert!(err("cube.obj", &b, Format::Obj)
        .to_string()
        .starts_with("cube.obj:8: expected a coordinate"));
    let mut b = obj_cube();
    b.extend_from_slice(b"\xff\xfe\x00garbage\n");
    assert_eq!(err("cube.obj", &b, Format::Obj).loc(), Loc::Line(19));
}

// ---- OFF ----

#[test]
fn off_polygons_comments_colours() {
    let s = read("a.off", &off(), Format::Off);
    assert_eq!(s.points, P.to_vec(), "unused point kept");
    assert_eq!(s.tris, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [0, 2, 1]]);
    assert_eq!(s.patch, vec![0; 4]);
    let s = read("c.off", &coff(), Format::Off);
    assert_eq!(s.points, P[..4].to_vec());
    assert_eq!(s.tris, T.to_vec());
}

#[test]
fn off_errors() {
    let b = replace(&off(), "3 0 1 3", "3 0 1 5");
    assert_eq!(
        err("a.off", &b, Format::Off).to_string(),
        "a.off:10: face 1: vertex index 5 out of range (file has 5 vertices)"
    );
    let b = replace(&off(), "5 3 0", "99999999999999 3 0");
    assert!(err("a.off", &b, Format::Off)
        .to_string()
        .contains("too large"));
    let b = replace(&off(), "5 3 0", "4000000000 3 0");
    assert!(err("a.off", &b, Format::Off)
        .to_string()
        .contains("unexpected end of file"));
    let b = replace(&off(), "0 1 0\n", "0 NaN 0\n");
    assert_eq!(
        err("a.off", &b, Format::Off).to_string(),
        "a.off:6: vertex 2 coordinate 1 is not finite (NaN)"
    );
    let b = replace(&off(), "OFF", "PLY");
    assert!(err("a.off", &b, Format::Off)
        .to_string()
        .starts_with("a.off:1: expected 'OFF' header"));
    assert!(err("a.off", &off()[..60], Format::Off)
        .to_string()
        .contains("unexpected end of file"));
}

// ---- Medit ----

fn expected_volume() -> VolumeData {
    VolumeData {
        points: P.to_vec(),
        tris: T.to_vec(),
        tri_tags: vec![5, 5, 2, 2],
        tets: vec![[0, 1, 2, 3]],
        tet_tags: vec![7],
        names: vec![(5, "wall".into())],
        volume_names: vec![(7, "body".into())],
    }
}

#[test]
fn medit_reads_triangles_and_tets_with_refs() {
    let d = medit::parse("a.mesh", &medit()).unwrap();
    let want = VolumeData {
        names: vec![],
        volume_names: vec![],
        ..expected_volume()
    };
    assert_eq!(d, want);
    let s = read("a.mesh", &medit(), Format::Medit);
    assert_eq!(s.patch, vec![5, 5, 2, 2]);
}

#[test]
fn medit_errors() {
    let b = replace(&medit(), "1 4 3 2\n", "1 4 0 2\n");
    assert_eq!(
        err("a.mesh", &b, Format::Medit).to_string(),
        "a.mesh:19: triangle 3: vertex index 0 out of range (file has 5 vertices)"
    );
    let b = replace(&medit(), "End\n", "");
    assert!(err("a.mesh", &b, Format::Medit)
        .to_string()
        .contains("missing 'End'"));
    let b = replace(&medit(), "Dimension\n3", "Dimension\n2");
    assert_eq!(err("a.mesh", &b, Format::Medit).loc(), Loc::Line(4));
    let b = replace(&medit(), "Edges", "Bogus");
    assert!(err("a.mesh", &b, Format::Medit)
        .to_string()
        .contains("unknown keyword 'Bogus'"));
}

// ---- Gmsh ----

#[test]
fn msh_all_variants_read_the_same_data() {
    for (name, b) in [
        ("a2.msh", msh2(false)),
        ("b2.msh", msh2(true)),
        ("a4.msh", msh4(false)),
        ("b4.msh", msh4(true)),
    ] {
        let d = msh::parse(name, &b).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(d, expected_volume(), "{name}");
        let s = read(name, &b, Format::Msh);
        assert_eq!(s.points.len(), 5, "{name}");
        assert_eq!(s.patch, vec![5, 5, 2, 2], "{name}");
        assert_eq!(s.patch_names, vec![(5, "wall".to_string())], "{name}");
    }
}

#[test]
fn msh_skips_other_element_types() {
    let b = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n6\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
4 0.5 0 0\n5 0.5 0.5 0\n6 0 0.5 0\n$EndNodes\n$Elements\n4\n1 15 2 0 1 1\n\
2 9 2 0 1 1 2 3 4 5 6\n3 2 2 0 1 1 2 3\n4 2 0 1 3 2\n$EndElements\n";
    let d = msh::parse("s.msh", b).unwrap();
    assert_eq!(d.tris, vec![[0, 1, 2], [0, 2, 1]]);
    assert_eq!(d.tri_tags, vec![1, 0]);
    // 4.1 ascii: a block of an unknown type is skipped line by line.
    let b = replace(
        &msh4(false),
        "$Elements\n4 6 1 6\n",
        "$Elements\n5 8 1 8\n2 1 99 2\n7 1 2\n8 2 3\n",
    );
    let d = msh::parse("a4.msh", &b).unwrap();
    assert_eq!(d, expected_volume());
}

#[test]
fn msh_errors() {
    let mut b = msh2(true);
    let at = b.windows(4).position(|w| w == 1i32.to_le_bytes()).unwrap();
    b[at..at + 4].copy_from_slice(&1i32.to_be_bytes());
    let e = msh::parse("b2.msh", &b).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("b2.msh: byte {at}: big-endian binary .msh is not supported")
    );
    let b = replace(
        &msh2(false),
        "6 4 2 7 1 10 20 30 40",
        "6 4 2 7 1 10 20 30 41",
    );
    assert_eq!(
        msh::parse("a2.msh", &b).unwrap_err().to_string(),
        "a2.msh:27: element 6 references node 41, which is not in $Nodes"
    );
    let b = replace(&msh2(false), "20 1.0 0.0 0.0", "20 1.0 inf 0.0");
    assert_eq!(
        msh::parse("a2.msh", &b).unwrap_err().to_string(),
        "a2.msh:15: node 20 coordinate 1 is not finite (inf)"
    );
    let b = replace(&msh2(false), "30 0.0 1.0 0.0", "20 0.0 1.0 0.0");
    assert!(msh::parse("a2.msh", &b)
        .unwrap_err()
        .to_string()
        .contains("duplicate node tag 20"));
    let b = replace(&msh4(false), "4.1 0 8", "4.0 0 8");
    assert!(msh::parse("a4.msh", &b)
        .unwrap_err()
        .to_string()
        .starts_with("a4.msh:2: unsupported .msh version '4.0'"));
    // Binary: every truncation is an error, never a panic.
    // Success only where the cut falls just after a complete section.
    for b in [msh2(true), msh4(true)] {
        for cut in 0..b.len() {
            if msh::parse("t.msh", &b[..cut]).is_ok() {
                let t = b[..cut].trim_ascii_end();
                let last = t.rsplit(|&c| c == b'\n').next().unwrap();
                assert!(last.starts_with(b"$End"), "cut {cut} read Ok");
            }
        }
    }
    // A node count far larger than the file.
    let mut b = msh4(true);
    let at = b.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7;
    b[at..at + 8].copy_from_slice(&1u64.to_le_bytes()); // one block...
    let blk = at + 32 + 12;
    b[blk..blk + 8].copy_from_slice(&(u64::MAX / 2).to_le_bytes()); // ...of 2^63 nodes
    let e = msh::parse("b4.msh", &b).unwrap_err();
    assert!(e.to_string().contains("needs more bytes"), "{e}");
    let e = msh::parse("x.msh", b"solid x\n").unwrap_err();
    assert_eq!(
        e.to_string(),
        "x.msh:1: expected a section header such as $Nodes, found 'solid x'"
    );
}

// ---- dispatch ----

#[test]
fn read_surface_dispatches_by_extension_case_insensitively() {
    let dir = std::env::temp_dir().join(format!("parafront-read-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, _, b) in samples() {
        let upper = name.to_uppercase();
        let path = dir.join(&upper);
        std::fs::write(&path, &b).unwrap();
        let s = read_surface(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.tris.len() >= 4, "{upper}");
        assert_eq!(s.tris.len(), s.patch.len(), "{upper}");
    }
    let path = dir.join("x.ply");
    std::fs::write(&path, b"ply").unwrap();
    assert!(matches!(
        read_surface(&path),
        Err(ReadError::UnknownFormat { .. })
    ));
    let e = read_surface(&dir.join("missing.obj")).unwrap_err();
    assert!(e.to_string().starts_with("missing.obj: "), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(Format::from_path("a/B.MeSh".as_ref()), Some(Format::Medit));
    let _ = read::Format::Stl;
}

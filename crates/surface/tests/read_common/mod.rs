//! Sample files for the reader tests, written in code: one small valid
//! file per format and variant, and writers for the binary formats.
#![allow(dead_code)]

use parafront_surface::read::Format;

/// The unit tetrahedron, outward triangles; point 4 only on a line element.
pub const P: [[f64; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.5, 0.5, -1.25],
];
pub const T: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// Sparse node tags used in the .msh samples.
pub const TAGS: [u64; 5] = [10, 20, 30, 40, 77];

pub fn stl_ascii() -> Vec<u8> {
    // Two solids, mixed-case keywords, -0 that must weld with 0.
    b"solid Left side\n\
  facet normal 0 0 -1\n    outer loop\n      vertex 0 0 0\n      vertex 0 1 0\n      vertex 1 0 0\n    endloop\n  endfacet\n\
  FACET NORMAL 0 -1 0\n    OUTER LOOP\n      VERTEX -0 0 0\n      VERTEX 1 0 0\n      VERTEX 0 0 1\n    ENDLOOP\n  ENDFACET\n\
endsolid Left side\n\
solid right\r\n\
  facet normal -1 0 0\r\n    outer loop\r\n      vertex 0 0 0\r\n      vertex 0 0 1e0\r\n      vertex 0 1 0\r\n    endloop\r\n  endfacet\r\n\
  facet normal 1 1 1\n    outer loop\n      vertex 1.0 0 0\n      vertex 0 1 0\n      vertex 0 0 1\n    endloop\n  endfacet\n\
endsolid\n"
        .to_vec()
}

/// Binary STL of the tetrahedron; the header starts with "solid" on purpose.
pub fn stl_binary() -> Vec<u8> {
    let mut b = b"solid but binary".to_vec();
    b.resize(80, b' ');
    b.extend_from_slice(&(T.len() as u32).to_le_bytes());
    for t in T {
        b.extend_from_slice(&[0u8; 12]);
        for v in t {
            for x in P[v as usize] {
                b.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

/// A cube of quads in three groups (18 lines).
pub fn obj_cube() -> Vec<u8> {
    b"# cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
g bottom\nf 1 4 3 2\ng sides\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\no top\nf 5 6 7 8\n"
        .to_vec()
}

/// All face syntaxes and negative indices, texture and normal data.
pub fn obj_mixed() -> Vec<u8> {
    b"mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvn 0 0 1\n\
usemtl m\ns off\nf 1/1 3/2 2/1\nf 1//1 2//1 4//1\nf 1/1/1 4/2/1 3/1/1\nf -3 -2 -1\n"
        .to_vec()
}

pub fn off() -> Vec<u8> {
    b"OFF\n# a comment\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 0.5 -1.25 # unused\n\
3 0 2 1\n3 0 1 3\n4 0 3 2 1\n"
        .to_vec()
}

pub fn coff() -> Vec<u8> {
    b"COFF\n4 4 6\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n0 1 0 0 0 255 255\n0 0 1 0 0 255 255\n\
3 0 2 1 0.5 0.5 0.5\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
        .to_vec()
}

pub fn medit() -> Vec<u8> {
    b"MeshVersionFormatted 2\n# comment\nDimension\n3\nVertices\n5\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n0.5 0.5 -1.25 0\n\
Edges\n1\n1 5 3\nTriangles\n4\n1 3 2 5\n1 2 4 5\n1 4 3 2\n2 3 4 2\nTetrahedra\n1\n1 2 3 4 7\nEnd\n"
        .to_vec()
}

fn le32(b: &mut Vec<u8>, v: i32) {
    b.extend_from_slice(&v.to_le_bytes());
}
fn le64(b: &mut Vec<u8>, v: u64) {
    b.extend_from_slice(&v.to_le_bytes());
}
fn f64s(b: &mut Vec<u8>, v: &[f64]) {
    for x in v {
        b.extend_from_slice(&x.to_le_bytes());
    }
}

/// Elements of the .msh samples: (type, entity dim, entity, physical,
/// node tags). Triangles on surface 1 (physical 5) and 2 (none), a tet
/// in volume 1 (physical 7) and a line on curve 3.
fn msh_elements() -> Vec<(i32, i32, i32, i32, Vec<u64>)> {
    let nt = |i: u32| TAGS[i as usize];
    let mut e = vec![(1, 1, 3, 0, vec![10, 77])];
    for (k, t) in T.iter().enumerate() {
        let (ent, phys) = if k < 2 { (1, 5) } else { (2, 0) };
        e.push((2, 2, ent, phys, t.iter().map(|&i| nt(i)).collect()));
    }
    e.push((4, 3, 1, 7, vec![10, 20, 30, 40]));
    e
}

const NAMES: &str = "$PhysicalNames\n2\n2 5 \"wall\"\n3 7 \"body\"\n$EndPhysicalNames\n";

/// MSH 2.2, ascii or binary, of the sample.
pub fn msh2(binary: bool) -> Vec<u8> {
    let mut b = Vec::new();
    if binary {
        b.extend_from_slice(b"$MeshFormat\n2.2 1 8\n");
        le32(&mut b, 1);
        b.extend_from_slice(b"\n$EndMeshFormat\n");
    } else {
        b.extend_from_slice(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    }
    b.extend_from_slice(b"$Comments\nskipped $Nodes\n$EndComments\n");
    b.extend_from_slice(NAMES.as_bytes());
    b.extend_from_slice(format!("$Nodes\n{}\n", P.len()).as_bytes());
    for (t, p) in TAGS.iter().zip(P) {
        if binary {
            le32(&mut b, *t as i32);
            f64s(&mut b, &p);
        } else {
            b.extend_from_slice(format!("{t} {:?} {:?} {:?}\n", p[0], p[1], p[2]).as_bytes());
        }
    }
    b.extend_from_slice(if binary {
        b"\n$EndNodes\n"
    } else {
        b"$EndNodes\n"
    });
    let els = msh_elements();
    b.extend_from_slice(format!("$Elements\n{}\n", els.len()).as_bytes());
    for (id, (ty, _, ent, phys, nodes)) in els.iter().enumerate() {
        if binary {
            for v in [*ty, 1, 2, id as i32 + 1, *phys, *ent] {
                le32(&mut b, v);
            }
            for &n in nodes {
                le32(&mut b, n as i32);
            }
        } else {
            let ns: Vec<String> = nodes.iter().map(|n| n.to_string()).collect();
            b.extend_from_slice(
                format!("{} {ty} 2 {phys} {ent} {}\n", id + 1, ns.join(" ")).as_bytes(),
            );
        }
    }
    b.extend_from_slice(if binary {
        b"\n$EndElements\n"
    } else {
        b"$EndElements\n"
    });
    b
}

/// MSH 4.1, ascii or binary, of the sample. Nodes in two blocks, the
/// second one parametric on a curve (one extra value per node).
pub fn msh4(binary: bool) -> Vec<u8> {
    let mut b = Vec::new();
    let ascii = |b: &mut Vec<u8>, s: String| b.extend_from_slice(s.as_bytes());
    if binary {
        b.extend_from_slice(b"$MeshFormat\n4.1 1 8\n");
        le32(&mut b, 1);
        b.extend_from_slice(b"\n$EndMeshFormat\n");
    } else {
        b.extend_from_slice(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    }
    b.extend_from_slice(NAMES.as_bytes());
    // Entities: 0 points, curve 3, surfaces 1 (phys 5) and 2, volume 1 (phys 7).
    b.extend_from_slice(b"$Entities\n");
    // (dim, tag, physicals, bounding)
    let ents: [(usize, i32, Vec<i32>, Vec<i32>); 4] = [
        (1, 3, vec![], vec![]),
        (2, 1, vec![5], vec![3]),
        (2, 2, vec![], vec![]),
        (3, 1, vec![7], vec![1, -2]),
    ];
    if binary {
        for n in [0u64, 1, 2, 1] {
            le64(&mut b, n);
        }
        for (_, tag, ph, bd) in &ents {
            le32(&mut b, *tag);
            f64s(&mut b, &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
            le64(&mut b, ph.len() as u64);
            ph.iter().for_each(|&p| le32(&mut b, p));
            le64(&mut b, bd.len() as u64);
            bd.iter().for_each(|&p| le32(&mut b, p));
        }
        b.push(b'\n');
    } else {
        ascii(&mut b, "0 1 2 1\n".into());
        for (_, tag, ph, bd) in &ents {
            let j = |v: &Vec<i32>| v.iter().map(|x| format!(" {x}")).collect::<String>();
            ascii(
                &mut b,
                format!(
                    "{tag} 0 0 0 1 1 1 {}{} {}{}\n",
                    ph.len(),
                    j(ph),
                    bd.len(),
                    j(bd)
                ),
            );
        }
    }
    b.extend_from_slice(b"$EndEntities\n$Nodes\n");
    // (dim, entity, parametric, node indices)
    let blocks: [(i32, i32, i32, Vec<usize>); 2] =
        [(2, 1, 0, vec![0, 1, 2]), (1, 3, 1, vec![3, 4])];
    if binary {
        for v in [2u64, 5, 10, 77] {
            le64(&mut b, v);
        }
        for (dim, ent, par, idx) in &blocks {
            for v in [*dim, *ent, *par] {
                le32(&mut b, v);
            }
            le64(&mut b, idx.len() as u64);
            idx.iter().for_each(|&i| le64(&mut b, TAGS[i]));
            for &i in idx {
                f64s(&mut b, &P[i]);
                if *par == 1 {
                    f64s(&mut b, &[0.25]);
                }
            }
        }
        b.push(b'\n');
    } else {
        ascii(&mut b, "2 5 10 77\n".into());
        for (dim, ent, par, idx) in &blocks {
            ascii(&mut b, format!("{dim} {ent} {par} {}\n", idx.len()));
            idx.iter()
                .for_each(|&i| ascii(&mut b, format!("{}\n", TAGS[i])));
            for &i in idx {
                let p = P[i];
                let u = if *par == 1 { " 0.25" } else { "" };
                ascii(&mut b, format!("{:?} {:?} {:?}{u}\n", p[0], p[1], p[2]));
            }
        }
    }
    b.extend_from_slice(b"$EndNodes\n$Elements\n");
    // One block per (type, entity).
    let els = msh_elements();
    type Block = ((i32, i32, i32), Vec<(u64, Vec<u64>)>);
    let mut groups: Vec<Block> = Vec::new();
    for (id, (ty, dim, ent, _, nodes)) in els.into_iter().enumerate() {
        let key = (dim, ent, ty);
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1.push((id as u64 + 1, nodes)),
            None => groups.push((key, vec![(id as u64 + 1, nodes)])),
        }
    }
    if binary {
        for v in [groups.len() as u64, 6, 1, 6] {
            le64(&mut b, v);
        }
        for ((dim, ent, ty), es) in &groups {
            for v in [*dim, *ent, *ty] {
                le32(&mut b, v);
            }
            le64(&mut b, es.len() as u64);
            for (id, nodes) in es {
                le64(&mut b, *id);
                nodes.iter().for_each(|&n| le64(&mut b, n));
            }
        }
        b.push(b'\n');
    } else {
        ascii(&mut b, format!("{} 6 1 6\n", groups.len()));
        for ((dim, ent, ty), es) in &groups {
            ascii(&mut b, format!("{dim} {ent} {ty} {}\n", es.len()));
            for (id, nodes) in es {
                let ns: String = nodes.iter().map(|n| format!(" {n}")).collect();
                ascii(&mut b, format!("{id}{ns}\n"));
            }
        }
    }
    b.extend_from_slice(b"$EndElements\n");
    b
}

/// Every sample: (name, format, bytes).
pub fn samples() -> Vec<(&'static str, Format, Vec<u8>)> {
    vec![
        ("a.stl", Format::Stl, stl_ascii()),
        ("b.stl", Format::Stl, stl_binary()),
        ("cube.obj", Format::Obj, obj_cube()),
        ("mixed.obj", Format::Obj, obj_mixed()),
        ("a.off", Format::Off, off()),
        ("c.off", Format::Off, coff()),
        ("a.mesh", Format::Medit, medit()),
        ("a2.msh", Format::Msh, msh2(false)),
        ("b2.msh", Format::Msh, msh2(true)),
        ("a4.msh", Format::Msh, msh4(false)),
        ("b4.msh", Format::Msh, msh4(true)),
    ]
}

//! Medit .mesh (ascii): `Vertices`, `Triangles` and `Tetrahedra` with
//! their references (the tags); other known sections are skipped.
//! Indices in the file are 1-based.

use super::cursor::{cap, show, Cur, Res};
use super::VolumeData;

/// What [`parse`] returns.
pub type MeditData = VolumeData;

/// Values per entry of the sections we skip (at dimension 3).
fn skip_width(kw: &[u8]) -> Option<usize> {
    const W: [(&str, usize); 17] = [
        ("Edges", 3),
        ("Quadrilaterals", 5),
        ("Hexahedra", 9),
        ("Prisms", 7),
        ("Pyramids", 6),
        ("Corners", 1),
        ("Ridges", 1),
        ("RequiredVertices", 1),
        ("RequiredEdges", 1),
        ("RequiredTriangles", 1),
        ("RequiredQuadrilaterals", 1),
        ("RequiredTetrahedra", 1),
        ("Normals", 3),
        ("Tangents", 3),
        ("NormalAtVertices", 2),
        ("NormalAtTriangleVertices", 3),
        ("TangentAtEdgeVertices", 3),
    ];
    W.iter()
        .find(|(k, _)| kw.eq_ignore_ascii_case(k.as_bytes()))
        .map(|&(_, w)| w)
}

/// Parses a .mesh file held in memory; `name` is used in errors only.
pub fn parse(name: &str, bytes: &[u8]) -> Res<MeditData> {
    let mut c = Cur::new(name, bytes, Some(b'#'));
    let mut d = VolumeData::default();
    let mut have_vertices = false;
    let mut ended = false;
    while let Some(kw) = c.token() {
        let is = |k: &str| kw.eq_ignore_ascii_case(k.as_bytes());
        if is("MeshVersionFormatted") {
            let v = c.i64("format version")?;
            if !(1..=4).contains(&v) {
                return Err(c.err(format!("unsupported MeshVersionFormatted {v}")));
            }
        } else if is("Dimension") {
            let dim = c.i64("dimension")?;
            if dim != 3 {
                return Err(c.err(format!("dimension {dim} is not supported (expected 3)")));
            }
        } else if is("Vertices") {
            if have_vertices {
                return Err(c.err("second Vertices section"));
            }
            have_vertices = true;
            let n = c.u64("number of vertices")?;
            if n > u32::MAX as u64 {
                return Err(c.err(format!("{n} vertices is too many for 32-bit indices")));
            }
            d.points.reserve(cap(n, c.remaining(), 8));
            for i in 1..=n {
                let mut p = [0.0; 3];
                for (k, x) in p.iter_mut().enumerate() {
                    *x = c.coord(&format!("vertex {i} coordinate {k}"))?;
                }
                c.i64("vertex reference")?;
                d.points.push(p);
            }
        } else if is("Triangles") || is("Tetrahedra") {
            if !have_vertices {
                return Err(c.err(format!("{} before Vertices", show(kw))));
            }
            let tri = is("Triangles");
            let n = c.u64("number of elements")?;
            let nv = d.points.len() as u64;
            let mut v = [0u32; 4];
            let k = if tri { 3 } else { 4 };
            let r = cap(n, c.remaining(), 2 * (k + 1));
            if tri {
                d.tris.reserve(r);
            } else {
                d.tets.reserve(r);
            }
            for e in 1..=n {
                for x in v.iter_mut().take(k) {
                    let i = c.u64("vertex index")?;
                    if i == 0 || i > nv {
                        return Err(c.err(format!(
                            "{} {e}: vertex index {i} out of range (file has {nv} vertices)",
                            if tri { "triangle" } else { "tetrahedron" }
                        )));
                    }
                    *x = (i - 1) as u32;
                }
                let r = c.i64("element reference")?;
                let r =
                    u32::try_from(r).map_err(|_| c.err(format!("reference {r} out of range")))?;
                if tri {
                    d.tris.push([v[0], v[1], v[2]]);
                    d.tri_tags.push(r);
                } else {
                    d.tets.push(v);
                    d.tet_tags.push(r);
                }
            }
        } else if let Some(w) = skip_width(kw) {
            let n = c.u64("number of entries")?;
            for _ in 0..n {
                for _ in 0..w {
                    c.need("value")?;
                }
            }
        } else if is("End") {
            ended = true;
            break;
        } else {
            return Err(c.err(format!("unknown keyword '{}'", show(kw))));
        }
    }
    if !ended {
        return Err(c.err_line(bytes.len(), "file truncated: missing 'End'"));
    }
    Ok(d)
}

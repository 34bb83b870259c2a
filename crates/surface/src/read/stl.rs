//! STL, ascii (several `solid` blocks, each a patch) and binary
//! (little-endian, patch 0). Corners are welded exactly.

use super::cursor::{cap, parse_f64, show, words, Cur, Res};
use super::weld::weld;
use super::ReadError;
use crate::Surface;
use parafront_geom::P3;

pub(crate) fn read(name: &str, b: &[u8]) -> Res<Surface> {
    if is_binary(b) {
        binary(name, b)
    } else {
        ascii(name, b)
    }
}

fn starts_with_solid(b: &[u8]) -> bool {
    let t = b.trim_ascii_start();
    t.len() >= 5 && t[..5].eq_ignore_ascii_case(b"solid")
}

/// Binary when the size is exactly 84 + 50 n (binary files may start with
/// "solid" too), unless the whole file is text starting with "solid".
/// Otherwise ascii if it starts with "solid" and has no NUL byte (so a
/// truncated binary file gets a binary error).
fn is_binary(b: &[u8]) -> bool {
    let solid = starts_with_solid(b);
    if b.len() >= 84 {
        let n = u32::from_le_bytes(b[80..84].try_into().unwrap()) as u64;
        if 84 + 50 * n == b.len() as u64 {
            let text = b
                .iter()
                .all(|&c| c == b'\t' || c == b'\n' || c == b'\r' || (b' '..=b'~').contains(&c));
            return !(solid && text);
        }
    }
    !solid || b.contains(&0)
}

fn binary(name: &str, b: &[u8]) -> Res<Surface> {
    let mut c = Cur::new(name, b, None);
    if b.len() < 84 {
        return Err(c.err_byte(
            b.len(),
            format!(
                "file truncated: {} bytes, less than a binary STL header (84), and no 'solid' for ascii",
                b.len()
            ),
        ));
    }
    c.pos = 80;
    let n = c.le_u32("triangle count")? as u64;
    let need = 84 + 50 * n;
    if need != b.len() as u64 {
        return Err(c.err_byte(
            80,
            format!(
                "binary STL header says {n} triangles ({need} bytes) but the file has {} bytes",
                b.len()
            ),
        ));
    }
    if 3 * n > u32::MAX as u64 {
        return Err(c.err_byte(80, format!("{n} triangles is too many for 32-bit indices")));
    }
    let mut corners: Vec<P3> = Vec::with_capacity(cap(3 * n, c.remaining(), 16));
    for t in 0..n {
        c.pos += 12; // normal: recomputed from the vertices downstream
        for k in 0..3 {
            let at = c.pos;
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = f32::from_le_bytes(c.bytes(4, "coordinate")?.try_into().unwrap()) as f64;
            }
            if !p.iter().all(|x| x.is_finite()) {
                return Err(c.err_byte(
                    at,
                    format!("triangle {t} vertex {k} has a non-finite coordinate {p:?}"),
                ));
            }
            corners.push(p);
        }
        c.pos += 2; // attribute byte count
    }
    let (points, tris) = weld(&corners);
    let patch = vec![0; tris.len()];
    Ok(Surface {
        points,
        tris,
        patch,
        patch_names: Vec::new(),
    })
}

fn ascii(name: &str, b: &[u8]) -> Res<Surface> {
    let c = Cur::new(name, b, None);
    let mut corners: Vec<P3> = Vec::new();
    let mut patch = Vec::new();
    let mut names = Vec::new();
    let mut nsolids = 0u32;
    // Parser state: current solid, inside a facet, vertices of the open
    // loop (None: no loop yet), loop closed.
    let mut solid: Option<u32> = None;
    let mut facet = false;
    let mut lp: Option<usize> = None;
    let mut closed = false;
    let mut cur = [[0.0; 3]; 3];
    for (i, line) in b.split(|&ch| ch == b'\n').enumerate() {
        let lineno = i + 1;
        let err = |what: String| ReadError::Bad {
            file: name.to_string(),
            at: super::Loc::Line(lineno),
            what,
        };
        let mut w = words(line);
        let Some(kw) = w.next() else { continue };
        let is = |k: &str| kw.eq_ignore_ascii_case(k.as_bytes());
        if is("solid") {
            if solid.is_some() {
                return Err(err("'solid' inside a solid (missing 'endsolid')".into()));
            }
            let t = line.trim_ascii();
            let nm = String::from_utf8_lossy(t[5..].trim_ascii()).into_owned();
            if !nm.is_empty() {
                names.push((nsolids, nm));
            }
            solid = Some(nsolids);
            nsolids += 1;
        } else if is("facet") {
            if solid.is_none() || facet {
                return Err(err("'facet' outside a solid or inside another facet".into()));
            }
            facet = true;
            lp = None;
            closed = false;
        } else if is("outer") {
            if !facet || lp.is_some() {
                return Err(err("'outer loop' outside a facet or repeated".into()));
            }
            match w.next() {
                Some(l) if l.eq_ignore_ascii_case(b"loop") => {}
                _ => return Err(err("expected 'outer loop'".into())),
            }
            lp = Some(0);
        } else if is("vertex") {
            let Some(k) = lp.filter(|_| !closed) else {
                return Err(err("'vertex' outside an 'outer loop'".into()));
            };
            if k == 3 {
                return Err(err("facet has more than 3 vertices".into()));
            }
            for x in cur[k].iter_mut() {
                let t = w
                    .next()
                    .ok_or_else(|| err("'vertex' needs 3 coordinates".into()))?;
                let v = parse_f64(t)
                    .ok_or_else(|| err(format!("expected a coordinate, found '{}'", show(t))))?;
                if !v.is_finite() {
                    return Err(err(format!("vertex coordinate is not finite ({v})")));
                }
                *x = v;
            }
            lp = Some(k + 1);
        } else if is("endloop") {
            match lp {
                Some(3) if !closed => closed = true,
                Some(k) if !closed => {
                    return Err(err(format!("facet has {k} vertices, expected 3")));
                }
                _ => return Err(err("'endloop' without 'outer loop'".into())),
            }
        } else if is("endfacet") {
            if !facet || !closed {
                return Err(err("'endfacet' without a complete facet".into()));
            }
            if corners.len() + 3 > u32::MAX as usize {
                return Err(err("too many triangles for 32-bit indices".into()));
            }
            corners.extend_from_slice(&cur);
            patch.push(solid.unwrap_or(0));
            facet = false;
        } else if is("endsolid") {
            if solid.is_none() || facet {
                return Err(err("'endsolid' without a solid or inside a facet".into()));
            }
            solid = None;
        } else {
            return Err(err(format!("unexpected '{}' in an ascii STL", show(kw))));
        }
    }
    if solid.is_some() {
        return Err(c.err_line(b.len(), "file truncated: missing 'endsolid'"));
    }
    if nsolids == 0 {
        return Err(c.err_line(0, "empty file: no 'solid'"));
    }
    let (points, tris) = weld(&corners);
    Ok(Surface {
        points,
        tris,
        patch,
        patch_names: names,
    })
}

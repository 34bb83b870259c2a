//! Wavefront OBJ: `v` and `f` (any of `v`, `v/vt`, `v//vn`, `v/vt/vn`,
//! negative = relative indices), polygons fan-triangulated, `g`/`o`
//! groups as named patches. Texture, normal and material data are ignored.

use super::cursor::{parse_f64, parse_i64, show, words, Res};
use super::{Loc, ReadError};
use crate::Surface;
use std::collections::HashMap;

/// Statements we know and skip (the spec has many more; any keyword made of
/// letters, digits and '_' is skipped, anything else is garbage).
fn skippable(kw: &[u8]) -> bool {
    kw.iter().all(|c| c.is_ascii_alphanumeric() || *c == b'_')
}

pub(crate) fn read(name: &str, b: &[u8]) -> Res<Surface> {
    let mut s = Surface::default();
    let mut group: Vec<u8> = Vec::new();
    let mut tag_of: HashMap<Vec<u8>, u32> = HashMap::new();
    let mut tag: Option<u32> = None;
    // Largest positive index seen and its line: forward references are
    // checked once all vertices are known.
    let mut max_idx: (u64, usize) = (0, 0);
    let mut poly: Vec<u32> = Vec::new();
    for (i, line) in b.split(|&ch| ch == b'\n').enumerate() {
        let lineno = i + 1;
        let err = |what: String| ReadError::Bad {
            file: name.to_string(),
            at: Loc::Line(lineno),
            what,
        };
        let mut w = words(line);
        let Some(kw) = w.next() else { continue };
        match kw {
            b"v" => {
                let mut p = [0.0; 3];
                for (k, x) in p.iter_mut().enumerate() {
                    let t = w
                        .next()
                        .ok_or_else(|| err("vertex needs 3 coordinates".into()))?;
                    let v = parse_f64(t).ok_or_else(|| {
                        err(format!("expected a coordinate, found '{}'", show(t)))
                    })?;
                    if !v.is_finite() {
                        return Err(err(format!(
                            "vertex {} coordinate {k} is not finite ({v})",
                            s.points.len() + 1
                        )));
                    }
                    *x = v;
                }
                if s.points.len() == u32::MAX as usize {
                    return Err(err("too many vertices for 32-bit indices".into()));
                }
                s.points.push(p);
            }
            b"f" => {
                poly.clear();
                let nv = s.points.len() as i64;
                for t in w {
                    let v = t.split(|&c| c == b'/').next().unwrap_or(t);
                    let i = parse_i64(v).ok_or_else(|| {
                        err(format!("expected a vertex index, found '{}'", show(t)))
                    })?;
                    let i0 = if i > 0 {
                        let i0 = (i - 1) as u64;
                        if i0 > u32::MAX as u64 - 1 {
                            return Err(err(format!("face index {i} out of range")));
                        }
                        if i0 >= max_idx.0 {
                            max_idx = (i0 + 1, lineno);
                        }
                        i0 as u32
                    } else if i < 0 && i >= -nv {
                        (nv + i) as u32
                    } else {
                        return Err(err(format!(
                            "face index {i} out of range ({} vertices so far)",
                            nv
                        )));
                    };
                    poly.push(i0);
                }
                if poly.len() < 3 {
                    return Err(err(format!("face has {} vertices, needs 3", poly.len())));
                }
                let t = match tag {
                    Some(t) => t,
                    None => {
                        let n = tag_of.len() as u32;
                        let t = *tag_of.entry(group.clone()).or_insert(n);
                        if t == n && !group.is_empty() {
                            s.patch_names
                                .push((t, String::from_utf8_lossy(&group).into_owned()));
                        }
                        tag = Some(t);
                        t
                    }
                };
                for k in 1..poly.len() - 1 {
                    s.tris.push([poly[0], poly[k], poly[k + 1]]);
                    s.patch.push(t);
                }
            }
            b"g" | b"o" => {
                let rest = line.trim_ascii();
                group = rest[1..].trim_ascii().to_vec();
                tag = None;
            }
            _ if skippable(kw) || kw.starts_with(b"#") => {}
            _ => return Err(err(format!("unexpected '{}' in an OBJ file", show(kw)))),
        }
    }
    if max_idx.0 > s.points.len() as u64 {
        return Err(ReadError::Bad {
            file: name.to_string(),
            at: Loc::Line(max_idx.1),
            what: format!(
                "face index {} out of range (file has {} vertices)",
                max_idx.0,
                s.points.len()
            ),
        });
    }
    Ok(s)
}

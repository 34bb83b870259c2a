//! OFF (and COFF, NOFF, STOFF...): a header, `nv nf ne`, one vertex per
//! line, one polygon per line (fan-triangulated). Values after the
//! coordinates or indices on a line (colours, normals) are ignored.

use super::cursor::{cap, parse_i64, show, Cur, Res};
use crate::Surface;

pub(crate) fn read(name: &str, b: &[u8]) -> Res<Surface> {
    let mut c = Cur::new(name, b, Some(b'#'));
    let first = c.need("'OFF' header")?;
    let counts_start;
    if first.len() >= 3 && first[first.len() - 3..].eq_ignore_ascii_case(b"OFF") {
        let prefix = &first[..first.len() - 3];
        if prefix.contains(&b'4')
            || prefix.contains(&b'n')
            || prefix.eq_ignore_ascii_case(b"binary")
        {
            return Err(c.err(format!("unsupported OFF variant '{}'", show(first))));
        }
        if !prefix
            .iter()
            .all(|ch| matches!(ch.to_ascii_uppercase(), b'S' | b'T' | b'C' | b'N'))
        {
            return Err(c.err(format!("expected 'OFF' header, found '{}'", show(first))));
        }
        // "OFF BINARY" is a binary variant we do not read.
        let save = c.pos;
        if let Some(t) = c.token() {
            if t.eq_ignore_ascii_case(b"BINARY") {
                return Err(c.err("binary OFF is not supported"));
            }
        }
        c.pos = save;
        counts_start = None;
    } else if parse_i64(first).is_some() {
        // Header keyword is optional.
        counts_start = Some(c.tok);
    } else {
        return Err(c.err(format!("expected 'OFF' header, found '{}'", show(first))));
    }
    if let Some(p) = counts_start {
        c.pos = p;
    }
    let nv = c.u64("vertex count")?;
    let nf = c.u64("face count")?;
    let _ne = c.u64("edge count")?;
    c.skip_line();
    if nv > u32::MAX as u64 {
        return Err(c.err(format!("vertex count {nv} is too large for 32-bit indices")));
    }
    let mut s = Surface {
        points: Vec::with_capacity(cap(nv, c.remaining(), 6)),
        ..Default::default()
    };
    for i in 0..nv {
        let mut p = [0.0; 3];
        for (k, x) in p.iter_mut().enumerate() {
            *x = c.coord(&format!("vertex {i} coordinate {k}"))?;
        }
        s.points.push(p);
        c.skip_line();
    }
    let mut poly = Vec::new();
    for f in 0..nf {
        let n = c.u64(&format!("vertex count of face {f}"))?;
        if n < 3 {
            return Err(c.err(format!("face {f} has {n} vertices, needs 3")));
        }
        poly.clear();
        for _ in 0..n {
            let i = c.u64(&format!("vertex index of face {f}"))?;
            if i >= nv {
                return Err(c.err(format!(
                    "face {f}: vertex index {i} out of range (file has {nv} vertices)"
                )));
            }
            poly.push(i as u32);
        }
        for k in 1..poly.len() - 1 {
            s.tris.push([poly[0], poly[k], poly[k + 1]]);
        }
        c.skip_line();
    }
    s.patch = vec![0; s.tris.len()];
    Ok(s)
}

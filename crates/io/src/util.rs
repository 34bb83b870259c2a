//! Shared helpers: input checks before writing, parallel ascii formatting.

use crate::IoError;
use parafront_mesh::TetMesh;
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

/// Checks what every writer relies on: array lengths agree and every point
/// id is in range. Done before the file is created.
pub fn check_mesh(path: &Path, m: &TetMesh) -> Result<(), IoError> {
    let bad = |msg: String| IoError::BadInput {
        path: path.to_path_buf(),
        msg,
    };
    let np = m.points.len();
    if np > u32::MAX as usize {
        return Err(bad(format!("{np} points is more than u32 ids hold")));
    }
    if m.region.len() != m.tets.len() {
        return Err(bad(format!(
            "{} region ids for {} tets",
            m.region.len(),
            m.tets.len()
        )));
    }
    if m.bnd_patch.len() != m.bnd_tris.len() {
        return Err(bad(format!(
            "{} patch tags for {} boundary triangles",
            m.bnd_patch.len(),
            m.bnd_tris.len()
        )));
    }
    if let Some(t) = m.tets.iter().position(|t| t.iter().any(|p| p.idx() >= np)) {
        return Err(bad(format!("tet {t} refers to a point >= {np}")));
    }
    if let Some(t) = m
        .bnd_tris
        .iter()
        .position(|t| t.iter().any(|p| p.idx() >= np))
    {
        return Err(bad(format!(
            "boundary triangle {t} refers to a point >= {np}"
        )));
    }
    Ok(())
}

/// Formats items `0..n` with `f` in parallel chunks and writes them in order.
/// Memory stays bounded: a batch of chunks at a time.
pub fn write_par<W: Write>(
    w: &mut W,
    n: usize,
    f: impl Fn(usize, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    const CHUNK: usize = 1 << 13;
    let nchunks = n.div_ceil(CHUNK);
    let batch = rayon::current_num_threads().max(1) * 4;
    let mut c0 = 0;
    while c0 < nchunks {
        let c1 = (c0 + batch).min(nchunks);
        let bufs: Vec<Vec<u8>> = (c0..c1)
            .into_par_iter()
            .map(|c| {
                let mut buf = Vec::with_capacity(CHUNK * 48);
                for i in c * CHUNK..((c + 1) * CHUNK).min(n) {
                    f(i, &mut buf);
                }
                buf
            })
            .collect();
        for b in &bufs {
            w.write_all(b)?;
        }
        c0 = c1;
    }
    Ok(())
}

/// Shortest text that parses back to the same `f64` (Rust's `{:?}`).
#[inline]
pub fn put_f64(buf: &mut Vec<u8>, x: f64) {
    // Writing to a Vec cannot fail.
    let _ = write!(buf, "{x:?}");
}

/// Decimal text of an integer.
#[inline]
pub fn put_int(buf: &mut Vec<u8>, x: impl std::fmt::Display) {
    let _ = write!(buf, "{x}");
}

/// XML attribute escaping.
pub fn xml_escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            c => o.push(c),
        }
    }
    o
}

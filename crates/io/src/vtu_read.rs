//! VTU reader: ascii, inline base64 binary and appended (raw or base64)
//! data, uncompressed or zlib-compressed, UInt32 or UInt64 headers, either
//! byte order. Several pieces are concatenated. Tets (type 10) become tets,
//! triangles (5) boundary triangles; vertices, lines and poly-lines are
//! skipped; other cells are an error. Regions come from the first cell
//! array among `region`, `gmsh:physical`, `medit:ref`, `CellEntityIds`,
//! `gmsh:geometrical`; patch tags from `patch`, else the same array.

use crate::IoError;
use flate2::read::ZlibDecoder;
use parafront_mesh::{PointId, TetMesh};
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

const REGION_KEYS: [&str; 5] = [
    "region",
    "gmsh:physical",
    "medit:ref",
    "CellEntityIds",
    "gmsh:geometrical",
];

/// An XML element: name, attributes, children, text (inline data).
#[derive(Default, Debug)]
struct El {
    name: String,
    attrs: Vec<(String, String)>,
    kids: Vec<El>,
    text: String,
}

impl El {
    fn attr(&self, k: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(a, _)| a == k)
            .map(|(_, v)| v.as_str())
    }
    fn kid(&self, name: &str) -> Option<&El> {
        self.kids.iter().find(|k| k.name == name)
    }
}

struct Ctx<'a> {
    path: &'a Path,
}

impl Ctx<'_> {
    fn err(&self, msg: impl Into<String>) -> IoError {
        IoError::Parse {
            path: self.path.to_path_buf(),
            msg: msg.into(),
        }
    }
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Parses the XML part (before `<AppendedData>`); returns the root.
fn parse_xml(cx: &Ctx, s: &str) -> Result<El, IoError> {
    let mut stack: Vec<El> = vec![El::default()];
    let mut i = 0;
    let b = s.as_bytes();
    let line = |pos: usize| s[..pos].bytes().filter(|&c| c == b'\n').count() + 1;
    while i < b.len() {
        if b[i] != b'<' {
            let j = s[i..].find('<').map_or(b.len(), |k| i + k);
            if let Some(top) = stack.last_mut() {
                top.text.push_str(&s[i..j]);
            }
            i = j;
            continue;
        }
        let rest = &s[i..];
        if rest.starts_with("<?") || rest.starts_with("<!--") || rest.starts_with("<!") {
            let end = if rest.starts_with("<!--") { "-->" } else { ">" };
            let k = rest
                .find(end)
                .ok_or_else(|| cx.err(format!("line {}: unterminated markup", line(i))))?;
            i += k + end.len();
            continue;
        }
        let k = rest
            .find('>')
            .ok_or_else(|| cx.err(format!("line {}: unterminated tag", line(i))))?;
        let tag = &rest[1..k];
        i += k + 1;
        if let Some(name) = tag.strip_prefix('/') {
            let name = name.trim();
            let el = stack.pop().filter(|e| e.name == name && !stack.is_empty());
            let Some(el) = el else {
                return Err(cx.err(format!("line {}: unexpected </{name}>", line(i))));
            };
            if let Some(top) = stack.last_mut() {
                top.kids.push(el);
            }
            continue;
        }
        let selfclose = tag.ends_with('/');
        let tag = tag.trim_end_matches('/');
        let (name, mut at) = match tag.find(|c: char| c.is_whitespace()) {
            Some(p) => (&tag[..p], &tag[p..]),
            None => (tag, ""),
        };
        let mut el = El {
            name: name.to_string(),
            ..El::default()
        };
        loop {
            at = at.trim_start();
            if at.is_empty() {
                break;
            }
            let bad = || cx.err(format!("line {}: bad attribute in <{name}>", line(i)));
            let eq = at.find('=').ok_or_else(bad)?;
            let key = at[..eq].trim().to_string();
            let v = at[eq + 1..].trim_start();
            let q = v
                .chars()
                .next()
                .filter(|c| *c == '"' || *c == '\'')
                .ok_or_else(bad)?;
            let end = v[1..].find(q).ok_or_else(bad)?;
            el.attrs.push((key, unescape(&v[1..1 + end])));
            at = &v[end + 2..];
        }
        if selfclose {
            if let Some(top) = stack.last_mut() {
                top.kids.push(el);
            }
        } else {
            stack.push(el);
        }
    }
    // The part before <AppendedData> leaves VTKFile open: close what is left.
    while stack.len() > 1 {
        let el = stack.pop().unwrap_or_default();
        if let Some(top) = stack.last_mut() {
            top.kids.push(el);
        }
    }
    let root = stack.pop().unwrap_or_default();
    root.kids
        .into_iter()
        .find(|k| k.name == "VTKFile")
        .ok_or_else(|| cx.err("no <VTKFile> element: not a VTK XML file"))
}

/// Decodes base64, quad by quad, so separately padded runs (VTK encodes
/// headers apart from data) decode to their concatenation.
fn base64(cx: &Ctx, what: &str, s: &[u8]) -> Result<Vec<u8>, IoError> {
    fn val(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let mut q = [0u8; 4];
    let mut n = 0;
    for &c in s.iter().filter(|c| !c.is_ascii_whitespace()) {
        q[n] = c;
        n += 1;
        if n < 4 {
            continue;
        }
        n = 0;
        let pad = q.iter().rev().take_while(|&&c| c == b'=').count();
        if pad > 2 {
            return Err(cx.err(format!("array {what}: bad base64 padding")));
        }
        let mut v = 0u32;
        for &c in &q[..4 - pad] {
            v = v << 6
                | val(c).ok_or_else(|| {
                    cx.err(format!(
                        "array {what}: bad base64 character {:?}",
                        c as char
                    ))
                })?;
        }
        v <<= 6 * pad as u32;
        let bytes = v.to_be_bytes();
        out.extend_from_slice(&bytes[1..4 - pad]);
    }
    if n != 0 {
        return Err(cx.err(format!("array {what}: base64 length not a multiple of 4")));
    }
    Ok(out)
}

/// Numbers of one array.
enum Num {
    F(Vec<f64>),
    I(Vec<i64>),
}

impl Num {
    fn len(&self) -> usize {
        match self {
            Num::F(v) => v.len(),
            Num::I(v) => v.len(),
        }
    }
    fn ints(self, cx: &Ctx, what: &str) -> Result<Vec<i64>, IoError> {
        match self {
            Num::I(v) => Ok(v),
            Num::F(v) => v
                .into_iter()
                .map(|x| {
                    if x.fract() == 0.0 && x.abs() < 9.0e15 {
                        Ok(x as i64)
                    } else {
                        Err(cx.err(format!("array {what}: {x} is not an integer")))
                    }
                })
                .collect(),
        }
    }
    fn floats(self) -> Vec<f64> {
        match self {
            Num::F(v) => v,
            Num::I(v) => v.into_iter().map(|x| x as f64).collect(),
        }
    }
}

struct File<'a> {
    cx: Ctx<'a>,
    big_endian: bool,
    header64: bool,
    zlib: bool,
    /// Appended data after the `_`, and whether it is base64.
    appended: &'a [u8],
    appended_b64: bool,
    /// Sorted offsets of appended arrays, to cut base64 runs apart.
    offsets: Vec<usize>,
}

impl File<'_> {
    fn header_val(&self, b: &[u8]) -> u64 {
        let mut a = [0u8; 8];
        let n = if self.header64 { 8 } else { 4 };
        if self.big_endian {
            a[8 - n..].copy_from_slice(&b[..n]);
            u64::from_be_bytes(a)
        } else {
            a[..n].copy_from_slice(&b[..n]);
            u64::from_le_bytes(a)
        }
    }

    /// The payload of a binary array given its bytes (header first).
    fn payload(&self, what: &str, b: &[u8]) -> Result<Vec<u8>, IoError> {
        let hs = if self.header64 { 8 } else { 4 };
        let short = || self.cx.err(format!("array {what}: data truncated"));
        let get = |k: usize| -> Result<u64, IoError> {
            let s = b.get(k * hs..(k + 1) * hs).ok_or_else(short)?;
            Ok(self.header_val(s))
        };
        if !self.zlib {
            let n = get(0)?;
            let n = usize::try_from(n).map_err(|_| short())?;
            return Ok(b
                .get(hs..hs.checked_add(n).ok_or_else(short)?)
                .ok_or_else(short)?
                .to_vec());
        }
        let nblocks = get(0)?;
        let bs = get(1)?;
        let last = get(2)?;
        if nblocks > (b.len() / hs) as u64 {
            return Err(short());
        }
        let nblocks = nblocks as usize;
        let mut pos = (3 + nblocks) * hs;
        let mut out = Vec::new();
        for k in 0..nblocks {
            let cs = usize::try_from(get(3 + k)?).map_err(|_| short())?;
            let blk = b
                .get(pos..pos.checked_add(cs).ok_or_else(short)?)
                .ok_or_else(short)?;
            pos += cs;
            let want = if k + 1 == nblocks && last != 0 {
                last
            } else {
                bs
            };
            let before = out.len();
            // `take` bounds what a corrupt block can inflate to.
            ZlibDecoder::new(blk)
                .take(want)
                .read_to_end(&mut out)
                .map_err(|e| self.cx.err(format!("array {what}: zlib block {k}: {e}")))?;
            if (out.len() - before) as u64 != want {
                return Err(self
                    .cx
                    .err(format!("array {what}: zlib block {k} has the wrong size")));
            }
        }
        Ok(out)
    }

    /// Reads a `<DataArray>` as numbers.
    fn read(&self, da: &El) -> Result<Num, IoError> {
        let what = format!("{:?}", da.attr("Name").unwrap_or("Points"));
        let ty = da
            .attr("type")
            .ok_or_else(|| self.cx.err(format!("array {what}: no type")))?;
        let fmt = da.attr("format").unwrap_or("ascii");
        if fmt == "ascii" {
            let float = ty.starts_with("Float");
            let mut fv = Vec::new();
            let mut iv = Vec::new();
            for (k, tok) in da.text.split_ascii_whitespace().enumerate() {
                let bad = || {
                    self.cx
                        .err(format!("array {what}: value {k} {tok:?} is not a number"))
                };
                if float {
                    fv.push(tok.parse::<f64>().map_err(|_| bad())?);
                } else {
                    iv.push(tok.parse::<i64>().map_err(|_| bad())?);
                }
            }
            return Ok(if float { Num::F(fv) } else { Num::I(iv) });
        }
        let raw = match fmt {
            "binary" => base64(&self.cx, &what, da.text.as_bytes())?,
            "appended" => {
                let off: usize = da
                    .attr("offset")
                    .and_then(|o| o.trim().parse().ok())
                    .ok_or_else(|| self.cx.err(format!("array {what}: bad or missing offset")))?;
                if off > self.appended.len() {
                    return Err(self
                        .cx
                        .err(format!("array {what}: offset {off} past the appended data")));
                }
                if self.appended_b64 {
                    let next = self.offsets.iter().find(|&&o| o > off).copied();
                    let end = next.unwrap_or(self.appended.len()).min(self.appended.len());
                    base64(&self.cx, &what, &self.appended[off..end])?
                } else {
                    // Raw: the header gives the length; no copy of the rest.
                    return self.convert(&what, ty, &self.payload(&what, &self.appended[off..])?);
                }
            }
            f => return Err(self.cx.err(format!("array {what}: unknown format {f:?}"))),
        };
        self.convert(&what, ty, &self.payload(&what, &raw)?)
    }

    fn convert(&self, what: &str, ty: &str, b: &[u8]) -> Result<Num, IoError> {
        // Bytes per value from the type name ("Float32" -> 4); unknown types fail below.
        let size = ty
            .trim_start_matches(char::is_alphabetic)
            .parse::<usize>()
            .unwrap_or(8)
            / 8;
        if size > 1 && b.len() / size * size != b.len() {
            return Err(self.cx.err(format!(
                "array {what}: {} bytes is not a whole number of {ty}",
                b.len()
            )));
        }
        macro_rules! conv {
            ($t:ty, $n:expr, $wrap:ident, $as:ty) => {{
                Num::$wrap(
                    b.chunks_exact($n)
                        .map(|c| {
                            let a: [u8; $n] = c.try_into().unwrap_or([0; $n]);
                            (if self.big_endian {
                                <$t>::from_be_bytes(a)
                            } else {
                                <$t>::from_le_bytes(a)
                            }) as $as
                        })
                        .collect(),
                )
            }};
        }
        Ok(match ty {
            "Float64" => conv!(f64, 8, F, f64),
            "Float32" => conv!(f32, 4, F, f64),
            "Int8" => conv!(i8, 1, I, i64),
            "UInt8" => conv!(u8, 1, I, i64),
            "Int16" => conv!(i16, 2, I, i64),
            "UInt16" => conv!(u16, 2, I, i64),
            "Int32" => conv!(i32, 4, I, i64),
            "UInt32" => conv!(u32, 4, I, i64),
            "Int64" => conv!(i64, 8, I, i64),
            "UInt64" => {
                let v = conv!(u64, 8, I, i64);
                if let Num::I(x) = &v {
                    if x.iter().any(|&x| x < 0) {
                        return Err(self
                            .cx
                            .err(format!("array {what}: UInt64 value beyond Int64")));
                    }
                }
                v
            }
            t => return Err(self.cx.err(format!("array {what}: unsupported type {t:?}"))),
        })
    }
}

/// Reads a `.vtu` file into a tet mesh.
pub fn read_vtu(path: &Path, bytes: &[u8]) -> Result<TetMesh, IoError> {
    let cx = Ctx { path };
    let (xml_end, appended, appended_b64) = split_appended(&cx, bytes)?;
    let text =
        std::str::from_utf8(&bytes[..xml_end]).map_err(|_| cx.err("XML part is not UTF-8"))?;
    let root = parse_xml(&cx, text)?;
    if root.attr("type") != Some("UnstructuredGrid") {
        return Err(cx.err(format!(
            "VTKFile type {:?} is not UnstructuredGrid",
            root.attr("type").unwrap_or("")
        )));
    }
    let zlib = match root.attr("compressor") {
        None | Some("") => false,
        Some("vtkZLibDataCompressor") => true,
        Some(c) => return Err(cx.err(format!("unsupported compressor {c:?}"))),
    };
    let grid = root
        .kid("UnstructuredGrid")
        .ok_or_else(|| cx.err("no <UnstructuredGrid>"))?;
    let mut offsets: Vec<usize> = Vec::new();
    fn collect(e: &El, out: &mut Vec<usize>) {
        if e.name == "DataArray" && e.attr("format") == Some("appended") {
            if let Some(o) = e.attr("offset").and_then(|o| o.trim().parse().ok()) {
                out.push(o);
            }
        }
        e.kids.iter().for_each(|k| collect(k, out));
    }
    collect(grid, &mut offsets);
    offsets.sort_unstable();
    let f = File {
        cx,
        big_endian: root.attr("byte_order") == Some("BigEndian"),
        header64: root.attr("header_type") == Some("UInt64"),
        zlib,
        appended,
        appended_b64,
        offsets,
    };
    let cx = &f.cx;
    let mut m = TetMesh::default();
    for (pi, piece) in grid.kids.iter().filter(|k| k.name == "Piece").enumerate() {
        let count = |k: &str| -> Result<usize, IoError> {
            piece
                .attr(k)
                .and_then(|v| v.trim().parse().ok())
                .ok_or_else(|| cx.err(format!("piece {pi}: bad or missing {k}")))
        };
        let (np, nc) = (count("NumberOfPoints")?, count("NumberOfCells")?);
        let base = m.points.len();
        if np > 0 {
            read_points(&f, pi, piece, np, &mut m)?;
        }
        if nc == 0 {
            continue;
        }
        read_cells(&f, pi, piece, np, nc, base, &mut m)?;
    }
    Ok(m)
}

/// Where the XML ends, and the appended data after its `_` (and whether
/// it is base64): split at `<AppendedData`, whose raw bytes are not text.
fn split_appended<'a>(cx: &Ctx, bytes: &'a [u8]) -> Result<(usize, &'a [u8], bool), IoError> {
    Ok(match find(bytes, b"<AppendedData") {
        Some(a) => {
            let gt = find(&bytes[a..], b">")
                .ok_or_else(|| cx.err("unterminated <AppendedData> tag"))?
                + a;
            let tag = String::from_utf8_lossy(&bytes[a..gt]);
            let b64 = tag.contains("base64");
            let us = find(&bytes[gt..], b"_")
                .ok_or_else(|| cx.err("appended data lacks its leading '_'"))?
                + gt;
            let mut data = &bytes[us + 1..];
            if b64 {
                // Base64 stops at the closing tag.
                let e = find(data, b"<").unwrap_or(data.len());
                data = &data[..e];
            }
            (a, data, b64)
        }
        None => (bytes.len(), &bytes[..0], false),
    })
}

/// Piece `pi`'s `np` points, appended to `m`'s.
fn read_points(f: &File, pi: usize, piece: &El, np: usize, m: &mut TetMesh) -> Result<(), IoError> {
    let cx = &f.cx;
    let base = m.points.len();
    let da = piece
        .kid("Points")
        .and_then(|p| p.kid("DataArray"))
        .ok_or_else(|| cx.err(format!("piece {pi}: no <Points> array")))?;
    let ncomp = da.attr("NumberOfComponents").unwrap_or("1");
    if ncomp != "3" {
        return Err(cx.err(format!(
            "piece {pi}: points have {ncomp} components, expected 3"
        )));
    }
    let p = f.read(da)?.floats();
    if p.len() != 3 * np {
        return Err(cx.err(format!(
            "piece {pi}: {} point coordinates for {np} points",
            p.len()
        )));
    }
    if let Some(k) = p.iter().position(|x| !x.is_finite()) {
        return Err(cx.err(format!(
            "piece {pi}: point {} has a non-finite coordinate",
            k / 3
        )));
    }
    if base + np > u32::MAX as usize {
        return Err(cx.err("more points than 32-bit ids hold"));
    }
    m.points
        .extend(p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
    Ok(())
}

/// Piece `pi`'s `nc` cells: tets with their regions, triangles with
/// their patches; its points start at `base`.
fn read_cells(
    f: &File,
    pi: usize,
    piece: &El,
    np: usize,
    nc: usize,
    base: usize,
    m: &mut TetMesh,
) -> Result<(), IoError> {
    let cx = &f.cx;
    let cells = piece
        .kid("Cells")
        .ok_or_else(|| cx.err(format!("piece {pi}: no <Cells>")))?;
    let mut arr: HashMap<&str, &El> = HashMap::new();
    for da in cells.kids.iter().filter(|k| k.name == "DataArray") {
        arr.insert(da.attr("Name").unwrap_or(""), da);
    }
    let get = |n: &str| -> Result<Vec<i64>, IoError> {
        let da = arr
            .get(n)
            .ok_or_else(|| cx.err(format!("piece {pi}: no {n:?} array in <Cells>")))?;
        f.read(da)?.ints(cx, n)
    };
    let (conn, offs, types) = (get("connectivity")?, get("offsets")?, get("types")?);
    if offs.len() != nc || types.len() != nc {
        return Err(cx.err(format!(
            "piece {pi}: {} offsets and {} types for {nc} cells",
            offs.len(),
            types.len()
        )));
    }
    let mut cdata: HashMap<&str, &El> = HashMap::new();
    if let Some(cd) = piece.kid("CellData") {
        for da in cd.kids.iter().filter(|k| k.name == "DataArray") {
            cdata.insert(da.attr("Name").unwrap_or(""), da);
        }
    }
    let tag_array = |keys: &[&str]| -> Result<Option<Vec<i64>>, IoError> {
        for k in keys {
            if let Some(da) = cdata.get(k) {
                let v = f.read(da)?;
                if v.len() != nc {
                    return Err(cx.err(format!(
                        "piece {pi}: cell array {k:?} has {} values for {nc} cells",
                        v.len()
                    )));
                }
                return v.ints(cx, k).map(Some);
            }
        }
        Ok(None)
    };
    let region = tag_array(&REGION_KEYS)?;
    let patch = match tag_array(&["patch"])? {
        Some(p) => Some(p),
        None => region.clone(),
    };
    let tag = |v: &Option<Vec<i64>>, c: usize, what: &str| -> Result<u32, IoError> {
        let t = v.as_ref().map_or(0, |v| v[c]);
        u32::try_from(t)
            .map_err(|_| cx.err(format!("piece {pi}: cell {c} has {what} {t}, not a u32")))
    };
    let mut start = 0i64;
    for c in 0..nc {
        let end = offs[c];
        if end < start || end as u64 > conn.len() as u64 {
            return Err(cx.err(format!("piece {pi}: cell {c} has bad offset {end}")));
        }
        let ids = &conn[start as usize..end as usize];
        start = end;
        let pid = |k: usize| -> Result<PointId, IoError> {
            let v = ids[k];
            if v < 0 || v as u64 >= np as u64 {
                return Err(cx.err(format!("piece {pi}: cell {c} refers to point {v} of {np}")));
            }
            Ok(PointId::from_raw((base + v as usize) as u32))
        };
        let ty = types[c];
        let want = match ty {
            10 => 4,
            5 => 3,
            1..=4 => continue,
            t => return Err(cx.err(format!("piece {pi}: cell {c} has unsupported VTK type {t}"))),
        };
        if ids.len() != want {
            return Err(cx.err(format!(
                "piece {pi}: cell {c} of type {ty} has {} points",
                ids.len()
            )));
        }
        if ty == 10 {
            m.tets.push([pid(0)?, pid(1)?, pid(2)?, pid(3)?]);
            m.region.push(tag(&region, c, "region")?);
        } else {
            m.bnd_tris.push([pid(0)?, pid(1)?, pid(2)?]);
            m.bnd_patch.push(tag(&patch, c, "patch")?);
        }
    }
    Ok(())
}

fn find(h: &[u8], n: &[u8]) -> Option<usize> {
    h.windows(n.len()).position(|w| w == n)
}

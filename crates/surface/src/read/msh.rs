//! Gmsh .msh 2.2 and 4.1, ascii and binary (little-endian only).
//!
//! Collects nodes (tags may be sparse: mapped to 0-based indices),
//! triangles (type 2) and tetrahedra (type 4) with their tag: the
//! physical tag if the element has one, else its entity tag. Other element
//! types are skipped. `$PhysicalNames` of dimension 2 and 3 give
//! [`VolumeData::names`] and [`VolumeData::volume_names`].

use super::cursor::{cap, show, Cur, Res};
use super::VolumeData;
use std::collections::HashMap;

/// What [`parse`] returns.
pub type MshData = VolumeData;

/// Nodes per element for the Gmsh element types (0: unknown).
fn nodes_of_type(t: u32) -> usize {
    const N: [usize; 32] = [
        0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13, 9, 10, 12, 15, 15, 21,
        4, 5, 6, 20, 35, 56,
    ];
    match t {
        0..=31 => N[t as usize],
        92 => 64,
        93 => 125,
        _ => 0,
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Ver {
    V2,
    V41,
}

/// Node tag -> 0-based index; dense when the tags are not too sparse.
enum NodeMap {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl NodeMap {
    /// Fails with the first duplicated tag.
    fn build(tags: &[u64]) -> Result<NodeMap, u64> {
        let max = tags.iter().copied().max().unwrap_or(0);
        // Bounded by the node count, which the input size bounds.
        if max <= 4 * tags.len() as u64 + 1024 {
            let mut v = vec![u32::MAX; max as usize + 1];
            for (i, &t) in tags.iter().enumerate() {
                if v[t as usize] != u32::MAX {
                    return Err(t);
                }
                v[t as usize] = i as u32;
            }
            Ok(NodeMap::Dense(v))
        } else {
            let mut m = HashMap::with_capacity(tags.len());
            for (i, &t) in tags.iter().enumerate() {
                if m.insert(t, i as u32).is_some() {
                    return Err(t);
                }
            }
            Ok(NodeMap::Sparse(m))
        }
    }
    fn get(&self, t: u64) -> Option<u32> {
        match self {
            NodeMap::Dense(v) => v
                .get(usize::try_from(t).ok()?)
                .copied()
                .filter(|&i| i != u32::MAX),
            NodeMap::Sparse(m) => m.get(&t).copied(),
        }
    }
}

struct P<'a> {
    c: Cur<'a>,
    bin: bool,
    ver: Ver,
}

impl<'a> P<'a> {
    /// Error at `pos`: a byte offset in binary files, a line in ascii ones.
    fn err_at(&self, pos: usize, what: impl Into<String>) -> super::ReadError {
        if self.bin {
            self.c.err_byte(pos, what)
        } else {
            self.c.err_line(pos, what)
        }
    }

    /// Position of the next item (past whitespace in ascii files).
    fn here(&mut self) -> usize {
        if !self.bin {
            self.c.skip_ws();
        }
        self.c.pos
    }

    /// Fails unless `count` items of `per` bytes fit in what is left.
    fn fits(&self, count: u64, per: u64, what: &str) -> Res<()> {
        match count.checked_mul(per) {
            Some(n) if n <= self.c.remaining() as u64 => Ok(()),
            _ => Err(self.err_at(
                self.c.pos,
                format!(
                    "{what} count {count} needs more bytes than the {} left (file truncated?)",
                    self.c.remaining()
                ),
            )),
        }
    }

    /// An ascii count on its own line (the binary formats have a few).
    fn count_line(&mut self, what: &str) -> Res<u64> {
        let v = self.c.u64(what)?;
        self.c.rest_of_line();
        Ok(v)
    }

    fn end_section(&mut self, sec: &[u8]) -> Res<()> {
        self.c.skip_ws();
        let pos = self.c.pos;
        let line = self.c.rest_of_line().trim_ascii_end();
        if line.len() == sec.len() + 4 && line.starts_with(b"$End") && &line[4..] == sec {
            Ok(())
        } else if line.is_empty() {
            Err(self.err_at(pos, format!("file truncated: missing $End{}", show(sec))))
        } else {
            Err(self.err_at(
                pos,
                format!("expected $End{}, found '{}'", show(sec), show(line)),
            ))
        }
    }

    fn skip_section(&mut self, sec: &[u8]) -> Res<()> {
        let mut needle = b"$End".to_vec();
        needle.extend_from_slice(sec);
        let rest = &self.c.b[self.c.pos..];
        match rest
            .windows(needle.len())
            .position(|w| w == needle.as_slice())
        {
            Some(i) => {
                self.c.pos += i;
                Ok(())
            }
            None => Err(self.err_at(
                self.c.pos,
                format!("file truncated: missing $End{}", show(sec)),
            )),
        }
    }

    fn mesh_format(&mut self) -> Res<()> {
        let v = self.c.need("version")?;
        let vpos = self.c.tok;
        self.ver = match v {
            b"2" | b"2.0" | b"2.1" | b"2.2" => Ver::V2,
            b"4.1" => Ver::V41,
            _ => {
                return Err(self.c.err_line(
                    vpos,
                    format!(
                        "unsupported .msh version '{}' (2.2 and 4.1 are read)",
                        show(v)
                    ),
                ))
            }
        };
        let ft = self.c.i64("file type")?;
        if ft != 0 && ft != 1 {
            return Err(self.c.err(format!(
                "file type {ft} is neither 0 (ascii) nor 1 (binary)"
            )));
        }
        let ds = self.c.i64("data size")?;
        if ds != 8 {
            return Err(self
                .c
                .err(format!("data size {ds} is not supported (expected 8)")));
        }
        self.c.rest_of_line();
        self.bin = ft == 1;
        if self.bin {
            let pos = self.c.pos;
            match self.c.le_i32("endianness marker")? {
                1 => {}
                0x0100_0000 => {
                    return Err(self
                        .c
                        .err_byte(pos, "big-endian binary .msh is not supported"))
                }
                m => return Err(self.c.err_byte(pos, format!("bad endianness marker {m}"))),
            }
        }
        Ok(())
    }

    fn physical_names(&mut self, d: &mut VolumeData) -> Res<()> {
        let n = self.c.u64("number of physical names")?;
        for _ in 0..n {
            let dim = self.c.i64("physical dimension")?;
            let tag = self.c.u32("physical tag")?;
            let pos = self.c.pos;
            let line = self.c.rest_of_line().trim_ascii();
            let name = match line {
                [b'"', inner @ .., b'"'] => inner,
                _ => return Err(self.err_at(pos, "physical name must be in double quotes")),
            };
            let name = String::from_utf8_lossy(name).into_owned();
            match dim {
                2 => d.names.push((tag, name)),
                3 => d.volume_names.push((tag, name)),
                _ => {}
            }
        }
        Ok(())
    }

    /// $Entities (4.1): first physical tag of each surface and volume.
    fn entities(&mut self) -> Res<HashMap<(u8, u32), u32>> {
        let mut phys = HashMap::new();
        let mut counts = [0u64; 4];
        for (k, n) in counts.iter_mut().enumerate() {
            *n = if self.bin {
                self.c.le_u64("entity count")?
            } else {
                self.c.u64(["points", "curves", "surfaces", "volumes"][k])?
            };
        }
        for (dim, &n) in counts.iter().enumerate() {
            // At least 4 bytes (binary) or 2 (ascii) per entity.
            self.fits(n, 2, "entity")?;
            for _ in 0..n {
                let pos = self.here();
                let nbox = if dim == 0 { 3 } else { 6 };
                let (tag, nphys) = if self.bin {
                    let tag = self.c.le_i32("entity tag")? as i64;
                    self.c.bytes(8 * nbox, "entity box")?;
                    (tag, self.c.le_u64("physical tag count")?)
                } else {
                    let tag = self.c.i64("entity tag")?;
                    for _ in 0..nbox {
                        self.c.f64("entity box coordinate")?;
                    }
                    (tag, self.c.u64("physical tag count")?)
                };
                let mut first = None;
                for _ in 0..nphys {
                    let p = if self.bin {
                        self.c.le_i32("physical tag")? as i64
                    } else {
                        self.c.i64("physical tag")?
                    };
                    first.get_or_insert(p);
                }
                if dim > 0 {
                    let nb = if self.bin {
                        self.c.le_u64("bounding entity count")?
                    } else {
                        self.c.u64("bounding entity count")?
                    };
                    for _ in 0..nb {
                        if self.bin {
                            self.c.le_i32("bounding entity")?;
                        } else {
                            self.c.i64("bounding entity")?;
                        }
                    }
                }
                if dim >= 2 {
                    let tag = u32::try_from(tag)
                        .map_err(|_| self.err_at(pos, format!("entity tag {tag} out of range")))?;
                    if let Some(p) = first.filter(|&p| p != 0) {
                        let p = u32::try_from(p.unsigned_abs()).map_err(|_| {
                            self.err_at(pos, format!("physical tag {p} out of range"))
                        })?;
                        phys.insert((dim as u8, tag), p);
                    }
                }
            }
        }
        Ok(phys)
    }

    /// Reads one node's coordinates; `extra` parametric values skipped.
    fn node_coords(&mut self, tag: u64, extra: usize) -> Res<[f64; 3]> {
        let pos = self.c.pos;
        let mut p = [0.0; 3];
        if self.bin {
            for x in &mut p {
                *x = self.c.le_f64("node coordinate")?;
            }
            self.c.bytes(8 * extra, "parametric coordinate")?;
            if !p.iter().all(|x| x.is_finite()) {
                return Err(self
                    .c
                    .err_byte(pos, format!("node {tag} has a non-finite coordinate {p:?}")));
            }
        } else {
            for (k, x) in p.iter_mut().enumerate() {
                *x = self.c.coord(&format!("node {tag} coordinate {k}"))?;
            }
            for _ in 0..extra {
                self.c.f64("parametric coordinate")?;
            }
        }
        Ok(p)
    }

    fn nodes(&mut self, d: &mut VolumeData) -> Res<NodeMap> {
        let start = self.c.pos;
        let mut tags: Vec<u64> = Vec::new();
        match self.ver {
            Ver::V2 => {
                let n = self.count_line("number of nodes")?;
                let per = if self.bin { 28 } else { 8 };
                let r = cap(n, self.c.remaining(), per);
                tags.reserve(r);
                d.points.reserve(r);
                if self.bin {
                    self.fits(n, 28, "node")?;
                }
                for _ in 0..n {
                    let tag = if self.bin {
                        let pos = self.c.pos;
                        let t = self.c.le_i32("node tag")?;
                        u64::try_from(t)
                            .map_err(|_| self.c.err_byte(pos, format!("negative node tag {t}")))?
                    } else {
                        self.c.u64("node tag")?
                    };
                    let p = self.node_coords(tag, 0)?;
                    tags.push(tag);
                    d.points.push(p);
                }
            }
            Ver::V41 => {
                let mut h = [0u64; 4];
                for x in &mut h {
                    *x = if self.bin {
                        self.c.le_u64("$Nodes header")?
                    } else {
                        self.c.u64("$Nodes header value")?
                    };
                }
                let r = cap(h[1], self.c.remaining(), if self.bin { 32 } else { 8 });
                tags.reserve(r);
                d.points.reserve(r);
                for _ in 0..h[0] {
                    let bpos = self.here();
                    let (dim, param, n) = if self.bin {
                        let dim = self.c.le_i32("entity dimension")? as i64;
                        self.c.le_i32("entity tag")?;
                        let param = self.c.le_i32("parametric flag")?;
                        (dim, param as i64, self.c.le_u64("nodes in block")?)
                    } else {
                        let dim = self.c.i64("entity dimension")?;
                        self.c.i64("entity tag")?;
                        let param = self.c.i64("parametric flag")?;
                        (dim, param, self.c.u64("nodes in block")?)
                    };
                    if !(0..=3).contains(&dim) {
                        return Err(self.err_at(bpos, format!("bad entity dimension {dim}")));
                    }
                    let extra = if param != 0 { dim as usize } else { 0 };
                    let first = tags.len();
                    if self.bin {
                        self.fits(n, 8 * (4 + extra as u64), "node")?;
                        for _ in 0..n {
                            tags.push(self.c.le_u64("node tag")?);
                        }
                    } else {
                        self.fits(n, 2, "node")?;
                        for _ in 0..n {
                            tags.push(self.c.u64("node tag")?);
                        }
                    }
                    for &t in &tags[first..] {
                        let p = self.node_coords(t, extra)?;
                        d.points.push(p);
                    }
                }
            }
        }
        super::check_point_count(self.c.name, d.points.len())?;
        NodeMap::build(&tags).map_err(|t| self.err_at(start, format!("duplicate node tag {t}")))
    }

    /// Maps element node tags; `id` names the element in errors.
    fn map_nodes<const K: usize>(
        &self,
        map: &NodeMap,
        raw: &[u64],
        id: u64,
        pos: usize,
    ) -> Res<[u32; K]> {
        let mut out = [0u32; K];
        for (o, &t) in out.iter_mut().zip(raw) {
            *o = map.get(t).ok_or_else(|| {
                self.err_at(
                    pos,
                    format!("element {id} references node {t}, which is not in $Nodes"),
                )
            })?;
        }
        Ok(out)
    }

    /// Keeps a triangle or tetrahedron; `e` is (type, id, tag, position).
    fn push(
        &self,
        d: &mut VolumeData,
        map: &NodeMap,
        raw: &[u64],
        e: (u32, u64, u32, usize),
    ) -> Res<()> {
        let (ty, id, tag, pos) = e;
        match ty {
            2 => {
                d.tris.push(self.map_nodes(map, raw, id, pos)?);
                d.tri_tags.push(tag);
            }
            4 => {
                d.tets.push(self.map_nodes(map, raw, id, pos)?);
                d.tet_tags.push(tag);
            }
            _ => {}
        }
        Ok(())
    }

    fn elements2(&mut self, d: &mut VolumeData, map: &NodeMap) -> Res<()> {
        let n = self.count_line("number of elements")?;
        let mut raw = Vec::new();
        if !self.bin {
            for _ in 0..n {
                let id = self.c.u64("element number")?;
                let pos = self.c.tok;
                let ty = self.c.u32("element type")?;
                let ntags = self.c.u64("number of tags")?;
                let mut tg = [0i64; 2];
                for k in 0..ntags {
                    let v = self.c.i64("element tag")?;
                    if k < 2 {
                        tg[k as usize] = v;
                    }
                }
                let nn = nodes_of_type(ty);
                if nn == 0 {
                    return Err(self
                        .c
                        .err_line(pos, format!("element {id}: unknown element type {ty}")));
                }
                raw.clear();
                for _ in 0..nn {
                    raw.push(self.c.u64("element node")?);
                }
                let tag = tag2(tg).map_err(|v| {
                    self.c
                        .err_line(pos, format!("element {id}: tag {v} out of range"))
                })?;
                self.push(d, map, &raw, (ty, id, tag, pos))?;
            }
            return Ok(());
        }
        let mut done = 0u64;
        while done < n {
            let pos = self.c.pos;
            let ty = self.c.le_i32("element type")?;
            let follow = self.c.le_i32("number of elements following")?;
            let ntags = self.c.le_i32("number of tags")?;
            let nn = u32::try_from(ty).map(nodes_of_type).unwrap_or(0);
            if nn == 0 {
                return Err(self.c.err_byte(pos, format!("unknown element type {ty}")));
            }
            if follow < 1 || ntags < 0 || done + follow as u64 > n {
                return Err(self.c.err_byte(
                    pos,
                    format!("bad element block header: {follow} elements, {ntags} tags ({} of {n} read)", done),
                ));
            }
            let per = 4 * (1 + ntags as u64 + nn as u64);
            self.fits(follow as u64, per, "element")?;
            for _ in 0..follow {
                let pos = self.c.pos;
                let id = self.c.le_i32("element number")? as i64 as u64;
                let mut tg = [0i64; 2];
                for k in 0..ntags {
                    let v = self.c.le_i32("element tag")? as i64;
                    if k < 2 {
                        tg[k as usize] = v;
                    }
                }
                raw.clear();
                for _ in 0..nn {
                    raw.push(self.c.le_i32("element node")? as i64 as u64);
                }
                let tag = tag2(tg).map_err(|v| {
                    self.c
                        .err_byte(pos, format!("element {id}: tag {v} out of range"))
                })?;
                self.push(d, map, &raw, (ty as u32, id, tag, pos))?;
            }
            done += follow as u64;
        }
        Ok(())
    }

    fn elements4(
        &mut self,
        d: &mut VolumeData,
        map: &NodeMap,
        phys: &HashMap<(u8, u32), u32>,
    ) -> Res<()> {
        let mut h = [0u64; 4];
        for x in &mut h {
            *x = if self.bin {
                self.c.le_u64("$Elements header")?
            } else {
                self.c.u64("$Elements header value")?
            };
        }
        let mut raw = Vec::new();
        for _ in 0..h[0] {
            let pos = self.here();
            let (dim, ent, ty, n) = if self.bin {
                let dim = self.c.le_i32("entity dimension")? as i64;
                let ent = self.c.le_i32("entity tag")? as i64;
                let ty = self.c.le_i32("element type")? as i64;
                (dim, ent, ty, self.c.le_u64("elements in block")?)
            } else {
                let dim = self.c.i64("entity dimension")?;
                let ent = self.c.i64("entity tag")?;
                let ty = self.c.i64("element type")?;
                (dim, ent, ty, self.c.u64("elements in block")?)
            };
            let ent = u32::try_from(ent)
                .map_err(|_| self.err_at(pos, format!("entity tag {ent} out of range")))?;
            let ty = u32::try_from(ty).unwrap_or(0);
            let nn = nodes_of_type(ty);
            let tag = u8::try_from(dim)
                .ok()
                .and_then(|dm| phys.get(&(dm, ent)).copied())
                .unwrap_or(ent);
            if nn == 0 {
                if self.bin {
                    return Err(self.c.err_byte(pos, format!("unknown element type {ty}")));
                }
                // Ascii: one element per line.
                self.c.skip_line();
                for _ in 0..n {
                    if self.c.at_end() {
                        return Err(self.c.err_line(self.c.pos, "file truncated in $Elements"));
                    }
                    self.c.skip_line();
                }
                continue;
            }
            self.fits(
                n,
                if self.bin {
                    8 * (1 + nn as u64)
                } else {
                    2 * (1 + nn as u64)
                },
                "element",
            )?;
            for _ in 0..n {
                let pos = self.here();
                raw.clear();
                let id = if self.bin {
                    let id = self.c.le_u64("element tag")?;
                    for _ in 0..nn {
                        raw.push(self.c.le_u64("element node")?);
                    }
                    id
                } else {
                    let id = self.c.u64("element tag")?;
                    for _ in 0..nn {
                        raw.push(self.c.u64("element node")?);
                    }
                    id
                };
                self.push(d, map, &raw, (ty, id, tag, pos))?;
            }
        }
        Ok(())
    }
}

/// MSH 2 element tag: the physical tag, else the entity tag.
fn tag2(tg: [i64; 2]) -> Result<u32, i64> {
    let t = if tg[0] != 0 { tg[0] } else { tg[1] };
    u32::try_from(t).map_err(|_| t)
}

/// Parses a .msh file held in memory; `name` is used in errors only.
pub fn parse(name: &str, bytes: &[u8]) -> Res<MshData> {
    let mut p = P {
        c: Cur::new(name, bytes, None),
        bin: false,
        ver: Ver::V2,
    };
    let mut d = VolumeData::default();
    let mut have_format = false;
    let mut nodes: Option<NodeMap> = None;
    let mut have_elements = false;
    let mut phys = HashMap::new();
    loop {
        p.c.skip_ws();
        if p.c.at_end() {
            break;
        }
        let pos = p.c.pos;
        let line = p.c.rest_of_line().trim_ascii_end();
        let Some(sec) = line.strip_prefix(b"$") else {
            return Err(p.err_at(
                pos,
                format!(
                    "expected a section header such as $Nodes, found '{}'",
                    show(line)
                ),
            ));
        };
        if !have_format && sec != b"MeshFormat" {
            return Err(p.err_at(pos, "missing $MeshFormat: not a Gmsh file"));
        }
        match sec {
            b"MeshFormat" if have_format => {
                return Err(p.err_at(pos, "second $MeshFormat"));
            }
            b"MeshFormat" => {
                p.mesh_format()?;
                have_format = true;
            }
            b"PhysicalNames" => p.physical_names(&mut d)?,
            b"Entities" if p.ver == Ver::V41 => phys = p.entities()?,
            b"Nodes" => {
                if nodes.is_some() {
                    return Err(p.err_at(pos, "second $Nodes section"));
                }
                nodes = Some(p.nodes(&mut d)?);
            }
            b"Elements" => {
                let Some(map) = &nodes else {
                    return Err(p.err_at(pos, "$Elements before $Nodes"));
                };
                if have_elements {
                    return Err(p.err_at(pos, "second $Elements section"));
                }
                have_elements = true;
                match p.ver {
                    Ver::V2 => p.elements2(&mut d, map)?,
                    Ver::V41 => p.elements4(&mut d, map, &phys)?,
                }
            }
            _ => p.skip_section(sec)?,
        }
        p.end_section(sec)?;
    }
    if !have_format {
        return Err(p.c.err_line(0, "empty file: no $MeshFormat"));
    }
    Ok(d)
}

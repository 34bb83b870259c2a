//! ParaView XML UnstructuredGrid (`.vtu`) and its parallel index (`.pvtu`).
//!
//! Arrays go into one raw `<AppendedData>` section with UInt64 headers,
//! optionally zlib-compressed in VTK's block format (header `[nblocks,
//! blocksize, lastblocksize, csize...]`, blocks compressed in parallel).
//! Cells: the tets (VTK type 10) then the boundary triangles (type 5), so
//! readers that split by cell type (meshio) see a tetra block then a
//! triangle block. Cell data `region` holds the tet region (-1 on
//! triangles), `patch` the triangle patch tag (-1 on tets).

use crate::util::{check_mesh, xml_escape};
use crate::{write_atomic, IoError, WriteOptions};
use flate2::Compression;
use flate2::{Compress, FlushCompress, Status};
use parafront_mesh::TetMesh;
use rayon::prelude::*;
use std::io::Write;
use std::marker::PhantomData;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Uncompressed bytes per compressed block (VTK's default); a multiple of
/// every scalar size, so blocks hold whole scalars.
const BLOCK: usize = 1 << 15;

/// The values of an extra array, `ncomp` scalars per point or cell.
#[derive(Clone, Copy, Debug)]
pub enum FieldData<'a> {
    /// `Float64` values.
    F64(&'a [f64]),
    /// `Int32` values.
    I32(&'a [i32]),
    /// `Int64` values.
    I64(&'a [i64]),
    /// `Int64` values, each a `u32` plus the offset: ids kept as `u32`
    /// are written without a wider copy.
    I64From(&'a [u32], i64),
    /// For markers such as `vtkGhostType`.
    U8(&'a [u8]),
}

impl FieldData<'_> {
    fn len(&self) -> usize {
        match self {
            FieldData::F64(s) => s.len(),
            FieldData::I32(s) => s.len(),
            FieldData::I64(s) => s.len(),
            FieldData::I64From(s, _) => s.len(),
            FieldData::U8(s) => s.len(),
        }
    }
}

/// A named extra array. Point fields hold `ncomp` values per point; cell
/// fields `ncomp` per tet (triangles then get NaN / -1 / 0 for u8) or per
/// cell (tets, then boundary triangles). `GlobalPointIds` and
/// `GlobalCellIds` are declared as VTK global ids.
#[derive(Clone, Copy, Debug)]
pub struct Field<'a> {
    /// The array's name in the file.
    pub name: &'a str,
    /// Components per point or cell.
    pub ncomp: usize,
    /// The values, `ncomp` per point or cell in order.
    pub data: FieldData<'a>,
}

impl<'a> Field<'a> {
    /// One value per point or cell.
    pub fn scalar(name: &'a str, data: FieldData<'a>) -> Self {
        Field {
            name,
            ncomp: 1,
            data,
        }
    }
}

/// One mesh with its extra arrays: a `.vtu` file or a part of a `.pvtu`.
#[derive(Clone, Debug)]
pub struct Piece<'a> {
    /// The mesh.
    pub mesh: &'a TetMesh,
    /// Its arrays per point.
    pub point_fields: Vec<Field<'a>>,
    /// Its arrays per cell.
    pub cell_fields: Vec<Field<'a>>,
}

impl<'a> Piece<'a> {
    /// The mesh alone, without extra arrays.
    pub fn new(mesh: &'a TetMesh) -> Self {
        Piece {
            mesh,
            point_fields: Vec::new(),
            cell_fields: Vec::new(),
        }
    }
}

/// A scalar type as stored in the file (little-endian).
trait Scalar: Copy + Send + Sync {
    const SIZE: usize;
    const VTK: &'static str;
    fn put(self, out: &mut Vec<u8>);
}

macro_rules! scalar {
    ($t:ty, $vtk:literal) => {
        impl Scalar for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            const VTK: &'static str = $vtk;
            #[inline(always)]
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    };
}
scalar!(f64, "Float64");
scalar!(i64, "Int64");
scalar!(i32, "Int32");
scalar!(u8, "UInt8");

/// The bytes of one array, produced on demand by scalar index.
trait Source: Sync {
    fn vtk_type(&self) -> &'static str;
    fn size(&self) -> usize;
    fn len(&self) -> usize;
    fn put(&self, r: Range<usize>, out: &mut Vec<u8>);
}

struct FnSrc<T, F> {
    n: usize,
    f: F,
    _t: PhantomData<T>,
}

impl<T: Scalar, F: Fn(usize) -> T + Sync> Source for FnSrc<T, F> {
    fn vtk_type(&self) -> &'static str {
        T::VTK
    }
    fn size(&self) -> usize {
        T::SIZE
    }
    fn len(&self) -> usize {
        self.n
    }
    fn put(&self, r: Range<usize>, out: &mut Vec<u8>) {
        for i in r {
            (self.f)(i).put(out);
        }
    }
}

fn src<'a, T: Scalar + 'a, F: Fn(usize) -> T + Sync + 'a>(n: usize, f: F) -> Box<dyn Source + 'a> {
    Box::new(FnSrc {
        n,
        f,
        _t: PhantomData,
    })
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Section {
    PointData,
    CellData,
    Points,
    Cells,
}

struct Arr<'a> {
    section: Section,
    name: String,
    ncomp: usize,
    src: Box<dyn Source + 'a>,
}

/// A field's source; cell fields given per tet are padded over triangles.
fn field_src<'a>(f: &Field<'a>, n: usize) -> Box<dyn Source + 'a> {
    let len = f.data.len();
    match f.data {
        FieldData::F64(s) => src(n, move |i| if i < len { s[i] } else { f64::NAN }),
        FieldData::I32(s) => src(n, move |i| if i < len { s[i] } else { -1 }),
        FieldData::I64(s) => src(n, move |i| if i < len { s[i] } else { -1 }),
        FieldData::I64From(s, o) => src(n, move |i| if i < len { o + s[i] as i64 } else { -1 }),
        FieldData::U8(s) => src(n, move |i| if i < len { s[i] } else { 0 }),
    }
}

/// The arrays of a piece, in file order, after checking their sizes.
fn piece_arrays<'a>(
    path: &Path,
    p: &Piece<'a>,
    opts: &WriteOptions,
) -> Result<Vec<Arr<'a>>, IoError> {
    let m: &'a TetMesh = p.mesh;
    check_mesh(path, m)?;
    let bad = |msg: String| IoError::BadInput {
        path: path.to_path_buf(),
        msg,
    };
    let (np, nt, nb) = (m.points.len(), m.tets.len(), m.bnd_tris.len());
    let nc = nt + nb;
    if let Some(r) = m.region.iter().find(|&&r| r > i32::MAX as u32) {
        return Err(bad(format!(
            "region {r} does not fit the Int32 region array"
        )));
    }
    if let Some(r) = m.bnd_patch.iter().find(|&&r| r > i32::MAX as u32) {
        return Err(bad(format!("patch {r} does not fit the Int32 patch array")));
    }
    let nconn = 4 * nt + 3 * nb;
    if !opts.vtu_int64 && nconn > i32::MAX as usize {
        return Err(bad(format!("{nconn} connectivity entries need Int64")));
    }
    let mut out = user_arrays(p, np, nt, nc, &bad)?;
    out.extend(mesh_arrays(m, opts.vtu_int64));
    Ok(out)
}

/// The caller's point and cell arrays, checked against the mesh: a cell
/// array may cover the tets alone; `region` and `patch` are reserved.
fn user_arrays<'a>(
    p: &Piece<'a>,
    np: usize,
    nt: usize,
    nc: usize,
    bad: &impl Fn(String) -> IoError,
) -> Result<Vec<Arr<'a>>, IoError> {
    let mut out = Vec::new();
    for (fields, section, count) in [
        (&p.point_fields, Section::PointData, np),
        (&p.cell_fields, Section::CellData, nc),
    ] {
        for f in fields.iter() {
            let full = f.ncomp * count;
            let ok = f.ncomp > 0
                && (f.data.len() == full
                    || (section == Section::CellData && f.data.len() == f.ncomp * nt));
            if !ok {
                return Err(bad(format!(
                    "array {:?}: {} values for {count} {} x {} components",
                    f.name,
                    f.data.len(),
                    if section == Section::PointData {
                        "points"
                    } else {
                        "cells"
                    },
                    f.ncomp
                )));
            }
            if f.name == "region" || f.name == "patch" {
                return Err(bad(format!("array name {:?} is reserved", f.name)));
            }
            out.push(Arr {
                section,
                name: f.name.to_string(),
                ncomp: f.ncomp,
                src: field_src(f, full),
            });
        }
    }
    Ok(out)
}

/// The mesh's own arrays: region and patch per cell, the points, and the
/// cells (Int64 ids when `int64`).
fn mesh_arrays(m: &TetMesh, int64: bool) -> Vec<Arr<'_>> {
    let (np, nt, nb) = (m.points.len(), m.tets.len(), m.bnd_tris.len());
    let (nc, nconn) = (nt + nb, 4 * nt + 3 * nb);
    let mut out = Vec::new();
    let (tets, tris, region, patch) = (&m.tets, &m.bnd_tris, &m.region, &m.bnd_patch);
    out.push(Arr {
        section: Section::CellData,
        name: "region".into(),
        ncomp: 1,
        src: src(nc, move |i| if i < nt { region[i] as i32 } else { -1 }),
    });
    out.push(Arr {
        section: Section::CellData,
        name: "patch".into(),
        ncomp: 1,
        src: src(nc, move |i| if i < nt { -1 } else { patch[i - nt] as i32 }),
    });
    let pts = &m.points;
    out.push(Arr {
        section: Section::Points,
        name: "Points".into(),
        ncomp: 3,
        src: src(3 * np, move |i| pts[i / 3][i % 3]),
    });
    let conn = move |i: usize| {
        if i < 4 * nt {
            tets[i / 4][i % 4].raw()
        } else {
            let j = i - 4 * nt;
            tris[j / 3][j % 3].raw()
        }
    };
    let offs = move |i: usize| {
        if i < nt {
            4 * (i + 1)
        } else {
            4 * nt + 3 * (i - nt + 1)
        }
    };
    let (csrc, osrc) = if int64 {
        (
            src(nconn, move |i| conn(i) as i64),
            src(nc, move |i| offs(i) as i64),
        )
    } else {
        (
            src(nconn, move |i| conn(i) as i32),
            src(nc, move |i| offs(i) as i32),
        )
    };
    out.push(Arr {
        section: Section::Cells,
        name: "connectivity".into(),
        ncomp: 1,
        src: csrc,
    });
    out.push(Arr {
        section: Section::Cells,
        name: "offsets".into(),
        ncomp: 1,
        src: osrc,
    });
    out.push(Arr {
        section: Section::Cells,
        name: "types".into(),
        ncomp: 1,
        src: src(nc, move |i| if i < nt { 10u8 } else { 5u8 }),
    });
    out
}

/// An array as it goes into the appended section.
enum Encoded<'s> {
    /// Compressed: the header bytes and the compressed blocks.
    Zlib(Vec<u8>, Vec<Vec<u8>>),
    /// Uncompressed: streamed from the source at write time.
    Raw(&'s dyn Source),
}

impl Encoded<'_> {
    fn nbytes(&self) -> usize {
        match self {
            Encoded::Zlib(h, b) => h.len() + b.iter().map(|b| b.len()).sum::<usize>(),
            Encoded::Raw(s) => 8 + s.len() * s.size(),
        }
    }
    fn write(&self, w: &mut impl Write) -> std::io::Result<()> {
        match self {
            Encoded::Zlib(h, blocks) => {
                w.write_all(h)?;
                for b in blocks {
                    w.write_all(b)?;
                }
            }
            Encoded::Raw(s) => {
                let n = s.len();
                w.write_all(&((n * s.size()) as u64).to_le_bytes())?;
                let per = BLOCK / s.size();
                let mut buf = Vec::with_capacity(BLOCK);
                let mut i = 0;
                while i < n {
                    buf.clear();
                    s.put(i..(i + per).min(n), &mut buf);
                    w.write_all(&buf)?;
                    i += per;
                }
            }
        }
        Ok(())
    }
}

/// Compresses `s` in VTK's zlib block format, blocks in parallel.
fn compress(s: &dyn Source, level: u32) -> Encoded<'_> {
    let total = s.len() * s.size();
    let per = BLOCK / s.size();
    let nblocks = total.div_ceil(BLOCK);
    // One compressor per rayon job, reset for each block: a fresh one
    // zeroes some 240 kB of tables (miniz_oxide's hash chains, dictionary
    // and LZ buffer), 63k of the 150k page faults of sphere_1e6 at --size
    // 0.037.
    let blocks: Vec<Vec<u8>> = (0..nblocks)
        .into_par_iter()
        .map_init(
            || {
                (
                    Compress::new(Compression::new(level.min(9)), true),
                    Vec::new(),
                )
            },
            |(z, raw), b| {
                raw.clear();
                s.put(b * per..((b + 1) * per).min(s.len()), raw);
                z.reset();
                deflate_block(z, raw)
            },
        )
        .collect();
    let mut h = Vec::with_capacity(8 * (3 + nblocks));
    for v in [nblocks, BLOCK, total % BLOCK] {
        h.extend_from_slice(&(v as u64).to_le_bytes());
    }
    for b in &blocks {
        h.extend_from_slice(&(b.len() as u64).to_le_bytes());
    }
    Encoded::Zlib(h, blocks)
}

/// One zlib stream of `raw`, from a compressor just reset.
fn deflate_block(z: &mut Compress, raw: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(raw.len() / 2 + 64);
    loop {
        let read = z.total_in() as usize;
        // Compressing into a Vec cannot fail; a full Vec is grown below.
        match z.compress_vec(&raw[read..], &mut out, FlushCompress::Finish) {
            Ok(Status::StreamEnd) | Err(_) => return out,
            Ok(_) => out.reserve(out.capacity().max(64)),
        }
    }
}

/// Name and type of each array, for the `.pvtu` index.
type Signature = Vec<(u8, String, &'static str, usize)>;

fn signature(arrs: &[Arr]) -> Signature {
    arrs.iter()
        .map(|a| (a.section as u8, a.name.clone(), a.src.vtk_type(), a.ncomp))
        .collect()
}

/// Scalars leave NumberOfComponents out (VTK's default 1), so meshio
/// returns them as 1-D arrays.
fn ncomp_attr(n: usize) -> String {
    if n == 1 {
        String::new()
    } else {
        format!(" NumberOfComponents=\"{n}\"")
    }
}

/// A piece's sections in document order: tag, and the array that holds
/// the global ids when there is one.
const PIECE_SECTIONS: [(Section, &str, &str); 4] = [
    (Section::PointData, "PointData", "GlobalPointIds"),
    (Section::CellData, "CellData", "GlobalCellIds"),
    (Section::Points, "Points", ""),
    (Section::Cells, "Cells", ""),
];

fn vtu_bytes(
    w: &mut impl Write,
    m: &TetMesh,
    arrs: &[Arr],
    enc: &[Encoded],
    compressed: bool,
) -> std::io::Result<()> {
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    write!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\""
    )?;
    if compressed {
        write!(w, " compressor=\"vtkZLibDataCompressor\"")?;
    }
    writeln!(w, ">\n  <UnstructuredGrid>")?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        m.points.len(),
        m.tets.len() + m.bnd_tris.len()
    )?;
    // The arrays in the order the document names them; their data goes in
    // the reverse order. meshio (5.3) re-encodes compressed data array by
    // array, looking each one up by its offset after it has rewritten the
    // offsets of those before: in document order, a rewritten offset equal
    // to a later array's original one would be found first.
    let doc: Vec<usize> = PIECE_SECTIONS
        .iter()
        .flat_map(|&(sec, _, _)| (0..arrs.len()).filter(move |&i| arrs[i].section == sec))
        .collect();
    let mut offsets = vec![0usize; enc.len()];
    let mut off = 0usize;
    for &i in doc.iter().rev() {
        offsets[i] = off;
        off += enc[i].nbytes();
    }
    for (section, tag, gid) in PIECE_SECTIONS {
        write!(w, "      <{tag}")?;
        if !gid.is_empty() && arrs.iter().any(|a| a.section == section && a.name == gid) {
            write!(w, " GlobalIds=\"{gid}\"")?;
        }
        writeln!(w, ">")?;
        for (a, off) in arrs.iter().zip(&offsets) {
            if a.section == section {
                writeln!(
                    w,
                    "        <DataArray type=\"{}\" Name=\"{}\"{} format=\"appended\" offset=\"{}\"/>",
                    a.src.vtk_type(),
                    xml_escape(&a.name),
                    ncomp_attr(a.ncomp),
                    off
                )?;
            }
        }
        writeln!(w, "      </{tag}>")?;
    }
    writeln!(w, "    </Piece>\n  </UnstructuredGrid>")?;
    // meshio finds the data after the first '_' and drops from the last '\n'.
    write!(w, "  <AppendedData encoding=\"raw\">\n   _")?;
    for &i in doc.iter().rev() {
        enc[i].write(w)?;
    }
    writeln!(w, "\n  </AppendedData>\n</VTKFile>")?;
    Ok(())
}

fn write_piece(path: &Path, p: &Piece, opts: &WriteOptions) -> Result<Signature, IoError> {
    let arrs = piece_arrays(path, p, opts)?;
    let enc: Vec<Encoded> = if opts.compress {
        arrs.iter()
            .map(|a| compress(&*a.src, opts.compress_level))
            .collect()
    } else {
        arrs.iter().map(|a| Encoded::Raw(&*a.src)).collect()
    };
    write_atomic(path, |w| vtu_bytes(w, p.mesh, &arrs, &enc, opts.compress))?;
    Ok(signature(&arrs))
}

/// Writes one piece as a `.vtu` file (atomic).
pub fn write_vtu(path: &Path, piece: &Piece, opts: &WriteOptions) -> Result<(), IoError> {
    write_piece(path, piece, opts).map(|_| ())
}

/// Writes each part as `<stem>_<k>.vtu` beside `path` and the `.pvtu` index
/// at `path`. All parts must carry the same arrays. Returns the part paths.
/// On error no file of this call remains.
pub fn write_pvtu(
    path: &Path,
    parts: &[Piece],
    opts: &WriteOptions,
) -> Result<Vec<PathBuf>, IoError> {
    let ids: Vec<usize> = (0..parts.len()).collect();
    write_pvtu_share(path, &ids, &ids, true, parts, |p| (*p).clone(), opts)
}

/// [`write_pvtu`] for one process's share of a partitioned mesh (MPI):
/// the `i`th of `parts`, as `piece` shows it, is written as
/// `<stem>_<ids[i]>.vtu`; with `index`, the index at `path` names the
/// pieces `listed` (the other processes' pieces carry the same arrays).
/// The parts are taken one at a time, each dropped once written: a caller
/// that makes their arrays as they come holds one piece's copy, not all.
/// Returns the parts' paths; on error no file of this call remains.
pub fn write_pvtu_share<T>(
    path: &Path,
    ids: &[usize],
    listed: &[usize],
    index: bool,
    parts: impl IntoIterator<Item = T>,
    piece: impl Fn(&T) -> Piece<'_>,
    opts: &WriteOptions,
) -> Result<Vec<PathBuf>, IoError> {
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or_else(|| IoError::BadInput {
            path: path.to_path_buf(),
            msg: "file name is not valid UTF-8".into(),
        })?
        .to_string();
    let mut written: Vec<PathBuf> = Vec::new();
    let cleanup = |written: &[PathBuf]| {
        for p in written {
            let _ = std::fs::remove_file(p);
        }
    };
    let mut sig: Option<Signature> = None;
    for (&k, part) in ids.iter().zip(parts) {
        let pp = path.with_file_name(format!("{stem}_{k}.vtu"));
        match write_piece(&pp, &piece(&part), opts) {
            Ok(s) => {
                written.push(pp);
                if let Some(s0) = &sig {
                    if *s0 != s {
                        cleanup(&written);
                        return Err(IoError::BadInput {
                            path: path.to_path_buf(),
                            msg: format!("part {k} has other arrays than part 0"),
                        });
                    }
                } else {
                    sig = Some(s);
                }
            }
            Err(e) => {
                cleanup(&written);
                return Err(e);
            }
        }
    }
    if !index {
        return Ok(written);
    }
    let sig = sig.unwrap_or_default();
    let names: Vec<String> = listed.iter().map(|k| format!("{stem}_{k}.vtu")).collect();
    let res = write_atomic(path, |w| {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
        )?;
        writeln!(w, "  <PUnstructuredGrid GhostLevel=\"0\">")?;
        for (section, tag, gid) in [
            (Section::PointData, "PPointData", "GlobalPointIds"),
            (Section::CellData, "PCellData", "GlobalCellIds"),
            (Section::Points, "PPoints", ""),
        ] {
            write!(w, "    <{tag}")?;
            if !gid.is_empty() && sig.iter().any(|a| a.0 == section as u8 && a.1 == gid) {
                write!(w, " GlobalIds=\"{gid}\"")?;
            }
            writeln!(w, ">")?;
            for (_, name, ty, nc) in sig.iter().filter(|a| a.0 == section as u8) {
                writeln!(
                    w,
                    "      <PDataArray type=\"{ty}\" Name=\"{}\"{}/>",
                    xml_escape(name),
                    ncomp_attr(*nc)
                )?;
            }
            if section == Section::Points && sig.is_empty() {
                writeln!(
                    w,
                    "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>"
                )?;
            }
            writeln!(w, "    </{tag}>")?;
        }
        for name in &names {
            writeln!(w, "    <Piece Source=\"{}\"/>", xml_escape(name))?;
        }
        writeln!(w, "  </PUnstructuredGrid>\n</VTKFile>")
    });
    match res {
        Ok(()) => Ok(written),
        Err(e) => {
            cleanup(&written);
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::read::ZlibDecoder;
    use flate2::write::ZlibEncoder;
    use std::io::Read;

    /// A compressor reset between blocks writes each block as a fresh one
    /// does, and the block decodes to its input: the file does not depend
    /// on which blocks one rayon job happened to take.
    #[test]
    fn a_reset_compressor_writes_each_block_as_a_fresh_one() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut z = Compress::new(Compression::new(6), true);
        for len in [0, 1, 100, BLOCK - 1, BLOCK] {
            // Half noise, half runs: both literal and match paths.
            let raw: Vec<u8> = (0..len)
                .map(|i| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    if i % 64 < 32 {
                        x as u8
                    } else {
                        (i / 64) as u8
                    }
                })
                .collect();
            z.reset();
            let ours = deflate_block(&mut z, &raw);
            let mut fresh = ZlibEncoder::new(Vec::new(), Compression::new(6));
            fresh.write_all(&raw).unwrap();
            assert_eq!(ours, fresh.finish().unwrap(), "block of {len} bytes");
            let mut back = Vec::new();
            ZlibDecoder::new(&ours[..]).read_to_end(&mut back).unwrap();
            assert_eq!(back, raw);
        }
    }
}

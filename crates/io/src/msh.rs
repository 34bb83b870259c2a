//! Gmsh `.msh` writers, versions 4.1 and 2.2, ascii and binary.
//!
//! Tets carry their region as physical tag, boundary triangles their patch
//! tag, both verbatim (0 included). Entities: one volume per region and one
//! surface per patch, the entity tag equal to the physical tag, so readers
//! that fall back to the entity tag when the physical tag is 0 (Gmsh's
//! "no physical group") still get the region back. Element tags are
//! the tet index + 1, then `ntets` + triangle index + 1, so a reader that
//! orders by tag recovers the input order.

use crate::util::{check_mesh, put_f64, put_int, write_par};
use crate::{write_atomic, IoError, MshVersion, WriteOptions};
use parafront_geom::Aabb;
use parafront_mesh::{PointId, TetMesh};
use std::io::Write;
use std::path::Path;

/// Elements of one entity: its physical tag and member indices.
struct Group {
    phys: u32,
    members: Vec<u32>,
    bbox: Aabb,
}

/// Groups element indices by tag (ascending tags), with bounding boxes.
fn groups<const N: usize>(m: &TetMesh, cells: &[[PointId; N]], tags: &[u32]) -> Vec<Group> {
    let mut uniq: Vec<u32> = tags.to_vec();
    uniq.sort_unstable();
    uniq.dedup();
    let mut gs: Vec<Group> = uniq
        .iter()
        .map(|&phys| Group {
            phys,
            members: Vec::new(),
            bbox: Aabb::EMPTY,
        })
        .collect();
    for (i, (c, t)) in cells.iter().zip(tags).enumerate() {
        // `uniq` holds every tag: the search cannot miss.
        let g = &mut gs[uniq.binary_search(t).unwrap_or(0)];
        g.members.push(i as u32);
        for p in c {
            g.bbox.grow(m.points[p.idx()]);
        }
    }
    gs
}

/// Writes `mesh` as Gmsh `.msh` in the version and encoding of `opts`.
pub fn write_msh(path: &Path, m: &TetMesh, opts: &WriteOptions) -> Result<(), IoError> {
    check_mesh(path, m)?;
    if m.region
        .iter()
        .chain(&m.bnd_patch)
        .any(|&t| t > i32::MAX as u32)
    {
        return Err(IoError::BadInput {
            path: path.to_path_buf(),
            msg: "a region or patch tag does not fit Gmsh's int tags".into(),
        });
    }
    let b = opts.binary;
    write_atomic(path, |w| {
        let v = match opts.msh_version {
            MshVersion::V41 => "4.1",
            MshVersion::V22 => "2.2",
        };
        writeln!(w, "$MeshFormat\n{v} {} 8", b as u8)?;
        if b {
            w.write_all(&1i32.to_le_bytes())?;
            writeln!(w)?;
        }
        writeln!(w, "$EndMeshFormat")?;
        physical_names(w, opts)?;
        match opts.msh_version {
            MshVersion::V41 => v41(w, m, b),
            MshVersion::V22 => v22(w, m, b),
        }
    })
}

fn physical_names(w: &mut impl Write, opts: &WriteOptions) -> std::io::Result<()> {
    let n = opts.region_names.len() + opts.patch_names.len();
    if n == 0 {
        return Ok(());
    }
    writeln!(w, "$PhysicalNames\n{n}")?;
    for (dim, names) in [(2, &opts.patch_names), (3, &opts.region_names)] {
        for (tag, name) in names.iter() {
            // Names are quoted and end at the line: drop what would break them.
            let clean: String = name
                .chars()
                .filter(|c| *c != '"' && *c != '\n' && *c != '\r')
                .collect();
            writeln!(w, "{dim} {tag} \"{clean}\"")?;
        }
    }
    writeln!(w, "$EndPhysicalNames")
}

fn sz(w: &mut impl Write, x: usize) -> std::io::Result<()> {
    w.write_all(&(x as u64).to_le_bytes())
}
fn int(w: &mut impl Write, x: i32) -> std::io::Result<()> {
    w.write_all(&x.to_le_bytes())
}
fn dbl(w: &mut impl Write, x: f64) -> std::io::Result<()> {
    w.write_all(&x.to_le_bytes())
}

fn v41(w: &mut impl Write, m: &TetMesh, b: bool) -> std::io::Result<()> {
    let vols = groups(m, &m.tets, &m.region);
    let surfs = groups(m, &m.bnd_tris, &m.bnd_patch);
    // $Entities: no points or curves; a bounding box per entity.
    writeln!(w, "$Entities")?;
    if b {
        for n in [0, 0, surfs.len(), vols.len()] {
            sz(w, n)?;
        }
    } else {
        writeln!(w, "0 0 {} {}", surfs.len(), vols.len())?;
    }
    for gs in [&surfs, &vols] {
        for g in gs.iter() {
            if b {
                int(w, g.phys as i32)?;
                for x in g.bbox.min.iter().chain(&g.bbox.max) {
                    dbl(w, *x)?;
                }
                sz(w, 1)?;
                int(w, g.phys as i32)?;
                sz(w, 0)?;
            } else {
                let mut l = Vec::new();
                put_int(&mut l, g.phys);
                for x in g.bbox.min.iter().chain(&g.bbox.max) {
                    l.push(b' ');
                    put_f64(&mut l, *x);
                }
                let _ = writeln!(l, " 1 {} 0", g.phys);
                w.write_all(&l)?;
            }
        }
    }
    if b {
        writeln!(w)?;
    }
    writeln!(w, "$EndEntities")?;

    // $Nodes: one block, in the first volume (else surface) entity.
    let first = vols.first().or(surfs.first()).map_or(0, |g| g.phys as i32);
    let np = m.points.len();
    let block = if !vols.is_empty() {
        Some(3)
    } else if !surfs.is_empty() {
        Some(2)
    } else {
        None
    };
    writeln!(w, "$Nodes")?;
    let nblocks = block.is_some() as usize;
    let nn = if block.is_some() { np } else { 0 };
    if b {
        for x in [nblocks, nn, 1.min(nn), nn] {
            sz(w, x)?;
        }
    } else {
        writeln!(w, "{nblocks} {nn} {} {nn}", 1.min(nn))?;
    }
    if let Some(dim) = block {
        if b {
            for x in [dim, first, 0] {
                int(w, x)?;
            }
            sz(w, np)?;
            let mut buf = Vec::with_capacity(8 * np);
            for i in 0..np {
                buf.extend_from_slice(&(i as u64 + 1).to_le_bytes());
            }
            w.write_all(&buf)?;
            write_par(w, np, |i, buf| {
                for x in m.points[i] {
                    buf.extend_from_slice(&x.to_le_bytes());
                }
            })?;
        } else {
            writeln!(w, "{dim} {first} 0 {np}")?;
            write_par(w, np, |i, buf| {
                put_int(buf, i + 1);
                buf.push(b'\n');
            })?;
            write_par(w, np, |i, buf| coords(buf, m.points[i]))?;
        }
    }
    if b {
        writeln!(w)?;
    }
    writeln!(w, "$EndNodes")?;

    // $Elements: a block per entity.
    let (nt, nb) = (m.tets.len(), m.bnd_tris.len());
    let ne = nt + nb;
    writeln!(w, "$Elements")?;
    let nblocks = vols.len() + surfs.len();
    if b {
        for x in [nblocks, ne, 1.min(ne), ne] {
            sz(w, x)?;
        }
    } else {
        writeln!(w, "{nblocks} {ne} {} {ne}", 1.min(ne))?;
    }
    for (dim, gs) in [(2, &surfs), (3, &vols)] {
        for g in gs.iter() {
            let n = g.members.len();
            let (etype, base) = if dim == 3 { (4, 0) } else { (2, nt) };
            if b {
                for x in [dim, g.phys as i32, etype] {
                    int(w, x)?;
                }
                sz(w, n)?;
                write_par(w, n, |j, buf| {
                    let e = g.members[j] as usize;
                    buf.extend_from_slice(&(base as u64 + e as u64 + 1).to_le_bytes());
                    for p in cell(m, dim, e) {
                        buf.extend_from_slice(&(p as u64 + 1).to_le_bytes());
                    }
                })?;
            } else {
                writeln!(w, "{dim} {} {etype} {n}", g.phys)?;
                write_par(w, n, |j, buf| {
                    let e = g.members[j] as usize;
                    put_int(buf, base + e + 1);
                    for p in cell(m, dim, e) {
                        buf.push(b' ');
                        put_int(buf, p as u64 + 1);
                    }
                    buf.push(b'\n');
                })?;
            }
        }
    }
    if b {
        writeln!(w)?;
    }
    writeln!(w, "$EndElements")
}

/// Point ids of element `e` of dimension `dim` (3: tet, 2: triangle).
fn cell(m: &TetMesh, dim: i32, e: usize) -> impl Iterator<Item = u32> + '_ {
    let s: &[PointId] = if dim == 3 { &m.tets[e] } else { &m.bnd_tris[e] };
    s.iter().map(|p| p.0)
}

fn coords(buf: &mut Vec<u8>, p: [f64; 3]) {
    put_f64(buf, p[0]);
    buf.push(b' ');
    put_f64(buf, p[1]);
    buf.push(b' ');
    put_f64(buf, p[2]);
    buf.push(b'\n');
}

fn v22(w: &mut impl Write, m: &TetMesh, b: bool) -> std::io::Result<()> {
    let np = m.points.len();
    writeln!(w, "$Nodes\n{np}")?;
    if b {
        write_par(w, np, |i, buf| {
            buf.extend_from_slice(&(i as i32 + 1).to_le_bytes());
            for x in m.points[i] {
                buf.extend_from_slice(&x.to_le_bytes());
            }
        })?;
        writeln!(w)?;
    } else {
        write_par(w, np, |i, buf| {
            put_int(buf, i + 1);
            buf.push(b' ');
            coords(buf, m.points[i]);
        })?;
    }
    writeln!(w, "$EndNodes")?;
    // Physical and elementary tag both the region / patch, as in 4.1.
    let (nt, nb) = (m.tets.len(), m.bnd_tris.len());
    writeln!(w, "$Elements\n{}", nt + nb)?;
    for (dim, n) in [(3, nt), (2, nb)] {
        if n == 0 {
            continue;
        }
        let (etype, base, tags) = if dim == 3 {
            (4, 0, &m.region)
        } else {
            (2, nt, &m.bnd_patch)
        };
        if b {
            for x in [etype, n as i32, 2] {
                int(w, x)?;
            }
            write_par(w, n, |e, buf| {
                buf.extend_from_slice(&((base + e) as i32 + 1).to_le_bytes());
                buf.extend_from_slice(&(tags[e] as i32).to_le_bytes());
                buf.extend_from_slice(&(tags[e] as i32).to_le_bytes());
                for p in cell(m, dim, e) {
                    buf.extend_from_slice(&(p as i32 + 1).to_le_bytes());
                }
            })?;
        } else {
            write_par(w, n, |e, buf| {
                put_int(buf, base + e + 1);
                let _ = write!(buf, " {etype} 2 {} {}", tags[e], tags[e]);
                for p in cell(m, dim, e) {
                    buf.push(b' ');
                    put_int(buf, p as u64 + 1);
                }
                buf.push(b'\n');
            })?;
        }
    }
    if b {
        writeln!(w)?;
    }
    writeln!(w, "$EndElements")
}

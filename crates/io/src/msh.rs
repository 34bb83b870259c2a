//! Gmsh `.msh` writers, versions 4.1 and 2.2, ascii and binary.
//!
//! Tets carry their region as physical tag, boundary triangles their patch
//! tag. Gmsh reads physical tag 0 as "no group", so groups start at 1:
//! tags are written verbatim when they are all at least 1, and all shifted
//! by 1 (per dimension) when one of them is 0. Every group gets a name in
//! `$PhysicalNames`: the one given in [`WriteOptions`], else `region N` /
//! `patch N` with N the tag before the shift. Entities: one volume per
//! region and one surface per patch, the entity tag equal to the physical
//! tag. Element tags are the tet index + 1, then `ntets` + triangle index
//! + 1, so a reader that orders by tag recovers the input order.

use crate::util::{check_mesh, put_f64, put_int, write_par};
use crate::{write_atomic, IoError, MshVersion, WriteOptions};
use parafront_geom::Aabb;
use parafront_mesh::{PointId, TetMesh};
use std::borrow::Cow;
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
    let (region, rshift) = physical_tags(&m.region);
    let (patch, pshift) = physical_tags(&m.bnd_patch);
    if region
        .iter()
        .chain(patch.iter())
        .any(|&t| t > i32::MAX as u32)
    {
        return Err(IoError::BadInput {
            path: path.to_path_buf(),
            msg: "a region or patch tag does not fit Gmsh's int tags".into(),
        });
    }
    let names = group_names(&m.bnd_patch, pshift, &opts.patch_names, "patch")
        .into_iter()
        .map(|(t, n)| (2, t, n))
        .chain(
            group_names(&m.region, rshift, &opts.region_names, "region")
                .into_iter()
                .map(|(t, n)| (3, t, n)),
        )
        .collect::<Vec<_>>();
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
        physical_names(w, &names)?;
        match opts.msh_version {
            MshVersion::V41 => v41(w, m, &region, &patch, b),
            MshVersion::V22 => v22(w, m, &region, &patch, b),
        }
    })
}

/// The tags as Gmsh physical tags: shifted by 1 when one of them is 0.
fn physical_tags(tags: &[u32]) -> (Cow<'_, [u32]>, u32) {
    if tags.contains(&0) {
        (tags.iter().map(|&t| t.saturating_add(1)).collect(), 1)
    } else {
        (Cow::Borrowed(tags), 0)
    }
}

/// (physical tag, name) of every tag used: the given name, else
/// `{kind} {tag}` with the tag before the shift.
fn group_names(
    tags: &[u32],
    shift: u32,
    given: &[(u32, String)],
    kind: &str,
) -> Vec<(u32, String)> {
    let mut used = tags.to_vec();
    used.sort_unstable();
    used.dedup();
    used.iter()
        .map(|&t| {
            let name = given
                .iter()
                .find(|(g, _)| *g == t)
                .map_or_else(|| format!("{kind} {t}"), |(_, n)| n.clone());
            (t.saturating_add(shift), name)
        })
        .collect()
}

fn physical_names(w: &mut impl Write, names: &[(i32, u32, String)]) -> std::io::Result<()> {
    if names.is_empty() {
        return Ok(());
    }
    writeln!(w, "$PhysicalNames\n{}", names.len())?;
    for (dim, tag, name) in names {
        // Names are quoted and end at the line: drop what would break them.
        let clean: String = name
            .chars()
            .filter(|c| *c != '"' && *c != '\n' && *c != '\r')
            .collect();
        writeln!(w, "{dim} {tag} \"{clean}\"")?;
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

fn v41(
    w: &mut impl Write,
    m: &TetMesh,
    region: &[u32],
    patch: &[u32],
    b: bool,
) -> std::io::Result<()> {
    let vols = groups(m, &m.tets, region);
    let surfs = groups(m, &m.bnd_tris, patch);
    v41_entities(w, &surfs, &vols, b)?;
    v41_nodes(w, m, &surfs, &vols, b)?;
    v41_elements(w, m, &surfs, &vols, b)
}

/// `$Entities`: no points or curves; a bounding box per entity.
fn v41_entities(
    w: &mut impl Write,
    surfs: &[Group],
    vols: &[Group],
    b: bool,
) -> std::io::Result<()> {
    writeln!(w, "$Entities")?;
    if b {
        for n in [0, 0, surfs.len(), vols.len()] {
            sz(w, n)?;
        }
    } else {
        writeln!(w, "0 0 {} {}", surfs.len(), vols.len())?;
    }
    for gs in [surfs, vols] {
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
    Ok(())
}

/// `$Nodes`: one block, in the first volume (else surface) entity.
fn v41_nodes(
    w: &mut impl Write,
    m: &TetMesh,
    surfs: &[Group],
    vols: &[Group],
    b: bool,
) -> std::io::Result<()> {
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
    Ok(())
}

/// `$Elements`: a block per entity.
fn v41_elements(
    w: &mut impl Write,
    m: &TetMesh,
    surfs: &[Group],
    vols: &[Group],
    b: bool,
) -> std::io::Result<()> {
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
    for (dim, gs) in [(2, surfs), (3, vols)] {
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
    s.iter().map(|p| p.raw())
}

fn coords(buf: &mut Vec<u8>, p: [f64; 3]) {
    put_f64(buf, p[0]);
    buf.push(b' ');
    put_f64(buf, p[1]);
    buf.push(b' ');
    put_f64(buf, p[2]);
    buf.push(b'\n');
}

fn v22(
    w: &mut impl Write,
    m: &TetMesh,
    region: &[u32],
    patch: &[u32],
    b: bool,
) -> std::io::Result<()> {
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
            (4, 0, region)
        } else {
            (2, nt, patch)
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

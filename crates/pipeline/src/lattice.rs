//! The lattice (§2's optimal space-filling tets) in the pipeline: built in
//! each region, counted in the summary, and improvement (§9) around it:
//! the lattice's inner tets are ideal and their points frozen, so they are
//! set aside while the rest is improved, and cost it nothing.
use crate::{LatticeMode, MeshOptions, RegionFront, Stage, Summary};
use parafront_improve::{improve, ImproveOptions, ImproveStats};
use parafront_lattice::{Lattice, LatticeOptions};
use parafront_mesh::quality::QualityReport;
use parafront_mesh::{PointId, TetMesh, TopoError};
use parafront_size::{SizeField, Sizing};
use std::time::Instant;

/// What [`improve_around_lattice`] did, and the quality reports it
/// leaves for the summary.
pub(crate) struct LatticeImproved {
    pub(crate) stats: ImproveStats,
    /// The quality of the mesh before improvement, when asked for.
    pub(crate) before: Option<QualityReport>,
    /// The tets set aside, the last ones of the mesh now, and their
    /// quality: improvement leaves them as they were, so the report after
    /// it needs only the others (on sphere_1e6 at --size 0.037 they are
    /// 65 % of the tets, and each report took 0.24 of 8.1 s).
    pub(crate) aside: Option<(usize, QualityReport)>,
}

/// The quality of the improved `mesh` (shapes only), whose last `n` tets
/// are those set aside, of report `r` (`LatticeImproved::aside`).
pub(crate) fn report_after(mesh: &TetMesh, (n, r): &(usize, QualityReport)) -> QualityReport {
    let kept = &mesh.tets[..mesh.tets.len() - n];
    QualityReport::of_tets(&mesh.points, kept).merge(r)
}

/// Improves `mesh`, whose first `n_surface` points are the surface's and
/// `inner` (ids) the lattice's inner points, all frozen. The inner points
/// are numbered right after the surface's first (improvement drops points
/// but keeps the ids of those below every dropped one), and the tets of
/// inner points only are set aside and put back after. With `reports`,
/// the quality before improvement, and that of the tets set aside.
pub(crate) fn improve_around_lattice(
    mesh: &mut TetMesh,
    n_surface: usize,
    inner: &[u32],
    io: &ImproveOptions,
    reports: bool,
) -> Result<LatticeImproved, TopoError> {
    if inner.is_empty() {
        let before = reports.then(|| QualityReport::new(mesh));
        let stats = improve(mesh, &vec![true; n_surface], io)?;
        return Ok(LatticeImproved {
            stats,
            before,
            aside: None,
        });
    }
    let n = mesh.points.len();
    let mut new_id = vec![u32::MAX; n];
    for (i, id) in new_id.iter_mut().enumerate().take(n_surface) {
        *id = i as u32;
    }
    let mut next = n_surface as u32;
    let mut sorted = inner.to_vec();
    sorted.sort_unstable();
    for &p in &sorted {
        new_id[p as usize] = next;
        next += 1;
    }
    let n_frozen = next as usize;
    for id in new_id.iter_mut() {
        if *id == u32::MAX {
            *id = next;
            next += 1;
        }
    }
    let mut points = vec![[0.0; 3]; n];
    for (old, &p) in mesh.points.iter().enumerate() {
        points[new_id[old] as usize] = p;
    }
    mesh.points = points;
    let inert = |t: &[PointId; 4]| t.iter().all(|p| (n_surface..n_frozen).contains(&p.idx()));
    let (mut kept, mut kept_region) = (Vec::new(), Vec::new());
    let (mut aside, mut aside_region) = (Vec::new(), Vec::new());
    for (t, &r) in mesh.tets.iter().zip(&mesh.region) {
        let t = t.map(|p| PointId::from_raw(new_id[p.idx()]));
        if inert(&t) {
            aside.push(t);
            aside_region.push(r);
        } else {
            kept.push(t);
            kept_region.push(r);
        }
    }
    mesh.tets = kept;
    mesh.region = kept_region;
    mesh.neigh.clear();
    let aside_report = reports.then(|| QualityReport::of_tets(&mesh.points, &aside));
    let before = aside_report
        .as_ref()
        .map(|r| QualityReport::new(mesh).merge(r));
    let mut stats = improve(mesh, &vec![true; n_frozen], io)?;
    debug_assert!(mesh.points.len() >= n_frozen);
    mesh.tets.extend_from_slice(&aside);
    mesh.region.extend_from_slice(&aside_region);
    mesh.neigh.clear();
    stats.tets_before += aside.len();
    stats.tets_after += aside.len();
    Ok(LatticeImproved {
        stats,
        before,
        aside: aside_report.map(|r| (aside.len(), r)),
    })
}

/// §2's optimal space-filling tets in region `rf` (its surface points
/// `points`), or none where `opts.lattice` turns them off or the size
/// field has no bound.
pub(crate) fn region_lattice(
    points: &[parafront_geom::P3],
    point_size: &[f64],
    rf: &RegionFront,
    sizing: &Sizing,
    opts: &MeshOptions,
    sum: &mut Summary,
) -> Lattice {
    let t_lat = Instant::now();
    let use_lattice = match opts.lattice {
        LatticeMode::On => true,
        LatticeMode::Off => false,
        LatticeMode::Auto => sizing.hmax().is_finite(),
    };
    let lattice = if use_lattice {
        parafront_lattice::build(
            points,
            point_size,
            &rf.faces,
            &|p| sizing.size(p),
            &LatticeOptions::default(),
        )
    } else {
        Lattice::default()
    };
    tracing::debug!(
        region = rf.region_id,
        tets = lattice.tets.len(),
        seconds = t_lat.elapsed().as_secs_f64(),
        "lattice"
    );
    if !lattice.tets.is_empty() {
        sum.push(Stage::Lattice, t_lat.elapsed().as_secs_f64());
    }
    lattice
}

/// The lattice's share of the summary, and its inner points (the region's
/// first new points, from `base`), which improvement leaves alone.
pub(crate) fn note_lattice(
    lattice: &Lattice,
    base: u32,
    sum: &mut Summary,
    lattice_inner: &mut Vec<u32>,
) {
    lattice_inner.extend(
        (0..lattice.points.len() as u32)
            .filter(|&k| lattice.interior[k as usize])
            .map(|k| base + k),
    );
    sum.lattice_tets += lattice.tets.len();
    sum.lattice_cells += lattice.cells;
}

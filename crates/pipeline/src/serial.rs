//! Step 3 on one process: the serial front (§4) on each region, its
//! initial front joined by §2's lattice, and the whole region's
//! constrained fill refined to the size field (GDT, §2) where the front
//! hands the region over or cannot close it. Also the helpers that put a
//! region's points and tets into the mesh, which the parts' path shares.
use super::*;
use std::borrow::Cow;

/// The serial front (§4) on each region, appended to `mesh`; the lattice's
/// inner points, for improvement to leave alone.
pub(crate) fn mesh_serial(
    s: &Surface,
    fronts: &[RegionFront],
    sizing: &Sizing,
    opts: &MeshOptions,
    mesh: &mut TetMesh,
    sum: &mut Summary,
) -> Result<Vec<u32>, MeshError> {
    let mut lattice_inner = Vec::new();
    for rf in fronts {
        serial_region(s, rf, sizing, opts, mesh, sum, &mut lattice_inner)?;
    }
    Ok(lattice_inner)
}

/// The serial front on region `r`, appended to `mesh`.
pub(crate) fn serial_region(
    s: &Surface,
    rf: &RegionFront,
    sizing: &Sizing,
    opts: &MeshOptions,
    mesh: &mut TetMesh,
    sum: &mut Summary,
    lattice_inner: &mut Vec<u32>,
) -> Result<(), MeshError> {
    let rm = serial_region_mesh(s, rf, sizing, opts, sum)?;
    let base = append_region(mesh, rf, &rm.points, &rm.tets);
    if let Some(lattice) = &rm.lattice {
        note_lattice(lattice, base, sum, lattice_inner);
    }
    Ok(())
}

/// One region's mesh in its local ids: its surface points first (in the
/// order of `rf.points`), then its new ones.
pub(crate) struct RegionMesh {
    pub(crate) points: Vec<parafront_geom::P3>,
    pub(crate) tets: Vec<[u32; 4]>,
    /// The lattice whose points and tets it holds (§2), where it does.
    pub(crate) lattice: Option<parafront_lattice::Lattice>,
}

/// The serial front's mesh of region `rf`.
pub(crate) fn serial_region_mesh(
    s: &Surface,
    rf: &RegionFront,
    sizing: &Sizing,
    opts: &MeshOptions,
    sum: &mut Summary,
) -> Result<RegionMesh, MeshError> {
    let filled = |(points, tets)| RegionMesh {
        points,
        tets,
        lattice: None,
    };
    let field = |p| sizing.size(p);
    let (points, point_size) = region_points(s, sizing, rf);
    // §2's optimal space-filling tets: the lattice's points follow the
    // surface's, its outer faces join the initial front.
    let n_in = points.len() as u32;
    let lattice = region_lattice(&points, &point_size, rf, sizing, opts, sum);
    let with_lattice = |(mut points, mut point_size): (Vec<parafront_geom::P3>, Vec<f64>)| {
        points.extend_from_slice(&lattice.points);
        point_size.extend_from_slice(&lattice.size);
        let mut faces = rf.faces.clone();
        faces.extend(lattice.faces.iter().map(|f| f.map(|v| v + n_in)));
        FrontInput {
            points,
            point_size,
            faces,
        }
    };
    let mut input = Some(with_lattice((points.into_owned(), point_size.into_owned())));
    let region = rf.region_id as usize;
    // With a lattice (§2), a region the front stalls on at once is handed
    // back rather than filled in the front: its whole surface is filled
    // here, the lattice's points seeding the refinement; where that fails,
    // the front runs again and fills or recovers in place.
    let mut hand_over = !lattice.faces.is_empty();
    let res = loop {
        let input = input.take().unwrap_or_else(|| {
            let (points, point_size) = region_points(s, sizing, rf);
            with_lattice((points.into_owned(), point_size.into_owned()))
        });
        let res = advance(
            input,
            SizeMode::Field(&field),
            &parafront_front::Everywhere,
            &FrontOptions {
                progress: opts.progress.clone(),
                keep_partial: opts.debug_partial,
                fill_after: opts.fill_after,
                fill_early: true,
                hand_over,
                release: opts.release_memory,
                ..FrontOptions::default()
            },
        );
        if !matches!(res, Err(FrontError::HandOver)) {
            break res;
        }
        if let Some(fill) = fill_whole(s, sizing, rf, &lattice.points) {
            sum.regions_refined.push(region);
            sum.fill_tets += fill.1.len();
            return Ok(filled(fill));
        }
        hand_over = false;
    };
    let res = match res {
        Ok(r) => r,
        // The front could not close the region: the constrained fill of its
        // whole surface, refined to the size field by Delaunay insertion
        // (GDT, §2), unless a debug dump was asked for.
        Err(e @ FrontError::Stuck { .. }) if !opts.debug_partial => {
            let Some(fill) = fill_whole(s, sizing, rf, &lattice.points) else {
                return Err(MeshError::Front { region, source: e });
            };
            tracing::warn!(
                region,
                tets = fill.1.len(),
                "the front could not close the region: filled whole by the constrained fill"
            );
            sum.regions_filled.push(region);
            sum.fill_tets += fill.1.len();
            return Ok(filled(fill));
        }
        Err(e) => return Err(MeshError::Front { region, source: e }),
    };
    let mut tets = res.tets;
    tets.extend(lattice.tets.iter().map(|t| t.map(|v| v + n_in)));
    sum.recovery_rounds += res.stats.recovery_rounds;
    sum.tets_removed += res.stats.tets_removed;
    sum.cavities_filled += res.stats.cavities_filled;
    sum.fill_tets += res.stats.fill_tets;
    sum.fills_failed += res.stats.fills_failed;
    if res.stats.regions_refined > 0 {
        sum.regions_refined.push(region);
    }
    Ok(RegionMesh {
        points: res.points,
        tets,
        lattice: Some(lattice),
    })
}

/// Region `rf`'s whole surface filled by the constrained fill, refined to
/// the size field by Delaunay insertion (GDT, §2; `seeds`, a lattice's
/// points, go in first): its points and tets, or `None` where the fill
/// fails. The fill is valid, so refinement takes it; were it not, the fill
/// as it is still is a mesh.
pub(crate) fn fill_whole(
    s: &Surface,
    sizing: &Sizing,
    rf: &RegionFront,
    seeds: &[parafront_geom::P3],
) -> Option<(Vec<parafront_geom::P3>, Vec<[u32; 4]>)> {
    let field = |p| sizing.size(p);
    // The front took the points; this path is rare, so they are gathered
    // again rather than copied on every run.
    let mut points = region_points(s, sizing, rf).0.into_owned();
    let fill = parafront_delaunay::fill_cavity(
        &points,
        &rf.faces,
        &parafront_delaunay::FillOptions::whole_region(),
    )
    .ok()?;
    let opts = parafront_delaunay::RefineOptions::default();
    let fill = parafront_delaunay::refine_fill(&points, &fill, seeds, &field, &opts)
        .unwrap_or_else(|err| {
            tracing::warn!(region = rf.region_id, %err, "the region's fill was not refined");
            fill
        });
    points.extend_from_slice(&fill.steiner);
    Some((points, fill.tets))
}

/// A region's surface points, in its local order, and their sizes (AG3).
/// A region bounded by the whole surface (its ids ascending and distinct,
/// so all of them in order) reads the surface's in place: their copies
/// were 1.9 MB of each MPI rank through the passes on sphere_5e6.
pub(crate) fn region_points<'s, 'f>(
    s: &'s Surface,
    sizing: &'f Sizing,
    rf: &RegionFront,
) -> (Cow<'s, [parafront_geom::P3]>, Cow<'f, [f64]>) {
    let h = sizing.surface_point_sizes();
    if rf.points.len() == s.points.len() {
        return (s.points[..].into(), h.into());
    }
    let (p, h): (Vec<_>, Vec<_>) = rf
        .points
        .iter()
        .map(|&i| (s.points[i as usize], h[i as usize]))
        .unzip();
    (p.into(), h.into())
}

/// The mesh id of a region's local point `p`: its surface points come
/// first (`rf.points`, in order), then its new points, which were appended
/// to the mesh from `base` on.
pub(crate) fn global_id(rf: &RegionFront, base: u32, p: u32) -> u32 {
    let n_in = rf.points.len();
    if (p as usize) < n_in {
        rf.points[p as usize]
    } else {
        base + p - n_in as u32
    }
}

/// Appends one region's points and tets (local ids) to `mesh`; returns the
/// `base` of its new points for [`global_id`].
pub(crate) fn append_region(
    mesh: &mut TetMesh,
    rf: &RegionFront,
    points: &[parafront_geom::P3],
    tets: &[[u32; 4]],
) -> u32 {
    let base = mesh.points.len() as u32;
    mesh.points.extend_from_slice(&points[rf.points.len()..]);
    mesh.tets.extend(
        tets.iter()
            .map(|t| t.map(|p| PointId::from_raw(global_id(rf, base, p)))),
    );
    mesh.region
        .extend(std::iter::repeat_n(rf.region_id, tets.len()));
    base
}

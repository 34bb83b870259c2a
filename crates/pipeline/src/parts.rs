//! Steps 4 to 6 of the pipeline for one surface (§5 to §8): the parallel
//! mesher on each region, its parts' messages through a `Comm`, and the end
//! of a partitioned run whose mesh stays in its pieces.
use super::*;
use parafront_lattice::Lattice;
use parafront_passes::{move_pieces, Piece};

/// The parallel mesher (§5 to §8, `parallel`: `passes_around`, or one
/// that fails in tests) on each region, its parts' messages through
/// `comm`; the merged result goes into `mesh` like the serial front's, on
/// the process of part 0 (the others leave `mesh` as it is). The size
/// field `held` (`Some`) comes back where what follows needs it (a merged
/// mesh, or the size report); the lattice's inner points with it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn mesh_parts<C: Comm>(
    s: &Surface,
    fronts: &mut [RegionFront],
    mut held: Option<Sizing>,
    opts: &MeshOptions,
    mesh: &mut TetMesh,
    sum: &mut Summary,
    comm: &C,
    parallel: ParallelMesher<C>,
) -> Result<(Vec<u32>, Option<Sizing>), MeshError> {
    // Pieces need the field no more once the last region's passes are
    // done, unless the report measures against it: it goes before the
    // tets move (§8), which set each MPI rank's peak; where every region
    // went to the serial front, at the end.
    let free_field = !opts.gather && !opts.size_report;
    let holds = comm.holds(0);
    // Without the merged mesh, where each region's new points start.
    let mut next_base = s.points.len() as u32;
    // The lattice's inner points, for improvement to leave alone.
    let mut lattice_inner = Vec::new();
    // Improvement renumbers the merged mesh, so its pieces would go
    // stale; they are a second copy of the mesh (13 of sphere_1e6's 77 MB
    // peak, which came in the improvement).
    let kept = !opts.gather || opts.optimize == 0;
    let popts = ParOptions {
        parts: opts.parts,
        growth: if opts.ddg_growth > 0.0 {
            opts.ddg_growth
        } else {
            parafront_ddg::DEFAULT_GROWTH
        },
        partition: opts.partition,
        ddg_passes: opts
            .ddg_passes
            .unwrap_or(parafront_passes::DEFAULT_DDG_PASSES),
        fill_after: opts.fill_after,
        thin_depth: opts.thin_depth,
        serial_from: opts.serial_from,
        ddg_cap: opts.ddg_cap,
        fail_part: opts.fail_part,
        gather: opts.gather,
        keep_pieces: kept,
        release: opts.release_memory,
        ..ParOptions::default()
    };
    // Seconds of each of `Stage::PARALLEL`, summed over the regions.
    let mut stage = [0.0f64; Stage::PARALLEL.len()];
    let n_regions = fronts.len();
    for (ri, rf) in fronts.iter_mut().enumerate() {
        // Freed only after the last region's passes.
        let Some(sizing) = held.as_ref() else { break };
        let field = |p| sizing.size(p);
        let (mut pts, mut hs) = region_points(s, sizing, rf);
        // The lattice fills the core; the passes mesh the layer between it
        // and the surface.
        let n_in = pts.len() as u32;
        let mut lattice = region_lattice(&pts, &hs, rf, sizing, opts, sum);
        if !lattice.points.is_empty() {
            pts.to_mut().extend_from_slice(&lattice.points);
            hs.to_mut().extend_from_slice(&lattice.size);
        }
        let core: Vec<[u32; 3]> = lattice.faces.iter().map(|f| f.map(|v| v + n_in)).collect();
        // In pieces the lattice's tets go with the fronts' (§8), each
        // process holding only its parts' blocks; a merged mesh takes them
        // whole below.
        let noted = (lattice_inner.len(), sum.lattice_tets, sum.lattice_cells);
        let core_tets = if opts.gather {
            Vec::new()
        } else {
            note_lattice(&lattice, next_base, sum, &mut lattice_inner);
            core_blocks(&mut lattice, n_in, comm.owned(), comm.parts())
        };
        let t_par = Instant::now();
        let around = (&core[..], &core_tets[..]);
        let passed = parallel(&pts, &hs, &rf.faces, around, &field, &popts, comm);
        drop(hs);
        let last = ri + 1 == n_regions;
        if passed.is_ok() && !opts.gather {
            // The fallback below is the last to read them (the region's
            // volume was taken before).
            rf.faces = Vec::new();
        }
        let passed = match passed {
            Ok(p) if free_field && last => {
                held = None;
                Ok(p)
            }
            r => r,
        };
        let out = match passed.and_then(|p| p.redistribute(&pts, &popts, comm)) {
            Ok(out) => out,
            // A valid surface must not fail (AF5, step 4): a front the
            // passes leave unclosable (CAD needles next to a part wall) gets
            // the serial front, which recovers from the input surface. So
            // does a thin part whose passes leave most of it to pass 4.
            Err(
                e @ (PassError::Pass { .. }
                | PassError::Remote {
                    pass_failed: true, ..
                }
                | PassError::Unsuited { .. }
                | PassError::Thin { .. }
                | PassError::Ddg(DdgError::Front(_))),
            ) => {
                // Redistribution's errors stop the run: the field freed
                // before it is never wanted here.
                let Some(sizing) = held.as_ref() else {
                    return Err(MeshError::Parallel {
                        region: rf.region_id as usize,
                        source: e,
                    });
                };
                tracing::warn!(
                    region = rf.region_id,
                    "parallel passes given up ({e}); meshing serially"
                );
                sum.serial_fallback
                    .push((rf.region_id as usize, e.to_string()));
                sum.push(Stage::PassesGivenUp, t_par.elapsed().as_secs_f64());
                if !opts.gather {
                    // The lattice noted for the pieces is not in this mesh.
                    lattice_inner.truncate(noted.0);
                    (sum.lattice_tets, sum.lattice_cells) = (noted.1, noted.2);
                    let t0 = Instant::now();
                    let (pieces, n_points) = serial_pieces(s, rf, sizing, opts, sum, comm)?;
                    sum.push(Stage::Front, t0.elapsed().as_secs_f64());
                    let base = next_base;
                    next_base += n_points - n_in;
                    sum.points = next_base as usize;
                    keep_pieces(sum, rf, base, pieces, comm.parts());
                    continue;
                }
                if !holds {
                    continue; // the serial front runs where the mesh gathers
                }
                let t0 = Instant::now();
                let lat0 = sum.seconds(Stage::Lattice);
                serial_region(s, rf, sizing, opts, mesh, sum, &mut lattice_inner)?;
                let lat = sum.seconds(Stage::Lattice) - lat0;
                sum.push(Stage::Front, t0.elapsed().as_secs_f64() - lat);
                continue;
            }
            Err(e) => {
                return Err(MeshError::Parallel {
                    region: rf.region_id as usize,
                    source: e,
                })
            }
        };
        let st = &out.stats;
        for (k, x) in [
            st.ddg_seconds,
            st.partition_seconds,
            st.pass_seconds[0],
            st.pass_seconds[1],
            st.pass_seconds[2],
            st.pass_seconds[3],
            st.redistribute_seconds,
        ]
        .into_iter()
        .enumerate()
        {
            stage[k] += x;
        }
        // Where the region's new points start in the whole mesh, for the
        // pieces' global ids; none when there are no pieces to keep.
        let pieces_base = if !opts.gather {
            let base = next_base;
            // The lattice's points are the region's first new ones.
            next_base += out.n_points - n_in;
            sum.points = next_base as usize;
            Some(base)
        } else if holds {
            let mut tets = out.tets;
            tets.extend(lattice.tets.iter().map(|t| t.map(|v| v + n_in)));
            let base = append_region(mesh, rf, &out.points, &tets);
            note_lattice(&lattice, base, sum, &mut lattice_inner);
            // The lattice's tets are in no piece of a merged run: no pieces
            // then (`--pvtu` turns the lattice off).
            lattice.tets.is_empty().then_some(base)
        } else {
            None
        };
        if let Some(base) = pieces_base.filter(|_| kept) {
            keep_pieces(sum, rf, base, out.pieces, comm.parts());
        }
        sum.parallel.push(out.stats);
    }
    if sum.parallel.is_empty() {
        // Every region went to the serial front.
        return Ok((lattice_inner, held.filter(|_| !free_field)));
    }
    for (name, x) in Stage::PARALLEL.into_iter().zip(stage) {
        sum.push(name, x);
    }
    Ok((lattice_inner, held.filter(|_| !free_field)))
}

/// Region `rf`'s pieces (of `parts` parts) into the summary, their points'
/// global ids from the region's local ones (its new points from `base`).
fn keep_pieces(sum: &mut Summary, rf: &RegionFront, base: u32, pieces: Vec<Piece>, parts: usize) {
    for mut pc in pieces {
        for g in &mut pc.gid {
            *g = global_id(rf, base, *g);
        }
        sum.pieces.push(pc);
    }
    sum.piece_parts = parts;
}

/// The serial front's mesh of region `rf` as pieces, for a run whose
/// passes gave way: made by the process of part 0, with the lattice off
/// (whose inner points the pieces' improvement would have to know on
/// every process), then each tet sent to its part by §8's redistribution,
/// each part an equal run of the tets along a Morton curve of their
/// centroids. This process's pieces (region-local point ids) and the
/// region's point count.
fn serial_pieces<C: Comm>(
    s: &Surface,
    rf: &RegionFront,
    sizing: &Sizing,
    opts: &MeshOptions,
    sum: &mut Summary,
    comm: &C,
) -> Result<(Vec<Piece>, u32), MeshError> {
    let held = comm.owned().len();
    let made = comm.holds(0).then(|| {
        let serial = MeshOptions {
            lattice: LatticeMode::Off,
            ..opts.clone()
        };
        serial_region_mesh(s, rf, sizing, &serial, sum)
    });
    // Part 0's process says the point count, or u32::MAX for a failure,
    // so that no process waits on a front that failed.
    let mut said = vec![0u32; held];
    if let Some(m) = &made {
        said[0] = m.as_ref().map_or(u32::MAX, |rm| rm.points.len() as u32);
    }
    let n_points = comm.all_gather(said)[0];
    let mut pieces: Vec<Piece> = (0..held).map(|_| Piece::default()).collect();
    match made {
        Some(Err(e)) => return Err(e),
        Some(Ok(rm)) => {
            let pc = &mut pieces[0];
            pc.gid = (0..rm.points.len() as u32).collect();
            pc.tet_pass = vec![4; rm.tets.len()];
            pc.points = rm.points;
            pc.tets = rm.tets;
        }
        None if n_points == u32::MAX => {
            return Err(MeshError::Partitioned(format!(
                "region {}: the serial front failed on the process of part 0",
                rf.region_id
            )))
        }
        None => {}
    }
    // Part 0's piece holds the whole mesh: its runs of the curve.
    let np = comm.parts();
    let dst = |i: usize, pc: &Piece| {
        if comm.owned().start + i == 0 {
            crate::pieces::curve_parts(&pc.points, &pc.tets, np)
        } else {
            Vec::new()
        }
    };
    let pieces = move_pieces(comm, pieces, dst).map_err(|source| MeshError::Parallel {
        region: rf.region_id as usize,
        source,
    })?;
    Ok((pieces, n_points))
}

/// The lattice's tets (ids offset by `n_in`, the region's surface points)
/// of the parts `owned` of `np`, one list per part: part `k` gets the
/// `k`-th of `np` blocks by index, the same on any number of processes.
/// The lattice keeps none (the summary has counted them): a process
/// holds only its blocks.
fn core_blocks(
    lattice: &mut Lattice,
    n_in: u32,
    owned: std::ops::Range<usize>,
    np: usize,
) -> Vec<Vec<[u32; 4]>> {
    let n = lattice.tets.len();
    let np = np.max(1);
    let blocks = owned
        .map(|k| {
            lattice.tets[k * n / np..(k + 1) * n / np]
                .iter()
                .map(|t| t.map(|v| v + n_in))
                .collect()
        })
        .collect();
    lattice.tets = Vec::new();
    blocks
}

type ParallelMesher<C> = fn(
    &[parafront_geom::P3],
    &[f64],
    &[[u32; 3]],
    (&[[u32; 3]], &[Vec<[u32; 4]>]),
    &(dyn Fn(parafront_geom::P3) -> f64 + Sync),
    &ParOptions,
    &C,
) -> Result<Passed, PassError>;

/// Six times the volume of the regions `fronts` bound (normals inward).
pub(crate) fn volume6(s: &Surface, fronts: &[RegionFront]) -> f64 {
    fronts
        .iter()
        .map(|rf| {
            let p = |i: u32| s.points[rf.points[i as usize] as usize];
            let o = rf.faces.first().map_or([0.0; 3], |f| p(f[0]));
            rf.faces
                .iter()
                .map(|f| parafront_geom::tet_volume6(o, p(f[0]), p(f[2]), p(f[1])))
                .sum::<f64>()
                .abs()
        })
        .sum()
}

/// The end of a partitioned run (`gather` off): the pieces improved,
/// checked and measured where they lie, the counts summed over the
/// processes; the mesh is empty. `fronts`: the regions (their faces gone
/// after their passes), which bound six times `vol6`. `lattice_inner`: the
/// global ids of the lattice's inner points, which improvement leaves
/// alone. `sizing`: the field, where the quality report measures the
/// sizes against it.
pub(crate) fn finish_pieces<C: Comm>(
    s: &Surface,
    (fronts, vol6): (&[RegionFront], f64),
    sizing: Option<Sizing>,
    opts: &MeshOptions,
    comm: &C,
    lattice_inner: &[u32],
    mut sum: Summary,
) -> Result<(TetMesh, Summary), MeshError> {
    // What the passes freed, and the field where it was dropped, go back
    // before the improvement builds its meshes.
    opts.release();
    if opts.optimize > 0 {
        opts.note_phase(parafront_front::Phase::Improving);
        let t0 = Instant::now();
        let region: Vec<u32> = fronts.iter().map(|rf| rf.region_id).collect();
        // A piece is one part unless asked: the pieces run in parallel
        // already, and a piece's parts were each a copy of it beside it
        // (sphere_5e6 at --parts 32: a second-round piece of 111k tets in
        // two parts, 7 MB of an MPI rank's peak).
        let io = parafront_improve::ImproveOptions {
            level: opts.optimize,
            parts: if opts.optimize_parts == 0 {
                1
            } else {
                opts.optimize_parts
            },
        };
        let mut inner = lattice_inner.to_vec();
        inner.sort_unstable();
        let (st, n) = crate::pieces::improve_pieces(
            comm,
            &mut sum.pieces,
            &region,
            (s.points.len(), &inner),
            &io,
            &|| opts.release(),
        )?;
        // The serial front's regions, shifted by the rounds' moves (on a
        // thin part, into one piece), get their runs of the curve again.
        let fell: Vec<bool> = region
            .iter()
            .map(|&r| sum.serial_fallback.iter().any(|f| f.0 == r as usize))
            .collect();
        if fell.contains(&true) {
            crate::pieces::resplit_regions(comm, &mut sum.pieces, &region, &fell)?;
        }
        sum.improve = Some(st);
        sum.points = n;
        sum.push(Stage::Improve, t0.elapsed().as_secs_f64());
        opts.release();
    }
    opts.note_phase(parafront_front::Phase::Checking);
    let t0 = Instant::now();
    // Region by region, one piece per part held here.
    let held = comm.owned().len();
    let mut by_part: Vec<Vec<&parafront_passes::Piece>> = vec![Vec::new(); held];
    for (i, pc) in sum.pieces.iter().enumerate() {
        by_part[i % held.max(1)].push(pc);
    }
    let tets = if opts.no_check {
        comm.all_reduce(
            by_part
                .iter()
                .map(|l| l.iter().map(|pc| pc.tets.len()).sum())
                .collect(),
            |a: usize, b| a + b,
        )
    } else {
        parafront_passes::check_pieces(comm, &by_part, &s.tris, vol6)?.tets
    };
    drop(by_part);
    sum.push(Stage::Check, t0.elapsed().as_secs_f64());
    sum.tets = tets;
    if !opts.no_quality {
        let t0 = Instant::now();
        let size = |p| sizing.as_ref().map_or(f64::NAN, |z| z.size(p));
        let size: Option<&(dyn Fn(_) -> f64 + Sync)> = sizing.is_some().then_some(&size);
        sum.quality = crate::pieces::pieces_quality(comm, &sum.pieces, size);
        sum.push(Stage::Quality, t0.elapsed().as_secs_f64());
    }
    sum.regions = fronts.len();
    Ok((TetMesh::default(), sum))
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_surface::generate;

    /// [`mesh_parts`] of the valid surface `s` under `opts` (on a threads
    /// comm of `opts.parts`), `parallel` making the passes, adding to
    /// `mesh`: the field it handed back, the summary and the fronts as it
    /// left them.
    fn run_parts(
        s: &Surface,
        opts: &MeshOptions,
        mesh: &mut TetMesh,
        parallel: ParallelMesher<parafront_comm::Threads>,
    ) -> (Option<Sizing>, Summary, Vec<RegionFront>) {
        let report = validate(s);
        assert!(report.is_valid());
        let mut fronts = material_regions(s, &report.shells);
        let sizing = Sizing::build(s, &opts.size, None).unwrap();
        let mut sum = Summary::default();
        let comm = parafront_comm::Threads::new(opts.parts);
        let (_, held) = mesh_parts(
            s,
            &mut fronts,
            Some(sizing),
            opts,
            mesh,
            &mut sum,
            &comm,
            parallel,
        )
        .unwrap();
        (held, sum, fronts)
    }

    /// A pass that cannot close its front must not fail the run: the
    /// region goes to the serial front, and the summary says so.
    #[test]
    fn failed_passes_fall_back_to_the_serial_front() {
        fn stuck(
            _: &[parafront_geom::P3],
            _: &[f64],
            _: &[[u32; 3]],
            _: (&[[u32; 3]], &[Vec<[u32; 4]>]),
            _: &(dyn Fn(parafront_geom::P3) -> f64 + Sync),
            _: &ParOptions,
            _: &parafront_comm::Threads,
        ) -> Result<Passed, PassError> {
            Err(PassError::Pass {
                pass: 4,
                part: 0,
                source: FrontError::Stuck {
                    rounds: 60,
                    faces: 12,
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                    partial: None,
                },
            })
        }
        let s = generate::torus([0.0; 3], 2.0, 0.7, 24, 12);
        let opts = MeshOptions {
            parts: 4,
            ..MeshOptions::default()
        };
        let mut mesh = surface_mesh(&s);
        let (held, sum, fronts) = run_parts(&s, &opts, &mut mesh, stuck);
        // A merged run keeps its field for what follows the passes, and
        // the fallback had the front.
        assert!(held.is_some());
        assert!(fronts.iter().all(|rf| !rf.faces.is_empty()));
        assert_eq!(sum.serial_fallback.len(), 1);
        assert_eq!(sum.serial_fallback[0].0, 1);
        assert!(sum.serial_fallback[0].1.contains("pass 4"));
        assert!(sum.parallel.is_empty());
        mesh.build_adjacency().unwrap();
        mesh.check_against_surface(&s.tris).unwrap();
        let v = mesh.volume();
        assert!((v - s.signed_volume()).abs() < 1e-9 * v, "{v}");
    }

    /// Pieces free the field before redistribution (unless the report
    /// wants it) and the fronts' faces; the volume they are checked
    /// against is taken before.
    #[test]
    fn pieces_free_the_field_before_redistribution_unless_the_report_wants_it() {
        let s = generate::torus([0.0; 3], 2.0, 0.7, 48, 24);
        let vol6 = 6.0 * s.signed_volume();
        let fronts = material_regions(&s, &validate(&s).shells);
        assert!((volume6(&s, &fronts) - vol6).abs() < 1e-9 * vol6);
        for size_report in [false, true] {
            let opts = MeshOptions {
                parts: 4,
                gather: false,
                size_report,
                ..MeshOptions::default()
            };
            let (held, sum, fronts) = run_parts(&s, &opts, &mut TetMesh::default(), passes_around);
            assert!(sum.serial_fallback.is_empty(), "{:?}", sum.serial_fallback);
            assert_eq!(held.is_some(), size_report);
            assert!(fronts.iter().all(|rf| rf.faces.is_empty()));
            // The pieces were made all the same: every tet once, the
            // torus's volume.
            assert_eq!(sum.pieces.len(), 4);
            let by_part: Vec<Vec<&Piece>> = sum.pieces.iter().map(|p| vec![p]).collect();
            let comm = parafront_comm::Threads::new(opts.parts);
            let st = parafront_passes::check_pieces(&comm, &by_part, &s.tris, vol6).unwrap();
            assert_eq!(
                st.tets,
                sum.pieces.iter().map(|p| p.tets.len()).sum::<usize>()
            );
            assert!(st.tets > 1000, "{}", st.tets);
        }
    }
}

//! The parallel mesher's report, its partitioned output and `bench`.
use crate::Fail;
use parafront_io::{write_pvtu_share, Field, FieldData, Piece, WriteOptions};
use parafront_mesh::{PointId, TetMesh};
use parafront_pipeline::{Stage, Summary};
use std::path::Path;

/// Per-region lines: DDG, imbalance, tets per pass.
pub fn print_parallel(sum: &Summary) {
    for (r, st) in sum.parallel.iter().enumerate() {
        let total: usize = st.pass_tets.iter().sum();
        let share = |n: usize| 100.0 * n as f64 / total.max(1) as f64;
        // The DDG's sizes are always the graded field: §5's growth per face
        // got stuck on real surfaces (parafront_ddg::build).
        println!(
            "region {}: {} parts; DDG {} tets, {} points ({} on the surface, {} new), growth {} (graded field), {:.3} s",
            r + 1,
            st.parts,
            st.ddg_tets,
            st.ddg_points,
            st.ddg_surface_points,
            st.ddg_points - st.ddg_surface_points,
            st.ddg_growth,
            st.ddg_seconds
        );
        println!(
            "  partition {}: {} DDG faces between parts (about {:.0} fine faces), most pieces in one part {}, split {:.3} s",
            st.partition.name(),
            st.cut_faces,
            st.cut_fine_faces,
            st.max_components,
            st.split_seconds
        );
        println!(
            "  DDG and partition: {:.3} + {:.3} s wall, {:.2} + {:.2} s CPU",
            st.ddg_seconds, st.partition_seconds, st.ddg_cpu_seconds, st.partition_cpu_seconds
        );
        if let Some(b) = &st.ddg_build {
            println!(
                "  DDG built by {} parallel passes and a serial one: tets {:?}, seconds {:.3?} (field {:.3} s, merge {:.3} s)",
                b.pass_tets.len() - 1,
                b.pass_tets,
                b.pass_seconds,
                b.field_seconds,
                b.merge_seconds
            );
        }
        println!(
            "  imbalance (max/mean): predicted {:.3}, made in passes 1-3 {:.3}, held after redistribution {:.3}",
            st.predicted_imbalance, st.made_imbalance, st.held_imbalance
        );
        println!(
            "  tets per pass: {} ({:.2}%), {} ({:.2}%), {} ({:.2}%), {} ({:.2}%); {} tets of passes 1-3 peeled for pass 4",
            st.pass_tets[0],
            share(st.pass_tets[0]),
            st.pass_tets[1],
            share(st.pass_tets[1]),
            st.pass_tets[2],
            share(st.pass_tets[2]),
            st.pass_tets[3],
            share(st.pass_tets[3]),
            st.peeled_tets
        );
        if st.crossing_passes > 0 {
            println!(
                "  pass 3 includes {} pass{} on a crossing partition (the front left would have made pass 4 large)",
                st.crossing_passes,
                if st.crossing_passes == 1 { "" } else { "es" }
            );
        }
        println!(
            "  seconds per pass: {:.3}, {:.3}, {:.3}, {:.3}; critical path (one core per part) {:.3} s",
            st.pass_seconds[0],
            st.pass_seconds[1],
            st.pass_seconds[2],
            st.pass_seconds[3],
            st.critical_path_seconds()
        );
    }
}

/// The partitioned mesh: a `.pvtu` and one `.vtu` per piece, with global
/// point and cell ids, the owning part of each point, a ghost flag on the
/// points another part owns, and the number of parts sharing each point.
/// Returns the number of pieces written (empty ones are left out).
pub fn write_partitioned(path: &Path, sum: &mut Summary, w: &WriteOptions) -> Result<usize, Fail> {
    // A merged run keeps no pieces of a region the serial front meshed.
    if let Some(&(r, _)) = sum.serial_fallback.first() {
        return Err(Fail(
            1,
            format!("--pvtu: region {r} was meshed by the serial front (its passes failed or left most of it to pass 4), so there is no partitioned mesh to write beside the merged one; -o x.pvtu alone writes pieces"),
        ));
    }
    let tets: Vec<usize> = sum.pieces.iter().map(|pc| pc.tets.len()).collect();
    let parts = 0..sum.piece_parts;
    write_partitioned_share(path, sum, w, parts, &tets)?;
    Ok(tets.iter().filter(|&&n| n > 0).count())
}

/// [`write_partitioned`] for the parts `held` of this process (MPI): its
/// pieces, and the index where part 0 is held. `tets[r * parts + k]`:
/// the tets of region r's piece of part k, over all processes; an empty
/// piece is neither written nor named (meshio cannot read a piece
/// without cells). The pieces leave `sum` as they are written: each one's
/// points and tets go into its file's mesh, and its memory is returned
/// before the next (copies of them set each MPI rank's peak on sphere_5e6).
/// Returns the files written.
pub(crate) fn write_partitioned_share(
    path: &Path,
    sum: &mut Summary,
    w: &WriteOptions,
    held: std::ops::Range<usize>,
    tets: &[usize],
) -> Result<Vec<std::path::PathBuf>, Fail> {
    if sum.pieces.is_empty() && held.start == 0 {
        return Err(Fail(2, "--pvtu needs --parts > 1".into()));
    }
    // The piece's own ids and passes are written as they are (`u32`, `u8`):
    // wider copies of them were a third of rank 0's peak in the write.
    struct Arrays {
        mesh: TetMesh,
        gid: Vec<u32>,
        ghost: Vec<u8>,
        owner: Vec<i32>,
        sharers: Vec<i32>,
        cell_gid: (Vec<u32>, i64),
        pass: Vec<u8>,
    }
    // Pieces come region by region, `parts` per region; global cell ids
    // are per region, so each region starts after the ones before it.
    let parts = sum.piece_parts.max(1);
    let n_held = held.len().max(1);
    let region_base: Vec<i64> = std::iter::once(0)
        .chain(tets.chunks(parts).scan(0i64, |at, c| {
            *at += c.iter().sum::<usize>() as i64;
            Some(*at)
        }))
        .collect();
    // The pieces with tets, each with its index in `sum.pieces`: piece
    // `i` is region `i / n_held`'s piece of part `held.start + i % n_held`.
    let ids: Vec<usize> = (0..sum.pieces.len())
        .filter(|&i| !sum.pieces[i].tets.is_empty())
        .map(|i| i / n_held * parts + held.start + i % n_held)
        .collect();
    let shown = std::mem::take(&mut sum.pieces)
        .into_iter()
        .enumerate()
        .filter(|(_, pc)| !pc.tets.is_empty());
    // Each piece's arrays are made as it is written, then dropped: a
    // process held a second copy of all its pieces here (its peak on
    // sphere_5e6 at 4 ranks).
    let arrays = shown.map(|(i, pc)| {
        let (r, k) = (i / n_held, held.start + i % n_held);
        let cell_base = region_base[r];
        let mut sharers = vec![0i32; pc.points.len()];
        for list in &pc.shared {
            for &p in list {
                sharers[p as usize] += 1;
            }
        }
        let region = vec![r as u32 + 1; pc.tets.len()];
        Arrays {
            mesh: TetMesh {
                // In place: `PointId` is a transparent `u32`.
                tets: pc
                    .tets
                    .into_iter()
                    .map(|t| t.map(PointId::from_raw))
                    .collect(),
                points: pc.points,
                region,
                ..Default::default()
            },
            gid: pc.gid,
            ghost: pc
                .owner
                .iter()
                .map(|&o| u8::from(o as usize != k))
                .collect(),
            owner: pc.owner.iter().map(|&o| o as i32).collect(),
            sharers,
            cell_gid: (pc.tet_gid, cell_base),
            pass: pc.tet_pass,
        }
    });
    fn piece(a: &Arrays) -> Piece<'_> {
        Piece {
            mesh: &a.mesh,
            point_fields: vec![
                Field::scalar("GlobalPointIds", FieldData::I64From(&a.gid, 0)),
                Field::scalar("vtkGhostType", FieldData::U8(&a.ghost)),
                Field::scalar("OwnerPart", FieldData::I32(&a.owner)),
                Field::scalar("SharingParts", FieldData::I32(&a.sharers)),
            ],
            cell_fields: vec![
                Field::scalar(
                    "GlobalCellIds",
                    FieldData::I64From(&a.cell_gid.0, a.cell_gid.1),
                ),
                Field::scalar("Pass", FieldData::U8(&a.pass)),
            ],
        }
    }
    let index = held.start == 0 && !held.is_empty();
    let listed: Vec<usize> = (0..tets.len()).filter(|&i| tets[i] > 0).collect();
    let mut written = write_pvtu_share(path, &ids, &listed, index, arrays, piece, w)?;
    if index {
        written.push(path.to_path_buf());
    }
    Ok(written)
}

/// `parafront bench`'s table head.
pub(crate) fn print_bench_head() {
    println!(
        "{:>5} {:>5} {:>5} {:>9} {:>9} {:>11} {:>11} | {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} | {:>6} {:>6} {:>6} {:>6} | {:>6} {:>6} {:>8} | {:>5} {:>6} {:>8} {:>4} {:>7} | {:>8} {:>6} {:>6}",
        "nproc", "nprol", "ncore", "nelem", "CPU s", "AbsSpeed", "RelSpeed",
        "ddg", "part", "pass1", "pass2", "pass3", "pass4",
        "%p1", "%p2", "%p3", "%p4", "imbP", "imbH", "crit s",
        "split", "cut", "cutF", "pcs", "split s", "cpu s", "%ddgW", "%ddgC"
    );
}

/// One row of `parafront bench`'s table: `n` tets made by `p` parts on
/// `t` threads in `secs` (wall) and `cpu` seconds; nproc is the parts,
/// nprol the threads per part, ncore the threads.
fn print_bench_row(p: usize, t: usize, n: usize, secs: f64, cpu: f64, sum: &Summary) {
    let cores = t.max(1);
    let nprol = (cores / p.max(1)).max(1);
    print_row((p, nprol, cores), n, secs, cpu, sum);
}

/// A row of the table for `(nproc, nprol, ncore)`.
pub(crate) fn print_row(
    (p, nprol, cores): (usize, usize, usize),
    n: usize,
    secs: f64,
    cpu: f64,
    sum: &Summary,
) {
    let ddg_cpu: f64 = sum
        .parallel
        .iter()
        .map(|x| x.ddg_cpu_seconds + x.partition_cpu_seconds)
        .sum();
    let st = sum.parallel.first();
    let share = |k: usize| {
        st.map_or(if k == 0 { 100.0 } else { 0.0 }, |_| {
            let tot: usize = sum
                .parallel
                .iter()
                .map(|x| x.pass_tets.iter().sum::<usize>())
                .sum();
            100.0 * sum.parallel.iter().map(|x| x.pass_tets[k]).sum::<usize>() as f64
                / tot.max(1) as f64
        })
    };
    let crit: f64 = if sum.parallel.is_empty() {
        secs
    } else {
        sum.total_seconds()
            - sum
                .parallel
                .iter()
                .map(|x| x.pass_seconds[..3].iter().sum::<f64>())
                .sum::<f64>()
            + sum
                .parallel
                .iter()
                .map(|x| {
                    x.part_seconds
                        .iter()
                        .map(|v| v.iter().cloned().fold(0.0, f64::max))
                        .sum::<f64>()
                })
                .sum::<f64>()
    };
    println!(
    "{:>5} {:>5} {:>5} {:>9} {:>9.2} {:>11.0} {:>11.0} | {:>7.2} {:>7.2} {:>7.2} {:>7.2} {:>7.2} {:>7.2} | {:>6.2} {:>6.2} {:>6.2} {:>6.2} | {:>6.3} {:>6.3} {:>8.2} | {:>5} {:>6} {:>8.0} {:>4} {:>7.3} | {:>8.2} {:>6.2} {:>6.2}",
    p, nprol, cores, n, secs, n as f64 / secs, n as f64 / secs / cores as f64,
    sum.seconds(Stage::Ddg) + 0.0, sum.seconds(Stage::Partition) + 0.0,
    if p > 1 { sum.seconds(Stage::Pass1) } else { sum.seconds(Stage::Front) } + 0.0,
    sum.seconds(Stage::Pass2) + 0.0, sum.seconds(Stage::Pass3) + 0.0, sum.seconds(Stage::Pass4) + 0.0,
    share(0), share(1), share(2), share(3),
    st.map_or(1.0, |x| x.predicted_imbalance), st.map_or(1.0, |x| x.held_imbalance),
    crit,
    st.map_or("-", |x| x.partition.name()),
    st.map_or(0, |x| x.cut_faces),
    st.map_or(0.0, |x| x.cut_fine_faces),
    st.map_or(1, |x| x.max_components),
    st.map_or(0.0, |x| x.split_seconds),
    cpu,
    100.0 * (sum.seconds(Stage::Ddg) + sum.seconds(Stage::Partition)) / secs + 0.0,
    if cpu > 0.0 { 100.0 * ddg_cpu / cpu + 0.0 } else { 0.0 }
);
}

/// `parafront bench`: every (parts, threads) pair on one surface.
pub fn run_bench(
    path: &Path,
    size: Option<f64>,
    parts: &[usize],
    threads: &[usize],
    methods: &[parafront_pipeline::Partition],
    ddg_passes: Option<usize>,
) -> Result<(), Fail> {
    let s = parafront_surface::read::read_surface(path)?;
    println!(
        "{}: {} points, {} triangles",
        path.display(),
        s.points.len(),
        s.tris.len()
    );
    print_bench_head();
    for &p in parts {
        // P = 1 is the serial front: no partition, one row.
        let methods = if p > 1 { methods } else { &methods[..1] };
        for &method in methods {
            for &t in threads {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(t.max(1))
                    .build()
                    .map_err(|e| Fail(2, e.to_string()))?;
                // Generation only, as in the paper's tables: no improvement.
                let mut o = parafront_pipeline::MeshOptions {
                    parts: p.max(1),
                    threads: t,
                    optimize: 0,
                    no_quality: true,
                    partition: method,
                    ddg_passes,
                    ..Default::default()
                };
                o.size.h = size;
                let t0 = std::time::Instant::now();
                let cpu0 = parafront_pipeline::process_cpu_seconds();
                let (m, sum) = pool
                    .install(|| parafront_pipeline::mesh_surface(&s, &o))
                    .map_err(|e| Fail(1, format!("parts {p}, threads {t}: {e}")))?;
                let secs = t0.elapsed().as_secs_f64();
                let cpu = parafront_pipeline::process_cpu_seconds()
                    .zip(cpu0)
                    .map_or(0.0, |(a, b)| a - b);
                print_bench_row(p, t, m.tets.len(), secs, cpu, &sum);
                for (r, e) in &sum.serial_fallback {
                    println!(
                        "      ^ region {r}: the serial front meshed it ({e}); the row's seconds include the passes given up"
                    );
                }
            }
        }
    }
    print_bench_notes();
    Ok(())
}

/// What the table's columns mean.
pub(crate) fn print_bench_notes() {
    println!(
        "imbP: predicted (DDG weights), imbH: tets held after redistribution (max/mean, region 1);"
    );
    println!(
        "split: DDG partition; cut: DDG faces between parts (cutF: the fine faces expected on them); pcs: most face-connected pieces of one part; split s: its seconds (region 1)."
    );
    println!(
        "crit s: the run with each parallel pass timed by its slowest part (one core per part)."
    );
    println!(
        "cpu s: CPU seconds of the run, all threads; %ddgW, %ddgC: the DDG and its partition's share of the wall time and of the CPU time."
    );
}

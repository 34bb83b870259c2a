//! `mpirun -n R parafront mesh SURFACE --parts P` (feature `mpi`): rank `r`
//! holds the parts `r*P/R .. (r+1)*P/R` and runs their passes on its own
//! `--threads`. Every rank reads the surface; the size field's octree and
//! the DDG are built over the ranks and then held by each (small; the same
//! bytes everywhere). With `-o x.vtu` or `.msh` the mesh gathers on rank 0,
//! which improves, checks and writes it and prints the summary; with
//! `-o x.pvtu` it stays in its pieces.
use crate::{Fail, MeshArgs, WriteArgs};
use parafront_comm::{Comm, Mpi};
use parafront_surface::Surface;
use std::path::Path;

/// Started by mpirun with more than one rank (OpenMPI's or a PMI
/// launcher's variables): then every mesh run goes through MPI.
pub(crate) fn launched() -> bool {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"]
        .iter()
        .filter_map(|v| std::env::var(v).ok())
        .filter_map(|n| n.parse::<usize>().ok())
        .any(|n| n > 1)
}

/// Before MPI starts, and before any other thread: hwloc, which OpenMPI
/// starts in every rank, would load its GL, OpenCL and libxml2 plugins,
/// and with them libX11, libOpenCL, libxml2 and libicu, 2.8 MiB of every
/// rank's resident memory (the demo on 4 ranks: 22.8 to 20.0 MiB a rank)
/// that a mesher never uses; hwloc reads XML with its own parser then. A
/// list the user set is kept.
pub(crate) fn skip_hwloc_plugins() {
    const VAR: &str = "HWLOC_PLUGINS_BLACKLIST";
    if std::env::var_os(VAR).is_none() {
        std::env::set_var(VAR, "hwloc_gl,hwloc_opencl,hwloc_xml_libxml");
    }
}

/// Rank 0 says why a run failed; the others exit with its code, silently.
fn quiet(rank: usize, f: Fail) -> Fail {
    if rank == 0 {
        f
    } else {
        Fail(f.0, String::new())
    }
}

/// MPI for this process, one part until the run says how many.
pub(crate) fn start() -> Result<Mpi, Fail> {
    Mpi::init(1).map_err(|e| Fail(2, format!("MPI: {e}")))
}

/// One mesh run over the ranks: `input` is what this rank read (or its
/// error). Rank 0 reports; the others say nothing and exit with the same
/// code (an empty message is not printed).
pub(crate) fn run_mesh(
    mpi: &mut Mpi,
    input: Result<(Surface, String), Fail>,
    out: &Path,
    a: &MeshArgs,
    w: &WriteArgs,
) -> Result<(), Fail> {
    let (rank, ranks) = (mpi.rank(), mpi.ranks());
    let quiet = |f: Fail| quiet(rank, f);
    if a.parts < ranks {
        let given = if a.parts == parafront_pipeline::AUTO_PARTS {
            "auto".to_string()
        } else {
            a.parts.to_string()
        };
        return Err(quiet(Fail(
            2,
            format!("--parts {given} under {ranks} MPI ranks: give every rank a part (--parts {ranks} or more)"),
        )));
    }
    if a.pvtu.is_some() {
        return Err(quiet(Fail(
            2,
            "--pvtu is not written under mpirun yet: write .vtu or .msh (gathered on rank 0)"
                .into(),
        )));
    }
    mpi.set_parts(a.parts);
    // Every rank must have read the surface before any collective of the
    // run, or the others would wait for it.
    let failed = input.is_err() as u8;
    let any = mpi.all_reduce(vec![failed; mpi.owned().len()], u8::max);
    let (s, name) = match input {
        Err(e) => return Err(quiet(e)),
        Ok(_) if any > 0 => {
            return Err(quiet(Fail(
                1,
                "another MPI rank could not read or heal the surface".into(),
            )))
        }
        Ok(x) => x,
    };
    crate::run_mesh_on(&s, &name, out, a, w, &*mpi, rank == 0).map_err(quiet)
}

/// `mpirun -n R parafront bench`: every (parts, threads) pair over the R
/// ranks, generation only (as in the paper's tables); rank 0 prints each
/// row with nproc = R, nprol = threads per rank, ncore = R x threads, the
/// wall time of the slowest rank and the CPU time of all.
pub(crate) fn run_bench(
    mpi: &mut Mpi,
    path: &Path,
    size: Option<f64>,
    parts: &[usize],
    threads: &[usize],
    methods: &[parafront_pipeline::Partition],
    ddg_passes: Option<usize>,
) -> Result<(), Fail> {
    let (rank, ranks) = (mpi.rank(), mpi.ranks());
    let quiet = |f: Fail| quiet(rank, f);
    if let Some(&p) = parts.iter().find(|&&p| p < ranks) {
        return Err(quiet(Fail(
            2,
            format!("--parts {p} under {ranks} MPI ranks: give every rank a part"),
        )));
    }
    let input = parafront_surface::read::read_surface(path).map_err(Fail::from);
    mpi.set_parts(parts[0].max(1));
    let any = mpi.all_reduce(vec![input.is_err() as u8; mpi.owned().len()], u8::max);
    let s = match input {
        Err(e) => return Err(quiet(e)),
        Ok(_) if any > 0 => {
            return Err(quiet(Fail(
                1,
                "another MPI rank could not read the surface".into(),
            )))
        }
        Ok(s) => s,
    };
    if rank == 0 {
        println!(
            "{}: {} points, {} triangles ({ranks} MPI ranks)",
            path.display(),
            s.points.len(),
            s.tris.len()
        );
        crate::parallel::print_bench_head();
    }
    for (&p, &method) in parts
        .iter()
        .flat_map(|p| methods.iter().map(move |m| (p, m)))
    {
        mpi.set_parts(p);
        if rank == 0 {
            println!("--parts {p}, partition {}:", method.name());
        }
        for &t in threads {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(t.max(1))
                .build()
                .map_err(|e| quiet(Fail(2, e.to_string())))?;
            let mut o = parafront_pipeline::MeshOptions {
                parts: p,
                threads: t,
                optimize: 0,
                no_quality: true,
                partition: method,
                ddg_passes,
                ..Default::default()
            };
            o.size.h = size;
            mpi.barrier();
            let t0 = std::time::Instant::now();
            let cpu0 = parafront_pipeline::process_cpu_seconds();
            let res = pool.install(|| parafront_pipeline::mesh_surface_on(&s, &o, &*mpi));
            let secs = t0.elapsed().as_secs_f64();
            let cpu = parafront_pipeline::process_cpu_seconds()
                .zip(cpu0)
                .map_or(0.0, |(a, b)| a - b);
            let res = res.map_err(|e| quiet(Fail(1, format!("parts {p}, threads {t}: {e}"))))?;
            let n = mpi.owned().len();
            let secs = mpi.all_reduce(vec![secs; n], f64::max);
            let cpu = mpi.all_reduce(
                (0..n).map(|i| if i == 0 { cpu } else { 0.0 }).collect(),
                |a, b| a + b,
            );
            if let Some((m, sum)) = res {
                let t = t.max(1);
                crate::parallel::print_row((ranks, t, ranks * t), m.tets.len(), secs, cpu, &sum);
            }
        }
    }
    if rank == 0 {
        crate::parallel::print_bench_notes();
        println!("nproc: MPI ranks, nprol: threads per rank, ncore: both; CPU s: the slowest rank's wall time, cpu s: all ranks' CPU.");
    }
    Ok(())
}

//! `parafront`: the command line. A thin layer: each subcommand parses its
//! flags into the library's option structs and calls one function.
// Not forbid: resetting SIGPIPE and glibc's malloc settings (in `main`)
// need unsafe calls.
#![deny(unsafe_code)]
mod args;
#[cfg(feature = "mpi")]
mod mpi_run;
mod parallel;
mod plot;
mod report;
mod surface_cmds;

use args::{Cli, Cmd, MeshArgs, WriteArgs};
use clap::Parser;
use parafront_comm::Comm;
use parafront_io::{read_mesh, write_mesh, MshVersion, WriteOptions};
use parafront_mesh::QualityReport;
use parafront_pipeline::{mesh_surface_on, MeshError, MeshOptions, Stage, Summary};
use parafront_surface::read::read_surface;
use parafront_surface::validate::validate;
use parafront_surface::Surface;
use report::{peak_memory_bytes, print_summary, ProgressLine};
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;
use surface_cmds::HealArgs;

/// A failure with its exit status: 1 for a bad surface or mesh, 2 for
/// unreadable input and bad options.
pub(crate) struct Fail(pub(crate) u8, pub(crate) String);

impl<E: std::fmt::Display> From<E> for Fail {
    fn from(e: E) -> Fail {
        Fail(2, e.to_string())
    }
}

fn main() -> ExitCode {
    #[cfg(unix)]
    // SAFETY: at startup, before any other thread exists. Rust ignores
    // SIGPIPE, so printing to a pipe whose reader has gone (`| head`)
    // panicked; the default action ends the process quietly, as for any
    // Unix tool. Meshes go to files (written aside, then renamed), never
    // to a pipe.
    #[allow(unsafe_code)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: at startup, before any allocation on another thread. glibc
    // raises its mmap threshold each time a large block is freed, up to
    // 32 MiB; the blocks the stages free then stay in its heaps, and the
    // next stage's, allocated on other threads (other arenas), come on top.
    // A fixed threshold gives blocks of 256 KiB and more back when freed:
    // the peak of sphere_5e6 drops from 297 to 256 MiB by default, and from
    // 306 to 213 MiB at --parts 8 -o x.pvtu, at the same speed.
    #[allow(unsafe_code)]
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 256 << 10);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 256 << 10);
    }
    #[cfg(feature = "mpi")]
    if mpi_run::launched() {
        mpi_run::skip_hwloc_plugins();
    }
    // Diagnostics on stderr, off unless RUST_LOG asks (e.g. RUST_LOG=debug).
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    // The pool before any parallel work: reading a surface sorts in
    // parallel, and the first use of rayon fixes the global pool.
    if let Cmd::Demo { mesh, .. } | Cmd::Mesh { mesh, .. } = &cli.cmd {
        if let Some(t) = mesh.threads.filter(|&t| t > 0) {
            let _ = rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build_global();
        }
    }
    // Under mpirun (feature `mpi`), `mesh` and `demo` run over the ranks.
    #[cfg(feature = "mpi")]
    let mut mpi = if mpi_run::launched() {
        match mpi_run::start() {
            Ok(m) => Some(m),
            Err(Fail(code, msg)) => {
                eprintln!("parafront: {msg}");
                return ExitCode::from(code);
            }
        }
    } else {
        None
    };
    #[cfg(feature = "mpi")]
    if let Some(m) = mpi.as_mut() {
        let res = match cli.cmd {
            Cmd::Demo {
                output,
                mesh,
                write,
                check_only: false,
            } => {
                let mut mesh = mesh;
                mesh.regions = true;
                let s = parafront_surface::generate::demo_part();
                mpi_run::run_mesh(m, Ok((s, "demo part".into())), &output, &mesh, &write)
            }
            Cmd::Mesh {
                surface,
                output,
                mesh,
                heal,
                write,
            } => {
                let input =
                    mesh_input(&surface, &heal, &write).map(|s| (s, surface.display().to_string()));
                mpi_run::run_mesh(m, input, &output, &mesh, &write)
            }
            Cmd::Bench {
                surface,
                size,
                parts,
                threads,
                partition,
                ddg_passes,
            } => mpi_run::run_bench(m, &surface, size, &parts, &threads, &partition, ddg_passes),
            _ => Err(Fail(
                2,
                "under mpirun, only `mesh`, `demo` and `bench` run (over the ranks)".into(),
            )),
        };
        return exit(res);
    }
    let res = match cli.cmd {
        Cmd::Demo {
            output,
            check_only,
            mesh,
            write,
        } => {
            let s = parafront_surface::generate::demo_part();
            println!("demo part: block 16x12x6 mm with a drilled hole, a spherical void and an embedded sphere");
            if check_only {
                run_demo_check(&s, &output, &write)
            } else {
                // The embedded sphere is the demo's second region.
                let mut mesh = mesh;
                mesh.regions = true;
                run_mesh(&s, "demo part", &output, &mesh, &write)
            }
        }
        Cmd::Mesh {
            surface,
            output,
            mesh,
            heal,
            write,
        } => mesh_input(&surface, &heal, &write)
            .and_then(|s| run_mesh(&s, &surface.display().to_string(), &output, &mesh, &write)),
        Cmd::Heal {
            input,
            output,
            tol,
            write,
        } => surface_cmds::run_heal(&input, &output, &tol, &write),
        Cmd::Check { surface } => run_check(&surface),
        Cmd::Bench {
            surface,
            size,
            parts,
            threads,
            partition,
            ddg_passes,
        } => parallel::run_bench(&surface, size, &parts, &threads, &partition, ddg_passes),
        Cmd::Quality { mesh, plot, before } => {
            run_quality(&mesh, plot.as_deref(), before.as_deref())
        }
        Cmd::Convert {
            input,
            output,
            write,
        } => surface_cmds::run_convert(&input, &output, &write),
    };
    exit(res)
}

/// The surface `mesh` reads: `path`, healed as `heal` says.
fn mesh_input(path: &Path, heal: &HealArgs, w: &WriteArgs) -> Result<Surface, Fail> {
    surface_cmds::heal_for_mesh(read_surface(path)?, heal, w)
}

/// The exit code, with the message on stderr (none when empty: an MPI
/// rank other than 0).
fn exit(res: Result<(), Fail>) -> ExitCode {
    match res {
        Ok(()) => ExitCode::SUCCESS,
        Err(Fail(code, msg)) => {
            if !msg.is_empty() {
                eprintln!("parafront: {msg}");
            }
            ExitCode::from(code)
        }
    }
}

pub(crate) fn write_options(w: &WriteArgs, s: Option<&Surface>) -> Result<WriteOptions, Fail> {
    let msh_version = match w.msh_version.as_str() {
        "4.1" | "4" => MshVersion::V41,
        "2.2" | "2" => MshVersion::V22,
        v => return Err(Fail(2, format!("--msh-version {v}: expected 4.1 or 2.2"))),
    };
    Ok(WriteOptions {
        msh_version,
        binary: w.binary,
        compress: !w.no_compress,
        patch_names: s.map(|s| s.patch_names.clone()).unwrap_or_default(),
        ..Default::default()
    })
}

/// Between stages: glibc keeps the free pages inside its heaps (the many
/// small blocks of the size field's build, of the front and of the
/// improvement, which the fixed thresholds in `main` do not cover) until
/// asked to give them back.
fn release_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free memory to the system; it is
    // thread-safe (it locks each arena).
    #[allow(unsafe_code)]
    unsafe {
        libc::malloc_trim(0);
    }
}

fn mesh_options(a: &MeshArgs) -> Result<MeshOptions, Fail> {
    let mut o = MeshOptions::default();
    if let Some(f) = &a.size_file {
        o.size = parafront_size::SizeOptions::from_toml_file(f)?;
    }
    if a.size.is_some() {
        o.size.h = a.size;
    }
    if let Some(v) = a.hmin {
        o.size.hmin = v;
    }
    if let Some(v) = a.hmax {
        o.size.hmax = v;
    }
    if let Some(v) = a.gradation {
        o.size.gradation = v;
    }
    o.threads = a.threads.unwrap_or(0);
    o.regions = a.regions;
    o.debug_partial = a.debug_dump.is_some();
    if let Some(l) = a.optimize {
        o.optimize = l;
    }
    if let Some(n) = a.optimize_parts {
        o.optimize_parts = n;
    }
    o.fill_after = a.fill_after;
    o.size_report = a.size_report;
    o.lattice = a.lattice;
    o.thin_depth = a.thin_depth;
    o.serial_from = a.serial_from;
    o.ddg_cap = a.ddg_cap;
    o.fail_part = a.fail_part;
    o.release_memory = Some(release_memory);
    if a.part_tets == 0 {
        return Err(Fail(2, "--part-tets must be at least 1".into()));
    }
    o.parts = a.parts;
    o.part_tets = a.part_tets;
    o.ddg_growth = a.ddg_growth.unwrap_or(0.0);
    o.partition = a.partition;
    o.ddg_passes = a.ddg_passes;
    if a.pvtu.is_some() {
        // Checked before the run: auto parts keep a small job serial.
        if a.parts < 2 {
            return Err(Fail(
                2,
                "--pvtu writes the parallel passes' parts: give --parts 2 or more".into(),
            ));
        }
        // The pieces are the passes' parts; the lattice's tets are in none.
        o.lattice = parafront_pipeline::LatticeMode::Off;
    }
    if a.pvtu.is_some() && o.optimize > 0 {
        // The pieces are the generation's partition (§8); improvement
        // (§9) changes the mesh after it and does not renumber them yet.
        return Err(Fail(
            2,
            "--pvtu writes the mesh as the parallel passes left it: add --optimize 0".into(),
        ));
    }
    Ok(o)
}

fn run_mesh(s: &Surface, name: &str, out: &Path, a: &MeshArgs, w: &WriteArgs) -> Result<(), Fail> {
    let comm = parafront_comm::Threads::new(a.parts.max(1));
    run_mesh_on(s, name, out, a, w, &comm, true)
}

/// [`run_mesh`] with the parts' messages through `comm`; only the `lead`
/// process (the one the mesh gathers on) prints and writes.
pub(crate) fn run_mesh_on<C: Comm>(
    s: &Surface,
    name: &str,
    out: &Path,
    a: &MeshArgs,
    w: &WriteArgs,
    comm: &C,
    lead: bool,
) -> Result<(), Fail> {
    let mut opts = mesh_options(a)?;
    let wopts = write_options(w, Some(s))?;
    // A .pvtu output keeps the mesh in its pieces (under MPI, each process
    // writes its own): no merged mesh.
    let pieces_out = out.extension().and_then(|e| e.to_str()) == Some("pvtu");
    if pieces_out {
        if a.pvtu.is_some() {
            return Err(Fail(2, "-o is a .pvtu already: leave out --pvtu".into()));
        }
        opts.gather = false;
    } else if parafront_io::Format::from_path(out).is_none() {
        return Err(Fail(
            2,
            format!(
                "{}: unknown output format (use .vtu, .pvtu, .msh or .mesh)",
                out.display()
            ),
        ));
    }
    let bar = lead.then(|| {
        println!(
            "{name}: {} points, {} triangles",
            s.points.len(),
            s.tris.len()
        );
        let progress = std::sync::Arc::new(parafront_front::Progress::default());
        opts.progress = Some(progress.clone());
        ProgressLine::start(progress)
    });
    let res = mesh_surface_on(s, &opts, comm);
    if let Some(bar) = bar {
        bar.finish();
    }
    let (mesh, mut sum) = match res {
        Ok(Some(r)) => r,
        Ok(None) => return Ok(()),
        Err(e) => {
            if let (Some(path), MeshError::Front { source, .. }) = (&a.debug_dump, &e) {
                write_partial(path, source, &wopts);
            }
            let hint = match (&e, &a.debug_dump) {
                (
                    MeshError::Front {
                        source: parafront_front::FrontError::Stuck { .. },
                        ..
                    },
                    None,
                ) => "\n(add --debug-dump STUCK.vtu to write what the front made and the faces it left, for ParaView)",
                _ => "",
            };
            return Err(Fail(1, format!("{name}: {e}{hint}")));
        }
    };
    if pieces_out {
        // Parts left to the estimate were made in this one process (the
        // pipeline refuses them over several), on a comm of their own.
        if let Some((parts, _)) = sum.auto_parts {
            let own = parafront_comm::Threads::new(parts);
            return write_pieces(out, &mut sum, &wopts, &own, lead);
        }
        return write_pieces(out, &mut sum, &wopts, comm, lead);
    }
    let t0 = Instant::now();
    write_mesh(out, &mesh, &wopts)?;
    sum.push(Stage::Write, t0.elapsed().as_secs_f64());
    print_summary(&sum);
    parallel::print_parallel(&sum);
    println!("wrote {}", out.display());
    if let Some(p) = &a.pvtu {
        let written = parallel::write_partitioned(p, &mut sum, &wopts)?;
        println!("wrote {} ({written} pieces)", p.display());
    }
    if let (Some(p), Some(q)) = (&a.plot, &sum.quality) {
        plot::plot_histograms(q, sum.quality_before.as_ref(), p)?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// `-o x.pvtu`: every process writes its pieces (the one holding part 0
/// the index too); when any fails, every process removes what it wrote.
/// The `lead` prints the summary, with each process's peak memory.
fn write_pieces<C: Comm>(
    out: &Path,
    sum: &mut Summary,
    w: &WriteOptions,
    comm: &C,
    lead: bool,
) -> Result<(), Fail> {
    let t0 = Instant::now();
    let held = comm.owned();
    let n = held.len();
    // The tets of each piece, over all processes: region by region, one
    // count per part (every process has every region's pieces).
    let mut tets = Vec::with_capacity(sum.regions * comm.parts());
    for r in 0..sum.regions {
        let local: Vec<u64> = (0..n)
            .map(|i| {
                sum.pieces
                    .get(r * n + i)
                    .map_or(0, |pc| pc.tets.len() as u64)
            })
            .collect();
        tets.extend(comm.all_gather(local).into_iter().map(|c| c as usize));
    }
    let res = parallel::write_partitioned_share(out, sum, w, held, &tets);
    let failed = comm.all_reduce(vec![res.is_err() as u8; n], u8::max);
    let files = match res {
        Err(e) => return Err(e),
        Ok(files) if failed > 0 => {
            for f in &files {
                let _ = std::fs::remove_file(f);
            }
            return Err(Fail(1, "another process could not write its pieces".into()));
        }
        Ok(files) => files,
    };
    sum.push(Stage::Write, t0.elapsed().as_secs_f64());
    // One value per process: its first part carries it, the others a
    // mark. (Told apart by value, two processes with the same peak were
    // one, and the line went missing.)
    let peak = peak_memory_bytes().unwrap_or(0).min(u64::MAX - 1);
    let mine: Vec<u64> = (0..n)
        .map(|i| if i == 0 { peak } else { u64::MAX })
        .collect();
    let per: Vec<u64> = comm
        .all_gather(mine)
        .into_iter()
        .filter(|&p| p != u64::MAX)
        .collect();
    if lead {
        print_summary(sum);
        parallel::print_parallel(sum);
        if per.len() > 1 {
            println!(
                "peak memory per process: {} MiB",
                per.iter()
                    .map(|&b| format!("{:.1}", b as f64 / 1048576.0))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        let total = tets.iter().filter(|&&c| c > 0).count();
        println!("wrote {} ({total} pieces)", out.display());
    }
    drop(files);
    Ok(())
}

/// The debug dump of a failed front: its tets, and the faces it left as
/// triangles. A failure to write it is reported, not fatal.
fn write_partial(path: &Path, e: &parafront_front::FrontError, w: &WriteOptions) {
    let parafront_front::FrontError::Stuck {
        partial: Some(p), ..
    } = e
    else {
        return;
    };
    let mesh = parafront_mesh::TetMesh {
        points: p.points.clone(),
        tets: p
            .tets
            .iter()
            .map(|t| t.map(parafront_mesh::PointId::from_raw))
            .collect(),
        region: vec![0; p.tets.len()],
        bnd_tris: p
            .front
            .iter()
            .map(|f| f.map(parafront_mesh::PointId::from_raw))
            .collect(),
        bnd_patch: vec![0; p.front.len()],
        ..Default::default()
    };
    match write_mesh(path, &mesh, w) {
        Ok(()) => eprintln!(
            "wrote the partial mesh ({} tets) and the stuck front ({} triangles) to {}",
            p.tets.len(),
            p.front.len(),
            path.display()
        ),
        Err(err) => eprintln!("could not write the debug dump {}: {err}", path.display()),
    }
}

/// Validate the built-in surface and write it as a triangle-only mesh.
fn run_demo_check(s: &Surface, out: &Path, w: &WriteArgs) -> Result<(), Fail> {
    let report = validate(s);
    println!("{report}");
    if !report.is_valid() {
        return Err(Fail(
            1,
            "the built-in demo surface is not valid (a bug)".into(),
        ));
    }
    let mesh = parafront_mesh::TetMesh {
        points: s.points.clone(),
        bnd_tris: s
            .tris
            .iter()
            .map(|t| t.map(parafront_mesh::PointId::from_raw))
            .collect(),
        bnd_patch: s.patch.clone(),
        ..Default::default()
    };
    write_mesh(out, &mesh, &write_options(w, Some(s))?)?;
    println!("wrote the surface to {}", out.display());
    Ok(())
}

fn run_check(path: &Path) -> Result<(), Fail> {
    let t0 = Instant::now();
    let s = read_surface(path)?;
    let report = validate(&s);
    println!("{}: {}", path.display(), report);
    if let Some(note) = surface_cmds::heal_hint(path, &s, &report) {
        println!("{note}");
    }
    let bodies = parafront_pipeline::bodies_in_material(&report.shells).len();
    if bodies > 0 && report.is_valid() {
        println!(
            "note: `parafront mesh` meshes the {bodies} inner bod{} as void{} unless given --regions",
            if bodies == 1 { "y" } else { "ies" },
            if bodies == 1 { "" } else { "s" }
        );
    }
    println!("checked in {:.3} s", t0.elapsed().as_secs_f64());
    if report.is_valid() {
        Ok(())
    } else {
        Err(Fail(
            1,
            format!("{}: the surface is not valid for meshing", path.display()),
        ))
    }
}

fn run_quality(path: &Path, plot_to: Option<&Path>, before: Option<&Path>) -> Result<(), Fail> {
    let mesh = read_mesh(path)?;
    if let Err(e) = mesh.check() {
        println!("warning: {}: {e}", path.display());
    }
    let q = QualityReport::new(&mesh);
    println!(
        "{}: {} points, {} tets",
        path.display(),
        mesh.points.len(),
        mesh.tets.len()
    );
    println!("{q}");
    let qb = match before {
        Some(b) => {
            let qb = QualityReport::new(&read_mesh(b)?);
            for (name, r) in [(b, &qb), (path, &q)] {
                println!(
                    "{}: {} tets, min dihedral {:.2} deg, {:.3}% of tets under 10 deg, mean radius ratio {:.3}",
                    name.display(),
                    r.n_tets,
                    r.min_dihedral.min,
                    100.0 * r.share_min_dihedral_below,
                    r.radius_ratio.mean
                );
            }
            Some(qb)
        }
        None => None,
    };
    if let Some(p) = plot_to {
        plot::plot_histograms(&q, qb.as_ref(), p)?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

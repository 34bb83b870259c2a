//! `mpirun -n R parafront mesh SURFACE --parts P` (feature `mpi`): rank `r`
//! holds the parts `r*P/R .. (r+1)*P/R` and runs their passes on its own
//! `--threads`. Every rank reads the surface and builds the size field and
//! the DDG (small; the same bytes everywhere); the mesh gathers on rank 0,
//! which improves, checks and writes it and prints the summary.
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
    let quiet = |f: Fail| {
        if rank == 0 {
            f
        } else {
            Fail(f.0, String::new())
        }
    };
    if a.parts < ranks {
        return Err(quiet(Fail(
            2,
            format!("--parts {} under {ranks} MPI ranks: give every rank a part (--parts {ranks} or more)", a.parts),
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

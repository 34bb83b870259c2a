//! Checks the MPI backend against the threads backend: run under
//! `mpirun -n R` (any R). For several part counts P, every rank builds
//! every part's messages (they are functions of the part), runs the
//! collectives through `Mpi` on its own parts and through `Threads` on all
//! of them, and compares its share byte for byte, order included.
//!
//! `--fail-on R` makes rank R panic (and `--abort-on R` call
//! `Mpi::abort`) while the others wait in an exchange: every rank must
//! end, with that rank's message. Prints `mpi_check: rank r of R: N checks
//! passed` on success.
use parafront_comm::wire::to_bytes;
use parafront_comm::{Comm, Mpi, Threads, Wire};

/// Part `s`'s outbox for a run on `np` parts, of messages `msg(s, j)`:
/// several messages per destination, destinations in no particular order,
/// to itself too.
fn outbox<T>(s: u32, np: u32, msg: impl Fn(u32, u32) -> T) -> Vec<(u32, T)> {
    (0..(s % 5) * 2 + 3)
        .map(|j| ((s * 7 + j * 5 + j * j / 2) % np, msg(s, j)))
        .collect()
}

struct Checker<'a> {
    mpi: &'a Mpi,
    threads: Threads,
    checks: usize,
}

impl Checker<'_> {
    fn same<T: Wire>(&mut self, what: &str, got: &T, want: &T) {
        self.checks += 1;
        assert!(
            to_bytes(got) == to_bytes(want),
            "{what} on {} parts: the MPI backend differs from the threads backend",
            self.mpi.parts()
        );
    }

    /// `exchange` of every part's `gen(s)` outbox.
    fn exchange<T: Wire + Send>(&mut self, what: &str, gen: impl Fn(u32) -> Vec<(u32, T)>) {
        let np = self.mpi.parts() as u32;
        let own = self.mpi.owned();
        let got = self
            .mpi
            .exchange(own.clone().map(|s| gen(s as u32)).collect());
        let mut want = self.threads.exchange((0..np).map(&gen).collect());
        let want: Vec<_> = want.drain(own).collect();
        self.same(what, &got, &want);
    }

    fn gather<T: Wire + Clone + Send>(&mut self, what: &str, gen: impl Fn(u32) -> T) {
        let np = self.mpi.parts() as u32;
        let got = self
            .mpi
            .all_gather(self.mpi.owned().map(|s| gen(s as u32)).collect());
        let want = self.threads.all_gather((0..np).map(&gen).collect());
        self.same(what, &got, &want);
    }

    fn reduce<T: Wire + Clone + Send>(
        &mut self,
        what: &str,
        gen: impl Fn(u32) -> T,
        op: impl Fn(T, T) -> T + Copy,
    ) {
        let np = self.mpi.parts() as u32;
        let got = self
            .mpi
            .all_reduce(self.mpi.owned().map(|s| gen(s as u32)).collect(), op);
        let want = self.threads.all_reduce((0..np).map(&gen).collect(), op);
        self.same(what, &got, &want);
    }
}

fn run_checks(mpi: &Mpi, c: &mut Checker<'_>) {
    let np = mpi.parts() as u32;
    c.exchange("exchange of u32", |s| outbox(s, np, |s, j| s * 1000 + j));
    // Floats whose bits matter, vectors, options, a bool.
    type Compound = (u32, Vec<[f64; 3]>, bool, Option<u64>);
    c.exchange("exchange of a compound", |s| {
        outbox(s, np, |s, j| -> Compound {
            let x = s as f64 + j as f64 / 8.0;
            (
                j,
                (0..j).map(|k| [x, -0.0, f64::NAN * k as f64]).collect(),
                (s + j) % 2 == 0,
                (j % 3 != 0).then_some(u64::MAX - s as u64),
            )
        })
    });
    // Everything to part 0 (pass 4's pattern), nothing from some parts.
    c.exchange("exchange to part 0", |s| {
        (0..s % 3).map(|j| (0u32, [s, j, s ^ j])).collect()
    });
    c.exchange("empty exchange", |_| Vec::<(u32, u8)>::new());
    // Large messages (past MPI's eager sends): 2.4 MB from each part to
    // the next.
    c.exchange("large exchange", |s| {
        vec![(
            (s + 1) % np,
            (0..300_000u64)
                .map(|i| i * 31 + s as u64)
                .collect::<Vec<u64>>(),
        )]
    });
    c.gather("all_gather of u32", |s| s * 3 + 1);
    c.gather("all_gather of vectors", |s| {
        (0..s % 4)
            .map(|i| [i as f64, -0.0, s as f64])
            .collect::<Vec<_>>()
    });
    c.gather("all_gather of strings", |s| {
        format!("part {s}: {}", "x".repeat(s as usize))
    });
    // Part order matters: a float sum that rounds differently in another
    // order, and a concatenation.
    c.reduce(
        "all_reduce of f64 (sum)",
        |s| [1e16, 1.0, -1e16, 0.5, 3.25][s as usize % 5] * (1.0 + s as f64 * 1e-3),
        |a, b| a + b,
    );
    c.reduce("all_reduce of f64 (max)", |s| (s as f64).sin(), f64::max);
    c.reduce("all_reduce of usize", |s| s as usize * 17, |a, b| a + b);
    c.reduce(
        "all_reduce of vectors (concatenation)",
        |s| vec![s; (s % 3) as usize],
        |mut a, b| {
            a.extend(b);
            a
        },
    );
}

fn flag(args: &[String], name: &str) -> Option<usize> {
    let i = args.iter().position(|a| a == name)?;
    Some(args.get(i + 1)?.parse().expect("a rank number"))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut mpi = match Mpi::init(1) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("mpi_check: {e}");
            std::process::exit(2);
        }
    };
    let (rank, ranks) = (mpi.rank(), mpi.ranks());
    let (fail_on, abort_on) = (flag(&args, "--fail-on"), flag(&args, "--abort-on"));
    if fail_on.is_some() || abort_on.is_some() {
        mpi.set_parts(8);
        // One exchange that works, then the failure while the others wait
        // in the next one.
        let own = mpi.owned();
        mpi.exchange(own.clone().map(|s| vec![(0u32, s as u32)]).collect());
        if fail_on == Some(rank) {
            panic!("deliberate failure on rank {rank} (test hook)");
        }
        if abort_on == Some(rank) {
            mpi.abort(&format!("deliberate abort on rank {rank} (test hook)"));
        }
        mpi.exchange(own.map(|s| vec![(0u32, s as u32)]).collect());
        eprintln!("mpi_check: rank {rank} was not stopped");
        std::process::exit(3);
    }
    let mut checks = 0;
    for np in [1, 2, 3, 5, 8, 13] {
        mpi.set_parts(np);
        let mut c = Checker {
            mpi: &mpi,
            threads: Threads::new(np),
            checks: 0,
        };
        run_checks(&mpi, &mut c);
        checks += c.checks;
    }
    mpi.barrier();
    println!("mpi_check: rank {rank} of {ranks}: {checks} checks passed");
}

//! The MPI backend under mpirun (feature `mpi`): the `mpi_check` program
//! on 2 and 4 ranks gives what the threads backend gives, and a rank that
//! fails ends them all. Skips, saying so, when mpirun is not on the PATH
//! (or `PARAFRONT_MPIRUN` names another launcher).
#![cfg(feature = "mpi")]

use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn mpirun() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("PARAFRONT_MPIRUN") {
        return Some(p.into());
    }
    // By name, not by the path found: Open MPI's mpirun called by an
    // absolute path takes its directory as the install prefix (`/bin`
    // next to a merged `/usr` is no prefix).
    std::env::split_paths(&std::env::var_os("PATH")?)
        .any(|d| d.join("mpirun").is_file())
        .then(|| "mpirun".into())
}

struct Run {
    ok: bool,
    out: String,
    err: String,
}

/// `mpirun -n ranks mpi_check args`, killed after `limit`.
fn launch(ranks: usize, args: &[&str], limit: Duration) -> Option<Run> {
    let Some(mpirun) = mpirun() else {
        eprintln!("skipping: mpirun not found (apt-get install openmpi-bin libopenmpi-dev)");
        return None;
    };
    let mut child = Command::new(mpirun)
        .args(["--oversubscribe", "-n", &ranks.to_string()])
        .arg(env!("CARGO_BIN_EXE_mpi_check"))
        .args(args)
        // CI runs as root; the machine has fewer cores than ranks.
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mpirun starts");
    let read = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut s = String::new();
            r.read_to_string(&mut s).ok();
            s
        })
    };
    let out = read(Box::new(child.stdout.take().unwrap()));
    let err = read(Box::new(child.stderr.take().unwrap()));
    let t0 = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().expect("wait for mpirun") {
            break st;
        }
        if t0.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            panic!(
                "mpirun -n {ranks} mpi_check {args:?} still running after {limit:?}: a rank hangs\n{}",
                err.join().unwrap()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    Some(Run {
        ok: status.success(),
        out: out.join().unwrap(),
        err: err.join().unwrap(),
    })
}

fn backends_agree(ranks: usize) {
    let Some(r) = launch(ranks, &[], Duration::from_secs(120)) else {
        return;
    };
    assert!(
        r.ok,
        "mpi_check on {ranks} ranks failed:\n{}\n{}",
        r.out, r.err
    );
    for k in 0..ranks {
        assert!(
            r.out.contains(&format!("mpi_check: rank {k} of {ranks}: ")),
            "rank {k} did not finish:\n{}\n{}",
            r.out,
            r.err
        );
    }
}

#[test]
fn two_ranks_match_threads() {
    backends_agree(2);
}

#[test]
fn four_ranks_match_threads() {
    backends_agree(4);
}

/// A rank that fails ends every rank within seconds, with its message.
fn failure_stops_all(flag: &str, message: &str) {
    let t0 = Instant::now();
    let Some(r) = launch(4, &[flag, "2"], Duration::from_secs(60)) else {
        return;
    };
    assert!(
        !r.ok,
        "a failing rank must fail the run:\n{}\n{}",
        r.out, r.err
    );
    assert!(
        r.err.contains(message),
        "the failing rank's message is missing:\n{}",
        r.err
    );
    assert!(
        !r.err.contains("was not stopped"),
        "a rank went on past the failure:\n{}",
        r.err
    );
    assert!(t0.elapsed() < Duration::from_secs(30), "{:?}", t0.elapsed());
}

#[test]
fn a_panicking_rank_aborts_every_rank() {
    failure_stops_all("--fail-on", "deliberate failure on rank 2 (test hook)");
}

#[test]
fn mpi_abort_ends_every_rank() {
    failure_stops_all("--abort-on", "deliberate abort on rank 2 (test hook)");
}

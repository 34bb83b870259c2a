//! `parafront mesh` under mpirun (feature `mpi`): 2 and 4 ranks give the
//! threads backend's mesh byte for byte, and a rank that fails stops them
//! all with its message and no file. Skips, saying so, when mpirun is not
//! on the PATH (`PARAFRONT_MPIRUN` names another launcher).
#![cfg(feature = "mpi")]

mod common;
use common::{tets_said, tmp};

use parafront_io::{read_mesh, write_surface, WriteOptions};
use parafront_surface::generate;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn mpirun() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("PARAFRONT_MPIRUN") {
        return Some(p.into());
    }
    // By name: Open MPI's mpirun called by an absolute path takes its
    // directory as the install prefix.
    std::env::split_paths(&std::env::var_os("PATH")?)
        .any(|d| d.join("mpirun").is_file())
        .then(|| "mpirun".into())
}

struct Run {
    ok: bool,
    out: String,
    err: String,
}

/// Reads a child's pipe to its end on a thread of its own.
fn drain(mut r: Box<dyn Read + Send>) -> std::thread::JoinHandle<String> {
    std::thread::spawn(move || {
        let mut s = String::new();
        r.read_to_string(&mut s).ok();
        s
    })
}

/// `parafront args`, under `mpirun -n ranks` when `ranks > 0`; fails the
/// test when it runs past `limit` (a rank that hangs).
fn run(ranks: usize, args: &[&str], limit: Duration) -> Run {
    let bin = env!("CARGO_BIN_EXE_parafront");
    let mut cmd = if ranks > 0 {
        let mut c = Command::new(mpirun().expect("checked by the caller"));
        c.args(["--oversubscribe", "-n", &ranks.to_string(), bin]);
        c
    } else {
        Command::new(bin)
    };
    let mut child = cmd
        .args(args)
        // CI runs as root; the machine has fewer cores than ranks.
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the command starts");
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let t0 = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().expect("wait") {
            break st;
        }
        if t0.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            panic!(
                "{ranks} ranks, {args:?}: still running after {limit:?}\n{}",
                err.join().unwrap()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    Run {
        ok: status.success(),
        out: out.join().unwrap(),
        err: err.join().unwrap(),
    }
}

/// Threads, then 2 and 4 ranks, on `args` (an output path is added): the
/// same bytes, and the mesh read back has the tets the summary gives.
fn ranks_match_threads(tag: &str, args: &[&str]) {
    let limit = Duration::from_secs(300);
    let one = tmp(&format!("{tag}_threads.vtu"));
    let o = one.to_str().unwrap();
    let base = run(0, &[args, &["-o", o, "--no-compress"]].concat(), limit);
    assert!(base.ok, "threads: {}", base.err);
    let n = tets_said(&base.out);
    assert_eq!(read_mesh(&one).unwrap().tets.len(), n);
    for ranks in [2, 4] {
        let many = tmp(&format!("{tag}_{ranks}.vtu"));
        let m = many.to_str().unwrap();
        let r = run(ranks, &[args, &["-o", m, "--no-compress"]].concat(), limit);
        assert!(r.ok, "{ranks} ranks: {}", r.err);
        assert_eq!(tets_said(&r.out), n, "{ranks} ranks: {}", r.out);
        // Only rank 0 reports and writes.
        assert_eq!(r.out.matches("wrote ").count(), 1, "{}", r.out);
        assert!(
            std::fs::read(&one).unwrap() == std::fs::read(&many).unwrap(),
            "{tag}: {ranks} ranks wrote another mesh than threads"
        );
    }
}

fn write(name: &str, s: &parafront_surface::Surface) -> PathBuf {
    let p = tmp(name);
    write_surface(&p, s, &WriteOptions::default()).unwrap();
    p
}

#[test]
fn two_and_four_ranks_give_the_threads_mesh() {
    if mpirun().is_none() {
        eprintln!("skipping: mpirun not found (apt-get install openmpi-bin libopenmpi-dev)");
        return;
    }
    // Two regions (an embedded sphere) and a void: passes 1 to 3 and
    // pass 4 on 8 parts, each region on its own.
    ranks_match_threads("demo", &["demo", "--parts", "8"]);
    // A lattice core at a uniform size: the passes mesh around it.
    let torus = write("torus.obj", &generate::torus([0.0; 3], 2.0, 0.7, 48, 24));
    let t = torus.to_str().unwrap();
    ranks_match_threads("torus", &["mesh", t, "--parts", "8", "--size", "0.12"]);
}

#[test]
fn every_rank_writes_its_pieces_of_a_pvtu() {
    if mpirun().is_none() {
        eprintln!("skipping: mpirun not found");
        return;
    }
    pieces_match_threads("pvtu", &["demo", "--parts", "8", "--optimize", "0"]);
    // A lattice core (§2) whose tets go into the pieces, improved with its
    // inner points frozen.
    let lattice = ["demo", "--parts", "8", "--size", "0.8", "--lattice", "on"];
    pieces_match_threads("pvtu_lattice", &lattice);
    // Passes that give way: the serial front's mesh, made on the rank of
    // part 0, sent to the parts.
    let serial = ["demo", "--parts", "8", "--serial-from", "0"];
    pieces_match_threads("pvtu_serial", &serial);
}

/// `args` plus `-o x.pvtu` on the threads backend, then on 2 and 4 ranks:
/// the index names the demo's pieces (2 regions x 8 parts, less any empty
/// one), which hold the summary's tets together, and every file is the
/// threads run's, byte for byte.
fn pieces_match_threads(tag: &str, args: &[&str]) {
    let limit = Duration::from_secs(300);
    let dir = |tag: &str| {
        let d = tmp(tag);
        std::fs::create_dir_all(&d).unwrap();
        d
    };
    let args = [args, &["--no-compress", "-o"]].concat();
    let one = dir(&format!("{tag}_threads")).join("demo.pvtu");
    let base = run(0, &[&args[..], &[one.to_str().unwrap()]].concat(), limit);
    assert!(base.ok, "{}", base.err);
    let n = tets_said(&base.out);
    let files = |p: &Path| -> Vec<(String, Vec<u8>)> {
        let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(p.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().path())
            .map(|f| {
                (
                    f.file_name().unwrap().to_string_lossy().into(),
                    std::fs::read(&f).unwrap(),
                )
            })
            .collect();
        v.sort();
        v
    };
    let want = files(&one);
    let index = std::fs::read_to_string(&one).unwrap();
    let named = index.matches("<Piece Source=").count();
    assert!(named > 8 && named <= 16, "{index}");
    assert_eq!(want.len(), named + 1);
    let sizes: Vec<usize> = want
        .iter()
        .filter(|(name, _)| name.ends_with(".vtu"))
        .map(|(name, _)| read_mesh(&one.with_file_name(name)).unwrap().tets.len())
        .collect();
    assert!(sizes.iter().all(|&s| s > 0), "{sizes:?}");
    assert_eq!(sizes.iter().sum::<usize>(), n);
    for ranks in [2, 4] {
        let many = dir(&format!("{tag}_{ranks}")).join("demo.pvtu");
        let r = run(
            ranks,
            &[&args[..], &[many.to_str().unwrap()]].concat(),
            limit,
        );
        assert!(r.ok, "{ranks} ranks: {}", r.err);
        assert_eq!(tets_said(&r.out), n);
        assert!(r.out.contains("peak memory per process"), "{}", r.out);
        let got = files(&many);
        assert_eq!(got.len(), want.len());
        for (a, b) in want.iter().zip(&got) {
            assert!(
                a == b,
                "{tag}, {ranks} ranks: {} differs from the threads run's",
                b.0
            );
        }
    }
}

#[test]
fn bench_under_mpirun_gives_the_papers_table() {
    if mpirun().is_none() {
        eprintln!("skipping: mpirun not found");
        return;
    }
    let torus = write(
        "bench_torus.obj",
        &generate::torus([0.0; 3], 2.0, 0.7, 40, 20),
    );
    let t = torus.to_str().unwrap();
    let args = ["bench", t, "--parts", "4", "--threads", "1,2"];
    let limit = Duration::from_secs(300);
    let one = run(0, &args, limit);
    assert!(one.ok, "{}", one.err);
    let r = run(2, &args, limit);
    assert!(r.ok, "{}", r.err);
    // Rows: nproc nprol ncore nelem ...; the tets are the threads run's.
    let rows = |out: &str| -> Vec<Vec<String>> {
        out.lines()
            .map(|l| l.split_whitespace().map(String::from).collect::<Vec<_>>())
            .filter(|w| w.len() > 4 && w[..4].iter().all(|x| x.parse::<usize>().is_ok()))
            .collect()
    };
    let (a, b) = (rows(&one.out), rows(&r.out));
    assert_eq!(b.len(), 2, "{}", r.out);
    assert_eq!(a.len(), 2, "{}", one.out);
    for (row, want) in b.iter().zip([["2", "1", "2"], ["2", "2", "4"]]) {
        assert_eq!(&row[..3], &want, "{}", r.out);
        assert_eq!(row[3], a[0][3], "tets differ: {}\n{}", r.out, one.out);
    }
}

#[test]
fn a_corpus_part_on_ranks_is_the_threads_mesh() {
    let (Some(_), Some(g)) = (mpirun(), std::env::var_os("PARAFRONT_GEOMETRY")) else {
        eprintln!("skipping: mpirun or PARAFRONT_GEOMETRY missing");
        return;
    };
    let f = Path::new(&g).join("valid/fertility.off");
    ranks_match_threads("fertility", &["mesh", f.to_str().unwrap(), "--parts", "8"]);
}

#[test]
fn a_failing_rank_stops_every_rank_with_its_message() {
    if mpirun().is_none() {
        eprintln!("skipping: mpirun not found");
        return;
    }
    let out = tmp("failed.vtu");
    // Part 5 is rank 2's of 4 (parts 4 and 5): rank 0 must stop as well.
    let r = run(
        4,
        &[
            "demo",
            "--parts",
            "8",
            "--fail-part",
            "5",
            "-o",
            out.to_str().unwrap(),
        ],
        Duration::from_secs(120),
    );
    assert!(!r.ok, "the run succeeded: {}", r.out);
    assert!(
        r.err.contains("part 5: the failure injected for the tests"),
        "{}",
        r.err
    );
    assert!(!out.exists(), "a failed run left {}", out.display());
    // Fewer parts than ranks: every rank stops at once, rank 0 says why.
    let r = run(
        4,
        &["demo", "--parts", "2", "-o", out.to_str().unwrap()],
        Duration::from_secs(60),
    );
    assert!(!r.ok);
    assert_eq!(
        r.err.matches("give every rank a part").count(),
        1,
        "{}",
        r.err
    );
    assert!(!out.exists());
}

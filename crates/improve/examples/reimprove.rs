//! Improves a mesh read from a file (e.g. a `--optimize 0` run) and
//! prints the quality before and after, the per-operation stats and the
//! worst tets; writes the result when an output path is given. For
//! profiling the improver without re-running the front:
//!
//!     cargo run --release -p parafront-improve --example reimprove -- IN.vtu [OUT.vtu] [LEVEL] [PARTS]
use parafront_improve::{improve, ImproveOptions};
use parafront_mesh::QualityReport;
use std::path::Path;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let input = args
        .get(1)
        .expect("usage: reimprove IN [OUT] [LEVEL] [PARTS]");
    let out = args.get(2).filter(|s| *s != "-");
    let level = args.get(3).map_or(2, |s| s.parse().unwrap());
    let parts = args.get(4).map_or(0, |s| s.parse().unwrap());
    let mut m = parafront_io::read_mesh(Path::new(input)).unwrap();
    let q0 = QualityReport::new(&m);
    let t0 = Instant::now();
    let st = improve(&mut m, &[], &ImproveOptions { level, parts }).unwrap();
    let secs = t0.elapsed().as_secs_f64();
    let q = QualityReport::new(&m);
    for (name, q) in [("before", &q0), ("after", &q)] {
        println!(
            "{name}: {} tets, min dihedral {:.3}, {:.4}% under 10 deg, mean radius ratio {:.5}",
            q.n_tets,
            q.min_dihedral.min,
            100.0 * q.share_min_dihedral_below,
            q.radius_ratio.mean
        );
    }
    println!("improve {secs:.2} s: {st:?}");
    if let Some(o) = out {
        parafront_io::write_mesh(Path::new(o), &m, &Default::default()).unwrap();
    }
}

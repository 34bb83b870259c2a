//! Fill the cavity in an OBJ file (faces pointing into it) and report:
//! `cargo run --example fill_obj -- CAVITY.obj [MAX_STEINER MAX_STEINER_FACES MAX_SEARCH_FACES [MAX_SPLIT [HEADWAY_ROUNDS]]]`.
use parafront_delaunay::{fill_cavity, FillOptions};
use std::time::Instant;

fn main() {
    // RUST_LOG=parafront_delaunay=trace shows the search's steps.
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    let path = std::env::args().nth(1).expect("usage: fill_obj CAVITY.obj");
    let s = parafront_surface::read::read_surface(std::path::Path::new(&path))
        .unwrap_or_else(|e| panic!("{e}"));
    let (pts, faces) = (s.points, s.tris);
    // Faces that meet other than in shared corners (the cavity must be
    // embedded).
    let mut bad = 0;
    for i in 0..faces.len() {
        for j in i + 1..faces.len() {
            let (a, b): ([u32; 3], [u32; 3]) = (faces[i], faces[j]);
            let twice = a.iter().all(|v| b.contains(v));
            if !twice && parafront_geom::intersect::faces_meet(a, b, &pts) {
                bad += 1;
                if bad < 5 {
                    println!("faces {i} {a:?} and {j} {b:?} meet");
                }
            }
        }
    }
    println!("{bad} pairs of faces meet");
    let t0 = Instant::now();
    // Optional: MAX_STEINER MAX_STEINER_FACES MAX_SEARCH_FACES.
    let mut opts = FillOptions::default();
    let arg = |k: usize| {
        std::env::args()
            .nth(k)
            .map(|a| a.parse::<usize>().expect("a count"))
    };
    if let Some(n) = arg(2) {
        opts.max_steiner = n;
    }
    if let Some(n) = arg(3) {
        opts.max_steiner_faces = n;
    }
    if let Some(n) = arg(4) {
        opts.max_search_faces = n;
    }
    // A fifth argument N: the conforming fill alone, its edges split
    // first, with at most N split points.
    if let Some(n) = arg(5) {
        opts.segments_first = true;
        opts.max_split = n;
    }
    // A sixth, R: it gives up after R rounds of splits without headway.
    if let Some(n) = arg(6) {
        opts.headway_rounds = n as u32;
    }
    match fill_cavity(&pts, &faces, &opts) {
        Ok(f) => {
            let all: Vec<_> = pts.iter().chain(f.steiner.iter()).copied().collect();
            // Tets flat in floating point (a solver reads them as inverted).
            let flat = f
                .tets
                .iter()
                .filter(|t| parafront_delaunay::is_flat(t.map(|v| all[v as usize])))
                .count();
            println!(
                "{path}: {} faces: {} tets ({flat} flat in floating point), {} Steiner points, {:?}, {} flips, {:.3} s",
                faces.len(),
                f.tets.len(),
                f.steiner.len(),
                f.method,
                f.flips,
                t0.elapsed().as_secs_f64()
            )
        }
        Err(e) => println!(
            "{path}: {} faces: {e} ({:.3} s)",
            faces.len(),
            t0.elapsed().as_secs_f64()
        ),
    }
}

//! Build and query timings of the surface-grown field on a ~100k-point
//! surface, and accuracy there. Slow (~10 s on 2 busy cores), so ignored:
//! `cargo test -p parafront-size --test bench_growth -- --ignored --nocapture`.
mod common;
use common::*;
use parafront_size::{SizeField, SizeOptions, Sizing};
use std::time::Instant;

#[test]
#[ignore]
fn torus_100k_build_and_query() {
    // 500 x 200 = 100k points; the inner side is finer than the outer one.
    let s = torus(500, 200, 1.0, 0.3);
    let t0 = Instant::now();
    let sz = Sizing::build(&s, &SizeOptions::default(), None).unwrap();
    let build = t0.elapsed();
    let g = sz.growth().unwrap();
    println!("build {:.3} s, stats {:?}", build.as_secs_f64(), g.stats());

    let mut rng = Rng(0x9e3779b97f4a7c15);
    let q: Vec<[f64; 3]> = (0..200_000).map(|_| rng.in_box(-1.3, 1.3)).collect();
    let t0 = Instant::now();
    let mut acc = 0.0;
    for &p in &q {
        acc += sz.size(p);
    }
    let per = t0.elapsed().as_nanos() as f64 / q.len() as f64;
    println!("random queries in the box: {per:.1} ns/query (sum {acc:.3})");

    // Near-surface queries (where the front asks), in surface order.
    let qs: Vec<[f64; 3]> = s
        .points
        .iter()
        .map(|p| [p[0] * 0.995, p[1] * 0.995, p[2] * 0.995])
        .collect();
    let t0 = Instant::now();
    let mut acc = 0.0;
    for &p in &qs {
        acc += sz.size(p);
    }
    let per = t0.elapsed().as_nanos() as f64 / qs.len() as f64;
    println!("near-surface queries: {per:.1} ns/query (sum {acc:.3})");

    let mut worst_over: f64 = 0.0;
    let mut worst_under: f64 = 0.0;
    for &p in q.iter().take(3000) {
        let e = g.exact(p);
        let v = g.size(p);
        worst_over = worst_over.max(v / e - 1.0);
        worst_under = worst_under.max(1.0 - v / e);
    }
    println!("vs exact at 3000 random points: over {worst_over:.4}, under {worst_under:.4}");
    assert!(worst_over < 0.03, "{worst_over}");

    // Inside the tube, within 0..6 surface sizes of the surface: where the
    // near leaves and the first far leaves meet.
    let (mut wo, mut wu): (f64, f64) = (0.0, 0.0);
    for k in 0..3000 {
        let i = (rng.next_f64() * s.points.len() as f64) as usize % s.points.len();
        let p = s.points[i];
        let u = p[1].atan2(p[0]);
        let core = [u.cos(), u.sin(), 0.0];
        let d = rng.next_f64() * 0.06;
        let dir = [core[0] - p[0], core[1] - p[1], core[2] - p[2]];
        let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        let x = [
            p[0] + dir[0] / n * d,
            p[1] + dir[1] / n * d,
            p[2] + dir[2] / n * d,
        ];
        let (e, v) = (g.exact(x), g.size(x));
        wo = wo.max(v / e - 1.0);
        wu = wu.max(1.0 - v / e);
        let _ = k;
    }
    println!("vs exact at 3000 points near the surface: over {wo:.4}, under {wu:.4}");
    assert!(wo < 0.03, "{wo}");
}

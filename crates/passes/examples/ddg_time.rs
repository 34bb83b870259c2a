//! Times the DDG's build alone:
//! `ddg_time SURFACE PARTS THREADS,.. PASSES,.. REPS [GROWTH [SURFACE_SIZE_SCALE]]`.
//! PASSES 0 is the serial front; the surface's normals point out.
use parafront_comm::Threads;
use parafront_passes::build_ddg;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let s = parafront_surface::read::read_surface(std::path::Path::new(&a[1])).unwrap();
    let parts: usize = a[2].parse().unwrap();
    let list = |x: &str| -> Vec<usize> { x.split(',').map(|v| v.parse().unwrap()).collect() };
    let threads = list(&a[3]);
    let passes = list(&a[4]);
    let reps: usize = a[5].parse().unwrap();
    let c: f64 = a.get(6).map_or(1.6, |x| x.parse().unwrap());
    let hscale: f64 = a.get(7).map_or(1.0, |x| x.parse().unwrap());
    let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let hs: Vec<f64> = s.mean_edge_lengths().iter().map(|h| h * hscale).collect();
    for &p in &passes {
        for &t in &threads {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap();
            let mut secs = Vec::new();
            for _ in 0..reps {
                let t0 = Instant::now();
                let line = pool.install(|| {
                    if p == 0 {
                        let d = parafront_ddg::build(
                            s.points.clone(),
                            hs.clone(),
                            faces.clone(),
                            c,
                        )
                        .unwrap();
                        format!("{} tets", d.tets.len())
                    } else {
                        let (d, st) =
                            build_ddg(&s.points, &faces, c, p, &Threads::new(parts)).unwrap();
                        if std::env::var_os("DDG_PARTITION_TIME").is_some() {
                            use parafront_ddg as g;
                            let t0 = Instant::now();
                            let loc = g::Locator::new(&d);
                            let t1 = t0.elapsed().as_secs_f64();
                            let w = g::tet_weights(&d, &|_p| 0.02);
                            let t2 = t0.elapsed().as_secs_f64();
                            let p0 = g::rcb(&d, &w, parts);
                            let t3 = t0.elapsed().as_secs_f64();
                            let _ = g::shifted(&d, &p0, g::Shift::FromHigher, 2);
                            let _ = g::shifted(&d, &p0, g::Shift::FromLower, 2);
                            let t4 = t0.elapsed().as_secs_f64();
                            let _ = g::Interfaces::new(&d, &p0, 0..parts as u32);
                            let t5 = t0.elapsed().as_secs_f64();
                            let mut n = 0usize;
                            for &p in &d.points {
                                n += loc.owner(p, &p0).is_some() as usize;
                            }
                            let t6 = t0.elapsed().as_secs_f64();
                            println!(
                                "locator {t1:.3} weights {:.3} rcb {:.3} shifts {:.3} interfaces {:.3} s; {} owner queries {:.3} s ({n} owned)",
                                t2 - t1, t3 - t2, t4 - t3, t5 - t4, d.points.len(), t6 - t5
                            );
                        }
                        if std::env::var_os("DDG_COUNT").is_some() {
                            let mut by = [0usize; 5];
                            for t in &d.tets {
                                by[t.iter().filter(|&&i| (i as usize) < d.n_input).count()] += 1;
                            }
                            println!(
                                "tets by surface points 0..4: {by:?}; {} new points, {} surface points",
                                d.points.len() - d.n_input,
                                d.n_input
                            );
                        }
                        if std::env::var_os("DDG_FIELD_TIME").is_some() {
                            let f = parafront_ddg::graded_field(&s.points, &faces, c).unwrap();
                            let t0 = Instant::now();
                            let x: f64 = d.points[d.n_input..].iter().map(|&p| f(p)).sum();
                            println!(
                                "{} field queries: {:.3} s ({x:.3})",
                                d.points.len() - d.n_input,
                                t0.elapsed().as_secs_f64()
                            );
                        }
                        format!(
                            "{} tets, per pass {:?}, s {:.2?}, field {:.3} merge {:.3}",
                            d.tets.len(),
                            st.pass_tets,
                            st.pass_seconds,
                            st.field_seconds,
                            st.merge_seconds
                        )
                    }
                });
                let dt = t0.elapsed().as_secs_f64();
                secs.push(dt);
                println!("passes {p} threads {t}: {dt:.3} s; {line}");
            }
            secs.sort_by(f64::total_cmp);
            println!(
                "passes {p} threads {t}: median {:.3} s",
                secs[secs.len() / 2]
            );
        }
    }
}

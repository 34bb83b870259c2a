//! A front left for pass 4 (closed, no pinch, no duplicate face) on which
//! the serial front's recovery used to trip: `fill_pockets` ->
//! `partial_cone` -> `commit` removed a dead face (a failed
//! `close_by_existing` re-adds the pocket's faces under new ids). Made by
//! `a_sphere_on_2_4_8_parts` (P = 8) with pass 4's first try at 12
//! recovery rounds.
use parafront_front::{advance, Everywhere, FrontInput, FrontOptions, SizeMode};

#[test]
fn the_front_closes_a_pass4_hole_with_recovery() {
    let txt = include_str!("data/pass4_hole_1602.txt");
    let mut l = txt.lines();
    let n: Vec<usize> = l
        .next()
        .unwrap()
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    let (mut points, mut point_size) = (Vec::new(), Vec::new());
    for _ in 0..n[0] {
        let v: Vec<f64> = l
            .next()
            .unwrap()
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        points.push([v[0], v[1], v[2]]);
        point_size.push(v[3]);
    }
    let faces: Vec<[u32; 3]> = (0..n[1])
        .map(|_| {
            let v: Vec<u32> = l
                .next()
                .unwrap()
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let h = |_p: [f64; 3]| 0.12;
    let r = advance(
        FrontInput {
            points,
            point_size,
            faces,
        },
        SizeMode::Field(&h),
        &Everywhere,
        &FrontOptions {
            recovery_rounds: 12,
            ..FrontOptions::default()
        },
    )
    .expect("the hole closes");
    assert!(r.front.is_empty() && !r.tets.is_empty());
}

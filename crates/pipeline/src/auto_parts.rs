//! `--parts auto`, the default: the parts of the parallel mesher (§5-8)
//! from the run's estimated tet count. Never from the thread count, so
//! the mesh is the same whatever the threads. A small job stays serial:
//! the DDG and its partition cost 0.9-1.8 s at 1e6 tets on 2 threads, and
//! the passes pay that back only on large jobs. On one thread they do not
//! (torus_1e6: 18-22 s serial, 25-27 s at 6 parts): the price of a mesh
//! that is the same on any number of threads.
use parafront_geom::{Aabb, P3};
use parafront_size::{SizeField, Sizing};
use parafront_surface::inside::Inside;
use parafront_surface::Surface;
use rayon::prelude::*;

/// `MeshOptions::parts` that asks for this choice.
pub const AUTO_PARTS: usize = 0;
/// About one part per this many estimated tets (`MeshOptions::part_tets`).
/// On this 2-core machine, against the serial front: sphere_1e6 (481k
/// tets) 10-20 % faster at 4 parts, slower at 3 (one thread waits for the
/// third part), no faster at 5-6, its min dihedral 20.2-21.6° there
/// against 23.2° at 4; torus_1e6 (704k) 10-16 % faster at 4-6.
pub const DEFAULT_PART_TETS: usize = 120_000;
/// The most parts the choice makes.
pub const MAX_AUTO_PARTS: usize = 64;
/// Samples per axis of the surface's bounding box: a coarse look first,
/// then a fine one where the job may be large enough for parts (on the
/// CAD parts, whose needles fill the ray test's bins, the fine grid alone
/// cost 0.04-0.12 s).
const COARSE_GRID: usize = 16;
const GRID: usize = 32;
/// A front mesh's tets (before improvement) over the volume in ideal
/// tets at the local size: 2.76-3.17 times [`estimate_tets`] at 0.5 on
/// ten inputs (the bench surfaces, fertility, skull, boot, the tray).
const TETS_PER_IDEAL: f64 = 1.5;

/// The estimate [`auto_parts`] takes at one part per `part_tets`: on a
/// 16^3 grid, and on a 32^3 one unless the first gives under one part.
pub fn estimate_for_parts(s: &Surface, sizing: &Sizing, part_tets: usize) -> f64 {
    let inside = Inside::new(&s.points, &s.tris);
    let coarse = estimate_with(s, sizing, &inside, COARSE_GRID);
    if coarse < part_tets as f64 {
        coarse
    } else {
        estimate_with(s, sizing, &inside, GRID)
    }
}

/// The tets a front mesh of `sizing` would make inside `s`: the volume
/// over the ideal tet's (`h^3 / (6 sqrt 2)`) at the local size, summed over
/// the cells of a `grid`^3 grid whose centres lie inside. A part thinner
/// than a cell can come out at 0, which keeps it serial (the passes give
/// up on thin parts anyway).
pub fn estimate_tets(s: &Surface, sizing: &Sizing, grid: usize) -> f64 {
    estimate_with(s, sizing, &Inside::new(&s.points, &s.tris), grid)
}

/// [`estimate_tets`] with `s`'s inside test built.
fn estimate_with(s: &Surface, sizing: &Sizing, inside: &Inside, grid: usize) -> f64 {
    let grid = grid.max(1);
    if s.points.is_empty() {
        return 0.0;
    }
    let Aabb { min: lo, max: hi } = Aabb::from_points(&s.points);
    let cell = [0, 1, 2].map(|k| (hi[k] - lo[k]) / grid as f64);
    let vol = cell[0] * cell[1] * cell[2];
    if !(vol > 0.0) {
        return 0.0;
    }
    // Off the cell centres by odd fractions, a different one on each
    // axis: CAD faces sit on round coordinates, and a ray along a
    // triangle's edge (a square's diagonal, y = z) answers nothing; such a
    // sample is asked again a little aside.
    const AT: [f64; 3] = [0.513_7, 0.477_1, 0.541_9];
    let inside_at = |p: P3| {
        inside
            .at(p)
            .or_else(|| inside.at([p[0], p[1] + 0.011 * cell[1], p[2] + 0.007 * cell[2]]))
    };
    let ideal = 1.0 / (6.0 * std::f64::consts::SQRT_2);
    let slabs: Vec<f64> = (0..grid)
        .into_par_iter()
        .map(|i| {
            let mut sum = 0.0;
            for j in 0..grid {
                for k in 0..grid {
                    let p: P3 = [
                        lo[0] + (i as f64 + AT[0]) * cell[0],
                        lo[1] + (j as f64 + AT[1]) * cell[1],
                        lo[2] + (k as f64 + AT[2]) * cell[2],
                    ];
                    if inside_at(p) == Some(true) {
                        let h = sizing.size(p);
                        if h > 0.0 && h.is_finite() {
                            sum += vol / (ideal * h * h * h);
                        }
                    }
                }
            }
            sum
        })
        .collect();
    TETS_PER_IDEAL * slabs.iter().sum::<f64>()
}

/// The parts for `estimate` tets at about one part per `part_tets` (the
/// quotient rounded): 1, the serial front, under one and a half.
pub fn auto_parts(estimate: f64, part_tets: usize) -> usize {
    let p = (estimate / part_tets.max(1) as f64).round();
    if p < 2.0 {
        1
    } else {
        (p as usize).min(MAX_AUTO_PARTS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_size::SizeOptions;
    use parafront_surface::generate;

    /// A cube under a constant size: the estimate is the volume over the
    /// ideal tet's, times the front's factor, within the sampling's
    /// error; and the parts follow it.
    #[test]
    fn a_cube_under_a_constant_size_is_estimated_from_its_volume() {
        let s = generate::voxels([0.0; 3], 0.25, [8, 8, 8], |_, _, _| true);
        let h = 0.1;
        let sizing = Sizing::build(
            &s,
            &SizeOptions {
                h: Some(h),
                ..Default::default()
            },
            None,
        )
        .unwrap();
        let want = TETS_PER_IDEAL * 8.0 / (h * h * h / (6.0 * std::f64::consts::SQRT_2));
        let got = estimate_tets(&s, &sizing, GRID);
        assert!((got / want - 1.0).abs() < 0.02, "{got} against {want}");
        let coarse = estimate_tets(&s, &sizing, COARSE_GRID);
        assert!(
            (coarse / want - 1.0).abs() < 0.02,
            "{coarse} against {want}"
        );
        // Under one part's worth on the coarse grid: the coarse estimate.
        assert_eq!(
            estimate_for_parts(&s, &sizing, (2.0 * want) as usize),
            coarse
        );
        assert_eq!(estimate_for_parts(&s, &sizing, (want / 3.0) as usize), got);
        assert_eq!(auto_parts(got, (want / 4.0) as usize), 4);
        assert_eq!(auto_parts(got, (want / 1.2) as usize), 1);
        assert_eq!(auto_parts(got, 1), MAX_AUTO_PARTS);
    }

    /// Nothing inside, nothing estimated: the serial front.
    #[test]
    fn nothing_inside_estimates_nothing() {
        let sizing = Sizing::constant(0.1).unwrap();
        assert_eq!(estimate_tets(&Surface::default(), &sizing, GRID), 0.0);
        assert_eq!(auto_parts(0.0, DEFAULT_PART_TETS), 1);
    }
}

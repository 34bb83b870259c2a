//! The domain-defining grid (paper §5, step 1) and what the parallel
//! passes ask of it: which DDG tets hold a point ([`Locator`]), how many
//! fine tets each DDG tet will hold, the balanced split into parts
//! (§6, step 2), the shifted partitions of passes 2 and 3 and the region
//! filter of one part (§7).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod adjacency;
mod check;
mod field;
mod filter;
mod locate;
mod partition;

pub use adjacency::{Adjacency, Neigh};
pub use field::GradedField;

pub use filter::{Interfaces, PartFilter};
pub use locate::{Locator, SHARED_PER_CELL};
pub use partition::{
    components, cut_faces, cut_fine_faces, imbalance, order_for_shift, partition, rcb, shift_loads,
    shifted, tet_weights, Partition, Shift,
};

use parafront_front::{advance, Everywhere, FrontError, FrontInput, FrontOptions, SizeMode};
use parafront_geom::P3;
use std::time::Instant;

/// Default growth factor `c_i` (§5: typical values 1.5 to 1.7).
pub const DEFAULT_GROWTH: f64 = 1.6;

/// The coarse mesh: fine at the surface (it keeps the surface triangles),
/// coarse inside.
#[derive(Clone, Debug, Default)]
pub struct Ddg {
    /// Input points first (same ids as the front handed in), then new ones.
    pub points: Vec<P3>,
    /// Point ids of each tet, as the front made them.
    pub tets: Vec<[u32; 4]>,
    /// The tet across each face: [`Ddg::neigh`].
    pub adjacency: Adjacency,
    /// Points of the input front.
    pub n_input: usize,
    /// The growth factor.
    pub growth: f64,
    /// Wall seconds of the build.
    pub seconds: f64,
}

/// Why the DDG could not be built.
#[derive(Debug, thiserror::Error)]
pub enum DdgError {
    /// The front could not close it.
    #[error("{0}")]
    Front(#[from] FrontError),
    /// Its size field could not be built.
    #[error("its size field: {0}")]
    Size(#[from] parafront_size::SizeError),
}

/// Builds the DDG of one closed front (§5): the scalar front with its
/// sizes grown from the surface by the growth factor `c`, as a field
/// ([`graded_field`]). §5 as written multiplies the sizes by `c` per face
/// removed instead; the front got stuck under that on every real surface
/// tried (sphere_1e5: 2664 faces left after 1.8 s), and closes the field
/// as reliably as a fine mesh.
pub fn build(
    points: Vec<P3>,
    point_size: Vec<f64>,
    faces: Vec<[u32; 3]>,
    c: f64,
) -> Result<Ddg, DdgError> {
    let t0 = Instant::now();
    let n_input = points.len();
    let field = graded_field(&points, &faces, c)?;
    let r = advance(
        FrontInput {
            point_size,
            points,
            faces,
        },
        SizeMode::Field(&field),
        &Everywhere,
        &FrontOptions::default(),
    )?;
    let d = Ddg {
        points: r.points,
        tets: r.tets,
        adjacency: r.neigh.into(),
        n_input,
        growth: c,
        seconds: t0.elapsed().as_secs_f64(),
    };
    debug_assert_eq!(d.check(), Ok(()));
    Ok(d)
}

/// The DDG's sizes ([`build`]): the surface sizes of the closed
/// front `faces` (the mean length of each point's edges) grown by `c - 1`
/// per unit distance ([`GradedField`]).
pub fn graded_field(
    points: &[P3],
    faces: &[[u32; 3]],
    c: f64,
) -> Result<impl Fn(P3) -> f64 + Sync, DdgError> {
    let f = GradedField::of_front(points, faces, (c - 1.0).max(0.0));
    Ok(move |p: P3| f.size(p))
}

impl Ddg {
    /// The corners of tet `t`.
    pub fn tet_points(&self, t: usize) -> [P3; 4] {
        self.tets[t].map(|p| self.points[p as usize])
    }
    /// The centroid of tet `t`.
    pub fn centroid(&self, t: usize) -> P3 {
        let p = self.tet_points(t);
        let mut c = [0.0; 3];
        for q in p {
            for k in 0..3 {
                c[k] += 0.25 * q[k];
            }
        }
        c
    }
    /// Tets around each point, CSR (`start`, `list`), ascending tet order.
    pub fn point_tets(&self) -> (Vec<u32>, Vec<u32>) {
        let mut start = vec![0u32; self.points.len() + 1];
        for t in &self.tets {
            for &p in t {
                start[p as usize + 1] += 1;
            }
        }
        for i in 0..self.points.len() {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut list = vec![0u32; start[self.points.len()] as usize];
        for (t, tv) in self.tets.iter().enumerate() {
            for &p in tv {
                list[fill[p as usize] as usize] = t as u32;
                fill[p as usize] += 1;
            }
        }
        (start, list)
    }
}

/// The DDG of the closed surface `s` at the default growth, its
/// triangles turned (the front's faces point into the region): for the
/// tests.
#[cfg(test)]
pub(crate) fn ddg_of(s: &parafront_surface::Surface) -> Ddg {
    let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
    build(
        s.points.clone(),
        s.mean_edge_lengths(),
        faces,
        DEFAULT_GROWTH,
    )
    .expect("the DDG of a closed surface")
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_surface::generate;

    #[test]
    fn the_ddg_of_a_sphere_is_coarse_inside_and_keeps_the_surface() {
        let s = generate::icosphere([0.0; 3], 1.0, 3);
        let d = ddg_of(&s);
        let n_new = d.points.len() - d.n_input;
        // §5: about as many extra points as surface points, or fewer.
        assert!(
            n_new > 0 && n_new <= 2 * d.n_input,
            "{n_new} new points for {} surface points",
            d.n_input
        );
        let vol: f64 = (0..d.tets.len())
            .map(|t| {
                let p = d.tet_points(t);
                parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]) / 6.0
            })
            .sum();
        let want = s.signed_volume().abs();
        assert!(
            (vol - want).abs() < 1e-9 * want.abs().max(1.0),
            "{vol} vs {want}"
        );
    }
}

//! The size field (paper AG1) and the sizes of the initial front (AG3).
//!
//! [`Sizing`] is the minimum of its components, clamped to `[hmin, hmax]`:
//! - the global size `h` (when set it is also the cap),
//! - the size grown from the surface ([`growth`]): each surface point gets
//!   the mean length of its incident edges (min any patch size of its
//!   triangles) and the field grows away from it no faster than the
//!   gradation `g`: `h(x) <= h_i + (g-1)|x - x_i|`,
//! - sources ([`sources`]): point, segment, sphere shell, box,
//! - a background tet grid with nodal sizes ([`background`]).
//!
//! Evaluation is cheap and allocation-free: an octree descent plus a few
//! cone evaluations, source formulas, and a tet walk. `Sizing` is `Sync`:
//! any number of threads query it at once. The front (AF4) should keep a
//! [`SizeCursor`] per thread and call [`Sizing::size_with`]: queries near the
//! previous one then skip the octree descent and the tet search.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod background;
pub mod growth;
mod options;
mod outside;
mod share;
pub mod sources;

pub use background::BackgroundGrid;
pub use growth::{GrowthCursor, GrowthStats, SurfaceGrowth};
pub use options::{SizeOptions, SourceSpec, DEFAULT_GRADATION};
pub use share::{Alone, OctreeShare, Subtree, SubtreeParts};
pub use sources::Source;

use parafront_geom::{dist, P3};
use parafront_mesh::TetMesh;
use parafront_surface::Surface;
use rayon::prelude::*;
use std::path::PathBuf;

/// A spatially varying element size. Implementations must be cheap and
/// safe to call from many threads.
pub trait SizeField: Send + Sync {
    /// The element size wanted at `p`.
    fn size(&self, p: P3) -> f64;
}

/// Why the size field cannot be built; each names what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum SizeError {
    /// A size options file that is not valid TOML for [`SizeOptions`].
    #[error("{origin}: {msg}")]
    Toml {
        /// Where the text came from (a file name).
        origin: String,
        /// What `toml` said: line, column and key.
        msg: String,
    },
    /// A size options file that cannot be read.
    #[error("{}: {msg}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        msg: String,
    },
    /// An option out of its range.
    #[error("size options: {what}: {why}")]
    Invalid {
        /// The option.
        what: String,
        /// What is wrong with its value.
        why: String,
    },
    /// A surface point with a NaN or infinite coordinate.
    #[error("surface: point {point} has non-finite coordinates {at:?}")]
    NonFinitePoint {
        /// The point.
        point: usize,
        /// Its coordinates.
        at: P3,
    },
    /// A triangle naming a point past the end of the surface's points.
    #[error("surface: triangle {tri} refers to point {point}, but there are {points} points")]
    PointOutOfRange {
        /// The triangle.
        tri: usize,
        /// The point it names.
        point: u32,
        /// Points in the surface.
        points: usize,
    },
    /// A surface point whose edges give no positive, finite size (AG3).
    #[error("surface point {point} at {at:?} gets no usable size ({size}) from its incident edges (zero or overflowing lengths; set hmin > 0 or fix the surface)")]
    ZeroSize {
        /// The point.
        point: usize,
        /// Its coordinates.
        at: P3,
        /// The size its edges give.
        size: f64,
    },
    /// A background grid that cannot be used.
    #[error("background grid: {why}")]
    Background {
        /// What is wrong with it.
        why: String,
    },
    /// Nothing bounds the size.
    #[error("no size given: set h or hmax, or give a surface, sources or a background grid")]
    NoSize,
}

/// Per-thread memory of the last query, for [`Sizing::size_with`].
#[derive(Clone, Copy, Debug, Default)]
pub struct SizeCursor {
    growth: GrowthCursor,
    tet: u32,
}

/// The composite size field: see the crate doc.
pub struct Sizing {
    hmin: f64,
    /// min(hmax, h)
    cap: f64,
    gradation: f64,
    growth: Option<SurfaceGrowth>,
    sources: Vec<Source>,
    background: Option<BackgroundGrid>,
    point_sizes: Vec<f64>,
}

impl Sizing {
    /// A constant size `h` everywhere (no surface, no sources).
    pub fn constant(h: f64) -> Result<Sizing, SizeError> {
        let o = SizeOptions {
            h: Some(h),
            ..Default::default()
        };
        Sizing::build(&Surface::default(), &o, None)
    }

    /// Builds every component. `background` is the grid named by
    /// `opts.background`, already read (the CLI reads it with the io crate).
    /// Triangles whose `patch` entry is missing count as patch 0.
    pub fn build(
        surface: &Surface,
        opts: &SizeOptions,
        background: Option<(TetMesh, Vec<f64>)>,
    ) -> Result<Sizing, SizeError> {
        Sizing::build_shared(surface, opts, background, &Alone)
    }

    /// [`build`](Self::build) with the surface field's octree shared out
    /// by `share` (each MPI rank builds some of its subtrees); the same
    /// field whatever the share.
    pub fn build_shared(
        surface: &Surface,
        opts: &SizeOptions,
        background: Option<(TetMesh, Vec<f64>)>,
        share: &dyn OctreeShare,
    ) -> Result<Sizing, SizeError> {
        opts.validate()?;
        let cap = opts.cap();
        let hmin = opts.hmin;
        let patch_sizes = opts.patch_size_map()?;
        let np = surface.points.len();
        for (i, p) in surface.points.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(SizeError::NonFinitePoint { point: i, at: *p });
            }
        }
        for (t, tri) in surface.tris.iter().enumerate() {
            if let Some(v) = tri.iter().find(|&&v| v as usize >= np) {
                return Err(SizeError::PointOutOfRange {
                    tri: t,
                    point: *v,
                    points: np,
                });
            }
        }

        let growth = if opts.surface_growth && !surface.tris.is_empty() {
            let seeds = surface_seeds(surface, &patch_sizes, hmin, cap)?;
            Some(SurfaceGrowth::in_domain_shared(
                &seeds,
                opts.gradation - 1.0,
                cap,
                &surface.points,
                &surface.tris,
                share,
            ))
        } else {
            None
        };
        if let Some(g) = &growth {
            let st = g.stats();
            tracing::debug!(
                seeds = st.seeds,
                nodes = st.nodes,
                near = st.near_leaves,
                far = st.far_leaves,
                "size field octree"
            );
        }
        let sources = opts
            .sources
            .iter()
            .map(|s| Source::new(s, opts.gradation))
            .collect();
        let background = match background {
            Some((m, s)) => Some(BackgroundGrid::new(&m, &s)?),
            None => None,
        };
        if cap == f64::INFINITY
            && growth.is_none()
            && opts.sources.is_empty()
            && background.is_none()
        {
            return Err(SizeError::NoSize);
        }
        let mut sz = Sizing {
            hmin,
            cap,
            gradation: opts.gradation,
            growth,
            sources,
            background,
            point_sizes: Vec::new(),
        };
        sz.point_sizes = surface.points.par_iter().map(|&p| sz.size(p)).collect();
        Ok(sz)
    }

    /// The size at `p`, reusing (and updating) the caller's cursor.
    #[inline]
    pub fn size_with(&self, p: P3, cur: &mut SizeCursor) -> f64 {
        let mut h = self.cap;
        if let Some(g) = &self.growth {
            h = h.min(g.size_with(p, &mut cur.growth));
        }
        for s in &self.sources {
            h = h.min(s.size(p));
        }
        if let Some(b) = &self.background {
            if let Some(v) = b.size_with(p, &mut cur.tet) {
                h = h.min(v);
            }
        }
        h.max(self.hmin)
    }

    /// AG3: the size at each input surface point, to seed the front.
    pub fn surface_point_sizes(&self) -> &[f64] {
        &self.point_sizes
    }

    /// The growth limit g: `size(p) <= size(q) + (g-1)|p-q|` holds for the
    /// surface-grown part and every source with the default growth, so a
    /// front may bound a new point's size from a cached neighbour's.
    pub fn gradation(&self) -> f64 {
        self.gradation
    }

    /// Upper bound from a neighbour's cached size (see [`gradation`](Self::gradation)).
    #[inline]
    pub fn bound_from(&self, p: P3, q: P3, hq: f64) -> f64 {
        (hq + (self.gradation - 1.0) * dist(p, q)).clamp(self.hmin, self.cap)
    }

    /// The smallest size.
    pub fn hmin(&self) -> f64 {
        self.hmin
    }
    /// `min(hmax, h)`.
    pub fn hmax(&self) -> f64 {
        self.cap
    }
    /// The size grown from the surface, when there is one.
    pub fn growth(&self) -> Option<&SurfaceGrowth> {
        self.growth.as_ref()
    }
}

impl SizeField for Sizing {
    #[inline]
    fn size(&self, p: P3) -> f64 {
        let mut cur = SizeCursor::default();
        // The thread's last tet is a better start than tet 0.
        if let Some(b) = &self.background {
            let mut h = self.size_with_no_bg(p, &mut cur);
            let v = b.size(p);
            h = h.min(v);
            return h.max(self.hmin);
        }
        self.size_with(p, &mut cur)
    }
}

impl Sizing {
    fn size_with_no_bg(&self, p: P3, cur: &mut SizeCursor) -> f64 {
        let mut h = self.cap;
        if let Some(g) = &self.growth {
            h = h.min(g.size_with(p, &mut cur.growth));
        }
        for s in &self.sources {
            h = h.min(s.size(p));
        }
        h
    }
}

/// Seeds of the surface growth: (point, size) for every point used by a
/// triangle, size = mean incident edge length, min the patch sizes of its
/// triangles, clamped to `[hmin, cap]`.
fn surface_seeds(
    s: &Surface,
    patch_sizes: &std::collections::BTreeMap<u32, f64>,
    hmin: f64,
    cap: f64,
) -> Result<Vec<(P3, f64)>, SizeError> {
    let np = s.points.len();
    let mut sum = vec![0.0f64; np];
    let mut cnt = vec![0u32; np];
    let mut patch_min = vec![f64::INFINITY; np];
    for (t, tri) in s.tris.iter().enumerate() {
        let ps = patch_sizes
            .get(&s.patch.get(t).copied().unwrap_or(0))
            .copied()
            .unwrap_or(f64::INFINITY);
        for k in 0..3 {
            let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
            let l = dist(s.points[a], s.points[b]);
            sum[a] += l;
            sum[b] += l;
            cnt[a] += 1;
            cnt[b] += 1;
            patch_min[a] = patch_min[a].min(ps);
        }
    }
    let mut seeds = Vec::new();
    for i in 0..np {
        if cnt[i] == 0 {
            continue;
        }
        let h = (sum[i] / cnt[i] as f64).min(patch_min[i]).clamp(hmin, cap);
        if !(h > 0.0 && h.is_finite()) {
            return Err(SizeError::ZeroSize {
                point: i,
                at: s.points[i],
                size: h,
            });
        }
        seeds.push((s.points[i], h));
    }
    Ok(seeds)
}

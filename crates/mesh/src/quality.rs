//! Element quality: dihedral angles, radius ratio, mean ratio, and edge
//! length against a target size, per tet and as a [`QualityReport`] with
//! histograms. All measures are similarity invariant; the ratios are 1 for
//! the regular tet and go to 0 for flat ones (negative when inverted).
use crate::ids::*;
use crate::tetmesh::{TetMesh, TET_FACES};
use parafront_geom::{cross, dist, dist2, dot, norm, norm2, scale, sub, tet_volume6, P3};
use rayon::prelude::*;
use std::fmt;

/// The six edges of a tet as local vertex pairs.
pub const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

/// Dihedral angle of the regular tet, degrees (`acos(1/3)`).
pub const REGULAR_DIHEDRAL: f64 = 70.528_779_365_509_31;

/// Quality of one tet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TetQuality {
    /// Smallest dihedral angle, degrees.
    pub min_dihedral: f64,
    /// Largest dihedral angle, degrees.
    pub max_dihedral: f64,
    /// `3 r / R` (inradius over circumradius); 1 regular, < 0 inverted.
    pub radius_ratio: f64,
    /// `12 (3V)^(2/3) / sum l^2`; 1 regular, < 0 inverted.
    pub mean_ratio: f64,
    /// Signed volume (floating point).
    pub volume: f64,
}

/// Dihedral angles in degrees at the edges [`TET_EDGES`]. The angle at
/// edge (i, j) is between the faces opposite the other two vertices.
pub fn dihedral_angles(p: [P3; 4]) -> [f64; 6] {
    crate::angles::dihedral_pairs(p).map(|[y, x]| y.atan2(x).to_degrees())
}

/// `3 r / R`, signed by the volume; 0 for a flat tet.
pub fn radius_ratio(p: [P3; 4]) -> f64 {
    let (u, v, w) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0]));
    let v6 = dot(u, cross(v, w));
    // Circumcentre offset from p[0] is num / (2 v6); r = 3V / area.
    let num = [
        scale(cross(v, w), norm2(u)),
        scale(cross(w, u), norm2(v)),
        scale(cross(u, v), norm2(w)),
    ];
    let num = norm([
        num[0][0] + num[1][0] + num[2][0],
        num[0][1] + num[1][1] + num[2][1],
        num[0][2] + num[1][2] + num[2][2],
    ]);
    let area: f64 = TET_FACES
        .iter()
        .map(|f| 0.5 * norm(cross(sub(p[f[1]], p[f[0]]), sub(p[f[2]], p[f[0]]))))
        .sum();
    let den = area * num;
    if den > 0.0 && den.is_finite() {
        3.0 * v6 * v6.abs() / den
    } else {
        0.0
    }
}

/// `12 (3|V|)^(2/3) / sum l^2`, signed by the volume: 1 for the regular
/// tet, 0 when flat. The improvement (§9) optimises it and the report
/// shows it; the front ranks its candidates by it (rounded its own way).
#[inline]
pub fn mean_ratio(p: [P3; 4]) -> f64 {
    mean_ratio_of(tet_volume6(p[0], p[1], p[2], p[3]), edge_length2_sum(p))
}

/// The mean ratio from `6V` and the sum of the squared edge lengths, for
/// callers that have the determinant already.
#[inline]
pub fn mean_ratio_of(v6: f64, l2: f64) -> f64 {
    if l2 > 0.0 {
        let v3 = 0.5 * v6; // 3V
        (12.0 * (v3 * v3).cbrt() / l2).copysign(v6)
    } else {
        0.0
    }
}

/// The sum of a tet's squared edge lengths, in [`TET_EDGES`] order.
#[inline]
pub fn edge_length2_sum(p: [P3; 4]) -> f64 {
    dist2(p[0], p[1])
        + dist2(p[0], p[2])
        + dist2(p[0], p[3])
        + dist2(p[1], p[2])
        + dist2(p[1], p[3])
        + dist2(p[2], p[3])
}

/// Dihedral angles, radius ratio, mean ratio and volume of the tet `p`.
pub fn tet_quality(p: [P3; 4]) -> TetQuality {
    let (min_dihedral, max_dihedral) = extremes(&dihedral_angles(p));
    TetQuality {
        min_dihedral,
        max_dihedral,
        radius_ratio: radius_ratio(p),
        mean_ratio: mean_ratio(p),
        volume: tet_volume6(p[0], p[1], p[2], p[3]) / 6.0,
    }
}

/// The smallest and the largest of a tet's dihedral angles (NaNs left
/// out, as `f64::min` and `max` leave them).
fn extremes(d: &[f64; 6]) -> (f64, f64) {
    let min = d.iter().copied().fold(f64::INFINITY, f64::min);
    let max = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (min, max)
}

/// Quality of every tet; `None` for a tet with a point id out of range.
pub fn tet_qualities(mesh: &TetMesh) -> Vec<Option<TetQuality>> {
    mesh.tets
        .par_iter()
        .map(|t| tet_coords(&mesh.points, t).map(tet_quality))
        .collect()
}

fn tet_coords(points: &[P3], t: &[PointId; 4]) -> Option<[P3; 4]> {
    let mut c = [[0.0; 3]; 4];
    for k in 0..4 {
        c[k] = *points.get(t[k].idx())?;
    }
    Some(c)
}

/// Edge length over the target size at the edge midpoint, once per edge,
/// in order of (smaller, larger) point id: `f` gets them in slices.
/// Edges with an out-of-range point, or where `size` is not positive, are
/// left out. Sliced by the smaller id, like the face table: the whole
/// edge list (48 B per tet) set the quality report's peak.
pub fn for_each_edge_size_ratio(
    mesh: &TetMesh,
    size: impl Fn(P3) -> f64 + Sync,
    mut f: impl FnMut(&[f64]),
) {
    let np = mesh.points.len();
    // An edge's smaller id is a tet's smallest (three edges), second (two)
    // or third (one); a repeating tet has fewer edges.
    let sl = crate::slices::Slices::new(
        &mesh.tets,
        [3, 2, 1],
        true,
        (crate::slices::SLICES, crate::slices::MIN_SLICE),
    );
    let mut edges: Vec<u64> = Vec::new();
    let mut ratios: Vec<f64> = Vec::new();
    for k in 0..sl.ranges.len() {
        let k = k as u8;
        sl.gather(k, &mesh.tets, &mut edges, u64::MAX, |_, t, g, out| {
            // The edges from the tet's i-th smallest id to larger ones,
            // for each rank i whose id is in the slice.
            let (v, _) = crate::slices::ranked(t);
            let mut n = 0;
            for i in 0..3 {
                if g[i] != k {
                    continue;
                }
                for j in i + 1..4 {
                    if v[i] != v[j] && (v[j] as usize) < np {
                        out[n] = ((v[i] as u64) << 32) | v[j] as u64;
                        n += 1;
                    }
                }
            }
            n
        });
        crate::faces::sort_unstable(&mut edges);
        edges.truncate(edges.partition_point(|&e| e != u64::MAX));
        edges.dedup();
        ratios.clear();
        ratios.par_extend(edges.par_iter().filter_map(|&e| {
            let (a, b) = (
                mesh.points[(e >> 32) as usize],
                mesh.points[e as u32 as usize],
            );
            let h = size(scale(parafront_geom::add(a, b), 0.5));
            (h > 0.0).then(|| dist(a, b) / h)
        }));
        f(&ratios);
    }
}

/// Min, mean and max of a measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stat {
    /// Smallest value.
    pub min: f64,
    /// Mean value.
    pub mean: f64,
    /// Largest value.
    pub max: f64,
    /// Values measured (0: the others are NaN).
    pub count: usize,
}

#[derive(Clone, Copy)]
struct StatAcc {
    min: f64,
    max: f64,
    sum: f64,
    n: usize,
}
impl StatAcc {
    const EMPTY: StatAcc = StatAcc {
        min: f64::INFINITY,
        max: f64::NEG_INFINITY,
        sum: 0.0,
        n: 0,
    };
    fn add(&mut self, x: f64) {
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        self.sum += x;
        self.n += 1;
    }
    fn merge(self, o: StatAcc) -> StatAcc {
        StatAcc {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
            sum: self.sum + o.sum,
            n: self.n + o.n,
        }
    }
    fn stat(self) -> Stat {
        if self.n == 0 {
            return Stat {
                min: f64::NAN,
                mean: f64::NAN,
                max: f64::NAN,
                count: 0,
            };
        }
        Stat {
            min: self.min,
            mean: self.sum / self.n as f64,
            max: self.max,
            count: self.n,
        }
    }
}

/// Equal bins from `lo` to `hi`; values outside (or NaN) go to the end
/// bins, so the counts always add up to the number of values.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    /// Lower end of the range.
    pub lo: f64,
    /// Upper end of the range.
    pub hi: f64,
    /// Values per bin.
    pub counts: Vec<u64>,
}

impl Histogram {
    /// `bins` empty bins (at least one) over `[lo, hi]`.
    pub fn new(lo: f64, hi: f64, bins: usize) -> Histogram {
        Histogram {
            lo,
            hi,
            counts: vec![0; bins.max(1)],
        }
    }
    /// Width of one bin.
    pub fn bin_width(&self) -> f64 {
        (self.hi - self.lo) / self.counts.len() as f64
    }
    /// Lower edge of bin `i`.
    pub fn bin_lo(&self, i: usize) -> f64 {
        self.lo + i as f64 * self.bin_width()
    }
    /// The bin `x` falls in (the end bins take what is outside).
    pub fn bin_of(&self, x: f64) -> usize {
        let n = self.counts.len();
        // Truncation floors what is not negative (libm's floor was a call).
        let b = (x - self.lo) / self.bin_width();
        if b >= n as f64 {
            n - 1
        } else if b >= 0.0 {
            b as usize
        } else {
            0 // negative or NaN
        }
    }
    /// Counts `x`.
    pub fn add(&mut self, x: f64) {
        let b = self.bin_of(x);
        self.counts[b] += 1;
    }
    /// Values counted.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }
    fn merge(mut self, o: &Histogram) -> Histogram {
        for (a, b) in self.counts.iter_mut().zip(&o.counts) {
            *a += b;
        }
        self
    }
    /// The same range in `k` times wider bins (the last may be narrower).
    pub fn coarsen(&self, k: usize) -> Histogram {
        let k = k.max(1);
        let n = self.counts.len().div_ceil(k);
        Histogram {
            lo: self.lo,
            hi: self.lo + (n * k) as f64 * self.bin_width(),
            counts: self.counts.chunks(k).map(|c| c.iter().sum()).collect(),
        }
    }
}

/// Threshold for [`QualityReport::share_min_dihedral_below`].
pub const SMALL_DIHEDRAL: f64 = 10.0;

/// Tets per task of the report: its sums do not depend on the threads.
const REPORT_CHUNK: usize = 1 << 13;

/// Mesh quality summary with histograms.
#[derive(Clone, Debug, PartialEq)]
pub struct QualityReport {
    /// Tets in the mesh.
    pub n_tets: usize,
    /// Tets with non-positive floating-point volume.
    pub n_inverted: usize,
    /// Tets left out because a point id is out of range.
    pub n_skipped: usize,
    /// Smallest dihedral angle per tet, degrees.
    pub min_dihedral: Stat,
    /// Largest dihedral angle per tet, degrees.
    pub max_dihedral: Stat,
    /// Radius ratio per tet.
    pub radius_ratio: Stat,
    /// Mean ratio per tet.
    pub mean_ratio: Stat,
    /// All six dihedral angles of every tet, 1-degree bins over [0, 180].
    pub dihedral_hist: Histogram,
    /// Smallest dihedral angle per tet, 1-degree bins over [0, 180].
    pub min_dihedral_hist: Histogram,
    /// Largest dihedral angle per tet, 1-degree bins over [0, 180].
    pub max_dihedral_hist: Histogram,
    /// 0.05 bins over [0, 1] (inverted tets in the first bin).
    pub radius_ratio_hist: Histogram,
    /// 0.05 bins over [0, 1] (inverted tets in the first bin).
    pub mean_ratio_hist: Histogram,
    /// Share (0..1) of tets whose smallest dihedral is below 10 degrees.
    pub share_min_dihedral_below: f64,
    /// Edge length over target size, once per edge (with a size function).
    pub edge_ratio: Option<Stat>,
    /// 0.1 bins over [0, 3] (longer edges in the last bin).
    pub edge_ratio_hist: Option<Histogram>,
}

struct Acc {
    skipped: usize,
    inverted: usize,
    small: usize,
    s: [StatAcc; 4],
    h: [Histogram; 5],
}
impl Acc {
    fn new() -> Acc {
        Acc {
            skipped: 0,
            inverted: 0,
            small: 0,
            s: [StatAcc::EMPTY; 4],
            h: [
                Histogram::new(0.0, 180.0, 180),
                Histogram::new(0.0, 180.0, 180),
                Histogram::new(0.0, 180.0, 180),
                Histogram::new(0.0, 1.0, 20),
                Histogram::new(0.0, 1.0, 20),
            ],
        }
    }
    fn merge(self, o: Acc) -> Acc {
        let [a0, a1, a2, a3, a4] = self.h;
        Acc {
            skipped: self.skipped + o.skipped,
            inverted: self.inverted + o.inverted,
            small: self.small + o.small,
            s: [0, 1, 2, 3].map(|i| self.s[i].merge(o.s[i])),
            h: [
                a0.merge(&o.h[0]),
                a1.merge(&o.h[1]),
                a2.merge(&o.h[2]),
                a3.merge(&o.h[3]),
                a4.merge(&o.h[4]),
            ],
        }
    }
}

impl Stat {
    /// Both measures' values together (`count`-weighted mean).
    pub fn merge(&self, o: &Stat) -> Stat {
        match (self.count, o.count) {
            (0, _) => *o,
            (_, 0) => *self,
            (a, b) => Stat {
                min: self.min.min(o.min),
                max: self.max.max(o.max),
                mean: (self.mean * a as f64 + o.mean * b as f64) / (a + b) as f64,
                count: a + b,
            },
        }
    }
}

impl QualityReport {
    /// The report of two meshes' tets together (pieces of one mesh, §8):
    /// counts and histograms add, means weigh by their counts. The edge
    /// measure stays only when both have it (a shared edge counts once
    /// per piece).
    pub fn merge(&self, o: &QualityReport) -> QualityReport {
        let small = |r: &QualityReport| {
            (r.share_min_dihedral_below * (r.n_tets - r.n_skipped) as f64).round()
        };
        let measured = (self.n_tets - self.n_skipped) + (o.n_tets - o.n_skipped);
        let both = |a: &Option<Stat>, b: &Option<Stat>| match (a, b) {
            (Some(a), Some(b)) => Some(a.merge(b)),
            _ => None,
        };
        QualityReport {
            n_tets: self.n_tets + o.n_tets,
            n_inverted: self.n_inverted + o.n_inverted,
            n_skipped: self.n_skipped + o.n_skipped,
            min_dihedral: self.min_dihedral.merge(&o.min_dihedral),
            max_dihedral: self.max_dihedral.merge(&o.max_dihedral),
            radius_ratio: self.radius_ratio.merge(&o.radius_ratio),
            mean_ratio: self.mean_ratio.merge(&o.mean_ratio),
            dihedral_hist: self.dihedral_hist.clone().merge(&o.dihedral_hist),
            min_dihedral_hist: self.min_dihedral_hist.clone().merge(&o.min_dihedral_hist),
            max_dihedral_hist: self.max_dihedral_hist.clone().merge(&o.max_dihedral_hist),
            radius_ratio_hist: self.radius_ratio_hist.clone().merge(&o.radius_ratio_hist),
            mean_ratio_hist: self.mean_ratio_hist.clone().merge(&o.mean_ratio_hist),
            share_min_dihedral_below: if measured == 0 {
                0.0
            } else {
                (small(self) + small(o)) / measured as f64
            },
            edge_ratio: both(&self.edge_ratio, &o.edge_ratio),
            edge_ratio_hist: match (&self.edge_ratio_hist, &o.edge_ratio_hist) {
                (Some(a), Some(b)) => Some(a.clone().merge(b)),
                _ => None,
            },
        }
    }

    /// Shape quality of every tet (no edge-length measure).
    pub fn new(mesh: &TetMesh) -> QualityReport {
        Self::compute(mesh, None::<fn(P3) -> f64>)
    }

    /// Shape quality plus edge length relative to the target size `size`.
    pub fn with_size(mesh: &TetMesh, size: impl Fn(P3) -> f64 + Sync) -> QualityReport {
        Self::compute(mesh, Some(size))
    }

    /// Shape quality of the tets `tets` over `points` (some of a mesh's
    /// tets: [`QualityReport::merge`] adds reports of the others).
    pub fn of_tets(points: &[P3], tets: &[[PointId; 4]]) -> QualityReport {
        Self::compute_over(points, tets, None::<(&TetMesh, fn(P3) -> f64)>)
    }

    fn compute(mesh: &TetMesh, size: Option<impl Fn(P3) -> f64 + Sync>) -> QualityReport {
        let edges = size.map(|h| (mesh, h));
        Self::compute_over(&mesh.points, &mesh.tets, edges)
    }

    fn compute_over(
        points: &[P3],
        tets: &[[PointId; 4]],
        edges: Option<(&TetMesh, impl Fn(P3) -> f64 + Sync)>,
    ) -> QualityReport {
        // Chunks of tets, merged in order: the same sums whatever the
        // threads, and no accumulator moved per tet (its copies were a
        // tenth of the report's time).
        let accs: Vec<Acc> = tets
            .par_chunks(REPORT_CHUNK)
            .map(|ch| {
                let mut a = Acc::new();
                for t in ch {
                    let Some(p) = tet_coords(points, t) else {
                        a.skipped += 1;
                        continue;
                    };
                    // Two arc tangents for most tets, six where one is undefined.
                    let (bins, min_dihedral, max_dihedral) = crate::angles::report_angles(p)
                        .unwrap_or_else(|| {
                            let d = dihedral_angles(p);
                            let (min, max) = extremes(&d);
                            (d, min, max)
                        });
                    let q = TetQuality {
                        min_dihedral,
                        max_dihedral,
                        radius_ratio: radius_ratio(p),
                        mean_ratio: mean_ratio(p),
                        volume: tet_volume6(p[0], p[1], p[2], p[3]),
                    };
                    if q.volume.is_nan() || q.volume <= 0.0 {
                        a.inverted += 1;
                    }
                    if q.min_dihedral.is_nan() || q.min_dihedral < SMALL_DIHEDRAL {
                        a.small += 1;
                    }
                    for x in bins {
                        a.h[0].add(x);
                    }
                    let v = [q.min_dihedral, q.max_dihedral, q.radius_ratio, q.mean_ratio];
                    for (i, x) in v.into_iter().enumerate() {
                        a.s[i].add(x);
                        a.h[i + 1].add(x);
                    }
                }
                a
            })
            .collect();
        let acc = accs.into_iter().fold(Acc::new(), Acc::merge);
        let n = tets.len();
        let measured = n - acc.skipped;
        let (edge_ratio, edge_ratio_hist) = match edges {
            None => (None, None),
            Some((mesh, h)) => {
                let mut s = StatAcc::EMPTY;
                let mut hist = Histogram::new(0.0, 3.0, 30);
                for_each_edge_size_ratio(mesh, h, |r| {
                    for &x in r {
                        s.add(x);
                        hist.add(x);
                    }
                });
                (Some(s.stat()), Some(hist))
            }
        };
        let [dihedral_hist, min_dihedral_hist, max_dihedral_hist, radius_ratio_hist, mean_ratio_hist] =
            acc.h;
        QualityReport {
            n_tets: n,
            n_inverted: acc.inverted,
            n_skipped: acc.skipped,
            min_dihedral: acc.s[0].stat(),
            max_dihedral: acc.s[1].stat(),
            radius_ratio: acc.s[2].stat(),
            mean_ratio: acc.s[3].stat(),
            dihedral_hist,
            min_dihedral_hist,
            max_dihedral_hist,
            radius_ratio_hist,
            mean_ratio_hist,
            share_min_dihedral_below: if measured == 0 {
                0.0
            } else {
                acc.small as f64 / measured as f64
            },
            edge_ratio,
            edge_ratio_hist,
        }
    }
}

fn write_hist(f: &mut fmt::Formatter<'_>, title: &str, h: &Histogram, prec: usize) -> fmt::Result {
    let total = h.total().max(1);
    let peak = h.counts.iter().copied().max().unwrap_or(0).max(1);
    // Skip empty bins at both ends: the table shows where the mass is.
    let first = h.counts.iter().position(|&c| c > 0).unwrap_or(0);
    let last = h.counts.iter().rposition(|&c| c > 0).unwrap_or(0);
    writeln!(f, "{title}")?;
    for i in first..=last {
        let c = h.counts[i];
        let bar = ((c as f64 / peak as f64) * 30.0).round() as usize;
        writeln!(
            f,
            "  {:>7.prec$} - {:<7.prec$} {:>10} {:>6.2}% {}",
            h.bin_lo(i),
            h.bin_lo(i + 1),
            c,
            100.0 * c as f64 / total as f64,
            "#".repeat(if c > 0 { bar.max(1) } else { 0 }),
        )?;
    }
    Ok(())
}

impl fmt::Display for QualityReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "quality of {} tets ({} inverted, {} skipped)",
            self.n_tets, self.n_inverted, self.n_skipped
        )?;
        writeln!(
            f,
            "  {:<16} {:>10} {:>10} {:>10}",
            "measure", "min", "mean", "max"
        )?;
        let mut row = |name: &str, s: &Stat, prec: usize| {
            writeln!(
                f,
                "  {:<16} {:>10.prec$} {:>10.prec$} {:>10.prec$}",
                name, s.min, s.mean, s.max
            )
        };
        row("min dihedral deg", &self.min_dihedral, 2)?;
        row("max dihedral deg", &self.max_dihedral, 2)?;
        row("radius ratio", &self.radius_ratio, 4)?;
        row("mean ratio", &self.mean_ratio, 4)?;
        if let Some(s) = &self.edge_ratio {
            row("edge / size", s, 4)?;
        }
        writeln!(
            f,
            "  tets with min dihedral < {SMALL_DIHEDRAL} deg: {:.4}%",
            100.0 * self.share_min_dihedral_below
        )?;
        write_hist(
            f,
            "min dihedral per tet (deg):",
            &self.min_dihedral_hist.coarsen(5),
            0,
        )?;
        write_hist(
            f,
            "max dihedral per tet (deg):",
            &self.max_dihedral_hist.coarsen(5),
            0,
        )?;
        write_hist(f, "radius ratio:", &self.radius_ratio_hist.coarsen(2), 2)?;
        if let Some(h) = &self.edge_ratio_hist {
            write_hist(f, "edge length / target size:", &h.coarsen(2), 1)?;
        }
        Ok(())
    }
}

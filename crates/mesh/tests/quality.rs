//! Quality measures on known shapes, and the report on box meshes.
use parafront_geom::{orient3d, P3};
use parafront_mesh::generate::box_mesh;
use parafront_mesh::quality::*;
use parafront_mesh::*;

fn regular() -> [P3; 4] {
    // Alternate corners of a cube: a regular tet, positively oriented.
    let p = [
        [1.0, -1.0, -1.0],
        [1.0, 1.0, 1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    assert!(orient3d(p[0], p[1], p[2], p[3]) > 0.0);
    p
}

#[test]
fn regular_tet_is_perfect() {
    let q = tet_quality(regular());
    assert!((q.radius_ratio - 1.0).abs() < 1e-14, "{q:?}");
    assert!((q.mean_ratio - 1.0).abs() < 1e-14, "{q:?}");
    for a in dihedral_angles(regular()) {
        assert!((a - REGULAR_DIHEDRAL).abs() < 1e-12, "{a}");
    }
    assert!((REGULAR_DIHEDRAL - (1.0f64 / 3.0).acos().to_degrees()).abs() < 1e-12);
    assert!((q.volume - 8.0 / 3.0).abs() < 1e-14);
}

#[test]
fn sliver_is_near_zero() {
    // Four nearly coplanar points around a square: the classic sliver.
    for h in [1e-2, 1e-4, 1e-8] {
        let mut p = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, h],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, h],
        ];
        if orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
            p.swap(0, 1);
        }
        let q = tet_quality(p);
        assert!(q.volume > 0.0);
        assert!(
            q.radius_ratio > 0.0 && q.radius_ratio < 10.0 * h,
            "{h} {q:?}"
        );
        assert!(
            q.mean_ratio > 0.0 && q.mean_ratio < 10.0 * h.powf(2.0 / 3.0),
            "{h} {q:?}"
        );
        assert!(q.min_dihedral < 300.0 * h, "{h} {q:?}");
        assert!(q.max_dihedral > 180.0 - 300.0 * h, "{h} {q:?}");
    }
    // Exactly flat: zero, not NaN.
    let q = tet_quality([[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]);
    assert_eq!((q.radius_ratio, q.mean_ratio, q.volume), (0.0, 0.0, 0.0));
    // Inverted: negative ratios.
    let mut p = regular();
    p.swap(0, 1);
    let q = tet_quality(p);
    assert!((q.radius_ratio + 1.0).abs() < 1e-14 && (q.mean_ratio + 1.0).abs() < 1e-14);
}

#[test]
fn kuhn_tets_and_box_report() {
    let m = box_mesh(3, 4, 5, [0.0; 3], [3.0, 4.0, 5.0]);
    let r = QualityReport::with_size(&m, |_| 1.0);
    assert_eq!(r.n_tets, 360);
    assert_eq!((r.n_inverted, r.n_skipped), (0, 0));
    // The Kuhn tet has dihedral angles 45, 60 and 90 degrees.
    assert!((r.min_dihedral.min - 45.0).abs() < 1e-9 && (r.min_dihedral.max - 45.0).abs() < 1e-9);
    assert!((r.max_dihedral.max - 90.0).abs() < 1e-9);
    let mut d = dihedral_angles(m.tet_points(TetId::from_raw(0)));
    d.sort_by(f64::total_cmp);
    let want = [45.0, 45.0, 60.0, 90.0, 90.0, 90.0];
    for (a, b) in d.iter().zip(want) {
        assert!((a - b).abs() < 1e-9, "{d:?}");
    }
    // Unit Kuhn tet: r = 3V / area = 0.5 / (1 + sqrt 2), R = sqrt 3 / 2.
    let rr = 3.0 * (0.5 / (1.0 + 2f64.sqrt())) / (3f64.sqrt() / 2.0);
    assert!(
        (r.radius_ratio.mean - rr).abs() < 1e-12,
        "{}",
        r.radius_ratio.mean
    );
    assert_eq!(r.share_min_dihedral_below, 0.0);
    assert_eq!(r.dihedral_hist.total(), 6 * 360);
    assert_eq!(r.min_dihedral_hist.total(), 360);
    assert_eq!(r.radius_ratio_hist.total(), 360);
    assert_eq!(
        r.radius_ratio_hist.counts[r.radius_ratio_hist.bin_of(rr)],
        360
    );
    assert_eq!(r.dihedral_hist.counts.len(), 180);
    assert_eq!(r.radius_ratio_hist.counts.len(), 20);
    // 90-degree angles: 3 per tet, in the 90 bin (or 89 by rounding).
    assert_eq!(
        r.dihedral_hist.counts[89] + r.dihedral_hist.counts[90],
        3 * 360
    );
    // Edges: axis (length 1), face diagonals (sqrt 2), cell diagonals (sqrt 3).
    let e = r.edge_ratio.unwrap();
    let (nx, ny, nz) = (3, 4, 5);
    let axis = nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
    let diag = nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz;
    assert_eq!(e.count, axis + diag + nx * ny * nz);
    assert!((e.min - 1.0).abs() < 1e-12 && (e.max - 3f64.sqrt()).abs() < 1e-12);
    let s = r.to_string();
    for w in [
        "360 tets",
        "min dihedral",
        "radius ratio",
        "mean ratio",
        "edge / size",
        "45.00",
    ] {
        assert!(s.contains(w), "{w} missing from:\n{s}");
    }
}

#[test]
fn report_counts_bad_tets() {
    let mut m = box_mesh(2, 2, 2, [0.0; 3], [1.0; 3]);
    // Flatten a neighbourhood: the centre point onto a cell face plane.
    m.points[13] = [0.5, 0.5, 0.999];
    m.tets.push([
        PointId::from_raw(0),
        PointId::from_raw(1),
        PointId::from_raw(2),
        PointId::from_raw(99),
    ]);
    let mut flipped = m.tets[0];
    flipped.swap(0, 1);
    m.tets.push(flipped);
    m.region.extend([0, 0]);
    let r = QualityReport::new(&m);
    assert_eq!(r.n_skipped, 1);
    assert_eq!(r.n_inverted, 1);
    assert!(r.share_min_dihedral_below > 0.0);
    assert!(r.min_dihedral.min < 10.0);
    assert_eq!(r.min_dihedral_hist.total() as usize, m.tets.len() - 1);
    assert!(r.edge_ratio.is_none());
    assert!(r.to_string().contains("1 skipped"));
    // Per-tet values agree with the report's extremes.
    let q = tet_qualities(&m);
    assert!(q[q.len() - 2].is_none());
    assert!(q.last().unwrap().unwrap().radius_ratio < 0.0);
    let lo = q
        .iter()
        .flatten()
        .map(|q| q.min_dihedral)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(lo, r.min_dihedral.min);
    assert_eq!(r.radius_ratio.min, q.last().unwrap().unwrap().radius_ratio);
}

#[test]
fn histogram_binning() {
    let mut h = Histogram::new(0.0, 1.0, 20);
    for x in [-0.5, 0.0, 0.049, 0.05, 0.99, 1.0, 7.0, f64::NAN] {
        h.add(x);
    }
    assert_eq!(h.total(), 8);
    assert_eq!(h.counts[0], 4);
    assert_eq!(h.counts[1], 1);
    assert_eq!(h.counts[19], 3);
    let c = h.coarsen(3);
    assert_eq!(c.counts.len(), 7);
    assert_eq!(c.total(), 8);
    assert!((c.bin_width() - 0.15).abs() < 1e-12);
}

#[test]
fn merged_reports_of_two_halves_are_the_whole() {
    let m = box_mesh(4, 3, 2, [0.0; 3], [2.0, 1.5, 1.0]);
    let half = |keep: bool| TetMesh {
        points: m.points.clone(),
        tets: m
            .tets
            .iter()
            .filter(|t| (m.points[t[0].idx()][0] < 1.0) == keep)
            .copied()
            .collect(),
        ..Default::default()
    };
    let size = |_: P3| 0.5;
    let whole = QualityReport::with_size(&m, size);
    let (a, b) = (
        QualityReport::with_size(&half(true), size),
        QualityReport::with_size(&half(false), size),
    );
    assert!(a.n_tets > 0 && b.n_tets > 0);
    let g = a.merge(&b);
    assert_eq!(g.n_tets, whole.n_tets);
    assert_eq!(g.min_dihedral.min, whole.min_dihedral.min);
    assert_eq!(g.max_dihedral.max, whole.max_dihedral.max);
    assert_eq!(g.radius_ratio.count, whole.radius_ratio.count);
    assert!((g.mean_ratio.mean - whole.mean_ratio.mean).abs() < 1e-12);
    assert_eq!(g.dihedral_hist, whole.dihedral_hist);
    assert_eq!(g.min_dihedral_hist, whole.min_dihedral_hist);
    assert_eq!(g.share_min_dihedral_below, whole.share_min_dihedral_below);
    // Edges on the cut count in both halves.
    assert!(g.edge_ratio.unwrap().count >= whole.edge_ratio.unwrap().count);
}

/// The report of some of a mesh's tets is that of a mesh of those tets
/// alone, and two such reports merge into the whole's shape report.
#[test]
fn a_report_of_some_tets_is_theirs() {
    let m = box_mesh(4, 3, 2, [0.0; 3], [2.0, 1.5, 1.0]);
    let cut = m.tets.len() / 3;
    let head = TetMesh {
        points: m.points.clone(),
        tets: m.tets[..cut].to_vec(),
        ..Default::default()
    };
    let a = QualityReport::of_tets(&m.points, &m.tets[..cut]);
    assert_eq!(a, QualityReport::new(&head));
    let g = a.merge(&QualityReport::of_tets(&m.points, &m.tets[cut..]));
    let whole = QualityReport::new(&m);
    assert_eq!(g.n_tets, whole.n_tets);
    assert_eq!(g.radius_ratio_hist, whole.radius_ratio_hist);
    assert_eq!(g.max_dihedral_hist, whole.max_dihedral_hist);
    assert_eq!(g.min_dihedral.min, whole.min_dihedral.min);
    assert!((g.radius_ratio.mean - whole.radius_ratio.mean).abs() < 1e-12);
    assert!(g.edge_ratio.is_none());
}

/// A box large enough that the edges are taken in several slices: each
/// edge still counted once, and the histogram holds them all.
#[test]
fn edge_ratios_of_a_large_box_count_each_edge_once() {
    let (nx, ny, nz) = (20, 24, 30);
    let m = box_mesh(nx, ny, nz, [0.0; 3], [nx as f64, ny as f64, nz as f64]);
    assert!(6 * m.tets.len() > 4 * (1 << 16));
    let r = QualityReport::with_size(&m, |_| 1.0);
    let e = r.edge_ratio.unwrap();
    let axis = nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
    let diag = nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz;
    assert_eq!(e.count, axis + diag + nx * ny * nz);
    assert_eq!(r.edge_ratio_hist.unwrap().total() as usize, e.count);
    let mean = (axis as f64 + diag as f64 * 2f64.sqrt() + (nx * ny * nz) as f64 * 3f64.sqrt())
        / e.count as f64;
    assert!((e.mean - mean).abs() < 1e-9, "{} {mean}", e.mean);
}

/// The report's histograms, extremes and count of small angles are those
/// of `tet_quality` and `dihedral_angles` tet by tet (the report takes
/// most angles from a polynomial, and `atan2` only where it decides).
#[test]
fn report_matches_the_measures_tet_by_tet() {
    let mut m = box_mesh(12, 9, 7, [0.0, 0.0, 0.0], [1.0, 0.7, 0.3]);
    // Shaken points: angles all over the range, some close to flat.
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for p in &mut m.points {
        for v in p.iter_mut() {
            *v += 0.04 * r();
        }
    }
    let rep = QualityReport::new(&m);
    let mut dih = Histogram::new(0.0, 180.0, 180);
    let mut lo = Histogram::new(0.0, 180.0, 180);
    let mut hi = Histogram::new(0.0, 180.0, 180);
    let (mut min, mut max, mut small) = (f64::INFINITY, f64::NEG_INFINITY, 0);
    for t in &m.tets {
        let p = t.map(|v| m.points[v.idx()]);
        let q = tet_quality(p);
        for a in dihedral_angles(p) {
            dih.add(a);
        }
        lo.add(q.min_dihedral);
        hi.add(q.max_dihedral);
        min = min.min(q.min_dihedral);
        max = max.max(q.max_dihedral);
        small += usize::from(q.min_dihedral < SMALL_DIHEDRAL);
    }
    assert!(small > 0 && min < 5.0 && max > 150.0, "{small} {min} {max}");
    assert_eq!(rep.dihedral_hist.counts, dih.counts);
    assert_eq!(rep.min_dihedral_hist.counts, lo.counts);
    assert_eq!(rep.max_dihedral_hist.counts, hi.counts);
    assert_eq!((rep.min_dihedral.min, rep.max_dihedral.max), (min, max));
    let share = small as f64 / m.tets.len() as f64;
    assert_eq!(rep.share_min_dihedral_below, share);
}

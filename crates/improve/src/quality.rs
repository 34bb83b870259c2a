//! The one quality measure every operation uses: the mean ratio,
//! `12 (3|V|)^(2/3) / sum l^2`, signed by the volume
//! (`parafront_mesh::quality::mean_ratio`). Smooth, scale invariant, 1 for
//! the regular tet, 0 for a flat one, and cheap (a cube root, no
//! arc-cosines; §9.4 warns about their cost).
use parafront_geom::P3;
use parafront_mesh::quality::{edge_length2_sum, mean_ratio_of};

pub use parafront_mesh::quality::mean_ratio as quality;

/// A new tet's `6V` under this share of the cube of its longest edge
/// from its first corner is flat: positive, but a float volume (which
/// other tools check, relative to the mesh's mean edge) may call it zero.
/// No operation makes such a tet (the slot at size 0.03 got two at 1e-18).
pub const FLAT: f64 = 1e-9;

/// `6V` of a tet that is positive both in floating point and exactly, and
/// not [`FLAT`], else `None`. The flat bound is far above the float
/// determinant's error bound (Shewchuk's first stage: under 1e-14 of the
/// same cube), so a tet it passes is exactly positive too.
#[inline]
pub fn positive_volume6(p: [P3; 4]) -> Option<f64> {
    use parafront_geom::{cross, dot, norm2, sub};
    let u = sub(p[1], p[0]);
    let w = sub(p[2], p[0]);
    let z = sub(p[3], p[0]);
    // `tet_volume6`, operation for operation.
    let v6 = dot(cross(u, w), z);
    let l2 = norm2(u).max(norm2(w)).max(norm2(z));
    (v6 > FLAT * l2 * l2.sqrt()).then_some(v6)
}

/// [`quality`]`(p)` where it may exceed `bar`, else `f64::NEG_INFINITY`
/// where it certainly does not. Most candidate tets of a swap lose: they
/// skip the cube root (a fifth of the improvement's time), comparing
/// `(3V)^2` with the cube of the bar instead, with a margin (1e-9) far
/// above the rounding of either side, so no answer changes.
#[inline]
pub fn quality_over(p: [P3; 4], bar: f64) -> f64 {
    let v6 = parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]);
    let l2 = edge_length2_sum(p);
    if bar >= 0.0 && l2 > 0.0 {
        if v6 <= 0.0 {
            return f64::NEG_INFINITY; // the quality is 0 or negative
        }
        // q > bar iff cbrt((3V)^2) > bar l2 / 12 =: t, iff (3V)^2 > t^3.
        let v3 = 0.5 * v6;
        let t = bar * l2 / 12.0;
        if v3 * v3 < t * t * t * (1.0 - 1e-9) {
            return f64::NEG_INFINITY;
        }
    }
    mean_ratio_of(v6, l2)
}

/// Whether a positive tet of `6V` = `v6` and squared edges `l2` has a
/// mean ratio (as `mean_ratio_of` rounds it) under `floor`: decided from
/// `(3V)^2` against `(floor l2 / 12)^3` where they differ by more than a
/// relative 1e-9, far above the rounding of either side (as
/// [`quality_over`]); the cube root only in between.
#[inline(always)]
pub(crate) fn mean_ratio_under(v6: f64, l2: f64, floor: f64) -> bool {
    if !(floor > 0.0) {
        return false; // a positive tet's quality is positive
    }
    let v3 = 0.5 * v6;
    let a = v3 * v3;
    let t = floor * l2 / 12.0;
    let b = t * t * t;
    if !(a.is_normal() && b.is_normal()) {
        // Overflow or underflow: no margin holds there.
        mean_ratio_of(v6, l2) < floor
    } else if a < b * (1.0 - 1e-9) {
        true
    } else if a > b * (1.0 + 1e-9) {
        false
    } else {
        mean_ratio_of(v6, l2) < floor
    }
}

/// The mean ratio of a tet that is positive both in floating point and
/// exactly, else `None`: [`quality`] with the one determinant.
#[inline]
pub fn positive_quality(p: [P3; 4]) -> Option<f64> {
    let v6 = positive_volume6(p)?;
    Some(mean_ratio_of(v6, edge_length2_sum(p)))
}

/// Each edge of a tet (its first two corners) with the two other corners.
const EDGE_SIDES: [[usize; 4]; 6] = [
    [0, 1, 2, 3],
    [0, 2, 1, 3],
    [0, 3, 1, 2],
    [1, 2, 0, 3],
    [1, 3, 0, 2],
    [2, 3, 0, 1],
];

/// The smallest dihedral angle of a tet, in degrees (the other
/// measure): the last polish, and the passes for the tets under 10° and
/// for the worst ones, which work on the angles themselves.
pub fn min_dihedral_deg(p: [P3; 4]) -> f64 {
    let (e, m) = edges_and_normals(p);
    min_dihedral_of(p, e, m)
}

/// `Some(min_dihedral_deg(p))` where [`has_dihedral_under`]`(p, tan_max)`,
/// else `None`: the searches that only need the small angles, with the
/// edges and normals computed once for both.
pub fn min_dihedral_deg_under(p: [P3; 4], tan_max: f64) -> Option<f64> {
    let (e, m) = edges_and_normals(p);
    dihedral_under(&e, &m, tan_max).then(|| min_dihedral_of(p, e, m))
}

/// `None` where [`positive_volume6`] refuses the tet, else
/// [`min_dihedral_deg_under`]`(p, tan_max)`: the searches that need both,
/// with one set of edges and normals (the volume is the same product,
/// operation for operation, so every answer is the two calls').
#[inline]
pub fn positive_min_dihedral_under(p: [P3; 4], tan_max: f64) -> Option<Option<f64>> {
    use parafront_geom::{dot, norm2};
    let (e, m) = edges_and_normals(p);
    // `positive_volume6`: its `u`, `w`, `z` are `e[0..3]`, and
    // `cross(u, w)` is `m[3]`.
    let v6 = dot(m[3], e[2]);
    let l2 = norm2(e[0]).max(norm2(e[1])).max(norm2(e[2]));
    if !(v6 > FLAT * l2 * l2.sqrt()) {
        return None;
    }
    Some(dihedral_under(&e, &m, tan_max).then(|| min_dihedral_of(p, e, m)))
}

/// [`min_dihedral_deg`] from the tet's edges and normals.
#[inline]
fn min_dihedral_of(p: [P3; 4], e: [P3; 6], m: [P3; 4]) -> f64 {
    use parafront_geom::{cross, dot, norm};
    // One arc tangent, at the smallest angle's edge, instead of six (they
    // were a fifth of the improvement's time), and the four face normals
    // instead of two cross products per edge (this function was a third
    // of the tray's improvement, and is a sixth).
    let Some(f) = Faces::new(e, m) else {
        return min_dihedral_slow(p);
    };
    // Every tet has an acute dihedral angle, and among acute ones the
    // smallest has the smallest sine, `|e| |6V| / (|m_k| |m_l|)` (sines,
    // unlike cosines, resolve small angles): the least
    // `|e|^2 / (|m_k|^2 |m_l|^2)`.
    let mut best = (f64::INFINITY, 0, 0);
    for (e2, k, l) in f.edges() {
        if dot(f.m[k], f.m[l]) < 0.0 {
            let key = e2 / (f.n2[k] * f.n2[l]);
            if key < best.0 {
                best = (key, k, l);
            }
        }
    }
    if best.0 == f64::INFINITY {
        return min_dihedral_slow(p);
    }
    let (_, k, l) = best;
    let (mk, ml) = (f.m[k], f.m[l]);
    norm(cross(mk, ml)).atan2(-dot(mk, ml)).to_degrees()
}

/// A tet's face normals, all inward for a positive tet (all outward for a
/// negative one), their squared lengths, and its edge vectors.
struct Faces {
    /// `m[i]`: the normal of the face opposite corner `i`, twice its area long.
    m: [P3; 4],
    n2: [f64; 4],
    /// Edges 01, 02, 03, 12, 13, 23.
    e: [P3; 6],
}

impl Faces {
    /// `None` where a face has no normal (a flat or non-finite tet).
    #[inline]
    fn new(e: [P3; 6], m: [P3; 4]) -> Option<Faces> {
        let n2 = m.map(parafront_geom::norm2);
        if !n2.iter().all(|&x| x > 0.0 && x.is_finite()) {
            return None;
        }
        Some(Faces { m, n2, e })
    }

    /// Each edge's squared length with the two faces that meet there.
    #[inline]
    fn edges(&self) -> impl Iterator<Item = (f64, usize, usize)> + '_ {
        (0..6).map(move |i| {
            let (k, l) = EDGE_FACES[i];
            (parafront_geom::norm2(self.e[i]), k, l)
        })
    }
}

/// The faces (by opposite corner) that meet at edges 01, 02, 03, 12, 13, 23.
const EDGE_FACES: [(usize, usize); 6] = [(2, 3), (1, 3), (1, 2), (0, 3), (0, 2), (0, 1)];

/// A tet's edge vectors (01, 02, 03, 12, 13, 23) and its face normals
/// (`m[i]` on the face opposite corner `i`, twice its area long, all
/// inward for a positive tet).
#[inline]
fn edges_and_normals(p: [P3; 4]) -> ([P3; 6], [P3; 4]) {
    use parafront_geom::{cross, sub};
    let (a, b, c) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0]));
    let (ab, ac, bc) = (sub(b, a), sub(c, a), sub(c, b));
    let m = [cross(ac, ab), cross(b, c), cross(c, a), cross(a, b)];
    ([a, b, c, ab, ac, bc], m)
}

/// Every edge's angle: for flat tets, where a normal vanishes.
fn min_dihedral_slow(p: [P3; 4]) -> f64 {
    use parafront_geom::{cross, dot, norm, sub};
    let mut m = f64::INFINITY;
    for [a, b, c, d] in EDGE_SIDES {
        let e = sub(p[b], p[a]);
        let n1 = cross(e, sub(p[c], p[a]));
        let n2 = cross(e, sub(p[d], p[a]));
        m = m.min(norm(cross(n1, n2)).atan2(dot(n1, n2)));
    }
    m.to_degrees()
}

/// Whether a dihedral angle of the tet is under `tan_max` in tangent
/// (and acute): `min_dihedral_deg(p) < deg` with `tan_max = tan(deg)`,
/// without the arc tangents. At the edge of faces `k` and `l`,
/// `|m_k x m_l| = |e| |6V|`.
pub fn has_dihedral_under(p: [P3; 4], tan_max: f64) -> bool {
    let (e, m) = edges_and_normals(p);
    dihedral_under(&e, &m, tan_max)
}

/// [`has_dihedral_under`] from the tet's edges and normals.
#[inline]
fn dihedral_under(e: &[P3; 6], m: &[P3; 4], tan_max: f64) -> bool {
    use parafront_geom::{dot, norm2};
    let v6 = dot(e[0], m[1]);
    let t2 = tan_max * tan_max;
    // Squared: `|e|^2 (6V)^2 < tan^2 c12^2`, no square roots.
    e.iter().zip(EDGE_FACES).any(|(&e, (k, l))| {
        let c12 = -dot(m[k], m[l]);
        c12 > 0.0 && norm2(e) * v6 * v6 < t2 * c12 * c12
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cube-root-free test answers as the mean ratio it stands for:
    /// floors just under, at and just over each tet's quality (a relative
    /// 1e-12 to 1e-6 away, inside and outside its margin), tets from
    /// regular to flat, at scales from 1e-120 to 1e100 (where `(3V)^2` or
    /// the floor's cube overflows or underflows, the root decides).
    #[test]
    fn mean_ratio_under_is_the_mean_ratio_against_the_floor() {
        use parafront_mesh::quality::{edge_length2_sum, mean_ratio_of};
        let mut u = crate::test_rng(0x9e37_79b9_7f4a_7c15u64);
        let (mut under, mut over) = (0, 0);
        for k in 0..100_000 {
            let scale = 10f64.powi((k % 45) as i32 * 5 - 120);
            let mut p = [[0.0; 3]; 4];
            for q in &mut p {
                *q = [u() - 0.5, u() - 0.5, u() - 0.5].map(|x| x * scale);
            }
            if k % 3 == 0 {
                p[3] = [
                    0.5 * (p[0][0] + p[1][0]),
                    0.5 * (p[0][1] + p[1][1]),
                    p[3][2] * 1e-4,
                ];
            }
            let Some(v6) = positive_volume6(p) else {
                continue;
            };
            let l2 = edge_length2_sum(p);
            let q = mean_ratio_of(v6, l2);
            let rel = [0.0, 1e-12, -1e-12, 1e-10, -1e-10, 1e-9, -1e-9, 1e-6, -1e-6][k % 9];
            for floor in [q * (1.0 + rel), q, f64::INFINITY, 0.0, -1.0, f64::NAN] {
                let want = q < floor;
                assert_eq!(mean_ratio_under(v6, l2, floor), want, "{p:?} {floor}");
                under += usize::from(want);
                over += usize::from(!want);
            }
        }
        assert!(under > 40_000 && over > 180_000, "{under} {over}");
    }

    /// Random tets, the `i`-th regular-ish, flattened, stretched or flat
    /// by turns (the CAD parts' needles and slivers among them).
    fn squashed_tets(seed: u64) -> impl FnMut(usize) -> [P3; 4] {
        let mut r = crate::test_rng(seed);
        move |i| {
            let squash = [1.0, 0.3, 0.05, 1e-3, 0.0][i % 5];
            std::array::from_fn(|_| [r(), r(), squash * r()])
        }
    }

    /// The cube-root-free bar: the quality itself, to the bit, or -inf
    /// only where the quality does not exceed the bar; and the bar test
    /// does skip most losers.
    #[test]
    fn quality_over_a_bar_is_the_quality_or_a_certain_loser() {
        let mut tet = squashed_tets(0x0bad_ba12);
        let mut skipped = 0;
        for i in 0..100_000 {
            let p = tet(i);
            let q = quality(p);
            // Bars near the quality too, where rounding would show.
            for bar in [-0.5, 0.0, 0.2, 0.7, q, q * (1.0 - 1e-12), q * (1.0 + 1e-12)] {
                let got = quality_over(p, bar);
                if got == f64::NEG_INFINITY {
                    assert!(q <= bar, "{p:?}: {q} over {bar}");
                    skipped += 1;
                } else {
                    assert_eq!(got.to_bits(), q.to_bits(), "{p:?}");
                }
            }
        }
        assert!(skipped > 100_000, "{skipped}");
    }

    /// The combined test gives what the two separate calls give, to the
    /// bit, on regular, flattened, stretched and flat tets.
    #[test]
    fn min_dihedral_under_is_the_two_calls_in_one() {
        let mut tet = squashed_tets(0xd1ed_d7a1);
        let mut under = 0;
        for i in 0..100_000 {
            let p = tet(i);
            for tan in [crate::TAN_SMALL_DIHEDRAL, crate::TAN_12_5, 1.0] {
                let two = has_dihedral_under(p, tan).then(|| min_dihedral_deg(p));
                let one = min_dihedral_deg_under(p, tan);
                assert_eq!(one.map(f64::to_bits), two.map(f64::to_bits), "{p:?}");
                under += usize::from(one.is_some());
            }
        }
        assert!(under > 10_000, "{under}");
    }

    /// The fused test gives what the two separate calls give, to the bit,
    /// flat and inverted tets among them.
    #[test]
    fn positive_min_dihedral_under_is_the_two_calls_in_one() {
        let mut tet = squashed_tets(0x90f1_7e57);
        let (mut refused, mut under) = (0, 0);
        for i in 0..100_000 {
            let mut p = tet(i);
            if i % 7 == 0 {
                p.swap(0, 1);
            }
            for tan in [crate::TAN_SMALL_DIHEDRAL, crate::TAN_12_5, 1.0] {
                let two = positive_volume6(p).map(|_| min_dihedral_deg_under(p, tan));
                let one = positive_min_dihedral_under(p, tan);
                assert_eq!(
                    one.map(|d| d.map(f64::to_bits)),
                    two.map(|d| d.map(f64::to_bits)),
                    "{p:?}"
                );
                refused += usize::from(one.is_none());
                under += usize::from(one.flatten().is_some());
            }
        }
        assert!(refused > 10_000 && under > 10_000, "{refused} {under}");
    }

    #[test]
    fn is_the_mean_ratio() {
        use parafront_geom::tet_volume6;
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 0.9, 0.1],
            [0.3, 0.2, 0.7],
        ];
        // 12 (3V)^(2/3) / sum l^2, written out.
        let v = tet_volume6(p[0], p[1], p[2], p[3]) / 6.0;
        let l2: f64 = (0..4)
            .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
            .map(|(i, j)| parafront_geom::dist2(p[i], p[j]))
            .sum();
        let want = 12.0 * (3.0 * v).powf(2.0 / 3.0) / l2;
        let a = quality(p);
        assert!(v > 0.0 && (a - want).abs() < 1e-12, "{a} {want}");
        assert_eq!(positive_quality(p), Some(a));
        assert!(
            quality([p[1], p[0], p[2], p[3]]) == -a
                && positive_quality([p[1], p[0], p[2], p[3]]).is_none()
        );
        let r = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        assert!((quality(r).abs() - 1.0).abs() < 1e-12);
        // The regular tet: arccos(1/3) at every edge.
        let d = min_dihedral_deg(r);
        assert!((d - (1.0f64 / 3.0).acos().to_degrees()).abs() < 1e-9, "{d}");
        // The fourth point at the centroid of the first three's face.
        let flat = [r[0], r[1], r[2], [1.0 / 3.0, 1.0 / 3.0, -1.0 / 3.0]];
        assert!(min_dihedral_deg(flat) < 1e-6);
        let t10 = 10f64.to_radians().tan();
        assert!(has_dihedral_under(flat, t10) && !has_dihedral_under(r, t10));
        // Wedges with a dihedral of 5° and 15° at edge 01: the cheap test
        // agrees with the angles.
        for deg in [5.0f64, 15.0] {
            let a = deg.to_radians();
            let w = [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, 1.0, 0.0],
                [0.5, a.cos(), a.sin()],
            ];
            assert_eq!(has_dihedral_under(w, t10), min_dihedral_deg(w) < 10.0);
            assert_eq!(has_dihedral_under(w, t10), deg < 10.0);
        }
    }

    #[test]
    fn one_arc_tangent_gives_the_six_angles_minimum() {
        // Random tets, inverted ones and near-flat ones among them.
        let mut u = crate::test_rng(0x9e37_79b9_7f4a_7c15u64);
        let mut r = || u() - 0.5;
        for k in 0..10_000 {
            let mut p = [[0.0; 3]; 4];
            for q in &mut p {
                *q = [r(), r(), r()];
            }
            if k % 3 == 0 {
                p[3][2] *= 1e-9;
                p[0][2] = 0.0;
                p[1][2] = 0.0;
                p[2][2] = 0.0;
            }
            let (a, b) = (min_dihedral_deg(p), min_dihedral_slow(p));
            assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-3), "{p:?}: {a} {b}");
        }
        let flat = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(min_dihedral_deg(flat), min_dihedral_slow(flat));
    }

    #[test]
    fn positive_quality_refuses_flat_tets_then_is_the_mean_ratio() {
        use parafront_geom::{orient3d, tet_volume6};
        let mut u = crate::test_rng(0x2545_f491_4f6c_dd1du64);
        let mut r = || u() - 0.5;
        let (mut near, mut neg) = (0, 0);
        for k in 0..20_000 {
            let mut p = [[0.0; 3]; 4];
            for q in &mut p {
                *q = [r(), r(), r()];
            }
            // Near-flat: the fourth point a rounding away from the plane
            // of the first three, where the float sign can be wrong.
            if k % 2 == 0 {
                let (s, t) = (r() + 0.5, r() + 0.5);
                for d in 0..3 {
                    p[3][d] = p[0][d] + s * (p[1][d] - p[0][d]) + t * (p[2][d] - p[0][d]);
                }
                p[3][k % 3] += r() * 1e-15;
            }
            let exact = orient3d(p[0], p[1], p[2], p[3]) > 0.0;
            let v6 = tet_volume6(p[0], p[1], p[2], p[3]);
            let l2 = (1..4)
                .map(|i| parafront_geom::dist2(p[i], p[0]))
                .fold(0.0, f64::max);
            let flat = v6 <= FLAT * l2 * l2.sqrt();
            let want = (v6 > 0.0 && exact && !flat).then(|| quality(p));
            let got = positive_quality(p);
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{p:?}");
            near += usize::from(exact && flat);
            neg += usize::from(got.is_none());
        }
        // Exactly positive but flat tets were refused, and both answers
        // were given.
        assert!(near > 1000 && neg > 5000, "{near} {neg}");
    }
}

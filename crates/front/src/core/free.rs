//! AF2.3, the free-tet test: a new tet crosses no front face and holds no
//! front point, with the clearances each round of recovery relaxes.
use super::*;

/// New face `f` and front face `g` share an edge and lie within `min`
/// radians of one plane (both normals point into free space).
fn thin_wedge(f: [u32; 3], fp: [P3; 3], g: [u32; 3], gp: [P3; 3], min: f64) -> bool {
    // The vertex of each off the shared edge.
    let Some(i) = (0..3).find(|&i| !g.contains(&f[i])) else {
        return false;
    };
    let Some(j) = (0..3).find(|&j| !f.contains(&g[j])) else {
        return false;
    };
    let a = fp[(i + 1) % 3];
    let e = normalize(sub(fp[(i + 2) % 3], a));
    let perp = |x: P3| {
        let d = sub(x, a);
        normalize(sub(d, scale(e, dot(d, e))))
    };
    let u = perp(fp[i]);
    let w = perp(gp[j]);
    let x = dot(w, u);
    if x < 0.0 {
        return false; // an open wedge, the usual case: no normal needed
    }
    let n = normalize(tri_normal(fp[0], fp[1], fp[2]));
    let y = dot(w, n);
    // On the tet's side, a tiny angle means two near-coplanar faces whose
    // crossing the exact test may see as a miss by rounding (a flat quad
    // cut by both diagonals). For x > 0 and min <= 0.1, |atan2(y, x)| < min
    // iff |y|/x < tan(min), in [min, min (1 + min^2 / 2)]: atan2 (slow)
    // decides only in between.
    if x > 0.0 && min <= 0.1 {
        let r = y.abs() / x;
        if r < min * (1.0 - 1e-9) {
            return true;
        }
        if r > min * (1.0 + 0.5 * min * min) * (1.0 + 1e-9) {
            return false;
        }
    }
    y.atan2(x).abs() < min
}

/// The four face planes of a tet, for a float filter ahead of the exact
/// tests: a triangle strictly outside one plane, by more than the rounding
/// error, cannot meet the tet.
struct SeparatingPlanes {
    o: [P3; 4],
    n: [P3; 4],
    tol: [f64; 4],
    inv_len: [f64; 4],
}

impl SeparatingPlanes {
    #[inline]
    fn new(tp: &[P3; 4]) -> SeparatingPlanes {
        let mut o = [[0.0; 3]; 4];
        let mut n = [[0.0; 3]; 4];
        let mut tol = [0.0; 4];
        let mut inv_len = [0.0; 4];
        for (i, f) in TET_FACES.iter().enumerate() {
            let (a, b, c) = (tp[f[0]], tp[f[1]], tp[f[2]]);
            // Outward for a positive tet in parafront's convention.
            let v = cross(sub(b, a), sub(c, a));
            o[i] = a;
            n[i] = v;
            // The factor of `separates`' error bound, multiplied first there.
            tol[i] = 1e-12 * (v[0].abs() + v[1].abs() + v[2].abs());
            inv_len[i] = 1.0 / norm(v).max(1e-300);
        }
        SeparatingPlanes { o, n, tol, inv_len }
    }

    /// `d[i][j]`: how far corner `j` of `g` lies outside face plane `i`.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // the same index into three arrays
    fn outside(&self, g: &[P3; 3]) -> [[f64; 3]; 4] {
        // Loops, not `map`: nested array maps were left out of line.
        let mut d = [[0.0; 3]; 4];
        for i in 0..4 {
            for j in 0..3 {
                d[i][j] = dot(self.n[i], sub(g[j], self.o[i])) * self.inv_len[i];
            }
        }
        d
    }

    /// Corner `i`'s height over the face opposite it.
    #[inline]
    fn height(&self, tp: &[P3; 4], i: usize) -> f64 {
        -dot(self.n[i], sub(tp[i], self.o[i])) * self.inv_len[i]
    }

    /// `x` is inside the tet grown by `margin` on every face.
    #[inline]
    fn within(&self, x: P3, margin: f64) -> bool {
        (0..4).all(|i| dot(self.n[i], sub(x, self.o[i])) * self.inv_len[i] < margin)
    }

    /// `gl[j]`: the tet's local index of `g[j]` when it is a tet corner,
    /// else 4. A plane through every shared corner with the other corners
    /// strictly outside leaves `g` meeting the tet in shared corners only.
    /// `out`: `outside(g)`, whose signs are the float signs of the same
    /// dot products: planes they rule out are not computed again.
    #[inline]
    fn separates(&self, g: &[P3; 3], gl: [usize; 3], out: &[[f64; 3]; 4]) -> bool {
        // The base plane first: front faces around the base face lie
        // mostly under it (any order gives the same answer).
        'planes: for i in [3, 0, 1, 2] {
            let mut maybe = true;
            for j in 0..3 {
                // Plane i does not hold corner i; other corners must be out.
                maybe &= if gl[j] < 4 {
                    gl[j] != i
                } else {
                    out[i][j] > 0.0
                };
            }
            if !maybe {
                continue;
            }
            let mut outside = 0;
            for j in 0..3 {
                if gl[j] < 4 {
                    continue;
                }
                let d = sub(g[j], self.o[i]);
                let s = dot(self.n[i], d);
                if s <= 0.0 {
                    continue 'planes; // under any error bound
                }
                let err = self.tol[i] * (d[0].abs() + d[1].abs() + d[2].abs());
                if s <= err {
                    continue 'planes;
                }
                outside += 1;
            }
            if outside > 0 {
                return true;
            }
        }
        false
    }
}

impl<'a> Front<'a> {
    /// AF2.3: tet `v + q` must cross no front face and hold no front point.
    /// One function on purpose: the hot path of the front. As a struct
    /// with a method per test it was 5-7 % slower (sphere_1e5, paired).
    pub(super) fn tet_is_free(
        &self,
        v: [u32; 3],
        q: u32,
        pq: P3,
        near_f: &[Near],
        near_p: &[u32],
        cl: Clearance,
    ) -> Verdict {
        let margin = cl.point;
        let tv = [v[0], v[1], v[2], q];
        let tp = [
            self.pts[v[0] as usize],
            self.pts[v[1] as usize],
            self.pts[v[2] as usize],
            pq,
        ];
        let tb = bbox(tp);
        // The three new faces, built once rather than per near face.
        let mut nfv = [[0u32; 3]; 3];
        let mut nfp = [[[0.0; 3]; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                nfv[i][j] = tv[TET_FACES[i][j]];
                nfp[i][j] = tp[TET_FACES[i][j]];
            }
        }
        // Their boxes: closed triangles with no common corner and apart
        // boxes cannot meet (exact, the boxes are of the coordinates).
        let nfb: [Aabb; 3] = nfp.map(bbox);
        let planes = SeparatingPlanes::new(&tp);
        let heights = [0, 1, 2].map(|i| planes.height(&tp, i));
        let m_apex = if policy::is_new_point(q) {
            cl.new_point.max(margin)
        } else {
            margin
        };
        let em = EDGE_CLEARANCE * margin;
        let tb_clear = tb.inflated(m_apex.max(em));
        // The new edges' boxes, grown by the edge clearance: a front edge
        // whose box misses one is farther than that from the edge.
        let ebox: [Aabb; 3] = [0, 1, 2].map(|e| bbox([tp[e], pq]).inflated(em));
        // Every face on three tet corners reaches the test below: no filter
        // before it skips a face that touches the tet.
        let mut matched = [NONE; 3];
        for at in Overlapping::new(near_f, tb_clear) {
            let nf = &near_f[at];
            let g = nf.v;
            let gp = &nf.p;
            let gl = local_ids(g, tv);
            // The apex keeps clear of front faces too, not only of front
            // points: a long face has its corners far away, and a tet that
            // hovers over its middle leaves a slab only slivers can fill.
            // The box is a cheap lower bound on the distance (kept with a
            // slack so that rounding cannot decide differently).
            if m_apex > 0.0
                && !g.contains(&q)
                && box_dist2(&nf.bb, pq) < m_apex * m_apex * (1.0 + 1e-9)
                && point_triangle_dist2(pq, gp[0], gp[1], gp[2]) < m_apex * m_apex
            {
                return Verdict::Face(at);
            }
            // Nor may a new edge pass close by a front edge: two edges
            // crossing a hair apart leave a slab between their faces that
            // only slivers fill (thin plates of CAD needles).
            let d = planes.outside(gp);
            // Some plane has all of `g` more than `em` outside: it keeps
            // that far from the tet.
            // (`&` and `|`, not `&&` and `||`: the branches mispredict.)
            let mut clear = false;
            for di in &d {
                clear |= (di[0] > em) & (di[1] > em) & (di[2] > em);
            }
            // Then `g` has no corner on the tet, and `separates` would find
            // that plane: its rounding bound, 3e-12 of the distance between
            // the two (under the boxes' span), is far below `em`.
            if clear && em > 3e-12 * span1(&tb, &nf.bb) {
                continue;
            }
            if em > 0.0 && !clear {
                // Front edge k against new edge e = (tv[e], q), by the tet's
                // local indices: one front edge's box serves all three.
                for k in 0..3 {
                    let k1 = (k + 1) % 3;
                    let (l0, l1) = (gl[k], gl[k1]);
                    if l0 == 3 || l1 == 3 || (l0 < 4 && l1 < 4) {
                        continue; // ends at the apex, or an edge of the tet
                    }
                    if l0 == 4 && l1 == 4 {
                        let mut off = false;
                        for di in &d {
                            off |= (di[k] > em) & (di[k1] > em);
                        }
                        if off {
                            continue; // a plane keeps the edge `em` off the tet
                        }
                    } else {
                        // From base corner a = tv[la] to x, outside a plane
                        // through a by dx: its points at a + s (x - a) keep
                        // s dx from the tet and h_a - s |x - a| from the
                        // face opposite a, which holds every new edge
                        // without a; so at least h_a dx / (dx + |x - a|).
                        let (la, j, ja) = if l0 < 4 { (l0, k1, k) } else { (l1, k, k1) };
                        // Squared, without the root: (h_a - em') dx > em' |x - a|.
                        let mut dx = f64::NEG_INFINITY;
                        for (i, di) in d.iter().enumerate() {
                            dx = if i != la && di[j] > dx { di[j] } else { dx };
                        }
                        let em1 = em * (1.0 + 1e-9);
                        let lift = (heights[la] - em1) * dx;
                        if (dx > 0.0) & (lift > 0.0)
                            && lift * lift > em1 * em1 * dist2(gp[j], gp[ja])
                        {
                            continue;
                        }
                    }
                    let (x0, x1) = (gp[k], gp[(k + 1) % 3]);
                    let sb = bbox([x0, x1]);
                    for e in 0..3 {
                        if l0 == e || l1 == e || !ebox[e].overlaps(&sb) {
                            continue;
                        }
                        if segment_segment_dist2(tp[e], pq, x0, x1) < em * em {
                            return Verdict::Face(at);
                        }
                    }
                }
            }
            // Corners shared with the tet; new face i has all its corners
            // but corner i.
            let nsh = gl.iter().filter(|&&l| l < 4).count();
            if nsh == 0 && !tb.overlaps(&nf.bb) {
                continue; // nothing in common with the tet, not even its box
            }
            let mut apart = planes.separates(gp, gl, &d);
            if !apart {
                // The other way round: `g`'s plane with every tet corner
                // off `g` strictly on one side (exact), so the tet meets
                // `g` only in their common corners.
                let mut pos = 0;
                let mut neg = 0;
                for (j, &x) in tp.iter().enumerate() {
                    if !gl.contains(&j) {
                        let o = parafront_geom::orient3d(gp[0], gp[1], gp[2], x);
                        pos += usize::from(o > 0.0);
                        neg += usize::from(o < 0.0);
                    }
                }
                apart = pos + nsh == 4 || neg + nsh == 4;
            }
            if apart && nsh < 2 {
                continue; // no common edge: no matching face, no wedge
            }
            for i in 0..3 {
                let fvid = nfv[i];
                let shared = nsh - gl.contains(&i) as usize;
                if shared == 3 {
                    // A matching face must face the other way (AF5).
                    if same_cycle(fvid, g) {
                        return Verdict::Face(at);
                    }
                    if matched[i] == NONE {
                        matched[i] = nf.id;
                    }
                    continue;
                }
                if shared == 2 && cl.wedge > 0.0 && thin_wedge(fvid, nfp[i], g, *gp, cl.wedge) {
                    return Verdict::Face(at);
                }
                if apart || (shared == 0 && !nfb[i].overlaps(&nf.bb)) {
                    continue;
                }
                let (fp, gq) = shared_first(fvid, nfp[i], g, *gp);
                if triangles_intersect(fp, gq, shared) {
                    return Verdict::Face(at);
                }
            }
        }
        // A front point inside the tet, or closer to it than `margin`,
        // would leave a gap only a flat tet could close.
        let tbm = tb.inflated(margin);
        for &p in near_p {
            if tv.contains(&p) {
                continue;
            }
            let x = self.pts[p as usize];
            if !tbm.contains(x) {
                continue;
            }
            if margin > 0.0 {
                if planes.within(x, margin) {
                    return Verdict::Point;
                }
            } else if orient3d(tp[1], tp[2], tp[3], x) < 0.0
                && orient3d(tp[0], tp[3], tp[2], x) < 0.0
                && orient3d(tp[0], tp[1], tp[3], x) < 0.0
                && orient3d(tp[0], tp[2], tp[1], x) < 0.0
            {
                return Verdict::Point;
            }
        }
        Verdict::Free(matched)
    }
}

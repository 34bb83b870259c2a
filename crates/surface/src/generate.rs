//! Surfaces the code makes itself: the built-in demo geometry and test
//! inputs that need no file.
use crate::Surface;
use parafront_geom::*;
use std::collections::HashMap;

impl Surface {
    /// Append `o` (its points and triangles) as further shells.
    pub fn append(&mut self, o: &Surface) {
        let off = self.points.len() as u32;
        self.points.extend_from_slice(&o.points);
        self.tris.extend(o.tris.iter().map(|t| t.map(|i| i + off)));
        self.patch.extend_from_slice(&o.patch);
        for (k, n) in &o.patch_names {
            if !self.patch_names.iter().any(|(j, _)| j == k) {
                self.patch_names.push((*k, n.clone()));
            }
        }
    }
    /// Reverse every triangle (turns a body into a void and back).
    pub fn flipped(mut self) -> Surface {
        for t in &mut self.tris {
            t.swap(1, 2);
        }
        self
    }
    /// Every triangle gets patch tag `tag`.
    pub fn with_patch(mut self, tag: u32, name: &str) -> Surface {
        self.patch.iter_mut().for_each(|p| *p = tag);
        self.patch_names = vec![(tag, name.to_string())];
        self
    }
}

/// Icosphere with outward normals: `subdiv` 4-to-1 refinements of an icosahedron.
pub fn icosphere(center: P3, radius: f64, subdiv: u32) -> Surface {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pts: Vec<P3> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for p in &mut pts {
        *p = normalize(*p);
    }
    for _ in 0..subdiv {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(tris.len() * 4);
        for tri in &tris {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[k] = *mid.entry(key).or_insert_with(|| {
                    pts.push(normalize(scale(add(pts[a as usize], pts[b as usize]), 0.5)));
                    pts.len() as u32 - 1
                });
            }
            next.push([tri[0], m[0], m[2]]);
            next.push([tri[1], m[1], m[0]]);
            next.push([tri[2], m[2], m[1]]);
            next.push([m[0], m[1], m[2]]);
        }
        tris = next;
    }
    let points = pts.iter().map(|p| add(center, scale(*p, radius))).collect();
    Surface::one_patch(points, tris)
}

/// Torus around the z axis with outward normals.
pub fn torus(center: P3, major: f64, minor: f64, nu: usize, nv: usize) -> Surface {
    let mut points = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = std::f64::consts::TAU * i as f64 / nu as f64;
        for j in 0..nv {
            let v = std::f64::consts::TAU * j as f64 / nv as f64;
            let r = major + minor * v.cos();
            points.push(add(center, [r * u.cos(), r * u.sin(), minor * v.sin()]));
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut tris = Vec::with_capacity(2 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    Surface::one_patch(points, tris)
}

/// Boundary of a union of voxels: cell `(i,j,k)` of size `h` from `origin`
/// is solid where `solid(i,j,k)`. Each boundary square splits into two
/// triangles; normals point out of the solid. Patch tag = the axis
/// direction the face looks along (0:-x 1:+x 2:-y 3:+y 4:-z 5:+z). The
/// caller keeps the solid free of cells touching only along an edge or at
/// a corner (that boundary would not be manifold).
pub fn voxels(
    origin: P3,
    h: f64,
    n: [usize; 3],
    solid: impl Fn(usize, usize, usize) -> bool,
) -> Surface {
    let is = |i: i64, j: i64, k: i64| {
        i >= 0
            && j >= 0
            && k >= 0
            && (i as usize) < n[0]
            && (j as usize) < n[1]
            && (k as usize) < n[2]
            && solid(i as usize, j as usize, k as usize)
    };
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut s = Surface::default();
    let mut vid = |g: [i64; 3], s: &mut Surface| -> u32 {
        *ids.entry(g).or_insert_with(|| {
            s.points.push([
                origin[0] + h * g[0] as f64,
                origin[1] + h * g[1] as f64,
                origin[2] + h * g[2] as f64,
            ]);
            s.points.len() as u32 - 1
        })
    };
    for i in 0..n[0] as i64 {
        for j in 0..n[1] as i64 {
            for k in 0..n[2] as i64 {
                if !is(i, j, k) {
                    continue;
                }
                for axis in 0..3 {
                    for side in 0..2i64 {
                        let mut nb = [i, j, k];
                        nb[axis] += 2 * side - 1;
                        if is(nb[0], nb[1], nb[2]) {
                            continue;
                        }
                        // The square's corners, counter-clockwise seen from outside.
                        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
                        let mut base = [i, j, k];
                        base[axis] += side;
                        let corner = |du: i64, dw: i64| {
                            let mut g = base;
                            g[u] += du;
                            g[w] += dw;
                            g
                        };
                        let mut q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        if side == 0 {
                            q.reverse();
                        }
                        let v = q.map(|g| vid(g, &mut s));
                        let tag = (2 * axis) as u32 + side as u32;
                        s.tris.push([v[0], v[1], v[2]]);
                        s.tris.push([v[0], v[2], v[3]]);
                        s.patch.extend([tag, tag]);
                    }
                }
            }
        }
    }
    s
}

/// The built-in demo part: a block with a square hole drilled through it,
/// a spherical void, and a spherical inner body (its own region with
/// `--regions`). Units are millimetres; about `h` = 1 everywhere.
pub fn demo_part() -> Surface {
    let (nx, ny, nz) = (16, 12, 6);
    let mut s = voxels([0.0, 0.0, 0.0], 1.0, [nx, ny, nz], |i, j, _k| {
        // The through-hole: a 3x3 square channel along z.
        !((2..5).contains(&i) && (4..7).contains(&j))
    });
    s.patch_names = ["-x", "+x", "-y", "+y", "-z", "+z"]
        .iter()
        .enumerate()
        .map(|(k, n)| (k as u32, format!("block {n}")))
        .collect();
    s.append(
        &icosphere([12.0, 3.0, 3.0], 1.5, 2)
            .flipped()
            .with_patch(6, "void"),
    );
    s.append(&icosphere([8.5, 8.5, 3.0], 1.8, 2).with_patch(7, "inner body"));
    s
}

/// A CAD-style plate, 50 x 30 x `thickness`, with a round through-hole of
/// radius 3 faceted by `rim` points, its flat faces triangulated as a CAD
/// exporter does: fans from the plate's corners to the hole's rim. The fan
/// triangles are needles (about 25 long, 0.3 wide at 64 rim points), like
/// those of the hinge and the tray in the corpus.
pub fn needle_plate(thickness: f64, rim: usize) -> Surface {
    let (l, w, r) = (50.0, 30.0, 3.0);
    let (cx, cy) = (l / 2.0, w / 2.0);
    let corners = [[0.0, 0.0], [l, 0.0], [l, w], [0.0, w]];
    let ang: Vec<f64> = (0..rim)
        .map(|i| std::f64::consts::TAU * (i as f64 + 0.5) / rim as f64)
        .collect();
    // The corner a rim direction faces: quadrants of the circle.
    let owner = |a: f64| match (a / std::f64::consts::FRAC_PI_2) as usize {
        0 => 2,
        1 => 3,
        2 => 0,
        _ => 1,
    };
    let mut s = Surface::default();
    let layer = |z: f64, s: &mut Surface| {
        let c: Vec<u32> = corners
            .iter()
            .map(|q| {
                s.points.push([q[0], q[1], z]);
                s.points.len() as u32 - 1
            })
            .collect();
        let h: Vec<u32> = ang
            .iter()
            .map(|a| {
                s.points.push([cx + r * a.cos(), cy + r * a.sin(), z]);
                s.points.len() as u32 - 1
            })
            .collect();
        (c, h)
    };
    let (ct, ht) = layer(thickness, &mut s);
    let (cb, hb) = layer(0.0, &mut s);
    let add = |t: [u32; 3], out: P3, s: &mut Surface| {
        // Orient by the wanted outward direction.
        let [a, b, c] = t.map(|i| s.points[i as usize]);
        let t = if dot(tri_normal(a, b, c), out) > 0.0 {
            t
        } else {
            [t[0], t[2], t[1]]
        };
        s.tris.push(t);
        s.patch.push(0);
    };
    for (c, h, up) in [(&ct, &ht, 1.0), (&cb, &hb, -1.0)] {
        for i in 0..rim {
            let j = (i + 1) % rim;
            let (ki, kj) = (owner(ang[i]), owner(ang[j]));
            if ki != kj {
                add([c[ki], h[i], c[kj]], [0.0, 0.0, up], &mut s);
            }
            add([c[kj], h[i], h[j]], [0.0, 0.0, up], &mut s);
        }
    }
    for k in 0..4 {
        let (a, b) = (k, (k + 1) % 4);
        let mid = [
            0.5 * (corners[a][0] + corners[b][0]) - cx,
            0.5 * (corners[a][1] + corners[b][1]) - cy,
            0.0,
        ];
        add([cb[a], cb[b], ct[b]], mid, &mut s);
        add([cb[a], ct[b], ct[a]], mid, &mut s);
    }
    for i in 0..rim {
        let j = (i + 1) % rim;
        let a = 0.5 * (ang[i] + ang[j]) + if j == 0 { std::f64::consts::PI } else { 0.0 };
        let inward = [-a.cos(), -a.sin(), 0.0];
        add([hb[i], hb[j], ht[j]], inward, &mut s);
        add([hb[i], ht[j], ht[i]], inward, &mut s);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edges_paired(s: &Surface) -> bool {
        let mut e: Vec<(u32, u32)> = s
            .tris
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .collect();
        e.sort();
        e.windows(2).all(|w| w[0] != w[1])
            && e.iter().all(|&(a, b)| e.binary_search(&(b, a)).is_ok())
    }

    #[test]
    fn generated_surfaces_are_closed_and_outward() {
        let sph = icosphere([1.0, 2.0, 3.0], 2.0, 3);
        assert_eq!(sph.tris.len(), 20 * 64);
        assert!(edges_paired(&sph));
        let v = sph.signed_volume();
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        assert!(v > 0.97 * exact && v < exact, "{v}");

        let tor = torus([0.0; 3], 3.0, 1.0, 40, 20);
        assert!(edges_paired(&tor));
        let exact = 2.0 * std::f64::consts::PI.powi(2) * 3.0;
        assert!((tor.signed_volume() - exact).abs() < 0.05 * exact);

        let block = voxels([0.0; 3], 0.5, [4, 4, 2], |i, j, _| !(i == 1 && j == 1));
        assert!(edges_paired(&block));
        assert!(
            (block.signed_volume() - 0.125 * 30.0).abs() < 1e-12,
            "{}",
            block.signed_volume()
        );

        let plate = needle_plate(5.0, 64);
        assert!(edges_paired(&plate));
        // The hole is a 64-gon of circumradius 3.
        let hole = 0.5 * 64.0 * 9.0 * (std::f64::consts::TAU / 64.0).sin();
        let exact = (50.0 * 30.0 - hole) * 5.0;
        assert!((plate.signed_volume() - exact).abs() < 1e-9 * exact);

        let demo = demo_part();
        assert!(edges_paired(&demo));
        let expect = (16.0 * 12.0 - 9.0) * 6.0;
        let v = demo.signed_volume();
        // Block minus the void, plus the inner body counted once more.
        assert!(v > expect - 20.0 && v < expect + 25.0, "{v}");
    }
}

//! Hard surfaces, made in code: needles, twisted prisms (no
//! triangulation without a Steiner point), thin slots, thin rods, a tiny
//! feature beside large faces. The tests mesh them; `examples/hard_surfaces`
//! in the CLI writes them for the benchmark script and the peers.
use crate::Surface;

type P3 = [f64; 3];

/// The surface of `points` and `tris`, turned outward if it faced in.
fn surface(points: Vec<P3>, tris: Vec<[u32; 3]>) -> Surface {
    let n = tris.len();
    let mut s = Surface {
        points,
        tris,
        patch: vec![0; n],
        ..Default::default()
    };
    if s.signed_volume() < 0.0 {
        s = s.flipped();
    }
    s
}

/// A `k`-sided frustum along z, `len` long, radii `r0` at z = 0 and `r1`
/// at the top; caps fanned from one corner (needle triangles on the sides
/// and caps alike).
pub fn frustum(k: usize, len: f64, r0: f64, r1: f64, twist: f64) -> Surface {
    let mut p = Vec::new();
    for (z, r, t) in [(0.0, r0, 0.0), (len, r1, twist)] {
        for i in 0..k {
            let a = t + i as f64 * std::f64::consts::TAU / k as f64;
            p.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    let k32 = k as u32;
    let mut t = Vec::new();
    for i in 0..k32 {
        let j = (i + 1) % k32;
        t.push([i, j, j + k32]);
        t.push([i, j + k32, i + k32]);
    }
    for i in 1..k32 - 1 {
        t.push([0, i + 1, i]);
        t.push([k32, k32 + i, k32 + i + 1]);
    }
    surface(p, t)
}

/// A box 1 x 1 x 1 with a slot `gap` wide cut down into it to depth 0.9.
pub fn slotted_box(gap: f64) -> Surface {
    let prof: Vec<[f64; 2]> = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.5 + gap / 2.0, 1.0],
        [0.5 + gap / 2.0, 0.1],
        [0.5 - gap / 2.0, 0.1],
        [0.5 - gap / 2.0, 1.0],
        [0.0, 1.0],
    ];
    let n = prof.len() as u32;
    let mut p = Vec::new();
    for y in [0.0, 1.0] {
        for q in &prof {
            p.push([q[0], y, q[1]]);
        }
    }
    let cap = [
        [0, 1, 4],
        [0, 4, 5],
        [1, 2, 3],
        [1, 3, 4],
        [0, 5, 6],
        [0, 6, 7],
    ];
    let mut t = Vec::new();
    for c in cap {
        t.push(c);
        t.push([c[0] + n, c[2] + n, c[1] + n]);
    }
    for k in 0..n {
        let (a, b) = (k, (k + 1) % n);
        t.push([a, a + n, b + n]);
        t.push([a, b + n, b]);
    }
    // Cap orientation follows the sides': fix by the volume's sign.
    surface(p, t)
}

/// A `k`-sided rod of radius `r` and length `len`, its sides cut into
/// `segs` rings, its caps fanned from their centres.
pub fn rod(k: usize, r: f64, len: f64, segs: usize) -> Surface {
    let mut p = Vec::new();
    for s in 0..=segs {
        let z = len * s as f64 / segs as f64;
        for i in 0..k {
            let a = i as f64 * std::f64::consts::TAU / k as f64;
            p.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    let (c0, c1) = (p.len() as u32, p.len() as u32 + 1);
    p.push([0.0, 0.0, 0.0]);
    p.push([0.0, 0.0, len]);
    let (k32, s32) = (k as u32, segs as u32);
    let at = |s: u32, i: u32| s * k32 + i % k32;
    let mut t = Vec::new();
    for s in 0..s32 {
        for i in 0..k32 {
            t.push([at(s, i), at(s, i + 1), at(s + 1, i + 1)]);
            t.push([at(s, i), at(s + 1, i + 1), at(s + 1, i)]);
        }
    }
    for i in 0..k32 {
        t.push([c0, at(0, i + 1), at(0, i)]);
        t.push([c1, at(s32, i), at(s32, i + 1)]);
    }
    surface(p, t)
}

/// A tower of twisted triangular layers (Schönhardt's prism stacked):
/// layer `l` of height `height` turns by `twists[l]` radians, its sides
/// split along the diagonal that makes it untetrahedralizable without a
/// Steiner point; radius 1.
pub fn twisted_tower(twists: &[f64], height: f64) -> Surface {
    let mut p = Vec::new();
    let mut angle = 0.0;
    for l in 0..=twists.len() {
        if l > 0 {
            angle += twists[l - 1];
        }
        for k in 0..3 {
            let a = k as f64 * std::f64::consts::TAU / 3.0 + angle;
            p.push([a.cos(), a.sin(), l as f64 * height]);
        }
    }
    let top = 3 * twists.len() as u32;
    let mut t = vec![[0, 2, 1], [top, top + 1, top + 2]];
    for l in 0..twists.len() as u32 {
        for k in 0..3u32 {
            let (a, b) = (3 * l + k, 3 * l + (k + 1) % 3);
            let (c, d) = (a + 3, b + 3);
            t.push([a, b, d]);
            t.push([a, d, c]);
        }
    }
    surface(p, t)
}

/// The unit box with a cubic boss `e` wide and high at the centre of its
/// top face (a feature `e` of the part beside faces of 1).
pub fn boss_box(e: f64) -> Surface {
    let mut p: Vec<P3> = Vec::new();
    for z in [0.0, 1.0] {
        for y in [0.0, 1.0] {
            for x in [0.0, 1.0] {
                p.push([x, y, z]);
            }
        }
    }
    let c = |x: u32, y: u32, z: u32| x + 2 * y + 4 * z;
    let mut t: Vec<[u32; 3]> = Vec::new();
    let quad = |t: &mut Vec<[u32; 3]>, a: u32, b: u32, cc: u32, d: u32| {
        t.push([a, b, cc]);
        t.push([a, cc, d]);
    };
    quad(&mut t, c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0));
    quad(&mut t, c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1));
    quad(&mut t, c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1));
    quad(&mut t, c(1, 1, 0), c(0, 1, 0), c(0, 1, 1), c(1, 1, 1));
    quad(&mut t, c(0, 1, 0), c(0, 0, 0), c(0, 0, 1), c(0, 1, 1));
    let (lo, hi) = (0.5 - e / 2.0, 0.5 + e / 2.0);
    let ring = |z: f64| [[lo, lo, z], [hi, lo, z], [hi, hi, z], [lo, hi, z]];
    let inner: Vec<u32> = ring(1.0)
        .iter()
        .map(|&q| {
            p.push(q);
            p.len() as u32 - 1
        })
        .collect();
    let top: Vec<u32> = ring(1.0 + e)
        .iter()
        .map(|&q| {
            p.push(q);
            p.len() as u32 - 1
        })
        .collect();
    let outer = [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)];
    for k in 0..4 {
        let k1 = (k + 1) % 4;
        t.push([outer[k], outer[k1], inner[k1]]);
        t.push([outer[k], inner[k1], inner[k]]);
        quad(&mut t, inner[k], inner[k1], top[k1], top[k]);
    }
    quad(&mut t, top[0], top[1], top[2], top[3]);
    surface(p, t)
}

//! Weights and the balanced split of the DDG (§6, step 2), and the shifted
//! partitions of passes 2 and 3 (§7).
//!
//! Two splits: recursive coordinate bisection ([`rcb`]) and METIS's
//! multilevel k-way partition of the DDG's dual graph ([`metis_kway`]:
//! tets as vertices weighted by the fine tets they will hold, shared faces
//! as edges weighted by the fine faces that will cross them), which cuts
//! fewer faces and keeps each part connected.
use crate::Ddg;
use parafront_geom::{cross, norm, sub, tet_volume6, Aabb, P3};
use rayon::prelude::*;
use std::sync::Mutex;

/// Fine tets each DDG tet will hold (§6): its volume over the volume of a
/// regular tet at the size `h` at its centroid.
pub fn tet_weights(d: &Ddg, h: &(dyn Fn(P3) -> f64 + Sync)) -> Vec<f64> {
    (0..d.tets.len())
        .into_par_iter()
        .map(|t| {
            let p = d.tet_points(t);
            let v = tet_volume6(p[0], p[1], p[2], p[3]) / 6.0;
            let s = h(d.centroid(t));
            let reg = s * s * s / (6.0 * std::f64::consts::SQRT_2);
            (v / reg).max(0.0)
        })
        .collect()
}

/// Max over mean of the parts' summed weights.
pub fn imbalance(part: &[u32], w: &[f64], parts: usize) -> f64 {
    let mut sum = vec![0.0; parts];
    for (&k, &x) in part.iter().zip(w) {
        sum[k as usize] += x;
    }
    let mean = sum.iter().sum::<f64>() / parts as f64;
    if mean <= 0.0 {
        return 1.0;
    }
    sum.iter().cloned().fold(0.0, f64::max) / mean
}

/// Recursive coordinate bisection by weight (§6): split the tets' centroids
/// across the longest axis of their box so that each side gets weight in
/// proportion to its number of parts. Deterministic: ties go by tet id.
pub fn rcb(d: &Ddg, w: &[f64], parts: usize) -> Vec<u32> {
    let mut part = vec![0u32; d.tets.len()];
    let cen: Vec<P3> = (0..d.tets.len()).map(|t| d.centroid(t)).collect();
    let mut ids: Vec<u32> = (0..d.tets.len() as u32).collect();
    split(&cen, w, &mut ids, 0, parts as u32, &mut part);
    part
}

fn split(cen: &[P3], w: &[f64], ids: &mut [u32], first: u32, parts: u32, part: &mut [u32]) {
    if parts <= 1 || ids.len() <= 1 {
        for &t in ids.iter() {
            part[t as usize] = first;
        }
        return;
    }
    let ax = Aabb::from_points(ids.iter().map(|&t| &cen[t as usize])).longest_axis();
    ids.sort_unstable_by(|&a, &b| {
        cen[a as usize][ax]
            .total_cmp(&cen[b as usize][ax])
            .then(a.cmp(&b))
    });
    let left = parts / 2;
    let total: f64 = ids.iter().map(|&t| w[t as usize]).sum();
    let target = total * left as f64 / parts as f64;
    let mut acc = 0.0;
    let mut cut = ids.len();
    for (i, &t) in ids.iter().enumerate() {
        if acc + 0.5 * w[t as usize] > target {
            cut = i;
            break;
        }
        acc += w[t as usize];
    }
    let cut = cut.clamp(1, ids.len() - 1);
    let (a, b) = ids.split_at_mut(cut);
    split(cen, w, a, first, left, part);
    split(cen, w, b, first + left, parts - left, part);
}

/// How the DDG is split into parts (§6, step 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Partition {
    /// Recursive coordinate bisection of the tets' centroids by weight.
    Rcb,
    /// METIS k-way on the dual graph, parts kept connected.
    #[default]
    Metis,
}

impl Partition {
    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Partition::Rcb => "rcb",
            Partition::Metis => "metis",
        }
    }
}

impl std::str::FromStr for Partition {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rcb" => Ok(Partition::Rcb),
            "metis" => Ok(Partition::Metis),
            _ => Err(format!("unknown partition method {s:?} (rcb or metis)")),
        }
    }
}

/// Splits the DDG into `parts` parts of about equal weight `w` by
/// `method`; `h` is the fine size (it weights the faces METIS cuts).
/// Deterministic: the same partition for any thread count.
pub fn partition(
    d: &Ddg,
    w: &[f64],
    h: &(dyn Fn(P3) -> f64 + Sync),
    parts: usize,
    method: Partition,
) -> Vec<u32> {
    match method {
        Partition::Rcb => rcb(d, w, parts),
        Partition::Metis => metis_kway(d, w, h, parts),
    }
}

/// Per DDG tet, the parts of the tets within `layers` point layers of it:
/// the parts that a shift by `layers` can hand it to. A bit set of
/// `words` words per tet, flat.
struct Near {
    words: usize,
    bits: Vec<u64>,
}

impl Near {
    fn new(d: &Ddg, part: &[u32], layers: usize, parts: usize) -> Near {
        let words = parts.div_ceil(64).max(1);
        let (start, list) = d.point_tets();
        let mut cur = vec![0u64; words * d.tets.len()];
        for (t, &k) in part.iter().enumerate() {
            cur[words * t + k as usize / 64] |= 1 << (k % 64);
        }
        for _ in 0..layers {
            let mut around = vec![0u64; words * d.points.len()];
            around
                .par_chunks_mut(words)
                .enumerate()
                .for_each(|(p, out)| {
                    for &t in &list[start[p] as usize..start[p + 1] as usize] {
                        for (o, x) in out.iter_mut().zip(&cur[words * t as usize..]) {
                            *o |= x;
                        }
                    }
                });
            cur.par_chunks_mut(words).enumerate().for_each(|(t, out)| {
                for &p in &d.tets[t] {
                    for (o, x) in out.iter_mut().zip(&around[words * p as usize..]) {
                        *o |= x;
                    }
                }
            });
        }
        Near { words, bits: cur }
    }

    /// The parts near tet `t`, ascending.
    fn of(&self, t: usize) -> impl Iterator<Item = u32> + '_ {
        self.bits[self.words * t..self.words * (t + 1)]
            .iter()
            .enumerate()
            .flat_map(|(w, &x)| {
                (0..64)
                    .filter(move |b| x >> b & 1 == 1)
                    .map(move |b| (64 * w + b) as u32)
            })
    }
}

/// New labels for the parts of `part` (old label to new), so that the
/// pass on its shift by `layers` (§7, pass 2: a part takes the DDG layers
/// of its neighbours of higher index) shares out the front that the pass before it left: `left[t]`
/// faces in DDG tet `t`. Such a face goes to the lowest part within
/// `layers` of its tet, so a part's load is what lies near it and no part
/// labelled before it. Labelling next, again and again, the part that
/// would take the least (a weighted degeneracy order) keeps the largest
/// load small; with METIS's own numbering a central part took half of
/// pass 2. Only names change: pass 1's regions are the same.
pub fn order_for_shift(
    d: &Ddg,
    part: &[u32],
    left: &[u32],
    layers: usize,
    parts: usize,
) -> Vec<u32> {
    let near = Near::new(d, part, layers, parts);
    let items: Vec<usize> = (0..d.tets.len()).filter(|&t| left[t] > 0).collect();
    let mut load = vec![0u64; parts];
    let mut items_of: Vec<Vec<usize>> = vec![Vec::new(); parts];
    for (i, &t) in items.iter().enumerate() {
        for k in near.of(t) {
            load[k as usize] += left[t] as u64;
            items_of[k as usize].push(i);
        }
    }
    let mut taken = vec![false; items.len()];
    let mut label = vec![u32::MAX; parts];
    for next in 0..parts as u32 {
        let k = (0..parts)
            .filter(|&k| label[k] == u32::MAX)
            .min_by_key(|&k| (load[k], k))
            .expect("a part is left");
        label[k] = next;
        for &i in &items_of[k] {
            if !taken[i] {
                taken[i] = true;
                let t = items[i];
                for j in near.of(t) {
                    load[j as usize] -= left[t] as u64;
                }
            }
        }
    }
    label
}

/// Per part, the front faces in `left` (per DDG tet) that the shift of
/// `part` by `layers` from higher parts hands it: the lowest part within
/// `layers` of each tet.
pub fn shift_loads(d: &Ddg, part: &[u32], left: &[u32], layers: usize, parts: usize) -> Vec<u64> {
    let near = Near::new(d, part, layers, parts);
    let mut load = vec![0u64; parts];
    for (t, &n) in left.iter().enumerate() {
        if n > 0 {
            load[near.of(t).next().expect("its own part") as usize] += n as u64;
        }
    }
    load
}

/// The DDG's dual graph in CSR form (METIS's `xadj`, `adjncy`): one vertex
/// per tet, one edge per interior face, in tet and face order.
pub(crate) fn dual_graph(d: &Ddg) -> (Vec<i32>, Vec<i32>) {
    let neigh = d.neigh();
    let mut xadj = Vec::with_capacity(d.tets.len() + 1);
    let mut adj = Vec::with_capacity(4 * d.tets.len());
    xadj.push(0);
    for t in 0..d.tets.len() {
        for f in 0..4 {
            let n = neigh[4 * t + f];
            if !n.is_none() {
                adj.push(n.tet().raw() as i32);
            }
        }
        xadj.push(adj.len() as i32);
    }
    (xadj, adj)
}

/// The fine faces that will cross face `f` (opposite vertex `f`) of DDG
/// tet `t`: its area over the area of an equilateral triangle of the fine
/// size at its centroid.
fn fine_faces(d: &Ddg, h: &(dyn Fn(P3) -> f64 + Sync), t: usize, f: usize) -> f64 {
    let tv = d.tets[t];
    let mut v = [[0.0; 3]; 3];
    let mut k = 0;
    for (i, &p) in tv.iter().enumerate() {
        if i != f {
            v[k] = d.points[p as usize];
            k += 1;
        }
    }
    let area = 0.5 * norm(cross(sub(v[1], v[0]), sub(v[2], v[0])));
    let c = [0, 1, 2].map(|i| (v[0][i] + v[1][i] + v[2][i]) / 3.0);
    let s = h(c);
    area / (0.25 * 3f64.sqrt() * s * s)
}

/// METIS's load tolerance in thousandths: 1.01 (its default, 1.03, gave
/// 1.013-1.03 on sphere_1e5 at P = 8 and 32; this gives 1.000-1.001 there
/// for about 2 % more cut faces).
const UFACTOR: i32 = 10;

/// METIS keeps its random state in a global: one call at a time, so that
/// the same input gives the same partition whatever else runs.
static METIS: Mutex<()> = Mutex::new(());

/// METIS's integer weights: `xs` scaled, rounded, and kept within
/// 1..=2^28 (every vertex and edge counts; 32-bit sums keep room).
fn metis_weights(xs: &[f64], scale: f64) -> Vec<i32> {
    xs.iter()
        .map(|&x| ((x * scale).round() as i64).clamp(1, 1 << 28) as i32)
        .collect()
}

/// METIS k-way partition of the dual graph (§6 with a graph refinement:
/// METIS coarsens, splits and refines with FM, lowering the cut). Vertex
/// weights are `w` scaled to integers, edge weights the fine faces across
/// each DDG face; a fixed seed and one call at a time make it
/// deterministic. Each part is kept connected when the DDG is (METIS's
/// `CONTIG`); on any METIS error it falls back to [`rcb`].
pub(crate) fn metis_kway(
    d: &Ddg,
    w: &[f64],
    h: &(dyn Fn(P3) -> f64 + Sync),
    parts: usize,
) -> Vec<u32> {
    let neigh = d.neigh();
    let n = d.tets.len();
    if parts <= 1 || n <= parts {
        return rcb(d, w, parts);
    }
    let (xadj, adj) = dual_graph(d);
    // Integer weights: the total scaled to about 2^26 (room in METIS's
    // 32-bit sums), every tet at least 1.
    let total: f64 = w.iter().sum();
    let scale = if total > 0.0 {
        (1u64 << 26) as f64 / total
    } else {
        1.0
    };
    let vwgt = metis_weights(w, scale);
    // Each face's weight once (from its lower tet), in parallel: the
    // size field is the costly part of building the graph.
    let fw: Vec<[f64; 4]> = (0..n)
        .into_par_iter()
        .map(|t| {
            let mut x = [0.0; 4];
            for (f, xf) in x.iter_mut().enumerate() {
                let nb = neigh[4 * t + f];
                if !nb.is_none() && nb.tet().idx() > t {
                    *xf = fine_faces(d, h, t, f);
                }
            }
            x
        })
        .collect();
    let mut ew = Vec::with_capacity(adj.len());
    for t in 0..n {
        for f in 0..4 {
            let nb = neigh[4 * t + f];
            if !nb.is_none() {
                let (u, g) = (nb.tet().idx(), nb.local());
                ew.push(if u > t { fw[t][f] } else { fw[u][g] });
            }
        }
    }
    // The f64 temporaries go before METIS runs: its own work space is
    // the largest allocation of the partition.
    drop(fw);
    let etot: f64 = ew.iter().sum();
    let escale = if etot > (1u64 << 29) as f64 {
        (1u64 << 29) as f64 / etot
    } else {
        1.0
    };
    let adjwgt = metis_weights(&ew, escale);
    drop(ew);
    let contig = components(d, &vec![0u32; n], 1)[0] == 1;
    let mut part = vec![0i32; n];
    let res = {
        let _one = METIS.lock().unwrap_or_else(|e| e.into_inner());
        metis::Graph::new(1, parts as i32, &xadj, &adj).map(|g| {
            g.set_vwgt(&vwgt)
                .set_adjwgt(&adjwgt)
                .set_option(metis::option::Seed(1))
                .set_option(metis::option::Contig(contig))
                .set_option(metis::option::UFactor(UFACTOR))
                .part_kway(&mut part)
        })
    };
    match res {
        Ok(Ok(_cut)) if part.iter().all(|&k| k >= 0 && (k as usize) < parts) => {
            part.iter().map(|&k| k as u32).collect()
        }
        _ => rcb(d, w, parts),
    }
}

/// DDG faces between tets of different parts (the cut of the dual graph).
pub fn cut_faces(d: &Ddg, part: &[u32]) -> usize {
    let neigh = d.neigh();
    let mut cut = 0;
    for t in 0..d.tets.len() {
        for f in 0..4 {
            let n = neigh[4 * t + f];
            if !n.is_none() && (n.tet().idx()) > t && part[n.tet().idx()] != part[t] {
                cut += 1;
            }
        }
    }
    cut
}

/// The fine faces that will lie on the walls between parts: the cut
/// faces weighted by their area over the fine size squared.
pub fn cut_fine_faces(d: &Ddg, part: &[u32], h: &(dyn Fn(P3) -> f64 + Sync)) -> f64 {
    let neigh = d.neigh();
    let mut cut = 0.0;
    for t in 0..d.tets.len() {
        for f in 0..4 {
            let n = neigh[4 * t + f];
            if !n.is_none() && (n.tet().idx()) > t && part[n.tet().idx()] != part[t] {
                cut += fine_faces(d, h, t, f);
            }
        }
    }
    cut
}

/// Per part, how many face-connected pieces its tets make (1 for a
/// connected part, 0 for an empty one).
pub fn components(d: &Ddg, part: &[u32], parts: usize) -> Vec<usize> {
    let neigh = d.neigh();
    let n = d.tets.len();
    let mut seen = vec![false; n];
    let mut count = vec![0usize; parts];
    let mut stack = Vec::new();
    for s in 0..n {
        if seen[s] {
            continue;
        }
        let k = part[s];
        count[k as usize] += 1;
        seen[s] = true;
        stack.push(s);
        while let Some(t) = stack.pop() {
            for f in 0..4 {
                let nb = neigh[4 * t + f];
                if nb.is_none() {
                    continue;
                }
                let u = nb.tet().idx();
                if !seen[u] && part[u] == k {
                    seen[u] = true;
                    stack.push(u);
                }
            }
        }
    }
    count
}

/// Which way passes 2 and 3 move the walls (§7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shift {
    /// Pass 2: each part takes layers from its neighbours of higher index.
    FromHigher,
    /// Pass 3: from its neighbours of lower index.
    FromLower,
}

/// The partition with `layers` layers of DDG tets (tets sharing a point)
/// moved across each wall, every layer from the partition before it.
pub fn shifted(d: &Ddg, part: &[u32], shift: Shift, layers: usize) -> Vec<u32> {
    let (start, list) = d.point_tets();
    let mut cur = part.to_vec();
    for _ in 0..layers {
        // Per point, the lowest (highest) part around it.
        let pick = |a: u32, b: u32| match shift {
            Shift::FromHigher => a.min(b),
            Shift::FromLower => a.max(b),
        };
        let around: Vec<u32> = (0..d.points.len())
            .map(|p| {
                let ts = &list[start[p] as usize..start[p + 1] as usize];
                ts.iter()
                    .map(|&t| cur[t as usize])
                    .reduce(pick)
                    .unwrap_or(0)
            })
            .collect();
        cur = (0..d.tets.len())
            .map(|t| {
                d.tets[t]
                    .iter()
                    .map(|&p| around[p as usize])
                    .fold(cur[t], pick)
            })
            .collect();
    }
    cur
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_surface::generate;

    fn sphere_ddg() -> Ddg {
        crate::ddg_of(&generate::icosphere([0.0; 3], 1.0, 3))
    }

    #[test]
    fn rcb_balances_the_predicted_weights() {
        let d = sphere_ddg();
        let w = tet_weights(&d, &|_p| 0.05);
        for parts in [2usize, 3, 8] {
            let part = rcb(&d, &w, parts);
            assert!(part.iter().all(|&k| (k as usize) < parts));
            for k in 0..parts as u32 {
                assert!(part.contains(&k), "part {k} of {parts} is empty");
            }
            let imb = imbalance(&part, &w, parts);
            assert!(imb < 1.15, "{parts} parts: imbalance {imb}");
        }
    }

    fn torus_ddg() -> Ddg {
        crate::ddg_of(&generate::torus([0.0; 3], 1.0, 0.4, 48, 20))
    }

    #[test]
    fn metis_balances_connects_and_cuts_less_than_rcb() {
        // The fine size: finer on one side, so the weights vary.
        let h = |p: P3| 0.04 + 0.02 * (p[0] + 1.5);
        for (name, d) in [("sphere", sphere_ddg()), ("torus", torus_ddg())] {
            let w = tet_weights(&d, &h);
            for parts in [2usize, 3, 8, 16] {
                let m = metis_kway(&d, &w, &h, parts);
                let r = rcb(&d, &w, parts);
                assert!(m.iter().all(|&k| (k as usize) < parts));
                let imb = imbalance(&m, &w, parts);
                // The tolerance asked of METIS is 1 %; whole DDG tets add a
                // little on these small grids.
                assert!(imb < 1.02, "{name}, {parts} parts: imbalance {imb}");
                let pieces = components(&d, &m, parts);
                assert!(
                    pieces.iter().all(|&c| c == 1),
                    "{name}, {parts} parts: pieces per part {pieces:?}"
                );
                let (cm, cr) = (cut_fine_faces(&d, &m, &h), cut_fine_faces(&d, &r, &h));
                let (fm, fr) = (cut_faces(&d, &m), cut_faces(&d, &r));
                eprintln!(
                    "{name}, {parts} parts, {} DDG tets: imbalance metis {imb:.3} rcb {:.3}; cut fine faces metis {cm:.0} rcb {cr:.0}; DDG faces {fm} / {fr}; rcb pieces {:?}",
                    d.tets.len(),
                    imbalance(&r, &w, parts),
                    components(&d, &r, parts)
                );
                assert!(
                    cm < cr,
                    "{name}, {parts} parts: cut {cm} against rcb's {cr}"
                );
            }
        }
    }

    #[test]
    fn metis_is_deterministic_across_threads_and_calls() {
        let d = torus_ddg();
        let h = |_p: P3| 0.05;
        let w = tet_weights(&d, &h);
        let one = rayon_pool(1).install(|| metis_kway(&d, &w, &h, 8));
        let two = rayon_pool(2).install(|| metis_kway(&d, &w, &h, 8));
        // Calls from several threads at once are serialised.
        let many: Vec<Vec<u32>> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..4)
                .map(|_| s.spawn(|| metis_kway(&d, &w, &h, 8)))
                .collect();
            hs.into_iter().map(|j| j.join().unwrap()).collect()
        });
        assert_eq!(one, two);
        for m in many {
            assert_eq!(one, m);
        }
    }

    fn rayon_pool(n: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    }

    #[test]
    fn partition_picks_the_method() {
        let d = sphere_ddg();
        let h = |_p: P3| 0.05;
        let w = tet_weights(&d, &h);
        // The same classes, relabelled for pass 2.
        let same = |a: &[u32], b: &[u32]| {
            let mut map = std::collections::HashMap::new();
            a.iter()
                .zip(b)
                .all(|(x, y)| *map.entry(*x).or_insert(*y) == *y)
                && map.len() == map.values().collect::<std::collections::HashSet<_>>().len()
        };
        assert!(same(
            &partition(&d, &w, &h, 4, Partition::Rcb),
            &rcb(&d, &w, 4)
        ));
        assert!(same(
            &partition(&d, &w, &h, 4, Partition::Metis),
            &metis_kway(&d, &w, &h, 4)
        ));
        assert_eq!("metis".parse::<Partition>(), Ok(Partition::Metis));
        assert_eq!("rcb".parse::<Partition>(), Ok(Partition::Rcb));
        assert!("x".parse::<Partition>().is_err());
        // One part, or fewer tets than parts: no METIS call.
        assert!(partition(&d, &w, &h, 1, Partition::Metis)
            .iter()
            .all(|&k| k == 0));
    }

    #[test]
    fn the_dual_graph_is_symmetric() {
        let d = sphere_ddg();
        let (xadj, adj) = dual_graph(&d);
        assert_eq!(xadj.len(), d.tets.len() + 1);
        for t in 0..d.tets.len() {
            for &u in &adj[xadj[t] as usize..xadj[t + 1] as usize] {
                let back = &adj[xadj[u as usize] as usize..xadj[u as usize + 1] as usize];
                assert!(back.contains(&(t as i32)));
            }
        }
    }

    #[test]
    fn shifts_work_on_the_metis_partition() {
        let d = torus_ddg();
        let neigh = d.neigh();
        let h = |_p: P3| 0.05;
        let w = tet_weights(&d, &h);
        let part = metis_kway(&d, &w, &h, 8);
        for layers in [1, 2] {
            let up = shifted(&d, &part, Shift::FromHigher, layers);
            let down = shifted(&d, &part, Shift::FromLower, layers);
            assert!(up.iter().zip(&part).any(|(a, b)| a != b));
            assert!(down.iter().zip(&part).any(|(a, b)| a != b));
            assert!(up.iter().zip(&part).all(|(a, b)| a <= b));
            assert!(down.iter().zip(&part).all(|(a, b)| a >= b));
            // Every wall moves: no DDG face keeps both sides it had.
            let walls = |p: &[u32]| {
                let mut v = Vec::new();
                for t in 0..d.tets.len() {
                    for f in 0..4 {
                        let n = neigh[4 * t + f];
                        if !n.is_none() && (n.tet().idx()) > t && p[n.tet().idx()] != p[t] {
                            v.push((t, f));
                        }
                    }
                }
                v
            };
            let w0 = walls(&part);
            let w2 = walls(&up);
            let kept = w0.iter().filter(|x| w2.binary_search(x).is_ok()).count();
            assert_eq!(kept, 0, "{layers} layers: {kept} walls stayed in pass 2");
        }
    }

    #[test]
    fn a_shift_moves_tets_toward_the_lower_part_only() {
        let d = sphere_ddg();
        let w = tet_weights(&d, &|_p| 0.05);
        let part = rcb(&d, &w, 4);
        let up = shifted(&d, &part, Shift::FromHigher, 2);
        let down = shifted(&d, &part, Shift::FromLower, 2);
        let moved = up.iter().zip(&part).filter(|(a, b)| a != b).count();
        assert!(moved > 0);
        assert!(up.iter().zip(&part).all(|(a, b)| a <= b));
        assert!(down.iter().zip(&part).all(|(a, b)| a >= b));
    }

    #[test]
    fn the_order_for_a_shift_shares_out_the_front_left() {
        let d = sphere_ddg();
        let neigh = d.neigh();
        let h = |_p: P3| 0.05;
        let w = tet_weights(&d, &h);
        // A front left along the walls: one face per tet beside a wall.
        for parts in [4usize, 8, 16, 70] {
            let raw = metis_kway(&d, &w, &h, parts);
            let left: Vec<u32> = (0..d.tets.len())
                .map(|t| {
                    (0..4)
                        .filter(|&f| {
                            let n = neigh[4 * t + f];
                            !n.is_none() && raw[n.tet().idx()] != raw[t]
                        })
                        .count() as u32
                })
                .collect();
            let label = order_for_shift(&d, &raw, &left, 2, parts);
            // A relabelling: every label used once.
            let mut sorted = label.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..parts as u32).collect::<Vec<_>>());
            let ord: Vec<u32> = raw.iter().map(|&k| label[k as usize]).collect();
            // Every face goes to one part, and the loads are what the
            // shift itself hands out.
            let loads = shift_loads(&d, &ord, &left, 2, parts);
            let total: u64 = left.iter().map(|&n| n as u64).sum();
            assert!(total > 0);
            assert_eq!(loads.iter().sum::<u64>(), total);
            let up = shifted(&d, &ord, Shift::FromHigher, 2);
            let mut by_shift = vec![0u64; parts];
            for t in 0..d.tets.len() {
                by_shift[up[t] as usize] += left[t] as u64;
            }
            assert_eq!(loads, by_shift, "{parts} parts");
            // No worse than the given numbering, its reverse, or any part
            // put first.
            let max = |p: &[u32]| *shift_loads(&d, p, &left, 2, parts).iter().max().unwrap();
            let best = max(&ord);
            assert!(best <= max(&raw), "{parts} parts");
            let rev: Vec<u32> = raw.iter().map(|&k| parts as u32 - 1 - k).collect();
            assert!(best <= max(&rev), "{parts} parts");
            for first in 0..parts as u32 {
                let swapped: Vec<u32> = ord
                    .iter()
                    .map(|&k| {
                        if k == 0 {
                            first
                        } else if k == first {
                            0
                        } else {
                            k
                        }
                    })
                    .collect();
                assert!(best <= max(&swapped), "{parts} parts, {first} first");
            }
        }
    }
}

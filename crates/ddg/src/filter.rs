//! The region filter of one part (§7): its walls, the DDG faces between
//! parts that its edges may not cross, and its points, those the DDG tets
//! of the part hold.
use crate::locate::{Bins, Locator, WALK_STEPS};
use crate::Ddg;
use parafront_front::{RegionFilter, NO_PLACE};
use parafront_geom::intersect::{segment_triangle, SegTri};
use parafront_geom::{Aabb, P3};
use parafront_mesh::FaceRef;
use std::sync::atomic::AtomicU32;

/// The DDG faces between tets of different parts, with both parts: the
/// walls a part's edges may not cross (§7, the neighbour-to-neighbour
/// traversal, done here as exact segment-triangle tests).
#[derive(Clone, Debug)]
pub struct Interfaces {
    bins: Bins,
    /// The walls; their boxes are taken when asked, not kept (they were a
    /// third of the walls' memory).
    faces: Vec<[P3; 3]>,
    pub(crate) sides: Vec<[u32; 2]>,
    held: std::ops::Range<u32>,
}

impl Interfaces {
    /// The walls of partition `part` (DDG tet -> part) of `d` that have a
    /// part of `held` on a side: [`crosses`](Self::crosses) is asked only
    /// about those parts. An MPI rank keeps its own parts' walls, not every
    /// rank's (sphere_5e6 at 32 parts: 1.8 MB on each rank).
    pub fn new(d: &Ddg, part: &[u32], held: std::ops::Range<u32>) -> Interfaces {
        let mut faces = Vec::new();
        let mut sides = Vec::new();
        let neigh = d.neigh();
        for t in 0..d.tets.len() {
            for f in 0..4 {
                let n = neigh[4 * t + f];
                if n.is_none() {
                    continue; // the surface: the front itself stops there
                }
                let u = n.tet().idx();
                if u < t
                    || part[u] == part[t]
                    || !(held.contains(&part[t]) || held.contains(&part[u]))
                {
                    continue;
                }
                let tv = d.tets[t];
                let fv: Vec<P3> = (0..4)
                    .filter(|&i| i != f)
                    .map(|i| d.points[tv[i] as usize])
                    .collect();
                faces.push([fv[0], fv[1], fv[2]]);
                sides.push([part[t], part[u]]);
            }
        }
        let bx = |i: usize| Aabb::from_points(faces[i].iter());
        Interfaces {
            bins: Bins::new(faces.len(), bx, |_, _| (), |_, _| true, 1.0),
            faces,
            sides,
            held,
        }
    }

    /// Whether segment `a`-`b` meets a wall of part `k` (one of the parts
    /// held).
    pub fn crosses(&self, k: u32, a: P3, b: P3) -> bool {
        debug_assert!(self.held.contains(&k), "part {k}'s walls were not kept");
        let mut bb = Aabb { min: a, max: a };
        bb.grow(b);
        !self.bins.visit(&bb, |x| {
            let s = self.sides[x as usize];
            if s[0] != k && s[1] != k {
                return true;
            }
            let [p, q, r] = self.faces[x as usize];
            if !Aabb::from_points([p, q, r].iter()).overlaps(&bb) {
                return true;
            }
            matches!(segment_triangle(a, b, p, q, r), SegTri::Disjoint)
        })
    }
}

/// Region filter of part `k` in one pass (§7): a point must lie inside
/// the part's DDG tets and off its boundary (the conservative assignment),
/// an edge must not cross a wall of the part.
pub struct PartFilter<'a> {
    /// Locates points in the DDG.
    pub loc: &'a Locator<'a>,
    /// The walls between parts.
    pub walls: &'a Interfaces,
    /// The partition (DDG tet -> part).
    pub part: &'a [u32],
    /// The part.
    pub k: u32,
    /// The DDG tet of the last point located alone ([`Locator::owner_near`]).
    pub hint: AtomicU32,
    /// The DDG's face neighbours to walk ([`Ddg::neigh`]), or none where
    /// they were let go ([`Ddg::let_go_neigh`]).
    pub neigh: &'a [FaceRef],
}

impl<'a> PartFilter<'a> {
    /// The filter of part `k` of partition `part`, with its walls; it
    /// walks over `neigh` where it is not empty.
    pub fn new(
        loc: &'a Locator<'a>,
        walls: &'a Interfaces,
        part: &'a [u32],
        k: u32,
        neigh: &'a [FaceRef],
    ) -> Self {
        PartFilter {
            loc,
            walls,
            part,
            k,
            hint: AtomicU32::new(u32::MAX),
            neigh,
        }
    }
}

impl RegionFilter for PartFilter<'_> {
    fn point_ok(&self, p: P3) -> bool {
        self.loc.owner_near(p, self.part, &self.hint) == Some(self.k)
    }
    fn edge_ok(&self, a: P3, b: P3) -> bool {
        !self.walls.crosses(self.k, a, b)
    }
    /// The place is the DDG tet that holds `p` strictly: a walk from one
    /// of `near` (only `near` itself without the face neighbours), else
    /// the last tet found, else the bins.
    fn locate(&self, p: P3, near: &[u32]) -> (bool, u32) {
        for (i, &t) in near.iter().enumerate() {
            if near[..i].contains(&t) {
                continue;
            }
            if let Some(t) = self.loc.walk(self.neigh, t, p, WALK_STEPS) {
                return (self.part[t as usize] == self.k, t);
            }
        }
        let (own, strict) = self.loc.owner_placed(p, self.part, &self.hint);
        (own == Some(self.k), strict.unwrap_or(NO_PLACE))
    }
    /// Two ends strictly inside one DDG tet: the segment is inside it
    /// (convex), so it meets no wall.
    fn edge_ok_at(&self, a: P3, ta: u32, b: P3, tb: u32) -> bool {
        (ta == tb && ta != NO_PLACE) || self.edge_ok(a, b)
    }
}

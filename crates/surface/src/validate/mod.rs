//! Surface validation (paper AG2 assumes a watertight, consistently oriented,
//! non-self-intersecting triangulation): finds every class of defect, counts
//! it and keeps the first offenders with coordinates, then splits the surface
//! into closed shells and works out how they nest (outer shells, voids,
//! inner bodies).
//!
//! Everything topological works on flat sorted arrays; every geometric
//! decision (zero area, self-intersection, nesting) is exact.

mod bvh;
mod selfint;
mod shells;
mod topology;

pub use shells::{regions, shells, Region, Shell, ShellKind};

use crate::Surface;
use parafront_geom::P3;
use std::fmt;

/// How many offenders of each class a report keeps.
pub const MAX_EXAMPLES: usize = 10;

/// A class of surface defect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// The surface has no triangles at all (an empty file, or one cut
    /// short after its points).
    NoTriangles,
    /// A triangle names a vertex id past the end of the point list.
    BadIndex,
    /// A referenced point has a NaN or infinite coordinate.
    NonFinite,
    /// Edge used by one triangle only (the surface is not closed).
    OpenEdge,
    /// Edge used by more than two triangles.
    NonManifoldEdge,
    /// Vertex with more than one fan of triangles around it.
    PinchedVertex,
    /// Edge whose two triangles traverse it in the same direction.
    InconsistentEdge,
    /// Triangle with collinear (or repeated) vertices.
    ZeroArea,
    /// Triangle with the same vertex set as an earlier one.
    DuplicateTriangle,
    /// Pair of triangles meeting in more than their shared vertices or edge.
    SelfIntersection,
    /// Closed shell whose orientation contradicts its nesting depth (an
    /// outer shell or inner body with negative volume, a void with positive).
    WrongShellOrientation,
    /// Point no triangle uses (a warning only).
    UnreferencedVertex,
}

impl Class {
    /// False for classes that are only warnings.
    pub fn is_error(self) -> bool {
        self != Class::UnreferencedVertex
    }
    /// A plain-words description of the class, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Class::NoTriangles => "no triangles (the file has points only, or nothing)",
            Class::BadIndex => "triangles with a vertex id out of range",
            Class::NonFinite => "points with a NaN or infinite coordinate",
            Class::OpenEdge => "open (boundary) edges, used by one triangle",
            Class::NonManifoldEdge => "non-manifold edges, used by more than two triangles",
            Class::PinchedVertex => "pinched (non-manifold) vertices, with several triangle fans",
            Class::InconsistentEdge => {
                "inconsistently oriented edges, traversed twice in the same direction"
            }
            Class::ZeroArea => "zero-area triangles (collinear or repeated vertices)",
            Class::DuplicateTriangle => "duplicate triangles (same vertex set)",
            Class::SelfIntersection => "self-intersecting triangle pairs",
            Class::WrongShellOrientation => {
                "wrongly oriented shells (inside-out surface, or void/body with the wrong sign)"
            }
            Class::UnreferencedVertex => "unreferenced vertices (warning)",
        }
    }
}

/// One offender, with the coordinates a user needs to find it.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// An edge `v[0]-v[1]` and (up to 6 of) the triangles using it.
    Edge {
        /// The edge's vertex ids.
        v: [u32; 2],
        /// The two vertices' coordinates.
        p: [P3; 2],
        /// Triangles using the edge, up to 6.
        tris: Vec<u32>,
    },
    /// A vertex; `fans` is the number of triangle fans around it (0 when unused).
    Vertex {
        /// The vertex id.
        v: u32,
        /// Its coordinates.
        p: P3,
        /// Triangle fans around it.
        fans: u32,
    },
    /// A triangle.
    Tri {
        /// The triangle id.
        t: u32,
        /// Its vertex ids.
        v: [u32; 3],
        /// Its corners' coordinates.
        p: [P3; 3],
    },
    /// Two triangles: (earlier, later) for duplicates, the pair for
    /// intersections.
    TriPair {
        /// The two triangle ids.
        t: [u32; 2],
        /// Their vertex ids.
        v: [[u32; 3]; 2],
        /// Their corners' coordinates.
        p: [[P3; 3]; 2],
    },
    /// A shell, its first triangle and signed volume.
    Shell {
        /// The shell's index in [`Report::shells`].
        shell: u32,
        /// Its lowest triangle id.
        first_tri: u32,
        /// Its signed enclosed volume (positive when the normals point outward).
        volume: f64,
        /// The number of closed shells containing it.
        depth: u32,
    },
    /// A triangle whose vertex id is out of range.
    BadTri {
        /// The triangle id.
        t: u32,
        /// Its vertex ids, one at least out of range.
        v: [u32; 3],
    },
}

/// All defects of one class.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// The defect class.
    pub class: Class,
    /// How many offenders there are, all of them (not only the examples).
    pub count: usize,
    /// The first `MAX_EXAMPLES` offenders, in id order.
    pub examples: Vec<Item>,
}

/// The result of [`validate`].
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Points in the surface.
    pub n_points: usize,
    /// Triangles in the surface.
    pub n_tris: usize,
    /// Non-empty classes only, in `Class` order.
    pub problems: Vec<Problem>,
    /// Edge-connected components, ordered by their first triangle; nesting
    /// is worked out among the closed ones.
    pub shells: Vec<Shell>,
}

impl Report {
    /// No error classes (warnings allowed).
    pub fn is_valid(&self) -> bool {
        self.problems.iter().all(|p| !p.class.is_error())
    }
    /// The defects of `class`, if any were found.
    pub fn problem(&self, class: Class) -> Option<&Problem> {
        self.problems.iter().find(|p| p.class == class)
    }
    /// Number of offenders of a class (0 when absent).
    pub fn count(&self, class: Class) -> usize {
        self.problem(class).map_or(0, |p| p.count)
    }
    fn push(&mut self, class: Class, count: usize, examples: Vec<Item>) {
        if count > 0 {
            self.problems.push(Problem {
                class,
                count,
                examples,
            });
        }
    }
}

/// Checks the surface for every defect class and computes its shells.
/// Never panics; out-of-range ids or non-finite points stop the check after
/// they are reported, since nothing else is meaningful then.
pub fn validate(s: &Surface) -> Report {
    let mut r = Report {
        n_points: s.points.len(),
        n_tris: s.tris.len(),
        problems: Vec::new(),
        shells: Vec::new(),
    };
    let np = s.points.len();
    let Some(used) = fatal(s, &mut r) else {
        return r;
    };

    let edges = topology::Edges::build(s);
    let (open, nonman, incons) = edges.classify(s);
    let pinched = topology::pinched_vertices(s);
    let zero = topology::zero_area(s);
    let dups = topology::duplicates(s);

    // Each problem is reported once: the self-intersection test skips
    // zero-area triangles and the later copies of duplicates.
    let mut skip = vec![false; s.tris.len()];
    for &t in &zero {
        skip[t as usize] = true;
    }
    for &(_, t) in &dups {
        skip[t as usize] = true;
    }
    let (n_pairs, pairs) = selfint::self_intersections(s, &skip, MAX_EXAMPLES);

    r.shells = shells::shells_with(s, &edges);

    let tri_item = |t: u32| tri_item(s, t);
    let pair_item = |a: u32, b: u32| pair_item(s, a, b);

    r.push(Class::OpenEdge, open.len(), edges.items(s, &open));
    r.push(
        Class::NonManifoldEdge,
        nonman.len(),
        edges.items(s, &nonman),
    );
    let pv: Vec<u32> = pinched.iter().map(|&(v, _)| v).collect();
    r.push(
        Class::PinchedVertex,
        pinched.len(),
        vertex_items(s, &pv, |i| pinched[i].1),
    );
    r.push(
        Class::InconsistentEdge,
        incons.len(),
        edges.items(s, &incons),
    );
    r.push(
        Class::ZeroArea,
        zero.len(),
        zero.iter()
            .take(MAX_EXAMPLES)
            .map(|&t| tri_item(t))
            .collect(),
    );
    r.push(
        Class::DuplicateTriangle,
        dups.len(),
        dups.iter()
            .take(MAX_EXAMPLES)
            .map(|&(a, b)| pair_item(a, b))
            .collect(),
    );
    r.push(
        Class::SelfIntersection,
        n_pairs,
        pairs.iter().map(|&(a, b)| pair_item(a, b)).collect(),
    );
    let wrong = wrong_shells(&r.shells);
    let nw = wrong.len();
    r.push(
        Class::WrongShellOrientation,
        nw,
        wrong.into_iter().take(MAX_EXAMPLES).collect(),
    );
    let unused: Vec<u32> = (0..np as u32).filter(|&v| !used[v as usize]).collect();
    r.push(
        Class::UnreferencedVertex,
        unused.len(),
        vertex_items(s, &unused, |_| 0),
    );
    r
}

/// The defects that make every other check meaningless: no triangles,
/// out-of-range ids, non-finite points (reported to `r`). `None` when one
/// is found, else which points the triangles use.
fn fatal(s: &Surface, r: &mut Report) -> Option<Vec<bool>> {
    let np = s.points.len();
    if s.tris.is_empty() {
        r.push(Class::NoTriangles, 1, Vec::new());
        return None;
    }
    let bad: Vec<u32> = (0..s.tris.len() as u32)
        .filter(|&t| s.tris[t as usize].iter().any(|&v| v as usize >= np))
        .collect();
    if !bad.is_empty() {
        let ex = bad
            .iter()
            .take(MAX_EXAMPLES)
            .map(|&t| Item::BadTri {
                t,
                v: s.tris[t as usize],
            })
            .collect();
        r.push(Class::BadIndex, bad.len(), ex);
        return None;
    }
    let used = topology::referenced(s);
    let nonfinite: Vec<u32> = (0..np as u32)
        .filter(|&v| used[v as usize] && s.points[v as usize].iter().any(|x| !x.is_finite()))
        .collect();
    if !nonfinite.is_empty() {
        let ex = vertex_items(s, &nonfinite, |_| 0);
        r.push(Class::NonFinite, nonfinite.len(), ex);
        return None;
    }
    Some(used)
}

/// Triangle `t` as a report item.
fn tri_item(s: &Surface, t: u32) -> Item {
    let v = s.tris[t as usize];
    Item::Tri {
        t,
        v,
        p: v.map(|i| s.points[i as usize]),
    }
}

/// Triangles `a` and `b` as a report item.
fn pair_item(s: &Surface, a: u32, b: u32) -> Item {
    let (va, vb) = (s.tris[a as usize], s.tris[b as usize]);
    Item::TriPair {
        t: [a, b],
        v: [va, vb],
        p: [
            va.map(|i| s.points[i as usize]),
            vb.map(|i| s.points[i as usize]),
        ],
    }
}

/// The shells turned the wrong way for their depth, as report items.
fn wrong_shells(shells: &[Shell]) -> Vec<Item> {
    shells
        .iter()
        .enumerate()
        .filter(|(_, sh)| !sh.orientation_ok())
        .map(|(i, sh)| Item::Shell {
            shell: i as u32,
            first_tri: sh.tris[0],
            volume: sh.volume,
            depth: sh.depth,
        })
        .collect()
}

fn vertex_items(s: &Surface, vs: &[u32], fans: impl Fn(usize) -> u32) -> Vec<Item> {
    vs.iter()
        .take(MAX_EXAMPLES)
        .enumerate()
        .map(|(i, &v)| Item::Vertex {
            v,
            p: s.points[v as usize],
            fans: fans(i),
        })
        .collect()
}

struct Pt(P3);
impl fmt::Display for Pt {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "({}, {}, {})", self.0[0], self.0[1], self.0[2])
    }
}

struct TriPts<'a>(&'a [P3; 3]);
impl fmt::Display for TriPts<'_> {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{} {} {}", Pt(self.0[0]), Pt(self.0[1]), Pt(self.0[2]))
    }
}

impl fmt::Display for Item {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Item::Edge { v, p, tris } => write!(
                f,
                "edge {}-{} {} {}, triangles {:?}",
                v[0],
                v[1],
                Pt(p[0]),
                Pt(p[1]),
                tris
            ),
            Item::Vertex { v, p, fans } if *fans > 0 => {
                write!(f, "vertex {} {}, {} fans", v, Pt(*p), fans)
            }
            Item::Vertex { v, p, .. } => write!(f, "vertex {} {}", v, Pt(*p)),
            Item::Tri { t, v, p } => write!(f, "triangle {} {:?}: {}", t, v, TriPts(p)),
            Item::TriPair { t, v, p } => write!(
                f,
                "triangles {} {:?} and {} {:?}: {} | {}",
                t[0],
                v[0],
                t[1],
                v[1],
                TriPts(&p[0]),
                TriPts(&p[1])
            ),
            Item::Shell {
                shell,
                first_tri,
                volume,
                depth,
            } => write!(
                f,
                "shell {} (first triangle {}): depth {}, signed volume {}",
                shell, first_tri, depth, volume
            ),
            Item::BadTri { t, v } => write!(f, "triangle {} {:?}", t, v),
        }
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        writeln!(
            f,
            "surface: {} points, {} triangles",
            self.n_points, self.n_tris
        )?;
        let errors = self.problems.iter().filter(|p| p.class.is_error()).count();
        if errors == 0 {
            writeln!(f, "valid")?;
        } else {
            writeln!(f, "INVALID: {} problem classes", errors)?;
        }
        for p in &self.problems {
            if p.class == Class::NoTriangles {
                writeln!(
                    f,
                    "  no triangles: the file has {} points and no triangles, so nothing to mesh",
                    self.n_points
                )?;
                continue;
            }
            writeln!(f, "  {}: {}", p.class.describe(), p.count)?;
            for e in &p.examples {
                writeln!(f, "    {}", e)?;
            }
            if p.count > p.examples.len() {
                writeln!(f, "    ... and {} more", p.count - p.examples.len())?;
            }
        }
        writeln!(f, "shells: {}", self.shells.len())?;
        for (i, sh) in self.shells.iter().enumerate() {
            write!(
                f,
                "  shell {}: {} triangles, signed volume {}",
                i,
                sh.tris.len(),
                sh.volume
            )?;
            if sh.kind == ShellKind::NotClosed {
                writeln!(f, ", not closed (nesting not computed)")?;
                continue;
            }
            write!(f, ", depth {}", sh.depth)?;
            if let Some(p) = sh.parent {
                write!(f, " (inside shell {})", p)?;
            }
            write!(f, ", {}", sh.kind.describe())?;
            if !sh.orientation_ok() {
                write!(f, " -- WRONG ORIENTATION")?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

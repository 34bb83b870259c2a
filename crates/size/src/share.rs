//! The size field's octree shared out: its build's second phase makes
//! independent subtrees, and an [`OctreeShare`] says which ones this
//! process builds and brings every process all of them (the MPI ranks
//! each build a share; one process builds them all, [`Alone`]).

/// One subtree of the octree, built on its own: its root is a cell of the
/// build's frontier; an internal node holds the index of its first child in
/// `nodes` (children come in blocks of eight), a leaf its `near` or `far`
/// entry. Its flat parts go between processes as [`SubtreeParts`].
#[derive(Clone, Debug, Default)]
pub struct Subtree {
    pub(crate) nodes: Vec<u32>,
    pub(crate) near: Vec<(u32, u32)>,
    pub(crate) cand: Vec<u32>,
    pub(crate) far: Vec<[f64; 8]>,
    pub(crate) depth: u32,
}

/// A [`Subtree`]'s arrays: `(depth, nodes, (near, cand), far)`.
pub type SubtreeParts = (u32, Vec<u32>, (Vec<(u32, u32)>, Vec<u32>), Vec<[f64; 8]>);

impl Subtree {
    /// Its arrays, to send.
    pub fn into_parts(self) -> SubtreeParts {
        (self.depth, self.nodes, (self.near, self.cand), self.far)
    }

    /// From the arrays [`into_parts`](Self::into_parts) gave.
    pub fn from_parts((depth, nodes, (near, cand), far): SubtreeParts) -> Subtree {
        Subtree {
            nodes,
            near,
            cand,
            far,
            depth,
        }
    }
}

/// Who builds which of the octree's subtrees, and how they reach every
/// process: the build is the same on one process or many (the same cells
/// split, the same values), only shared out. [`Alone`] builds them all.
pub trait OctreeShare: Sync {
    /// Whether this process builds subtree `i` of `n`.
    fn builds(&self, i: usize, n: usize) -> bool;
    /// Every process's built subtrees, `(i, subtree)` from this one: all
    /// `n` of them, by index, on every process.
    fn gather(&self, mine: Vec<(u32, Subtree)>, n: usize) -> Vec<Subtree>;
}

/// One process builds every subtree.
pub struct Alone;

impl OctreeShare for Alone {
    fn builds(&self, _i: usize, _n: usize) -> bool {
        true
    }

    fn gather(&self, mut mine: Vec<(u32, Subtree)>, n: usize) -> Vec<Subtree> {
        assert_eq!(mine.len(), n, "one process builds every subtree");
        mine.sort_unstable_by_key(|x| x.0);
        mine.into_iter().map(|x| x.1).collect()
    }
}

//! A bounding-volume hierarchy over boxes (median split on the longest
//! axis of the box centres), for triangle pairs and shell nesting.
use parafront_geom::Aabb;

const LEAF: usize = 4;

struct Node {
    bb: Aabb,
    /// Leaf: `order[a..b]`; inner node: children `a` and `b`.
    a: u32,
    b: u32,
    leaf: bool,
}

pub(super) struct Bvh {
    nodes: Vec<Node>,
    pub order: Vec<u32>,
}

impl Bvh {
    /// Over the items `ids`, whose boxes are `boxes[id]`.
    pub fn build(ids: Vec<u32>, boxes: &[Aabb]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * ids.len() / LEAF + 1),
            order: ids,
        };
        if !bvh.order.is_empty() {
            let mut order = std::mem::take(&mut bvh.order);
            bvh.build_rec(&mut order, 0, boxes);
            bvh.order = order;
        }
        bvh
    }

    fn build_rec(&mut self, items: &mut [u32], offset: usize, boxes: &[Aabb]) -> u32 {
        let mut bb = Aabb::EMPTY;
        let mut cb = Aabb::EMPTY;
        for &i in items.iter() {
            bb = bb.union(&boxes[i as usize]);
            cb.grow(boxes[i as usize].center());
        }
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            bb,
            a: offset as u32,
            b: (offset + items.len()) as u32,
            leaf: true,
        });
        if items.len() <= LEAF {
            return id;
        }
        let ext = [0, 1, 2].map(|k| cb.max[k] - cb.min[k]);
        let axis = (0..3).fold(0, |m, k| if ext[k] > ext[m] { k } else { m });
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |&x, &y| {
            let cx = boxes[x as usize].min[axis] + boxes[x as usize].max[axis];
            let cy = boxes[y as usize].min[axis] + boxes[y as usize].max[axis];
            cx.total_cmp(&cy)
        });
        let (lo, hi) = items.split_at_mut(mid);
        let l = self.build_rec(lo, offset, boxes);
        let r = self.build_rec(hi, offset + mid, boxes);
        let n = &mut self.nodes[id as usize];
        n.a = l;
        n.b = r;
        n.leaf = false;
        id
    }

    /// Calls `f` for every item whose box overlaps `q`.
    pub fn query(&self, q: &Aabb, boxes: &[Aabb], stack: &mut Vec<u32>, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        stack.clear();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.bb.overlaps(q) {
                continue;
            }
            if node.leaf {
                for &i in &self.order[node.a as usize..node.b as usize] {
                    if boxes[i as usize].overlaps(q) {
                        f(i);
                    }
                }
            } else {
                stack.push(node.a);
                stack.push(node.b);
            }
        }
    }
}

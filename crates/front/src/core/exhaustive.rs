//! Step 5.3's exhaustive search: a small pocket closed with tets on its
//! own corners, depth first, undone if it does not close.
use super::cavity::INPUT_BOUND_FLOOR;
use super::*;
use crate::quality::mean_ratio;

impl<'a> Front<'a> {
    /// Close a small pocket with tets on its own corners (step 5.3's
    /// exhaustive search): the space between close input faces may need no
    /// new point, only tets flatter than the front accepts. Depth first:
    /// the face with the fewest possible apexes goes first, its apexes best
    /// first, and a face with none left undoes the tet before it. At most
    /// `budget` apex checks; undone if it does not close.
    pub(super) fn close_by_existing(&mut self, pocket: &[u32], budget: usize) -> bool {
        struct Level {
            face: [u32; 3],
            cands: Vec<u32>,
            next: usize,
            tet: u32,
        }
        let mut corners: Vec<u32> = pocket.iter().flat_map(|&f| self.fv[f as usize].v).collect();
        corners.sort_unstable();
        corners.dedup();
        let mut faces: Vec<u32> = pocket.to_vec();
        let mut stack: Vec<Level> = Vec::new();
        let mut left = budget;
        let mut descend = true;
        loop {
            if descend {
                if faces.is_empty() {
                    self.stats.pockets_filled += 1;
                    return true;
                }
                // The most constrained face: fewest corners it could reach.
                let mut pick: Option<(usize, [u32; 3], u32)> = None;
                for &f in &faces {
                    let v = self.fv[f as usize].v;
                    let [a, b, c] = v.map(|i| self.pts[i as usize]);
                    let n = corners
                        .iter()
                        .filter(|&&q| {
                            !v.contains(&q)
                                && mean_ratio(a, b, c, self.pts[q as usize]) >= INPUT_BOUND_FLOOR
                        })
                        .count();
                    let key = sorted3(v);
                    if pick.is_none_or(|(m, k, _)| n < m || (n == m && key < k)) {
                        pick = Some((n, key, f));
                    }
                }
                let (_, _, f) = pick.expect("faces is not empty");
                let v = self.fv[f as usize].v;
                let [a, b, c] = v.map(|i| self.pts[i as usize]);
                let mut cands: Vec<(f64, u32)> = corners
                    .iter()
                    .filter(|&&q| !v.contains(&q))
                    .map(|&q| (mean_ratio(a, b, c, self.pts[q as usize]), q))
                    .filter(|x| x.0 >= INPUT_BOUND_FLOOR)
                    .collect();
                cands.sort_unstable_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
                stack.push(Level {
                    face: v,
                    cands: cands.into_iter().map(|x| x.1).collect(),
                    next: 0,
                    tet: NONE,
                });
            }
            // Try the next apex of the top face.
            let Some(top) = stack.last_mut() else {
                return false;
            };
            let fid = self
                .face_id(top.face)
                .expect("a pocket face is in the front");
            let mut placed = false;
            while top.next < top.cands.len() && left > 0 {
                let q = top.cands[top.next];
                top.next += 1;
                left -= 1;
                let p = self.pts[q as usize];
                if self.apex_free(fid, q, p, Clearance::EXACT) {
                    let before = self.fv.len() as u32;
                    top.tet = self.tets.len() as u32;
                    self.commit(fid, q, p, None);
                    self.refresh(&mut faces, before);
                    placed = true;
                    break;
                }
            }
            if placed {
                descend = true;
                continue;
            }
            // No apex left here (or no budget): back up one level.
            stack.pop();
            descend = false;
            let undo = stack
                .last_mut()
                .map(|l| std::mem::replace(&mut l.tet, NONE));
            if left == 0 {
                // Give up: undo every tet made, newest first.
                let mut made: Vec<u32> =
                    stack.iter().map(|l| l.tet).filter(|&t| t != NONE).collect();
                made.extend(undo.filter(|&t| t != NONE));
                made.sort_unstable();
                for &t in &made {
                    self.talive[t as usize] = false;
                }
                for &t in made.iter().rev() {
                    self.unlink_tet(t);
                }
                return false;
            }
            match undo {
                Some(t) if t != NONE => {
                    let before = self.fv.len() as u32;
                    self.talive[t as usize] = false;
                    self.unlink_tet(t);
                    self.refresh(&mut faces, before);
                }
                _ => return false,
            }
        }
    }
}

//! The front's bookkeeping (AF3-AF4): faces join and leave the front, a
//! committed tet closes the front faces it matches and opens the others,
//! and a removed tet gives its faces back.
use super::*;

impl<'a> Front<'a> {
    pub(super) fn add_face(&mut self, v: [u32; 3], owner: u32) {
        let id = self.fv.len() as u32;
        self.fv.push(Face {
            v,
            owner,
            tries: 0,
            alive: true,
        });
        if let Some(m) = &mut self.fmap {
            m.insert(sorted3(v), id);
        }
        self.n_front += 1;
        self.fgrid.insert(id, v, &tri_box(&self.pts, v));
        let key = self.face_key(v);
        self.heap.push(heap_entry(key, id));
    }

    pub(super) fn remove_face(&mut self, id: u32) {
        let i = id as usize;
        let v = self.fv[i].v;
        self.fv.kill(i);
        if let Some(m) = &mut self.fmap {
            m.remove(&sorted3(v));
        }
        self.n_front -= 1;
        self.fgrid.remove(id, &tri_box(&self.pts, v));
    }

    /// Remove live tets `ts` (recovery, a fill's growth or takeover): all
    /// are marked dead before any is unlinked, so that the faces between
    /// two of them do not join the front.
    pub(super) fn remove_tets(&mut self, ts: &[u32]) {
        for &t in ts {
            self.talive[t as usize] = false;
        }
        for &t in ts {
            self.unlink_tet(t);
        }
        self.stats.tets_removed += ts.len();
    }

    /// Take dead tet `t` out: its faces towards live tets or the input
    /// surface join the front, its front faces leave it.
    pub(super) fn unlink_tet(&mut self, t: u32) {
        let tv = self.tets[t as usize];
        for i in 0..4 {
            let fr = 4 * t + i as u32;
            let w = TET_FACES[i].map(|k| tv[k]);
            let nb = self.neigh[fr as usize];
            if nb != NONE {
                // A dead neighbour leaves nothing behind: the hole spans both.
                let u = nb >> 2;
                if self.talive[u as usize] {
                    self.neigh[nb as usize] = NONE;
                    let uv = self.tets[u as usize];
                    let fw = TET_FACES[(nb & 3) as usize].map(|k| uv[k]);
                    self.add_face(fw, nb);
                }
                continue;
            }
            match self.face_id(w) {
                Some(g) if self.fv[g as usize].owner == fr => self.remove_face(g),
                found => {
                    // An input face: it faces the hole again.
                    debug_assert!(found.is_none(), "face {w:?} twice in the front");
                    self.add_face([w[0], w[2], w[1]], NONE);
                }
            }
        }
    }

    /// The live face with corners `w` (any order), from the map, built
    /// on the first call.
    pub(super) fn face_id(&mut self, w: [u32; 3]) -> Option<u32> {
        let fv = &self.fv;
        let m = self.fmap.get_or_insert_with(|| {
            (0..fv.len() as u32)
                .filter(|&f| fv[f as usize].alive)
                .map(|f| (sorted3(fv[f as usize].v), f))
                .collect()
        });
        m.get(&sorted3(w)).copied()
    }

    /// AF3-AF5: add the tet, its new point, and update the front.
    /// `matched`, when given, is `tet_is_free`'s match of each new face
    /// among AF2's near faces, which hold every live face within the tet's
    /// box; without it, or once recovery has built the map, the map is
    /// asked.
    pub(super) fn commit(&mut self, fid: u32, q: u32, pq: P3, matched: Option<[u32; 3]>) {
        let v = self.fv[fid as usize].v;
        let q = if policy::is_new_point(q) {
            let id = self.pts.len() as u32;
            let h = self.new_point_size(v, pq);
            self.pts.push(pq);
            self.hp.push(h);
            self.stats.new_points += 1;
            // The region filter located it as a candidate: inside.
            if let Some(&(_, at)) = self.new_at.iter().find(|x| x.0 == pq) {
                self.grow_point_cache(id as usize + 1);
                self.point_in[id as usize] = 1;
                self.point_at[id as usize] = at;
            }
            id
        } else {
            q
        };
        let t = self.tets.len() as u32;
        let tv = [v[0], v[1], v[2], q];
        self.tets.push(tv);
        self.talive.push(true);
        self.neigh.extend_from_slice(&[NONE; 4]);
        self.stats.tets += 1;
        let owner = self.fv[fid as usize].owner;
        self.neigh[4 * t as usize + 3] = owner;
        if owner != NONE {
            self.neigh[owner as usize] = 4 * t + 3;
        }
        self.remove_face(fid);
        for i in 0..3 {
            let w = TET_FACES[i].map(|k| tv[k]);
            let fr = 4 * t + i as u32;
            let found = match matched {
                Some(m) if self.fmap.is_none() => (m[i] != NONE).then_some(m[i]),
                _ => self.face_id(w),
            };
            self.close_or_open(w, fr, found);
        }
        if self.opts.progress_every > 0 && self.stats.tets.is_multiple_of(self.opts.progress_every)
        {
            if let Some(p) = &self.opts.progress {
                p.set(
                    self.stats.tets as u64,
                    self.n_front as u64,
                    self.relax as u64,
                );
            }
        }
    }

    /// AF5 for a new tet's face `w` (`fr` = `4t+f`): a matching front face
    /// `found` leaves the front, the two tets linked; else `w` joins it.
    #[inline]
    pub(super) fn close_or_open(&mut self, w: [u32; 3], fr: u32, found: Option<u32>) {
        if let Some(g) = found {
            let o = self.fv[g as usize].owner;
            self.neigh[fr as usize] = o;
            if o != NONE {
                self.neigh[o as usize] = fr;
            }
            self.remove_face(g);
        } else {
            self.add_face(w, fr);
        }
    }

    /// The faces among `faces` on each edge (sorted corners).
    pub(super) fn faces_by_edge(&self, faces: &[u32]) -> FxHashMap<(u32, u32), Vec<u32>> {
        let mut by_edge: FxHashMap<(u32, u32), Vec<u32>> = FxHashMap::default();
        for &f in faces {
            let v = self.fv[f as usize].v;
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                by_edge.entry((a.min(b), a.max(b))).or_default().push(f);
            }
        }
        by_edge
    }
}

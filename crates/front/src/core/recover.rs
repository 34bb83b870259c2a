//! Recovery (AF5 when the front stalls): the tets around the stuck faces
//! are removed, one growing layer per round, and the hole is re-meshed
//! with relaxed acceptance.
use super::*;

impl<'a> Front<'a> {
    /// Recovery: remove the tets around the stuck faces, one growing layer
    /// per round, then re-mesh the hole with relaxed acceptance.
    pub(super) fn recover(&mut self) {
        tracing::debug!(
            round = self.relax,
            stuck = self.stuck.len(),
            tets = self.stats.tets,
            "front stuck: recovery"
        );
        self.relax += 1;
        self.stats.recovery_rounds = self.relax;
        if self.relax >= 2 {
            // Step 5.3 before more removal: cone the pockets that allow it.
            let (progress, _) = self.fill_pockets();
            // Growth may have replaced stuck faces by new ones.
            let mut held = vec![false; self.fv.len()];
            for &f in &self.prohibited {
                held[f as usize] = true;
            }
            self.stuck = (0..self.fv.len() as u32)
                .filter(|&f| self.fv[f as usize].alive && !held[f as usize])
                .collect();
            if self.stuck.is_empty() {
                return;
            }
            if progress > 0 {
                // Partial cones made new faces: the front goes on from them.
                self.requeue_front();
                return;
            }
        }
        // Later rounds take less: only tets on an edge of the stuck faces'
        // points, so that one stubborn pocket does not undo the rest.
        let need = if self.relax >= 2 {
            LATE_REMOVAL_POINTS
        } else {
            1
        };
        let mut mark = vec![false; self.pts.len()];
        for &f in &self.stuck {
            for &p in &self.fv[f as usize].v {
                mark[p as usize] = true;
            }
        }
        let removed: Vec<u32> = (0..self.tets.len() as u32)
            .filter(|&t| {
                let tv = self.tets[t as usize];
                self.talive[t as usize] && tv.iter().filter(|&&p| mark[p as usize]).count() >= need
            })
            .collect();
        self.remove_tets(&removed);
        self.requeue_front();
    }

    /// Every face of the front gets another go, relaxed.
    pub(super) fn requeue_front(&mut self) {
        self.stuck.clear();
        // Every live face is queued again, once (faces the removal just
        // added are queued already); held ones are held again.
        self.heap.clear();
        self.prohibited.clear();
        for id in 0..self.fv.len() {
            if self.fv[id].alive {
                self.fv[id].tries = 0;
                let key = self.face_key(self.fv[id].v);
                self.heap.push(heap_entry(key, id as u32));
            }
        }
    }
}

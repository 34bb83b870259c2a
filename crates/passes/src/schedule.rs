//! The parallel passes of §7 (step 3) as a schedule of named steps: pass 1
//! on the balanced partition, passes 2 and 3 on its two shifts, then,
//! while the front left would make pass 4 large, crossing passes on the
//! partition by the other method and its shifts. What they take and make
//! goes into a [`Recorder`].
use super::*;
use std::fmt;

/// Crossing passes after pass 3: one on a partition by the other method,
/// then one on each of its shifts.
const MAX_CROSSING: usize = 3;
/// A crossing pass runs while the front left has more faces than this
/// share of the tets made (pass 4 makes about a tet per face left).
const CROSSING_FROM: f64 = 0.0025;

/// One parallel pass of the schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Step {
    /// Pass 1 on the balanced partition (the paper's DDG0).
    Pass1,
    /// Pass 2: the parts renamed by what pass 1 left, the partition
    /// shifted to take layers from higher neighbours.
    Pass2,
    /// Pass 3: the same names, layers taken from lower neighbours.
    Pass3,
    /// Crossing pass `k` (1 to [`MAX_CROSSING`]), counted as pass 3: what
    /// passes 2 and 3 leave sits where the walls of both shifts meet,
    /// inside the crossing parts (P >= 32 on 1M tets).
    Crossing(u8),
}

/// The passes in order; the crossing ones stop as soon as the front left
/// is small ([`Passes::crossing_wanted`]).
pub(crate) const SCHEDULE: [Step; 3 + MAX_CROSSING] = [
    Step::Pass1,
    Step::Pass2,
    Step::Pass3,
    Step::Crossing(1),
    Step::Crossing(2),
    Step::Crossing(3),
];

impl Step {
    /// The pass it counts as, 1 to 3.
    pub(crate) fn pass(self) -> u8 {
        match self {
            Step::Pass1 => 1,
            Step::Pass2 => 2,
            Step::Pass3 | Step::Crossing(_) => 3,
        }
    }

    /// Crossing passes run with this one (0 before them).
    pub(crate) fn crossing(self) -> usize {
        match self {
            Step::Crossing(k) => k as usize,
            _ => 0,
        }
    }

    /// Whether its partition is one of a pair of shifts made just before
    /// it (the other one runs next).
    fn shifts(self) -> bool {
        matches!(self, Step::Pass2 | Step::Crossing(2))
    }
}

impl fmt::Display for Step {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Step::Crossing(k) => write!(f, "3 (crossing {k})"),
            s => write!(f, "{}", s.pass()),
        }
    }
}

/// The DDG partitions the passes run on (DDG tet -> part).
#[derive(Default)]
pub(crate) struct Partitions {
    /// The balanced split (§6), renamed before pass 2 so that its shifts
    /// share out what pass 1 left (`order_for_shift`); redistribution
    /// uses it as renamed.
    pub(crate) base: Vec<u32>,
    /// Its shifts for passes 2 and 3, each made for its pass.
    up: Vec<u32>,
    down: Vec<u32>,
    /// The crossing partition, then its two shifts (the first emptied
    /// once the second is made).
    crossing: Vec<Vec<u32>>,
}

impl Partitions {
    /// From the balanced split; the passes make the others.
    pub(crate) fn new(base: Vec<u32>) -> Partitions {
        Partitions {
            base,
            ..Default::default()
        }
    }

    fn of(&self, step: Step) -> &[u32] {
        match step {
            Step::Pass1 => &self.base,
            Step::Pass2 => &self.up,
            Step::Pass3 => &self.down,
            Step::Crossing(k) => &self.crossing[k as usize - 1],
        }
    }
}

/// What the passes of one region read: the DDG and its locator, the fine
/// size field, the options and the parts' messages.
pub(crate) struct Passes<'a, C: Comm> {
    pub(crate) d: &'a Ddg,
    pub(crate) loc: &'a Locator<'a>,
    pub(crate) size: &'a (dyn Fn(P3) -> f64 + Sync),
    pub(crate) opts: &'a ParOptions,
    pub(crate) comm: &'a C,
}

impl<C: Comm> Passes<'_, C> {
    /// Runs [`SCHEDULE`] on `parts`, from the balanced partition in `on`.
    pub(crate) fn run(
        &self,
        parts: &mut [Part],
        on: &mut Partitions,
        next_gid: &mut u32,
        rec: &mut Recorder,
    ) -> Result<(), PassError> {
        for step in SCHEDULE {
            if step.crossing() > 0 && !self.crossing_wanted(parts, &rec.st) {
                break;
            }
            if step == Step::Crossing(1) {
                let t = Instant::now();
                let method = match self.opts.partition {
                    Partition::Rcb => Partition::Metis,
                    Partition::Metis => Partition::Rcb,
                };
                let np = self.comm.parts();
                let w = ddg::tet_weights(self.d, self.size);
                on.crossing = vec![ddg::partition(self.d, &w, self.size, np, method)];
                rec.st.partition_seconds += t.elapsed().as_secs_f64();
            }
            if step.shifts() {
                self.shift(step, parts, on, rec);
            }
            if matches!(step, Step::Pass3 | Step::Crossing(3)) {
                self.shift_down(step, on, rec);
            }
            self.pass(step, parts, on.of(step), next_gid, rec)?;
            crate::debug_check_parts(parts, format_args!("pass {step}"));
        }
        Ok(())
    }

    /// Whether the front left would make pass 4 large.
    fn crossing_wanted(&self, parts: &[Part], st: &ParStats) -> bool {
        let left = self
            .comm
            .all_reduce(parts.iter().map(|p| p.front.len()).collect(), |a, b| a + b);
        let made: usize = st.pass_tets.iter().sum();
        (left as f64) >= CROSSING_FROM * made as f64
    }

    /// Renames the parts of the partition before `step` (the balanced one,
    /// or the crossing one) so that the next shift shares out what the
    /// pass on it left, then shifts it to take layers from higher
    /// neighbours (§7 pass 2; [`shift_down`](Self::shift_down) makes pass
    /// 3's).
    fn shift(&self, step: Step, parts: &[Part], on: &mut Partitions, rec: &mut Recorder) {
        let (d, layers, np) = (self.d, self.opts.layers, self.comm.parts());
        let t = Instant::now();
        let left = front_left_per_tet(parts, self.comm, self.loc, d.tets.len());
        let base = if step == Step::Pass2 {
            &mut on.base
        } else {
            &mut on.crossing[0]
        };
        let label = ddg::order_for_shift(d, base, &left, layers, np);
        for k in base.iter_mut() {
            *k = label[*k as usize];
        }
        let up = ddg::shifted(d, base, Shift::FromHigher, layers);
        if tracing::enabled!(tracing::Level::DEBUG) {
            let loads = ddg::shift_loads(d, base, &left, layers, np);
            tracing::debug!(
                "relabelled for pass {step}: {:.3} s, front left per part {loads:?}",
                t.elapsed().as_secs_f64()
            );
        }
        if step == Step::Pass2 {
            rec.renamed(&label);
            on.up = up;
        } else {
            on.crossing.push(up);
        }
        rec.st.partition_seconds += t.elapsed().as_secs_f64();
    }

    /// The second shift, for the pass after the first one's (the partition
    /// it shifts is as [`shift`](Self::shift) left it), in place of the
    /// first: a rank held three partitions of the DDG through pass 2
    /// (0.8 MB each on sphere_5e6 at 32 parts).
    fn shift_down(&self, step: Step, on: &mut Partitions, rec: &mut Recorder) {
        let t = Instant::now();
        let (d, layers) = (self.d, self.opts.layers);
        if step == Step::Pass3 {
            on.up = Vec::new();
            on.down = ddg::shifted(d, &on.base, Shift::FromLower, layers);
        } else {
            on.crossing[1] = Vec::new();
            let down = ddg::shifted(d, &on.crossing[0], Shift::FromLower, layers);
            on.crossing.push(down);
        }
        rec.st.partition_seconds += t.elapsed().as_secs_f64();
    }

    /// One pass on `part_of`, then room for the next one around what it
    /// left stuck.
    fn pass(
        &self,
        step: Step,
        parts: &mut [Part],
        part_of: &[u32],
        next_gid: &mut u32,
        rec: &mut Recorder,
    ) -> Result<(), PassError> {
        // Partition work before it counts in `partition_seconds`, not here.
        let t0 = Instant::now();
        let walls = Interfaces::new(self.d, part_of, {
            let r = self.comm.owned();
            r.start as u32..r.end as u32
        });
        let cells = crate::reach::PartCells::new(self.d, part_of, self.comm.parts());
        // A process that holds only some of the parts (an MPI rank) lets
        // the DDG's face neighbours go while its fronts run, which set its
        // peak (3.3 MB of sphere_5e6's 77 MiB at 32 parts on 4 ranks); the
        // next partition rebuilds them. One that holds them all walks them
        // (without, its passes took 7 % longer on sphere_1e6).
        let held = if let_go_neigh(self.comm) {
            self.d.let_go_neigh();
            crate::release(self.opts.release);
            None
        } else {
            Some(self.d.neigh())
        };
        let regions = DdgRegions {
            d: self.d,
            loc: self.loc,
            walls,
            part_of,
            cells,
            neigh: held.as_deref().unwrap_or(&[]),
        };
        let size = Sizes::fine(self.size);
        let (tets, secs) = parallel_pass(
            parts,
            self.comm,
            &regions,
            size,
            (step.pass(), self.opts.release),
            next_gid,
        )?;
        if tracing::enabled!(tracing::Level::DEBUG) {
            let fr: usize = parts.iter().map(|p| p.front.len()).sum();
            let stuck: usize = parts.iter().map(|p| p.stuck.len() / 3).sum();
            tracing::debug!("pass {step} tets {tets:?} front left {fr}, {stuck} stuck");
        }
        let peeled = peel_stuck(parts, self.comm);
        if tracing::enabled!(tracing::Level::DEBUG) {
            tracing::debug!("after pass {step}: {peeled} tets peeled around stuck faces");
        }
        rec.pass(step, &tets, secs, peeled, t0.elapsed().as_secs_f64());
        // The pass's filter and the peel's messages are freed: returned
        // before the next pass builds its own (an MPI rank started pass 2
        // 3 MB higher on sphere_5e6).
        drop(regions);
        crate::release(self.opts.release);
        Ok(())
    }
}

/// The statistics of one region's passes as they run: [`ParStats`], the
/// tets each part made in passes 1 to 3, and the process CPU clock at the
/// DDG's start and end.
pub(crate) struct Recorder {
    pub(crate) st: ParStats,
    made: Vec<usize>,
    cpu: [Option<f64>; 2],
}

impl Recorder {
    /// For `np` parts; reads the CPU clock at the DDG's start.
    pub(crate) fn new(np: usize) -> Recorder {
        Recorder {
            st: ParStats {
                parts: np,
                ..Default::default()
            },
            made: vec![0; np],
            cpu: [process_cpu_seconds(), None],
        }
    }

    /// The DDG `d`, built in `seconds` (by passes: `build`).
    pub(crate) fn ddg(&mut self, d: &Ddg, build: Option<DdgBuildStats>, seconds: f64) {
        let st = &mut self.st;
        st.ddg_build = build;
        st.ddg_tets = d.tets.len();
        st.ddg_points = d.points.len();
        st.ddg_surface_points = d.n_input;
        st.ddg_growth = d.growth;
        // A failed try of the passes included.
        st.ddg_seconds = seconds;
        self.cpu[1] = process_cpu_seconds();
    }

    /// The partition is done: the CPU seconds of it and of the DDG.
    pub(crate) fn partitioned(&mut self) {
        let end = process_cpu_seconds();
        if let ([Some(a), Some(b)], Some(c)) = (self.cpu, end) {
            self.st.ddg_cpu_seconds = b - a;
            self.st.partition_cpu_seconds = c - b;
        }
    }

    /// The parts were renamed (`label[old] = new`) before pass 2.
    fn renamed(&mut self, label: &[u32]) {
        let mut made = vec![0; self.made.len()];
        for (k, &n) in self.made.iter().enumerate() {
            made[label[k] as usize] = n;
        }
        self.made = made;
    }

    /// A parallel pass: the tets and front seconds of each part, the tets
    /// peeled after it, and its wall seconds.
    fn pass(&mut self, step: Step, tets: &[usize], secs: Vec<f64>, peeled: usize, seconds: f64) {
        for (k, &n) in tets.iter().enumerate() {
            self.made[k] += n;
        }
        let i = step.pass() as usize - 1;
        self.st.pass_tets[i] += tets.iter().sum::<usize>();
        self.st.part_seconds.push(secs);
        self.st.crossing_passes = step.crossing();
        self.st.peeled_tets += peeled;
        self.st.pass_seconds[i] += seconds;
    }

    /// Passes 1 to 3 are done: their imbalance.
    pub(crate) fn parallel_done(&mut self) {
        self.st.made_imbalance = max_over_mean(&self.made, self.st.parts);
    }

    /// Pass 4 made `made` tets and removed `removed`, in `seconds`.
    pub(crate) fn pass4(&mut self, made: usize, removed: usize, seconds: f64) {
        self.st.pass_tets[3] = made;
        self.st.peeled_tets += removed;
        self.st.pass_seconds[3] = seconds;
    }

    /// Redistribution gave `out` in `seconds`: the tets each pass has in
    /// the final mesh, and what each part holds.
    /// `held`: the tets of every part's piece; `pass_tets`: the tets each
    /// pass has in the final mesh.
    pub(crate) fn finish(
        mut self,
        out: ParOutput,
        held: Vec<usize>,
        pass_tets: [usize; 4],
        seconds: f64,
    ) -> ParOutput {
        let st = &mut self.st;
        st.redistribute_seconds = seconds;
        st.pass_tets = pass_tets;
        st.held_imbalance = max_over_mean(&held, st.parts);
        ParOutput {
            stats: self.st,
            ..out
        }
    }
}

/// The largest of `v` over its sum shared by `np` (1 when nothing).
fn max_over_mean(v: &[usize], np: usize) -> f64 {
    let mean = v.iter().sum::<usize>() as f64 / np as f64;
    if mean > 0.0 {
        *v.iter().max().unwrap() as f64 / mean
    } else {
        1.0
    }
}

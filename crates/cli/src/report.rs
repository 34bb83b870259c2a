//! What `parafront mesh` prints: the front's progress line while it runs,
//! and the summary after (tets, stage times, parts, fill, memory, quality).
use parafront_pipeline::{Stage, Summary};
use std::time::Instant;

/// The front's progress on a terminal: tets made, front size, rate.
/// indicatif draws nothing when stderr is not a terminal.
pub(crate) struct ProgressLine {
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    handle: Option<std::thread::JoinHandle<()>>,
}

impl ProgressLine {
    pub(crate) fn start(p: std::sync::Arc<parafront_front::Progress>) -> ProgressLine {
        use std::sync::atomic::{AtomicBool, Ordering};
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let handle = std::thread::spawn(move || {
            let bar = indicatif::ProgressBar::new_spinner();
            bar.set_style(
                indicatif::ProgressStyle::with_template("{spinner} {elapsed} {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
            );
            let t0 = Instant::now();
            while !flag.load(Ordering::Relaxed) {
                bar.set_message(progress_message(&p, t0.elapsed().as_secs_f64()));
                bar.tick();
                // Parked, not asleep: `finish` wakes it at once (a sleep
                // kept every run waiting up to 100 ms at its end).
                std::thread::park_timeout(std::time::Duration::from_millis(100));
            }
            bar.finish_and_clear();
        });
        ProgressLine {
            stop,
            handle: Some(handle),
        }
    }

    pub(crate) fn finish(mut self) {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            h.thread().unpark();
            let _ = h.join();
        }
    }
}

/// The progress line's text, `secs` into the run.
fn progress_message(p: &parafront_front::Progress, secs: f64) -> String {
    use parafront_front::Phase;
    match p.phase() {
        Phase::Meshing => {
            let tets = p.tets();
            let rate = tets as f64 / secs.max(1e-9);
            let mut msg = format!("{tets} tets, front {} faces, {rate:.0} tets/s", p.front());
            if p.rounds() > 0 {
                msg.push_str(&format!(", recovery round {}", p.rounds()));
            }
            if p.fills() > 0 {
                msg.push_str(&format!(", constrained fill {}", p.fills()));
            }
            msg
        }
        Phase::Improving => {
            "meshed; improving the tets (swaps, collapses, smoothing, point moves)".to_string()
        }
        Phase::Checking => "improved; checking the mesh".to_string(),
    }
}

/// The summary of a run, on stdout.
pub(crate) fn print_summary(sum: &Summary) {
    let front = sum.seconds(Stage::Front);
    println!(
        "{} tets, {} points, {} region{}",
        sum.tets,
        sum.points,
        sum.regions,
        if sum.regions == 1 { "" } else { "s" }
    );
    let stages: Vec<String> = sum
        .stages
        .iter()
        .map(|(n, s)| format!("{n} {s:.3}"))
        .collect();
    println!(
        "seconds: {} (total {:.3}, {} thread{})",
        stages.join(", "),
        sum.total_seconds(),
        sum.threads,
        if sum.threads == 1 { "" } else { "s" }
    );
    if front > 0.0 {
        println!("front: {:.0} tets/s", sum.tets as f64 / front);
    }
    if let Some((parts, estimate)) = sum.auto_parts {
        let how = if parts == 1 {
            "the serial front".to_string()
        } else {
            format!("{parts} parts")
        };
        println!(
            "parts (auto): {how}, for about {:.0}k tets estimated (--parts N sets them)",
            estimate / 1e3
        );
    }
    if !sum.voided_shells.is_empty() {
        let n = sum.voided_shells.len();
        let mut ids: Vec<String> = sum
            .voided_shells
            .iter()
            .take(6)
            .map(|k| k.to_string())
            .collect();
        if n > 6 {
            ids.push(format!("and {} more", n - 6));
        }
        let s = if n == 1 { "" } else { "s" };
        println!(
            "inner shell{s} {} (outward normals, `parafront check` numbering) meshed as void{s}; --regions meshes inner bodies as regions",
            ids.join(", ")
        );
    }
    for (r, e) in &sum.serial_fallback {
        println!("region {r}: meshed by the serial front, the parallel passes gave way: {e}");
    }
    if sum.lattice_tets > 0 {
        println!(
            "lattice: {} tets in {} cubes, {:.1}% of the tets",
            sum.lattice_tets,
            sum.lattice_cells,
            100.0 * sum.lattice_tets as f64 / sum.tets.max(1) as f64
        );
    }
    if sum.recovery_rounds > 0 {
        println!(
            "recovery: {} rounds, {} tets removed and re-meshed",
            sum.recovery_rounds, sum.tets_removed
        );
    }
    if sum.cavities_filled > 0 {
        println!(
            "constrained fill: {} cavit{} the front could not close, {} tets",
            sum.cavities_filled,
            if sum.cavities_filled == 1 { "y" } else { "ies" },
            sum.fill_tets
        );
    }
    if sum.fills_failed > 0 {
        println!(
            "constrained fill: {} cavit{} left open by it (grown, recovered, or filled with the region's surface)",
            sum.fills_failed,
            if sum.fills_failed == 1 { "y" } else { "ies" },
        );
    }
    if !sum.regions_refined.is_empty() {
        let s = if sum.regions_refined.len() == 1 {
            ""
        } else {
            "s"
        };
        println!(
            "region{s} {:?}: the front stalled on much of the surface, so the constrained fill of the whole surface, refined to the size field (GDT), meshed it",
            sum.regions_refined
        );
    }
    if !sum.regions_filled.is_empty() {
        println!(
            "warning: the front could not close region{} {:?}: filled whole by the constrained Delaunay fill of its surface, refined to the size field (GDT: valid, but not the front's quality)",
            if sum.regions_filled.len() == 1 { "" } else { "s" },
            sum.regions_filled
        );
    }
    if let Some(m) = peak_memory_bytes() {
        println!(
            "peak memory: {:.1} MiB ({:.0} bytes/tet)",
            m as f64 / 1048576.0,
            m as f64 / sum.tets.max(1) as f64
        );
    }
    if let (Some(b), Some(st)) = (&sum.quality_before, &sum.improve) {
        println!(
            "before improvement: min dihedral {:.2} deg, {:.3}% of tets under 10 deg, mean radius ratio {:.3} ({} tets)",
            b.min_dihedral.min,
            100.0 * b.share_min_dihedral_below,
            b.radius_ratio.mean,
            st.tets_before
        );
        let ops: Vec<String> = st
            .ops()
            .iter()
            .map(|(n, o)| format!("{n} {}/{} in {:.3} s", o.done, o.tried, o.seconds))
            .collect();
        println!(
            "improvement (seconds of CPU per operation, summed over parts): {} ({} 2-3, {} 3-2, {} edge removals, {} points removed, {} inserted)",
            ops.join(", "),
            st.swaps_23,
            st.swaps_32,
            st.edge_removals,
            st.points_removed,
            st.points_inserted
        );
    }
    if let Some(q) = &sum.quality {
        println!(
            "quality: min dihedral {:.2} deg, {:.3}% of tets under 10 deg, mean radius ratio {:.3}",
            q.min_dihedral.min,
            100.0 * q.share_min_dihedral_below,
            q.radius_ratio.mean
        );
        if let Some(e) = &q.edge_ratio {
            println!(
                "edge length / target size: min {:.3}, mean {:.3}, max {:.3} ({} edges)",
                e.min, e.mean, e.max, e.count
            );
        }
    }
}

/// Peak resident memory (VmHWM) on Linux.
pub(crate) fn peak_memory_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use super::progress_message;
    use parafront_front::{Phase, Progress};

    /// After the front, the line says what the run does instead of a
    /// front count that no longer moves.
    #[test]
    fn the_progress_line_names_the_phase() {
        let p = Progress::default();
        let m = progress_message(&p, 1.0);
        assert!(m.contains("tets/s") && m.contains("front"), "{m}");
        p.set_phase(Phase::Improving);
        let m = progress_message(&p, 1.0);
        assert!(m.contains("improving") && !m.contains("tets/s"), "{m}");
        p.set_phase(Phase::Checking);
        assert!(progress_message(&p, 1.0).contains("checking"));
        p.set_phase(Phase::Meshing);
        assert!(progress_message(&p, 1.0).contains("tets/s"));
    }
}

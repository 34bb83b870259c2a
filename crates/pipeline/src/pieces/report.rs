//! The quality report of the pieces where they lie: each process's
//! pieces measured, the reports merged over all processes.
use super::*;
use parafront_comm::{Wire, WireError};
use parafront_mesh::quality::{Histogram, Stat};

/// The quality of every process's pieces, merged (the same on all).
pub(crate) fn pieces_quality<C: Comm>(
    comm: &C,
    pieces: &[Piece],
    size: Option<&(dyn Fn(parafront_geom::P3) -> f64 + Sync)>,
) -> Option<QualityReport> {
    let held = comm.owned().len().max(1);
    let local: Vec<Option<QWire>> = (0..comm.owned().len())
        .map(|i| {
            pieces
                .iter()
                .skip(i)
                .step_by(held)
                .map(|pc| {
                    let m = TetMesh {
                        points: pc.points.clone(),
                        tets: pc.tets.iter().map(|t| t.map(PointId::from_raw)).collect(),
                        ..Default::default()
                    };
                    match size {
                        Some(h) => QualityReport::with_size(&m, h),
                        None => QualityReport::new(&m),
                    }
                })
                .reduce(|a, b| a.merge(&b))
                .map(QWire)
        })
        .collect();
    comm.all_reduce(local, |a, b| match (a, b) {
        (Some(a), Some(b)) => Some(QWire(a.0.merge(&b.0))),
        (a, b) => a.or(b),
    })
    .map(|q| q.0)
}

/// A quality report as it travels between processes.
#[derive(Clone)]
struct QWire(QualityReport);

fn put_stat(s: &Stat, buf: &mut Vec<u8>) {
    (s.min, s.mean, s.max, s.count).put(buf);
}

fn get_stat(buf: &mut &[u8]) -> Result<Stat, WireError> {
    let (min, mean, max, count) = Wire::get(buf)?;
    Ok(Stat {
        min,
        mean,
        max,
        count,
    })
}

fn put_hist(h: &Histogram, buf: &mut Vec<u8>) {
    (h.lo, h.hi).put(buf);
    h.counts.put(buf);
}

fn get_hist(buf: &mut &[u8]) -> Result<Histogram, WireError> {
    let (lo, hi) = Wire::get(buf)?;
    let counts = Wire::get(buf)?;
    Ok(Histogram { lo, hi, counts })
}

impl Wire for QWire {
    fn put(&self, buf: &mut Vec<u8>) {
        let q = &self.0;
        (
            q.n_tets,
            q.n_inverted,
            q.n_skipped,
            q.share_min_dihedral_below,
        )
            .put(buf);
        for s in [
            &q.min_dihedral,
            &q.max_dihedral,
            &q.radius_ratio,
            &q.mean_ratio,
        ] {
            put_stat(s, buf);
        }
        for h in [
            &q.dihedral_hist,
            &q.min_dihedral_hist,
            &q.max_dihedral_hist,
            &q.radius_ratio_hist,
            &q.mean_ratio_hist,
        ] {
            put_hist(h, buf);
        }
        match (&q.edge_ratio, &q.edge_ratio_hist) {
            (Some(s), Some(h)) => {
                true.put(buf);
                put_stat(s, buf);
                put_hist(h, buf);
            }
            _ => false.put(buf),
        }
    }

    fn get(buf: &mut &[u8]) -> Result<Self, WireError> {
        let (n_tets, n_inverted, n_skipped, share_min_dihedral_below) = Wire::get(buf)?;
        let [min_dihedral, max_dihedral, radius_ratio, mean_ratio] = [
            get_stat(buf)?,
            get_stat(buf)?,
            get_stat(buf)?,
            get_stat(buf)?,
        ];
        let [dihedral_hist, min_dihedral_hist, max_dihedral_hist, radius_ratio_hist, mean_ratio_hist] = [
            get_hist(buf)?,
            get_hist(buf)?,
            get_hist(buf)?,
            get_hist(buf)?,
            get_hist(buf)?,
        ];
        let (edge_ratio, edge_ratio_hist) = if bool::get(buf)? {
            (Some(get_stat(buf)?), Some(get_hist(buf)?))
        } else {
            (None, None)
        };
        Ok(QWire(QualityReport {
            n_tets,
            n_inverted,
            n_skipped,
            min_dihedral,
            max_dihedral,
            radius_ratio,
            mean_ratio,
            dihedral_hist,
            min_dihedral_hist,
            max_dihedral_hist,
            radius_ratio_hist,
            mean_ratio_hist,
            share_min_dihedral_below,
            edge_ratio,
            edge_ratio_hist,
        }))
    }
}

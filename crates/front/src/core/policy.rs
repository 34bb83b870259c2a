//! AF2's candidate policy in one place: the new points' heights, the
//! scores a candidate needs, and the clearances a new tet keeps, each by
//! round (a face's own failed tries plus the front's recovery rounds).
//! Later rounds accept more, so that a face the first rules cannot close
//! still closes before recovery must remove tets.
use super::NONE;

/// Heights of the new-point candidates above a face, in ideal heights
/// (AF2.1): the ideal one alone on a first try, then lower ones (a narrow
/// gap has room for a flat tet only). Candidate `NONE - k` is height `k`.
pub(super) const NEW_HEIGHTS: [f64; 4] = [1.0, 0.7, 0.45, 0.25];

/// The new-point heights a face tries in round `round`.
pub(super) fn new_heights(round: u32) -> &'static [f64] {
    if round == 0 {
        &NEW_HEIGHTS[..1]
    } else {
        &NEW_HEIGHTS
    }
}

/// The candidate id of new-point height `k`.
#[inline]
pub(super) fn new_point_id(k: usize) -> u32 {
    NONE - k as u32
}

/// A candidate apex that is not a point yet: a new-point height, or `NONE`
/// (height 0), a cone apex in recovery.
#[inline]
pub(super) fn is_new_point(q: u32) -> bool {
    q >= NONE - (NEW_HEIGHTS.len() as u32 - 1)
}

/// The height, in ideal heights, of new-point candidate `q`.
#[inline]
pub(super) fn new_point_height(q: u32) -> f64 {
    NEW_HEIGHTS[(NONE - q) as usize]
}

/// The score a candidate needs, by round; no more than
/// [`MIN_SCORE_OF_BEST`] of the best its face allows, since a needle
/// surface triangle makes no good tet at all and must not wait for
/// recovery.
const MIN_SCORE: [f64; 4] = [0.12, 0.05, 0.01, 0.0];
const MIN_SCORE_OF_BEST: f64 = 0.3;

/// The score a candidate needs in round `round` on a face whose ideal
/// point scores `best`.
pub(super) fn min_score(round: u32, best: f64) -> f64 {
    MIN_SCORE[(round as usize).min(MIN_SCORE.len() - 1)].min(MIN_SCORE_OF_BEST * best)
}

/// How far a new point keeps from front faces, in sizes, by round.
const NEW_POINT_CLEARANCE: [f64; 3] = [0.3, 0.2, 0.1];

/// How far a new tet keeps from the rest of the front: front points stay
/// `point` away from it, and a new face and a front face on one edge leave
/// a free wedge of at least `wedge` radians. Either gap could otherwise be
/// closed only by a flat tet.
#[derive(Clone, Copy)]
pub(super) struct Clearance {
    pub(super) point: f64,
    pub(super) wedge: f64,
    /// A new point keeps this far from every front face: closer, it would
    /// split a gap in two, one of them too thin for anything but slivers
    /// (two fronts meeting across a plate); an existing point does better.
    pub(super) new_point: f64,
}

impl Clearance {
    /// The clearances of round `round` for a face of size `h`; from round
    /// 5, validity only, for a front no rule lets close.
    pub(super) fn for_round(round: u32, h: f64) -> Clearance {
        // (point in sizes, wedge in radians, new-point clearance index).
        let (point, wedge, k) = match round {
            0 => (0.05, 0.05, 0),
            1 | 2 => (0.03, 0.03, 1),
            3 | 4 => (0.015, 0.02, 2),
            _ => (0.0, 0.0, 2),
        };
        Clearance {
            point: point * h,
            wedge,
            new_point: NEW_POINT_CLEARANCE[k] * h,
        }
    }

    /// Validity only: for cones that must close a pocket.
    pub(super) const EXACT: Clearance = Clearance {
        point: 0.0,
        wedge: 0.0,
        new_point: 0.0,
    };
}

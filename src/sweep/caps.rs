//! The caps of an open sweep of a closed profile: its triangulation on the first and last rings.

use super::layout::Plan;
use super::scale::Index;

/// Caps: the profile's triangulation `tris` on the first ring (facing −t) and the last (+t).
pub(super) fn write_caps<I: Index>(
    caps: &mut [[I; 3]],
    plan: &Plan,
    tris: &[[usize; 3]],
    vbase: usize,
) {
    let last = vbase + (plan.rings - 1) * plan.cols;
    let first = vbase;
    let k = tris.len();
    let (lo, hi) = caps.split_at_mut(k);
    for ((tr, c0), c1) in tris.iter().zip(lo).zip(hi) {
        let [a, b, d] = *tr;
        *c0 = [I::of(first + a), I::of(first + d), I::of(first + b)]; // faces −t
        *c1 = [I::of(last + a), I::of(last + b), I::of(last + d)]; // faces +t
    }
}

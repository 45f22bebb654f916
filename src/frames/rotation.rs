//! Rotation method (Bloomenthal 1990; matrix form of Poston, Fang & Lawton 1995), also
//! known as discrete parallel transport or the Bishop frame of a polyline.
//!
//! The frame is turned about `a = t_i × t_{i+1}` by the angle between the tangents
//! (Rodrigues). With `c = t_i·t_{i+1}` and `|a|² = 1 − c²` the rotation is
//! `R v = c v + a × v + (a·v) a / (1 + c)`, which needs no threshold for parallel tangents
//! (`a = 0` gives the identity) and is undefined only for exactly opposite tangents
//! (`c = −1`), which the caller refuses. 2nd-order accurate (TOG §2.1, Table IV).

use glam::DVec3;

use super::transport::Step;
use crate::math::rotation::minimal_rotate;

/// `r` carried from `t0` to `t1` by the minimal rotation (the shared kernel, same arithmetic
/// as the fused path's step).
#[inline(always)]
pub fn rotation_step(t0: DVec3, t1: DVec3, r: DVec3) -> DVec3 {
    minimal_rotate(t0, t1, r)
}

pub struct Rotation<'a> {
    /// Unit tangents `t_i` at the samples.
    pub t: &'a [DVec3],
}

impl Step for Rotation<'_> {
    #[inline(always)]
    fn step(&self, i: usize, r: DVec3) -> DVec3 {
        let j = if i + 1 == self.t.len() { 0 } else { i + 1 };
        rotation_step(self.t[i], self.t[j], r)
    }
    fn is_rotation(&self) -> bool {
        true
    }
}

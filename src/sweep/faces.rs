//! The side faces of a segment between two rings: two triangles per quad, split along `a c` or
//! `b d`, wound by the profile's orientation.

use super::scale::Index;

/// The side faces of a segment (ring `i` to ring `i + 1`), two triangles per quad of profile
/// edge `j` (`a b` on ring `i`, `d c` on ring `i + 1`, `a`, `d` in column `j`): split along
/// `a c`, or along `b d`, wound by `sign`. Without split seams the last edge of a closed
/// profile wraps to the first column. A profile of at most [`FacePattern::TABLE`] edges keeps
/// the two splits as tables of vertex offsets from ring `i`'s first vertex (ring `i + 1`
/// from `cols` on), which the faces copy; a larger one computes them per edge (no table of
/// the profile's size).
pub(super) struct FacePattern {
    pub(super) cols: usize,
    pub(super) edges: usize,
    /// Wound the other way (clockwise closed profiles).
    pub(super) flip: bool,
    /// The tables (empty for a large profile).
    pub(super) ac: Vec<[usize; 3]>,
    pub(super) bd: Vec<[usize; 3]>,
    /// The column shift at a closed spine's seam (`m/2` for a half turn, else 0; see
    /// [`super::seam`]).
    pub(super) seam: usize,
}

impl FacePattern {
    /// Edges at most of a profile whose faces come from tables (≤ 1.5 MiB of them).
    const TABLE: usize = 1 << 14;

    pub(super) fn of(cols: usize, edges: usize, sign: f64) -> FacePattern {
        let flip = sign < 0.0;
        let (mut ac, mut bd) = (Vec::new(), Vec::new());
        if edges <= Self::TABLE {
            let col = |j: usize| if j == cols { 0 } else { j };
            let wind = |t: [usize; 3]| if flip { [t[0], t[2], t[1]] } else { t };
            for j in 0..edges {
                let (a, b, c, d) = (col(j), col(j + 1), cols + col(j + 1), cols + col(j));
                ac.extend([wind([a, b, c]), wind([a, c, d])]);
                bd.extend([wind([a, b, d]), wind([b, c, d])]);
            }
        }
        FacePattern {
            cols,
            edges,
            flip,
            ac,
            bd,
            seam: 0,
        }
    }

    /// The faces of edges `e0..` of the closing segment of a closed spine, from the last
    /// ring (at vertex `b0`) to the first (at `b1`), whose column `j` meets column
    /// `j + seam (mod cols)` of the first ring; [`FacePattern::write`] without a shift.
    pub(super) fn write_seam<I: Index>(
        &self,
        out: &mut [[I; 3]],
        bd: bool,
        b0: usize,
        b1: usize,
        e0: usize,
    ) {
        if self.seam == 0 {
            return self.write(out, bd, b0, b1, e0);
        }
        let cols = self.cols;
        let on_first = |j: usize| b1 + (j + self.seam) % cols;
        for (k, f) in out.chunks_exact_mut(2).enumerate() {
            let j = e0 + k;
            let jn = if j + 1 == cols { 0 } else { j + 1 };
            let (a, b, c, d) = (b0 + j, b0 + jn, on_first(jn), on_first(j));
            let (t0, t1) = match bd {
                false => ([a, b, c], [a, c, d]),
                true => ([a, b, d], [b, c, d]),
            };
            let wind = |t: [usize; 3]| match self.flip {
                false => [I::of(t[0]), I::of(t[1]), I::of(t[2])],
                true => [I::of(t[0]), I::of(t[2]), I::of(t[1])],
            };
            f[0] = wind(t0);
            f[1] = wind(t1);
        }
    }

    /// Faces per segment.
    #[inline(always)]
    pub(super) fn per_segment(&self) -> usize {
        2 * self.edges
    }

    /// The faces of edges `e0..` (as many as `out` holds pairs) of the segment from the ring
    /// starting at vertex `b0` to the one starting at `b1`.
    #[inline(always)]
    pub(super) fn write<I: Index>(
        &self,
        out: &mut [[I; 3]],
        bd: bool,
        b0: usize,
        b1: usize,
        e0: usize,
    ) {
        let table = if bd { &self.bd } else { &self.ac };
        if let Some(pat) = table.get(2 * e0..2 * e0 + out.len()) {
            if b1 == b0 + self.cols {
                for (f, t) in out.iter_mut().zip(pat) {
                    *f = [I::of(b0 + t[0]), I::of(b0 + t[1]), I::of(b0 + t[2])];
                }
            } else {
                let cols = self.cols;
                let id = |x: usize| I::of(if x < cols { b0 + x } else { b1 + x - cols });
                for (f, t) in out.iter_mut().zip(pat) {
                    *f = t.map(id);
                }
            }
            return;
        }
        match (bd, self.flip) {
            (false, false) => self.faces::<I, false, false>(out, b0, b1, e0),
            (false, true) => self.faces::<I, false, true>(out, b0, b1, e0),
            (true, false) => self.faces::<I, true, false>(out, b0, b1, e0),
            (true, true) => self.faces::<I, true, true>(out, b0, b1, e0),
        }
    }

    #[inline(always)]
    fn faces<I: Index, const BD: bool, const FLIP: bool>(
        &self,
        out: &mut [[I; 3]],
        b0: usize,
        b1: usize,
        e0: usize,
    ) {
        let cols = self.cols;
        let wind = |t: [usize; 3]| match FLIP {
            false => [I::of(t[0]), I::of(t[1]), I::of(t[2])],
            true => [I::of(t[0]), I::of(t[2]), I::of(t[1])],
        };
        for (k, f) in out.chunks_exact_mut(2).enumerate() {
            let j = e0 + k;
            let jn = if j + 1 == cols { 0 } else { j + 1 };
            let (a, b, c, d) = (b0 + j, b0 + jn, b1 + jn, b1 + j);
            let (t0, t1) = match BD {
                false => ([a, b, c], [a, c, d]),
                true => ([a, b, d], [b, c, d]),
            };
            f[0] = wind(t0);
            f[1] = wind(t1);
        }
    }
}

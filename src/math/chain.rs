//! A hierarchy of boxes over the consecutive items of a chain (the edges of a polyline):
//! level 0 holds the boxes of blocks of [`LEAF`] consecutive items, level `l + 1` the
//! unions of pairs of level `l` (the layout of a segment tree: de Berg et al.,
//! "Computational Geometry", 3rd ed., §10.3). [`ChainBoxes::nearest_from`] is the
//! branch-and-bound nearest search (Friedman, Bentley & Finkel 1977) of
//! [`super::bvh::Bvh::nearest`] started at a leaf instead of the root: after the start item
//! it searches the sibling subtrees of the start's ancestors, nearest first, each only when
//! its box lies within the bound, so a query whose answer is near the start (a vertex bound
//! to the edge of the vertex before) costs about one box test per level, `O(log n)`.

use super::bvh::Aabb;

/// Items per leaf (consecutive items: a leaf's are tested one by one).
pub const LEAF: usize = 8;

/// The levels of boxes over a chain of items (see the module notes).
pub struct ChainBoxes {
    items: Vec<Aabb>,
    /// level 0: the leaves (blocks of [`LEAF`] items); level `l + 1`: pairs of level `l`
    levels: Vec<Vec<Aabb>>,
}

impl ChainBoxes {
    pub fn build(boxes: &[Aabb]) -> ChainBoxes {
        let union = |c: &[Aabb]| c.iter().copied().reduce(Aabb::union).unwrap_or(c[0]);
        let mut levels = vec![boxes.chunks(LEAF).map(union).collect::<Vec<_>>()];
        while levels[levels.len() - 1].len() > 1 {
            let up = levels[levels.len() - 1].chunks(2).map(union).collect();
            levels.push(up);
        }
        ChainBoxes {
            items: boxes.to_vec(),
            levels,
        }
    }

    /// Calls `visit` for the items of leaf `leaf` whose box lies within `bound` (but
    /// `skip`); returns the bound from then on.
    #[inline]
    fn leaf(
        &self,
        p: glam::DVec3,
        leaf: usize,
        skip: usize,
        mut bound: f64,
        visit: &mut impl FnMut(usize) -> f64,
    ) -> f64 {
        let end = (LEAF * leaf + LEAF).min(self.items.len());
        for j in LEAF * leaf..end {
            if j != skip && self.items[j].distance_squared(p) <= bound {
                bound = visit(j);
            }
        }
        bound
    }

    /// Branch and bound about `p` from item `start`: calls `visit(j)` for every item whose
    /// box lies within squared distance `bound` of `p` (an item at exactly the bound
    /// included) — `start` first, then the other items of its leaf, then the sibling
    /// subtrees of its ancestors nearest first, nearer children first — where `visit`
    /// returns the bound from then on (the squared distance of the best answer so far).
    /// Items whose boxes are all farther than the final bound may be skipped. `stack`:
    /// scratch space that a caller making many queries passes each time.
    pub fn nearest_from(
        &self,
        p: glam::DVec3,
        start: usize,
        mut bound: f64,
        stack: &mut Vec<(usize, usize, f64)>,
        mut visit: impl FnMut(usize) -> f64,
    ) {
        if start >= self.items.len() {
            return;
        }
        if self.items[start].distance_squared(p) <= bound {
            bound = visit(start);
        }
        bound = self.leaf(p, start / LEAF, start, bound, &mut visit);
        // the sibling subtrees of the start's ancestors, the nearest popped first (a
        // start far from the answer, whose own candidates set no bound, then finds it
        // nearest first as from the root)
        stack.clear();
        let mut idx = start / LEAF;
        for (l, level) in self.levels.iter().enumerate() {
            let sib = idx ^ 1;
            if sib < level.len() {
                let d = level[sib].distance_squared(p);
                if d <= bound {
                    stack.push((l, sib, d));
                }
            }
            idx >>= 1;
        }
        if stack.len() > 1 {
            stack.sort_unstable_by(|a, b| b.2.total_cmp(&a.2).then(b.0.cmp(&a.0)));
        }
        while let Some((lv, i, d)) = stack.pop() {
            if d > bound {
                continue;
            }
            if lv == 0 {
                bound = self.leaf(p, i, usize::MAX, bound, &mut visit);
                continue;
            }
            let below = &self.levels[lv - 1];
            let (a, b) = (2 * i, 2 * i + 1);
            let da = below[a].distance_squared(p);
            if b < below.len() {
                let db = below[b].distance_squared(p);
                // the nearer child is popped first
                if da <= db {
                    stack.extend([(lv - 1, b, db), (lv - 1, a, da)]);
                } else {
                    stack.extend([(lv - 1, a, da), (lv - 1, b, db)]);
                }
            } else {
                stack.push((lv - 1, a, da));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn nearest_from_any_start_finds_the_closest_edge_of_a_chain_as_a_scan_does() {
        // a coiled chain (it comes back near itself), its edges as boxes: the nearest edge
        // to each query (ties to the smaller index), from any start, equals a brute-force
        // scan, and a start at the answer visits few edges
        let pts: Vec<DVec3> = (0..301)
            .map(|i| {
                let u = i as f64 * 0.07;
                DVec3::new(u.cos() * (1.0 + 0.02 * u), u.sin(), 0.01 * u)
            })
            .collect();
        let boxes: Vec<Aabb> = pts
            .windows(2)
            .map(|w| Aabb {
                lo: w[0].min(w[1]),
                hi: w[0].max(w[1]),
            })
            .collect();
        let dist = |p: DVec3, j: usize| {
            let (a, e) = (pts[j], pts[j + 1] - pts[j]);
            let s = ((p - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            (p - (a + s * e)).length_squared()
        };
        let tree = ChainBoxes::build(&boxes);
        let mut stack = Vec::new();
        for q in 0..300 {
            let x = q as f64 * 0.37;
            let p = DVec3::new(x.sin() * 1.3, x.cos() * 0.9, (x * 0.3).sin() * 0.2);
            let scan = (0..boxes.len())
                .map(|j| (dist(p, j), j))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            for start in [0, q % boxes.len(), boxes.len() - 1, scan.1] {
                let mut best = (f64::INFINITY, usize::MAX);
                let mut visited = 0;
                tree.nearest_from(p, start, f64::INFINITY, &mut stack, |j| {
                    visited += 1;
                    let d = dist(p, j);
                    if d < best.0 || (d == best.0 && j < best.1) {
                        best = (d, j);
                    }
                    best.0
                });
                assert_eq!(best, scan, "{q} {start}");
                if start == scan.1 {
                    assert!(visited < boxes.len() / 4, "visited {visited}");
                }
            }
        }
    }
}

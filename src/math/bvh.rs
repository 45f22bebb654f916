//! A bounding-volume hierarchy over axis-aligned boxes: median splits of the box centres
//! along the longest axis of their spread, leaves of at most [`LEAF`] items (the
//! construction of Wald, Boulos & Shirley, ACM TOG 26(1), 2007, without the surface-area
//! heuristic). Two queries:
//!
//! * [`Bvh::query`]: every item whose box overlaps a box (closed intervals, exact
//!   coordinates: no tolerance), for pairs of faces that may cross;
//! * [`Bvh::nearest`]: the items whose box lies within a shrinking squared distance of a
//!   point, nearer children first (branch and bound, as in a k-d tree's nearest-neighbour
//!   search: Friedman, Bentley & Finkel, ACM TOMS 3(3), 1977), for the closest feature of
//!   many items.
//!
//! The split is deterministic (ties broken by item index), so any query visits the same
//! items in the same order whatever the thread that asks.

use glam::DVec3;

/// Items per leaf of the hierarchy.
pub const LEAF: usize = 8;

/// An axis-aligned box `[lo, hi]`.
#[derive(Clone, Copy, Debug)]
pub struct Aabb {
    pub lo: DVec3,
    pub hi: DVec3,
}

impl Aabb {
    /// The box of three points (a triangle).
    pub fn of_points(t: &[DVec3; 3]) -> Aabb {
        Aabb {
            lo: t[0].min(t[1]).min(t[2]),
            hi: t[0].max(t[1]).max(t[2]),
        }
    }

    /// The box of the ball of radius `r` about `c`.
    pub fn of_ball(c: DVec3, r: f64) -> Aabb {
        Aabb {
            lo: c - DVec3::splat(r),
            hi: c + DVec3::splat(r),
        }
    }

    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.lo.cmple(o.hi).all() && o.lo.cmple(self.hi).all()
    }

    /// The squared distance from `p` to the box (0 inside): a lower bound of the squared
    /// distance from `p` to anything in it.
    pub fn distance_squared(&self, p: DVec3) -> f64 {
        let d = (self.lo - p).max(p - self.hi).max(DVec3::ZERO);
        d.length_squared()
    }
}

/// A node: a box and either two children or a range of `order`.
struct Node {
    bound: Aabb,
    /// children `(left, right)` for an inner node; `(start, end)` in `order` for a leaf
    kids: (usize, usize),
    leaf: bool,
}

/// The hierarchy over the boxes it was built from (items are their indices).
pub struct Bvh {
    nodes: Vec<Node>,
    order: Vec<usize>,
}

impl Bvh {
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let mut order: Vec<usize> = (0..boxes.len()).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len() / LEAF + 1);
        if !boxes.is_empty() {
            Self::split(boxes, &mut order, 0, boxes.len(), &mut nodes);
        }
        Bvh { nodes, order }
    }

    /// The node over `order[lo..hi]` (its index); children first split at the median of
    /// the centres along the longest axis of their spread.
    fn split(
        boxes: &[Aabb],
        order: &mut [usize],
        lo: usize,
        hi: usize,
        nodes: &mut Vec<Node>,
    ) -> usize {
        let bound = order[lo..hi]
            .iter()
            .map(|&f| boxes[f])
            .reduce(Aabb::union)
            .unwrap_or(Aabb {
                lo: DVec3::ZERO,
                hi: DVec3::ZERO,
            });
        let me = nodes.len();
        nodes.push(Node {
            bound,
            kids: (lo, hi),
            leaf: true,
        });
        if hi - lo <= LEAF {
            return me;
        }
        let centre = |f: usize| boxes[f].lo + boxes[f].hi;
        let (clo, chi) = order[lo..hi].iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(a, b), &f| (a.min(centre(f)), b.max(centre(f))),
        );
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = (lo + hi) / 2;
        order[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
            centre(a)[axis].total_cmp(&centre(b)[axis]).then(a.cmp(&b))
        });
        let left = Self::split(boxes, order, lo, mid, nodes);
        let right = Self::split(boxes, order, mid, hi, nodes);
        nodes[me].kids = (left, right);
        nodes[me].leaf = false;
        me
    }

    /// Calls `hit(j)` for every item `j` whose box overlaps `b`.
    pub fn query(&self, b: &Aabb, mut hit: impl FnMut(usize)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if !node.bound.overlaps(b) {
                continue;
            }
            if node.leaf {
                for &j in &self.order[node.kids.0..node.kids.1] {
                    hit(j);
                }
            } else {
                stack.push(node.kids.0);
                stack.push(node.kids.1);
            }
        }
    }

    /// Branch and bound about `p`: calls `visit(j)` for the items of every leaf whose box
    /// lies within squared distance `bound` of `p` (nearer children first), where `visit`
    /// returns the bound from then on (the squared distance of the best answer so far).
    /// Items whose boxes are all farther than the final bound may be skipped; an item whose
    /// box is at exactly the bound is visited (so ties can be decided by the caller).
    /// `stack`: scratch space that a caller making many queries passes each time.
    pub fn nearest(
        &self,
        p: DVec3,
        mut bound: f64,
        stack: &mut Vec<(usize, f64)>,
        mut visit: impl FnMut(usize) -> f64,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        stack.clear();
        stack.push((0, self.nodes[0].bound.distance_squared(p)));
        while let Some((n, d)) = stack.pop() {
            if d > bound {
                continue;
            }
            let node = &self.nodes[n];
            if node.leaf {
                for &j in &self.order[node.kids.0..node.kids.1] {
                    bound = visit(j);
                }
                continue;
            }
            let (a, b) = node.kids;
            let (da, db) = (
                self.nodes[a].bound.distance_squared(p),
                self.nodes[b].bound.distance_squared(p),
            );
            // the nearer child is popped first
            if da <= db {
                stack.extend([(b, db), (a, da)]);
            } else {
                stack.extend([(a, da), (b, db)]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_finds_the_closest_point_of_a_cloud_as_a_scan_does() {
        // points on a jittered spiral, boxes of zero size: the nearest item to each query
        // point, ties to the smaller index, equals a brute-force scan
        let pts: Vec<DVec3> = (0..500)
            .map(|i| {
                let u = i as f64 * 0.1;
                DVec3::new(
                    u.cos() * (1.0 + 0.01 * u),
                    u.sin(),
                    0.05 * u + (i % 7) as f64 * 1e-3,
                )
            })
            .collect();
        let boxes: Vec<Aabb> = pts.iter().map(|&c| Aabb::of_ball(c, 0.0)).collect();
        let bvh = Bvh::build(&boxes);
        for q in 0..200 {
            let x = q as f64 * 0.37;
            let p = DVec3::new(x.sin() * 1.3, x.cos() * 0.7, (x * 0.3).sin() * 2.0);
            let scan = pts
                .iter()
                .enumerate()
                .map(|(i, c)| ((p - *c).length_squared(), i))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            let mut best = (f64::INFINITY, usize::MAX);
            let mut visited = 0;
            bvh.nearest(p, f64::INFINITY, &mut Vec::new(), |j| {
                visited += 1;
                let d = (p - pts[j]).length_squared();
                if d < best.0 || (d == best.0 && j < best.1) {
                    best = (d, j);
                }
                best.0
            });
            assert_eq!(best, scan);
            assert!(
                visited < pts.len() / 4,
                "visited {visited} of {}",
                pts.len()
            );
        }
    }

    #[test]
    fn box_distance_is_zero_inside_and_euclidean_outside() {
        let b = Aabb {
            lo: DVec3::ZERO,
            hi: DVec3::ONE,
        };
        assert_eq!(b.distance_squared(DVec3::splat(0.5)), 0.0);
        assert_eq!(b.distance_squared(DVec3::new(2.0, 0.5, -1.0)), 2.0);
    }
}

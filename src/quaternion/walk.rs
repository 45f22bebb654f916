//! Walking on a triangle mesh with a moving frame (Ma 1996, §4.2.1, Eq. 4.1).
//!
//! A walker stands at a point `p` of a face with a frame `E = (e₁, e₂, e₃)`: `e₁, e₂` in
//! the face plane (screen right and up), `e₃ = e₁ × e₂` the face normal. A move
//! `(dx, dy)` goes the distance `|d|` in the direction `d = dx e₁ + dy e₂`. Where the
//! straight path leaves the face through an edge with unit direction `ê`, the frame and the
//! direction are rotated about `ê` by the angle `θ` taking `Â` (in the old face, ⟂ `ê`,
//! pointing out of it) to `B̂` (in the next face, ⟂ `ê`, pointing into it): the next face
//! is unfolded onto the plane of the old one, so the path is straight in the unfolded strip
//! (a "straightest" polyhedral geodesic) and the frame is transported without twist. On
//! consistently oriented meshes the rotation maps one face normal onto the next exactly.
//!
//! A walk stops at a boundary edge. A path that hits a vertex exactly is nudged along the
//! edge by a round-off amount (Ma assumes it never happens).
//!
//! Sizes: a straight path of length `L` crosses about `L / ℓ` edges, `ℓ` the median edge
//! length of the mesh (an estimate, not a bound: it sizes the memory check and refuses
//! absurd moves). The shortest edge plays no part, so one near-degenerate edge of a
//! scanned mesh does not turn ordinary moves into refusals. The loop over the crossings
//! of one move is capped (`64 + 16·F + 64·L/ℓ` crossings, `F` faces), a guard against a
//! malformed mesh, never reached by a straight path on a valid one.

use glam::{DMat3, DQuat, DVec2, DVec3};

use crate::error::{InputError, Result};
use crate::math::mesh;
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// Most edge crossings (estimated, see the module docs) of one move; a longer move is
/// refused by name.
const MAX_CROSSINGS: f64 = 1e8;

/// Edge crossings between polls of a cancellable move ([`Walker::step`]).
const CANCEL_CROSSINGS: usize = 1 << 14;

/// A triangle mesh prepared for walking: faces and edge adjacency.
pub struct Walker<'a> {
    v: &'a [DVec3],
    f: Vec<[usize; 3]>,
    /// For face `f` and local edge `k` (from corner `k` to corner `k+1`): the neighbouring
    /// face and its local index of the shared edge.
    adj: Vec<[Option<(usize, usize)>; 3]>,
    scale: f64,
    /// Median edge length (sizes the crossings of a move; see the module docs).
    typical_edge: f64,
}

/// The state of a walker after a move.
#[derive(Debug, Clone, Copy)]
pub struct State {
    pub point: DVec3,
    pub face: usize,
    /// Columns `e₁, e₂, e₃`.
    pub frame: DMat3,
    /// The move ended at a boundary edge before its full length.
    pub stopped: bool,
}

impl<'a> Walker<'a> {
    /// Check the mesh (indices in range, no degenerate faces, manifold edges) and build
    /// the edge adjacency.
    pub fn new(vertices: &'a [DVec3], faces: &[[i64; 3]]) -> Result<Self> {
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(InputError::new(
                "vertices",
                format!("non-finite value at row {i}"),
            ));
        }
        if faces.is_empty() {
            return Err(InputError::new("faces", "the mesh has no faces"));
        }
        let nv = vertices.len();
        let mut f = alloc::with_capacity("walk_mesh", faces.len())?;
        for (i, tri) in faces.iter().enumerate() {
            let mut c = [0usize; 3];
            for k in 0..3 {
                c[k] = usize::try_from(tri[k])
                    .ok()
                    .filter(|&x| x < nv)
                    .ok_or_else(|| {
                        InputError::new(
                            "faces",
                            format!(
                                "face {i} refers to vertex {} but there are {nv} vertices",
                                tri[k]
                            ),
                        )
                    })?;
            }
            f.push(c);
        }
        let (lo, hi) = vertices.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(a, b), v| (a.min(*v), b.max(*v)),
        );
        let diag = (hi - lo).length();
        let scale = if diag > 0.0 { diag } else { 1.0 };
        for (i, c) in f.iter().enumerate() {
            let area2 = (vertices[c[1]] - vertices[c[0]])
                .cross(vertices[c[2]] - vertices[c[0]])
                .length();
            if !(area2 > 1e-12 * scale * scale) {
                return Err(InputError::new(
                    "faces",
                    format!("face {i} is degenerate (zero area or repeated vertices)"),
                ));
            }
        }
        // every face has positive area here, so every edge a positive length
        let mut lengths = alloc::flat(
            "walk_mesh",
            f.iter()
                .map(|c| [0, 1, 2].map(|k| vertices[c[(k + 1) % 3]].distance(vertices[c[k]]))),
        )?;
        let mid = lengths.len() / 2;
        let typical_edge = *lengths.select_nth_unstable_by(mid, f64::total_cmp).1;
        drop(lengths);
        let (edges, slot) = mesh::edges("walk_mesh", &f)?;
        let count = mesh::edge_counts("walk_mesh", &slot, edges.len())?;
        if let Some(e) = count.iter().position(|&c| c > 2) {
            let [a, b] = edges[e];
            return Err(InputError::new(
                "faces",
                format!(
                    "the edge between vertices {a} and {b} is shared by {} faces (the mesh \
                     must be manifold)",
                    count[e]
                ),
            ));
        }
        // faces on both sides of each interior edge: the first slot seen waits for the second
        let mut first: Vec<Option<(usize, usize)>> = alloc::filled("walk_mesh", edges.len(), None)?;
        let mut adj = alloc::filled("walk_mesh", f.len(), [None; 3])?;
        for (i, s) in slot.iter().enumerate() {
            for (k, &e) in s.iter().enumerate() {
                if let Some((f1, k1)) = first[e] {
                    adj[f1][k1] = Some((i, k));
                    adj[i][k] = Some((f1, k1));
                } else {
                    first[e] = Some((i, k));
                }
            }
        }
        Ok(Walker {
            v: vertices,
            f,
            adj,
            scale,
            typical_edge,
        })
    }

    fn corners(&self, face: usize) -> [DVec3; 3] {
        self.f[face].map(|i| self.v[i])
    }

    fn normal(&self, face: usize) -> DVec3 {
        let [a, b, c] = self.corners(face);
        (b - a).cross(c - a).normalize()
    }

    /// The start state: `point` (must lie in `face`, it is projected onto its plane) and a
    /// frame with `e₃` the face normal and `e₁` along `direction` projected onto the face
    /// (default: the face's first edge).
    pub fn start(&self, face: i64, point: DVec3, direction: Option<DVec3>) -> Result<State> {
        let face = usize::try_from(face)
            .ok()
            .filter(|&f| f < self.f.len())
            .ok_or_else(|| {
                InputError::new(
                    "face",
                    format!("{face} is not a face index (there are {})", self.f.len()),
                )
            })?;
        if !point.is_finite() {
            return Err(InputError::new("point", "contains a non-finite value"));
        }
        let [a, b, c] = self.corners(face);
        let n = self.normal(face);
        let p = point - (point - a).dot(n) * n;
        // barycentric coordinates of the projection
        let area = (b - a).cross(c - a).dot(n);
        let w = [
            (c - b).cross(p - b).dot(n) / area,
            (a - c).cross(p - c).dot(n) / area,
            (b - a).cross(p - a).dot(n) / area,
        ];
        let off = (point - p).length();
        if w.iter().any(|&x| x < -1e-9) || off > 1e-6 * self.scale {
            return Err(InputError::new(
                "point",
                format!(
                    "is not on face {face} (barycentric coordinates {w:?}, distance {off:.3e} \
                     from its plane)"
                ),
            ));
        }
        let d = direction.unwrap_or(b - a);
        if !d.is_finite() {
            return Err(InputError::new("direction", "contains a non-finite value"));
        }
        let e1 = d - d.dot(n) * n;
        let l = e1.length();
        if !(l > 1e-12 * d.length()) || l == 0.0 {
            return Err(InputError::new(
                "direction",
                format!("is zero or perpendicular to face {face}; it must lie along the face"),
            ));
        }
        let e1 = e1 / l;
        Ok(State {
            point: p,
            face,
            frame: DMat3::from_cols(e1, n.cross(e1), n),
            stopped: false,
        })
    }

    /// The edges a move of length `length` crosses, about (`length / median edge`).
    fn crossings_of(&self, length: f64) -> f64 {
        length / self.typical_edge
    }

    /// One move of `(dx, dy)` in the walker's `(e₁, e₂)` axes. `path` receives every edge
    /// crossing (point and the face entered).
    ///
    /// Polls `cancel` every [`CANCEL_CROSSINGS`] edge crossings; once it says stop the move ends
    /// where it is (the result is then meaningless and the caller discards it; see
    /// [`crate::run::cancel`]).
    pub fn step(
        &self,
        s: State,
        mv: DVec2,
        path: &mut Vec<(DVec3, usize)>,
        cancel: Cancel<'_>,
    ) -> Result<State> {
        if !mv.is_finite() {
            return Err(InputError::new("moves", "contains a non-finite value"));
        }
        let mut st = State {
            stopped: false,
            ..s
        };
        // |(dx, dy)| without overflow for huge moves
        let mut left = mv.x.hypot(mv.y);
        if left == 0.0 {
            return Ok(st);
        }
        let m = mv / left;
        let mut u = (m.x * st.frame.x_axis + m.y * st.frame.y_axis).normalize();
        let mut entered: Option<usize> = None;
        // about length / (median edge) crossings; the cap (see the module docs) guards
        // against a malformed mesh looping forever
        let per_edge = self.crossings_of(left);
        if !(per_edge < MAX_CROSSINGS) {
            return Err(InputError::new(
                "moves",
                format!(
                    "a move of length {left:.3e} would cross about {per_edge:.1e} edges of \
                     this mesh (median edge {:.3e}); split it into shorter moves",
                    self.typical_edge
                ),
            ));
        }
        let cap = (64 + 16 * self.f.len()).saturating_add(64 * per_edge.ceil() as usize);
        for crossed in 0..cap {
            if crossed % CANCEL_CROSSINGS == CANCEL_CROSSINGS - 1 && cancel() {
                return Ok(st);
            }
            let corners = self.corners(st.face);
            let mut best: Option<(f64, usize)> = None;
            for k in 0..3 {
                if entered == Some(k) {
                    continue;
                }
                let (a, b, c) = (corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]);
                let e = (b - a).normalize();
                let m = (c - a) - (c - a).dot(e) * e;
                let mh = m.normalize();
                let du = u.dot(mh);
                if du < -1e-15 {
                    let delta = (st.point - a).dot(mh).max(0.0);
                    let dist = delta / -du;
                    if best.is_none_or(|(bd, _)| dist < bd) {
                        best = Some((dist, k));
                    }
                }
            }
            let Some((dist, k)) = best else {
                // the direction does not leave the face (round-off): finish in place
                st.point += left * u;
                return Ok(st);
            };
            if dist >= left {
                st.point += left * u;
                return Ok(st);
            }
            let (a, b) = (corners[k], corners[(k + 1) % 3]);
            let e = (b - a).normalize();
            let mut pe = st.point + dist * u;
            left -= dist;
            // keep off the vertices
            let along = (pe - a).dot(e);
            let len = (b - a).length();
            let nudge = 1e-9 * len;
            if along < nudge {
                pe = a + nudge * e;
            } else if along > len - nudge {
                pe = b - nudge * e;
            }
            let Some((g, kg)) = self.adj[st.face][k] else {
                st.point = pe;
                st.stopped = true;
                return Ok(st);
            };
            let c = corners[(k + 2) % 3];
            let m = (c - a) - (c - a).dot(e) * e;
            let a_hat = -m.normalize();
            let vg = self.v[self.f[g][(kg + 2) % 3]];
            let bm = (vg - a) - (vg - a).dot(e) * e;
            let b_hat = bm.normalize();
            let theta = a_hat.cross(b_hat).dot(e).atan2(a_hat.dot(b_hat));
            let rot = DQuat::from_axis_angle(e, theta);
            let fr = st.frame;
            let (e1, e3) = ((rot * fr.x_axis).normalize(), (rot * fr.z_axis).normalize());
            let e1 = (e1 - e1.dot(e3) * e3).normalize();
            st.frame = DMat3::from_cols(e1, e3.cross(e1), e3);
            u = (rot * u).normalize();
            st.face = g;
            st.point = pe;
            entered = Some(kg);
            alloc::push("walk_mesh", path, (pe, g))?;
        }
        Err(InputError::new(
            "moves",
            "the walk crossed more edges than the mesh allows (is the mesh malformed?)",
        ))
    }
}

/// A point of a walker's path: where it stood or crossed an edge, the face it is on (the
/// face entered, at a crossing), and the move it belongs to (0 for the start, `k + 1` for
/// the crossings and the end point of move `k`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    pub point: DVec3,
    pub face: usize,
    pub step: usize,
}

/// One walker's whole walk: the `moves.len() + 1` states (start first) and the path through
/// every edge crossing.
#[derive(Debug, Clone)]
pub struct Walk {
    pub states: Vec<State>,
    pub path: Vec<PathPoint>,
}

/// Bytes a crossing of the path takes: its [`PathPoint`] and the rows the binding makes of
/// it (point, face, move).
const PATH_BYTES: usize = size_of::<PathPoint>() + 5 * 8;

/// The memory the crossing path of `moves` needs (about `Σ |move| / median edge`
/// crossings, see the module docs), checked before the walk: a refusal is a
/// `MemoryError` naming `moves`, and the walk does not start. The path also grows
/// fallibly, so an estimate that falls short still ends in the same error.
fn check_path_memory(w: &Walker, moves: &[DVec2]) -> Result<()> {
    // a non-finite or overlong move is refused by name when the walk reaches it
    if moves
        .iter()
        .any(|m| !(w.crossings_of(m.x.hypot(m.y)) < MAX_CROSSINGS))
    {
        return Ok(());
    }
    let length: f64 = moves.iter().map(|m| m.x.hypot(m.y)).sum();
    let crossings = w.crossings_of(length) + moves.len() as f64 + 1.0;
    let bytes = crossings * PATH_BYTES as f64;
    let refused = || {
        InputError::oom_message(
            "walk_mesh",
            format!(
                "moves: a walk of total length {length:.3e} crosses about {crossings:.2e} \
                 edges of this mesh (median edge {:.3e}), {:.3} GB of path; split it into \
                 calls of fewer or shorter moves",
                w.typical_edge,
                bytes / 1e9
            ),
        )
    };
    if !(bytes <= isize::MAX as f64) {
        return Err(refused());
    }
    alloc::with_capacity::<u8>("walk_mesh", bytes as usize).map_err(|_| refused())?;
    Ok(())
}

/// One walker from `(face, point, direction)` (see [`Walker::start`]) making `moves` in turn
/// (see [`Walker::step`]); records every state and the crossing path.
///
/// Polls `cancel` before every move and inside long moves (see [`Walker::step`]); a
/// cancelled walk returns an incomplete result.
pub fn walk_path(
    w: &Walker,
    face: i64,
    point: DVec3,
    direction: Option<DVec3>,
    moves: &[DVec2],
    cancel: Cancel<'_>,
) -> Result<Walk> {
    let mut s = w.start(face, point, direction)?;
    check_path_memory(w, moves)?;
    let mut states = alloc::with_capacity("walk_mesh", moves.len() + 1)?;
    states.push(s);
    let mut path = alloc::with_capacity("walk_mesh", moves.len() + 1)?;
    path.push(PathPoint {
        point: s.point,
        face: s.face,
        step: 0,
    });
    let mut crossings = Vec::new();
    for (k, m) in moves.iter().enumerate() {
        if cancel() {
            break;
        }
        crossings.clear();
        s = w.step(s, *m, &mut crossings, cancel)?;
        alloc::reserve("walk_mesh", &mut path, crossings.len() + 1)?;
        path.extend(crossings.iter().map(|&(point, face)| PathPoint {
            point,
            face,
            step: k + 1,
        }));
        path.push(PathPoint {
            point: s.point,
            face: s.face,
            step: k + 1,
        });
        states.push(s);
    }
    Ok(Walk { states, path })
}

/// Where one of many walkers starts: face, point on it, optional first direction.
pub type Start = (i64, DVec3, Option<DVec3>);

/// Many walkers on one mesh, in parallel: walker `i` starts at `starts[i]` and makes the
/// moves `moves[i·k .. (i+1)·k]`. Returns the `k + 1` states of every walker, walker by
/// walker (the adjacency is built once, by the caller's [`Walker::new`]). The first error
/// (in walker order) is reported with the walker's index.
///
/// Polls `cancel` before each move (see [`crate::run::cancel`]).
pub fn walk_many(
    w: &Walker,
    starts: &[Start],
    moves: &[DVec2],
    k: usize,
    cancel: Cancel<'_>,
) -> Result<Vec<State>> {
    use rayon::prelude::*;
    if moves.len() != starts.len() * k {
        return Err(InputError::new(
            "moves",
            format!(
                "expected {k} moves for each of the {} walkers, got {} in all",
                starts.len(),
                moves.len()
            ),
        ));
    }
    // every state in one buffer, allocated before any walker runs (the walkers write their
    // rows in place), so running out of memory is an error here rather than an abort later
    let total = alloc::product("walk_mesh_many", starts.len(), k + 1, size_of::<State>())?;
    let blank = State {
        point: DVec3::ZERO,
        face: 0,
        frame: DMat3::IDENTITY,
        stopped: false,
    };
    let mut all = alloc::filled("walk_mesh_many", total, blank)?;
    let first_error = all
        .par_chunks_mut(k + 1)
        .zip(starts.par_iter())
        .enumerate()
        .filter_map(|(i, (out, &(face, point, dir)))| {
            let ctx = |e: InputError| e.context(&format!("walker {i}"));
            let mut run = || -> Result<()> {
                let mut s = w.start(face, point, dir).map_err(ctx)?;
                out[0] = s;
                let mut crossings = Vec::new();
                for (j, m) in moves[i * k..(i + 1) * k].iter().enumerate() {
                    if cancel() {
                        return Ok(());
                    }
                    crossings.clear();
                    s = w.step(s, *m, &mut crossings, cancel).map_err(ctx)?;
                    out[j + 1] = s;
                }
                Ok(())
            };
            run().err().map(|e| (i, e))
        })
        .min_by_key(|(i, _)| *i);
    if let Some((_, e)) = first_error {
        return Err(e);
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cancel;

    use crate::math::mesh::fixtures::cube_i64 as cube;

    #[test]
    fn walk_path_agrees_with_steps_by_hand() {
        let (v, f) = cube();
        let w = Walker::new(&v, &f).unwrap();
        let p = DVec3::new(0.4, 0.2, 1.0);
        let moves = [
            DVec2::new(0.3, 0.1),
            DVec2::new(1.7, -0.4),
            DVec2::new(0.0, 0.0),
            DVec2::new(-0.2, 2.5),
        ];
        let walk = walk_path(&w, 2, p, None, &moves, &cancel::never).unwrap();
        // by hand
        let mut s = w.start(2, p, None).unwrap();
        let mut states = vec![s];
        let mut path = vec![(s.point, s.face, 0)];
        for (k, m) in moves.iter().enumerate() {
            let mut crossings = Vec::new();
            s = w.step(s, *m, &mut crossings, &cancel::never).unwrap();
            path.extend(crossings.iter().map(|&(q, g)| (q, g, k + 1)));
            path.push((s.point, s.face, k + 1));
            states.push(s);
        }
        assert_eq!(walk.states.len(), moves.len() + 1);
        for (a, b) in walk.states.iter().zip(&states) {
            assert_eq!(
                (a.point, a.face, a.frame, a.stopped),
                (b.point, b.face, b.frame, b.stopped)
            );
        }
        let got: Vec<_> = walk
            .path
            .iter()
            .map(|q| (q.point, q.face, q.step))
            .collect();
        assert_eq!(got, path);
        // the long moves cross edges of the cube
        assert!(walk.path.len() > moves.len() + 2);
        // a start off the face is an error of the start
        let e = walk_path(&w, 2, DVec3::splat(5.0), None, &moves, &cancel::never).unwrap_err();
        assert_eq!(e.arg, "point");
    }

    #[test]
    fn a_mesh_without_faces_is_refused() {
        let (v, _) = cube();
        let e = Walker::new(&v, &[]).err().expect("no faces");
        assert_eq!(
            (&*e.arg, e.msg.as_str()),
            ("faces", "the mesh has no faces")
        );
    }

    /// A regular tetrahedron around the origin, faces wound outwards.
    fn tetrahedron() -> (Vec<DVec3>, Vec<[i64; 3]>) {
        let v = vec![
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        let f = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
            .map(|[a, b, c]: [usize; 3]| {
                let n = (v[b] - v[a]).cross(v[c] - v[a]);
                let out = n.dot(v[a] + v[b] + v[c]) > 0.0;
                if out { [a, b, c] } else { [a, c, b] }.map(|i| i as i64)
            })
            .to_vec();
        (v, f)
    }

    /// The distance of `p` from face `f` (0 on it: in its plane and inside its edges).
    fn off_face(w: &Walker, f: usize, p: DVec3) -> f64 {
        let [a, b, c] = w.corners(f);
        let n = w.normal(f);
        let outside = [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(p0, p1)| (-(p1 - p0).cross(p - p0).dot(n) / (p1 - p0).length()).max(0.0))
            .fold(0.0, f64::max);
        outside.max((p - a).dot(n).abs())
    }

    /// The frame is a rotation with `e₃` the normal of the walker's face.
    fn assert_frame(w: &Walker, s: &State) {
        let m = s.frame;
        let off = (m.transpose() * m - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0_f64, |a, v| a.max(v.abs()));
        assert!(off < 1e-12 && (m.determinant() - 1.0).abs() < 1e-12, "{m}");
        assert!((m.z_axis - w.normal(s.face)).length() < 1e-12);
    }

    /// Moves across several faces: the path (start, edge crossings, end) is as long as the
    /// move, runs inside the faces it passes, the frames stay rotations on the faces, and
    /// the reverse move walks back to the start.
    #[test]
    fn straight_moves_keep_their_length_and_walk_back() {
        for (v, f) in [cube(), tetrahedron()] {
            let w = Walker::new(&v, &f).expect("a closed mesh");
            for face in 0..f.len() {
                let [a, b, c] = w.corners(face);
                let p = 0.5 * a + 0.3 * b + 0.2 * c;
                for (dir, mv) in [
                    (None, DVec2::new(2.7, 0.9)),
                    (Some(c - a), DVec2::new(-1.3, 3.1)),
                    (Some(DVec3::new(0.3, -0.7, 0.2)), DVec2::new(4.2, -0.4)),
                ] {
                    let s0 = w.start(face as i64, p, dir).expect("a point on the face");
                    assert_frame(&w, &s0);
                    let mut path = Vec::new();
                    let s1 = w
                        .step(s0, mv, &mut path, &cancel::never)
                        .expect("a valid move");
                    assert!(!s1.stopped && path.len() >= 2, "{} crossings", path.len());
                    assert_frame(&w, &s1);
                    // every piece of the path lies in the face it crosses
                    let mut points = vec![(s0.point, s0.face)];
                    points.extend(path.iter().copied());
                    points.push((s1.point, s1.face));
                    let mut length = 0.0;
                    for k in 0..points.len() - 1 {
                        let ((p, fp), (q, fq)) = (points[k], points[k + 1]);
                        assert!(off_face(&w, fp, p) < 1e-12 && off_face(&w, fp, q) < 1e-12);
                        assert!(off_face(&w, fq, q) < 1e-12, "crossing {k} off face {fq}");
                        length += (q - p).length();
                    }
                    assert!(
                        (length - mv.length()).abs() < 1e-12,
                        "{length} vs {}",
                        mv.length()
                    );
                    let back = w
                        .step(s1, -mv, &mut Vec::new(), &cancel::never)
                        .expect("a valid move");
                    assert_eq!(back.face, s0.face);
                    assert!((back.point - s0.point).length() < 1e-12);
                    assert!(
                        (back.frame - s0.frame)
                            .to_cols_array()
                            .iter()
                            .all(|d| d.abs() < 1e-12)
                    );
                }
            }
        }
    }

    /// On the cube a move parallel to an edge goes round a belt of four faces: a quarter of
    /// the way it is on the next face at the known point, after length 4 back at the start
    /// with the start's frame.
    #[test]
    fn belt_around_the_cube_closes() {
        let (v, f) = cube();
        let w = Walker::new(&v, &f).expect("a cube");
        // bottom face (z = 0, normal −z), heading +x
        let s0 = w
            .start(1, DVec3::new(0.5, 0.3, 0.0), Some(DVec3::X))
            .expect("on face 1");
        for (length, want) in [
            (1.0, DVec3::new(1.0, 0.3, 0.5)),
            (2.25, DVec3::new(0.25, 0.3, 1.0)),
            (3.0, DVec3::new(0.0, 0.3, 0.5)),
            (4.0, DVec3::new(0.5, 0.3, 0.0)),
        ] {
            let s = w
                .step(s0, DVec2::new(length, 0.0), &mut Vec::new(), &cancel::never)
                .expect("a move");
            assert!(
                (s.point - want).length() < 1e-12,
                "{length}: {} vs {want}",
                s.point
            );
        }
        let s = w
            .step(s0, DVec2::new(4.0, 0.0), &mut Vec::new(), &cancel::never)
            .expect("a move");
        assert!(
            (s.frame - s0.frame)
                .to_cols_array()
                .iter()
                .all(|d| d.abs() < 1e-12)
        );
    }

    /// A walk stops where it meets the boundary of an open mesh, on the boundary edge.
    #[test]
    fn walk_stops_at_the_boundary() {
        let (v, mut f) = cube();
        f.drain(2..4); // no top
        let w = Walker::new(&v, &f).expect("an open box");
        let s0 = w
            .start(1, DVec3::new(0.5, 0.3, 0.0), Some(DVec3::X))
            .expect("on face 1");
        let s = w
            .step(s0, DVec2::new(3.0, 0.0), &mut Vec::new(), &cancel::never)
            .expect("a move");
        assert!(s.stopped);
        assert!(
            (s.point - DVec3::new(1.0, 0.3, 1.0)).length() < 1e-12,
            "{}",
            s.point
        );
    }

    /// Many walkers in parallel: each exactly as walked alone; errors name the walker.
    #[test]
    fn walk_many_equals_single_walks() {
        for (v, f) in [cube(), tetrahedron()] {
            let w = Walker::new(&v, &f).expect("a closed mesh");
            let k = 4;
            let starts: Vec<Start> = (0..f.len())
                .map(|i| {
                    let [a, b, c] = w.corners(i);
                    let dir = (i % 2 == 0).then_some(c - b);
                    (i as i64, (a + b + 2.0 * c) / 4.0, dir)
                })
                .collect();
            let moves: Vec<DVec2> = (0..starts.len() * k)
                .map(|j| DVec2::new(1.0 + 0.37 * j as f64, (0.9 * j as f64).sin()))
                .collect();
            let all = walk_many(&w, &starts, &moves, k, &cancel::never).expect("valid walks");
            assert_eq!(all.len(), starts.len() * (k + 1));
            for (i, &(face, point, dir)) in starts.iter().enumerate() {
                let mut s = w.start(face, point, dir).expect("a start");
                for j in 0..=k {
                    if j > 0 {
                        s = w
                            .step(s, moves[i * k + j - 1], &mut Vec::new(), &cancel::never)
                            .expect("a move");
                    }
                    let got = all[i * (k + 1) + j];
                    assert_eq!(got.face, s.face);
                    assert_eq!(got.stopped, s.stopped);
                    assert_eq!(got.point.to_array(), s.point.to_array());
                    assert_eq!(got.frame.to_cols_array(), s.frame.to_cols_array());
                }
            }
            let mut bad = moves.clone();
            bad[2 * k + 1].x = f64::NAN;
            let err = walk_many(&w, &starts, &bad, k, &cancel::never).unwrap_err();
            assert_eq!(err.arg, "moves");
            assert!(err.msg.starts_with("walker 2"), "{err}");
            assert_eq!(
                walk_many(&w, &starts, &moves[1..], k, &cancel::never)
                    .unwrap_err()
                    .arg,
                "moves"
            );
        }
    }
}

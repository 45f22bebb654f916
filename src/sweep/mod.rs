//! Sweep surfaces: a profile polygon carried along a spine by moving frames, as a triangle
//! mesh with normals and texture coordinates.
//!
//! Ring `i` (one per spine sample) holds the profile vertices
//!
//! ```text
//! v_ij = x_i + M_i (a′_j r_i + b′_j s_i),   (a′, b′) = Rot(θ_i) · (σ_i,a a_j, σ_i,b b_j)
//! ```
//!
//! with the frame `(r_i, s_i, t_i)`, the per-sample scale `σ_i` (per profile axis) and twist
//! `θ_i`. `M_i` is the **mitre stretch**: where the spine turns by the angle `φ` between its
//! incoming and outgoing chords, the ring is stretched by `1/cos(φ/2)` along the in-plane
//! direction of the turn, so that a ring lying in the bisector plane of a corner is exactly
//! the cut of both adjacent straight prisms — the tube keeps its cross-section through the
//! corner instead of pinching (VTK's tube filter leaves this correction commented out).
//! On smoothly sampled curves `1/cos(φ/2) = 1 + κ²h²/8 + …`, a second-order change. The
//! stretch is capped by `miter_limit`.
//!
//! **Faces** join ring `i` to ring `i + 1` (and the last ring to the first on a closed
//! spine) vertex to vertex, two triangles per quad, wound so that the normals point to the
//! right of the profile's direction of travel, which is outwards for a counter-clockwise
//! closed profile; clockwise closed profiles are wound the other way, so closed sweeps always
//! face outwards. Caps are a triangulation of the profile on its own vertices (by monotone
//! pieces, `monotone.rs`) on the first and last rings. Every vertex is shared by all its
//! faces, so closed sweeps and capped open sweeps are watertight by construction.
//!
//! **Alternating diagonals.** A twisted quad `a b c d` (`a b` on ring `i`, `d c` on ring
//! `i + 1`) is not planar; its two splits enclose volumes that differ by the tetrahedron on
//! its corners, `τ/6` with `τ = det(b − a, d − a, c − a)`, one above and one below the
//! bilinear patch through the corners (whose volume is their mean). One diagonal everywhere
//! makes that error add up to first order in the ring spacing `h`, with the sign of the
//! twist. Segments whose quads are not planar (some `|τ| > 10⁻⁹ |b − a| |d − a| |c − d|`:
//! twist, torsion of the spine, a closing twist spread along a loop) are split along `a c`
//! on even `i` and along `b d` on odd `i`, so the errors of neighbouring segments cancel and
//! the volume converges at second order, like the bilinear surface (the same cancellation as
//! the alternating rows of the "4-8"/checkerboard splits, with every vertex of valence 6).
//! Segments of planar quads (straight and circular spines without twist) keep `a c`
//! everywhere: the split does not change their volume, and the regular triangulation is the
//! one discrete curvature operators converge on. The test is done in `f64` on the geometry,
//! so `f32` output has the same faces.
//!
//! **Output precision.** Everything is computed in `f64`; the buffers are `f64` or `f32`
//! ([`Real`]) and the face indices `i64` or `i32` ([`Index`]), written directly (no
//! conversion pass). Normals and uv are optional.
//!
//! **Normals** are those of the smooth swept surface `S(u, v)`: `n ∝ S_v × S_u` from
//! differences of the ring vertices — around the profile (central) and along the spine (the
//! three-point derivative in arc length, one-sided at open ends). They therefore include the
//! tilt `−dρ/ds · t` of a variable radius, the twist and the mitre, and are exact on
//! cylinders, cones and tori sampled evenly.
//!
//! **Fold-over.** Where the profile reaches past the centre of curvature (`1 − κ ρ cos ψ ≤ 0`)
//! the surface folds over itself. The discrete test used here: every rail edge
//! `v_{i+1,j} − v_{ij}` must advance along both `t_i` and `t_{i+1}`; segments that fail are
//! reported.
//!
//! **Texture coordinates**: `u` = arc length of the spine polyline at the ring, `v` = arc
//! length around the profile divided by its perimeter.

mod monotone;
pub mod profile;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::OnceLock;

use crate::cancel::{self, Cancel};
use crate::error::{InputError, Result};
use crate::frames::validate;
pub use profile::Profile;

/// One spine with its per-sample data (all slices have the spine's row count).
#[derive(Debug, Clone, Copy)]
pub struct Spine<'a> {
    pub points: &'a [DVec3],
    /// Row-major `(n, 3, 3)` frames, columns `(r, s, t)`.
    pub frames: &'a [[f64; 9]],
    /// Scale along the profile's `(a, b)` axes: one row per sample, or a single row for
    /// all of them.
    pub scale: &'a [DVec2],
    /// Twist about the tangent, radians (empty: none).
    pub twist: &'a [f64],
}

/// Options shared by all spines of a sweep.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub closed: bool,
    pub caps: bool,
    pub miter_limit: f64,
    /// Duplicate the vertices on the texture seams (see [`sweep_many`]).
    pub split_seams: bool,
}

/// A triangle mesh.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub vertices: Vec<DVec3>,
    pub faces: Vec<[i64; 3]>,
    pub normals: Vec<DVec3>,
    /// Texture coordinates: `u` spine arc length, `v` profile arc length / perimeter.
    pub uv: Vec<DVec2>,
    /// Spine rows (global, as given) starting a segment where the sweep folds over.
    pub folds: Vec<usize>,
}

#[inline]
fn columns(f: &[f64; 9]) -> (DVec3, DVec3, DVec3) {
    (
        DVec3::new(f[0], f[3], f[6]),
        DVec3::new(f[1], f[4], f[7]),
        DVec3::new(f[2], f[5], f[8]),
    )
}

/// The size of one spine's part of the mesh, from its rows alone (and, on a closed spine,
/// whether its last point repeats the first); [`check_spine`] checks the spine.
#[derive(Debug, Clone, Copy)]
struct Size {
    /// Distinct spine samples.
    rings: usize,
    segments: usize,
    caps: bool,
    /// Rings stored (one more than `rings` for a closed spine with split seams).
    stored_rings: usize,
    /// Vertices per stored ring (one more than the profile for a closed profile with split
    /// seams).
    cols: usize,
}

impl Size {
    /// The size of the sweep of spine `x` (a spine too short to sweep gets a size, which its
    /// check refuses).
    fn of(x: &[DVec3], opts: &Options, p: &Profile) -> Size {
        let n = x.len();
        let mut rings = n;
        if opts.closed && n >= 2 && validate::coincide(x[0], x[n - 1]) {
            rings -= 1;
        }
        Size {
            rings,
            segments: if opts.closed {
                rings
            } else {
                rings.saturating_sub(1)
            },
            caps: opts.caps && !opts.closed && p.closed,
            stored_rings: rings + usize::from(opts.closed && opts.split_seams),
            cols: p.len() + usize::from(p.closed && opts.split_seams),
        }
    }
    fn vertices(&self) -> usize {
        self.stored_rings * self.cols
    }
    fn faces(&self, p: &Profile) -> usize {
        let edges = if p.closed { p.len() } else { p.len() - 1 };
        2 * self.segments * edges + if self.caps { 2 * (p.len() - 2) } else { 0 }
    }
}

/// A checked spine: its [`Size`] and the arc length of the spine polyline at every ring
/// (and after the closing chord).
#[derive(Debug, Clone)]
struct Plan {
    size: Size,
    arc: Vec<f64>,
}

impl std::ops::Deref for Plan {
    type Target = Size;
    fn deref(&self) -> &Size {
        &self.size
    }
}

/// Check one spine and plan its part of the mesh; polls `cancel` between its passes and
/// before every block of rows within them, and returns `None` once it says stop (see
/// [`crate::cancel`]). `given`: the frames came with the input and are checked too (frames
/// computed here are rotations along the spine by construction).
fn check_spine(
    s: &Spine,
    opts: &Options,
    p: &Profile,
    given: bool,
    cancel: Cancel<'_>,
) -> Result<Option<Plan>> {
    let n = s.points.len();
    if s.frames.len() != n {
        return Err(InputError::new(
            "frames",
            format!("has {} rows but points has {n}", s.frames.len()),
        ));
    }
    if s.scale.len() != n && s.scale.len() != 1 {
        return Err(InputError::new(
            "scale",
            format!("has {} rows but points has {n}", s.scale.len()),
        ));
    }
    if !s.twist.is_empty() && s.twist.len() != n {
        return Err(InputError::new(
            "twist",
            format!("has {} entries but points has {n} rows", s.twist.len()),
        ));
    }
    validate::finite_cancellable("points", s.points, cancel)?;
    if cancel() {
        return Ok(None);
    }
    let size = Size::of(s.points, opts, p);
    let rings = size.rings;
    let min = if opts.closed { 3 } else { 2 };
    if rings < min {
        return Err(InputError::new(
            "points",
            format!(
                "a{} spine needs at least {min} distinct points, got {rings}",
                if opts.closed { " closed" } else { "n open" }
            ),
        ));
    }
    let chords = validate::chords_cancellable(&s.points[..rings], opts.closed, cancel)?;
    if cancel() {
        return Ok(None);
    }
    let bad_frame = match given {
        true => validate::first_bad_cancellable(s.frames, validate::is_rotation, cancel),
        false => None,
    };
    if let Some(i) = bad_frame {
        return Err(InputError::new(
            "frames",
            format!(
                "row {i} is not a rotation matrix (columns r, s, t must be orthonormal and \
                 right-handed; use spinal.frames)"
            ),
        ));
    }
    if cancel() {
        return Ok(None);
    }
    let against = match given {
        true => against_spine(&s.points[..rings], s.frames, opts.closed, cancel),
        false => None,
    };
    let hint = "the sweep would be inside out there; frames must be computed for the points \
                in their order (spinal.frames(points))";
    match against {
        Some(Against::Row(k)) => {
            return Err(InputError::new(
                "frames",
                format!(
                    "the tangent column t of row {k} points against the spine (negative \
                     dot product with the chord{} at point {k}): {hint}",
                    if opts.closed || (k > 0 && k + 1 < rings) {
                        "s"
                    } else {
                        ""
                    }
                ),
            ));
        }
        Some(Against::Segment(i)) => {
            let j = if i + 1 == rings { 0 } else { i + 1 };
            return Err(InputError::new(
                "frames",
                format!(
                    "the tangent column t of rows {i} and {j} points against the spine (from \
                     point {i} to point {j}): {hint}"
                ),
            ));
        }
        None => {}
    }
    if cancel() {
        return Ok(None);
    }
    let positive = |v: &DVec2| v.x > 0.0 && v.y > 0.0 && v.is_finite();
    if let Some(i) = validate::first_bad_cancellable(s.scale, positive, cancel) {
        return Err(InputError::new(
            "scale",
            format!(
                "must be positive and finite, got {} at row {i} (for a pointed end use a \
                 small positive value)",
                shown(s.scale[i])
            ),
        ));
    }
    if let Some(i) = validate::first_bad_cancellable(s.twist, |v| v.is_finite(), cancel) {
        return Err(InputError::new(
            "twist",
            format!("non-finite value at row {i}"),
        ));
    }
    if cancel() {
        return Ok(None);
    }
    // the arc lengths in the chords' buffer (no second array of the spine's length)
    let mut arc = chords;
    arc.reserve_exact(1);
    arc.insert(0, 0.0);
    let mut acc = 0.0;
    for a in arc.iter_mut() {
        acc += *a;
        *a = acc;
    }
    Ok(Some(Plan { size, arc }))
}

/// A row of the scale as the user gave it: one number for a radius (both factors equal),
/// the pair otherwise.
fn shown(v: DVec2) -> String {
    if v.x == v.y || (v.x.is_nan() && v.y.is_nan()) {
        format!("{}", v.x)
    } else {
        format!("{:?}", v.to_array())
    }
}

/// Where given frames point against the spine, which would turn the mesh there inside out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Against {
    /// The tangent `t_k` of row `k` has a negative dot product with every chord at that row
    /// (both `x_k − x_{k−1}` and `x_{k+1} − x_k`; the one chord at an open end): a reversed
    /// frame. A tangent estimated from the points (any weighting of the two chords' unit
    /// vectors) agrees with at least one of them, however tight the turn.
    Row(usize),
    /// The chord of segment `i` (from sample `i` to the next) runs against the tangents of
    /// both its ends, `(x_{i+1} − x_i)·t_i < 0` and `(x_{i+1} − x_i)·t_{i+1} < 0`.
    Segment(usize),
}

/// The first row `k` where the frames point against the spine ([`Against`]; a row's own
/// test first, then the segment that starts there). Polls `cancel` before every block of
/// rows and finds nothing in the blocks after it says stop.
fn against_spine(
    x: &[DVec3],
    frames: &[[f64; 9]],
    closed: bool,
    cancel: Cancel<'_>,
) -> Option<Against> {
    const BLOCK: usize = 1 << 14;
    let n = x.len();
    let t = |k: usize| columns(&frames[k]).2;
    // the chord from row k to the next (None past the end of an open spine)
    let chord = |k: usize| match (k + 1 == n, closed) {
        (false, _) => Some(x[k + 1] - x[k]),
        (true, true) => Some(x[0] - x[k]),
        (true, false) => None,
    };
    let before = |k: usize| match (k, closed) {
        (0, false) => None,
        (0, true) => chord(n - 1),
        _ => chord(k - 1),
    };
    (0..n.div_ceil(BLOCK)).into_par_iter().find_map_first(|b| {
        if cancel() {
            return None;
        }
        (b * BLOCK..((b + 1) * BLOCK).min(n)).find_map(|k| {
            let tk = t(k);
            let (cin, cout) = (before(k), chord(k));
            let against = |c: Option<DVec3>| c.is_none_or(|c| c.dot(tk) < 0.0);
            if (cin.is_some() || cout.is_some()) && against(cin) && against(cout) {
                return Some(Against::Row(k));
            }
            let j = if k + 1 == n { 0 } else { k + 1 };
            cout.filter(|c| c.dot(tk) < 0.0 && c.dot(t(j)) < 0.0)
                .map(|_| Against::Segment(k))
        })
    })
}

/// The unit vector along a chord of the spine (zero for a zero chord), scaled by the largest
/// component before squaring: any finite spine size.
#[inline(always)]
fn unit_chord(v: DVec3) -> DVec3 {
    crate::math::scale::normalize(v).unwrap_or(DVec3::ZERO)
}

/// Mitre stretch at a ring between the unit chords `din` (in) and `dout` (out) of the spine
/// ([`unit_chord`]) with tangent `t`: `(factor − 1, unit direction)`, or zero where the
/// spine is straight.
fn mitre(din: DVec3, dout: DVec3, t: DVec3, limit: f64) -> (f64, DVec3) {
    let half_cos = 0.5 * (1.0 + din.dot(dout)); // cos²(φ/2)
    let k = din - dout;
    let k = k - k.dot(t) * t;
    let kl = k.length();
    if !(kl > 1e-12) || !(half_cos > 0.0) {
        return (0.0, DVec3::ZERO);
    }
    let factor = (1.0 / half_cos.sqrt()).min(limit);
    (factor - 1.0, k / kl)
}

/// Three-point derivative weights at the middle of samples spaced `h1`, `h2`.
#[inline]
fn central_weights(h1: f64, h2: f64) -> [f64; 3] {
    [
        -h2 / (h1 * (h1 + h2)),
        (h2 - h1) / (h1 * h2),
        h1 / (h2 * (h1 + h2)),
    ]
}

/// Derivative along the spine at ring `i`: three rings and their weights (three-point rule
/// in arc length; one-sided at open ends; two points for a two-sample spine).
fn spine_weights(arc: &[f64], i: usize, r_n: usize, closed: bool) -> ([usize; 3], [f64; 3]) {
    if closed {
        let a = if i == 0 { r_n - 1 } else { i - 1 };
        let b = if i + 1 == r_n { 0 } else { i + 1 };
        let h1 = if i == 0 {
            arc[r_n] - arc[r_n - 1]
        } else {
            arc[i] - arc[i - 1]
        };
        let h2 = arc[i + 1] - arc[i];
        ([a, i, b], central_weights(h1, h2))
    } else if r_n == 2 {
        let h = arc[1] - arc[0];
        ([0, 1, 1], [-1.0 / h, 1.0 / h, 0.0])
    } else if i == 0 || i + 1 == r_n {
        let (i0, i1, i2) = if i == 0 {
            (0, 1, 2)
        } else {
            (r_n - 1, r_n - 2, r_n - 3)
        };
        let h1 = (arc[i1] - arc[i0]).abs();
        let h2 = (arc[i2] - arc[i1]).abs();
        let sg = if i == 0 { 1.0 } else { -1.0 };
        (
            [i0, i1, i2],
            [
                -sg * (2.0 * h1 + h2) / (h1 * (h1 + h2)),
                sg * (h1 + h2) / (h1 * h2),
                -sg * h1 / (h2 * (h1 + h2)),
            ],
        )
    } else {
        let h1 = arc[i] - arc[i - 1];
        let h2 = arc[i + 1] - arc[i];
        ([i - 1, i, i + 1], central_weights(h1, h2))
    }
}

/// Storage of the output coordinates: `f64`, or `f32` rounded from the `f64` results.
pub trait Real: Copy + Send + Sync + 'static {
    fn of(x: f64) -> Self;
    fn to_f64(self) -> f64;
    fn finite(self) -> bool;
}

impl Real for f64 {
    #[inline(always)]
    fn of(x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Real for f32 {
    #[inline(always)]
    fn of(x: f64) -> f32 {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// A spine, profile and scale far from unit size brought near it by powers of two (exact):
/// spine points times `2^k` (`k` from the spine's size), the profile divided by `2^j` (its
/// largest coordinate) and the scale multiplied by `2^(k + j)`, so `x + M (scale ⊙ profile)`
/// is the swept surface times `2^k`. The normals and fold tests multiply lengths, which
/// would overflow or underflow otherwise; [`unscaled`] divides the vertices and arc lengths
/// by `2^k` again as they are written.
struct Scaled {
    k: i32,
    points: Vec<DVec3>,
    profile: Vec<DVec2>,
    scale: Vec<DVec2>,
}

/// The [`Scaled`] input, or `None` when the input is near unit size (or not finite: the
/// checks then report it as given).
///
/// Polls `cancel` between its passes and returns `None` once it says stop (the caller polls
/// again and discards the result).
fn scaled_input(
    points: &[DVec3],
    profile: &[DVec2],
    scale: &[DVec2],
    cancel: Cancel<'_>,
) -> Option<Scaled> {
    use crate::math::scale as s;
    let finite = validate::first_bad_cancellable(points, |p| p.is_finite(), cancel).is_none()
        && !cancel()
        && profile.iter().all(|p| p.is_finite())
        && scale
            .iter()
            .all(|v| v.x > 0.0 && v.y > 0.0 && v.is_finite());
    if !finite {
        return None;
    }
    let (lo, hi) = crate::frames::geometry::bounds(points);
    let k = s::curve_exponent(lo, hi);
    let pmax = profile
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs().max_element()));
    let j = match pmax > 0.0 {
        true => Some(s::exponent(pmax)).filter(|e| e.abs() > s::SAFE_EXP),
        false => None,
    };
    if (k.is_none() && j.is_none()) || cancel() {
        return None;
    }
    let (k, j) = (k.unwrap_or(0), j.unwrap_or(0));
    let mul2 = |v: &DVec2, e: i32| DVec2::new(s::ldexp(v.x, e), s::ldexp(v.y, e));
    Some(Scaled {
        k,
        points: s::scaled(points, k),
        profile: profile.iter().map(|v| mul2(v, -j)).collect(),
        scale: scale.iter().map(|v| mul2(v, k + j)).collect(),
    })
}

/// The output value of a coordinate computed for input scaled by `2^k` ([`scaled_input`]):
/// stored in `R`, then divided by `2^k` again (`k = None`: stored as computed).
#[inline(always)]
fn unscaled<R: Real>(x: f64, k: Option<i32>) -> R {
    match k {
        None => R::of(x),
        Some(k) => R::of(crate::math::scale::ldexp(R::of(x).to_f64(), -k)),
    }
}

/// The error for swept vertex `i` beyond the range of the output type (float64, or float32
/// with `dtype=float32`); named by the profile's `scale`.
fn out_of_range<R>(i: usize) -> InputError {
    InputError::new(
        "scale",
        format!(
            "the swept vertex {i} (spine point + frame · scale · profile) is out of the \
             representable range of the output dtype (float{}); reduce the profile, its \
             scale or the spine",
            8 * std::mem::size_of::<R>()
        ),
    )
}

/// Storage of the face indices: `i64`, or `i32` (the caller checks that they fit).
pub trait Index: Copy + Send + Sync + 'static {
    fn of(i: usize) -> Self;
}

impl Index for i64 {
    #[inline(always)]
    fn of(i: usize) -> i64 {
        i as i64
    }
}

impl Index for i32 {
    #[inline(always)]
    fn of(i: usize) -> i32 {
        i as i32
    }
}

#[inline(always)]
fn put3<R: Real>(v: DVec3) -> [R; 3] {
    [R::of(v.x), R::of(v.y), R::of(v.z)]
}

/// Output buffers of a sweep, sized by [`Layout`]; every element is written.
#[derive(Debug)]
pub struct MeshMut<'a, R, I> {
    pub vertices: &'a mut [[R; 3]],
    pub faces: &'a mut [[I; 3]],
    /// Unit normals (`None`: not computed).
    pub normals: Option<&'a mut [[R; 3]]>,
    /// Texture coordinates `(u, v)`, as in [`Mesh::uv`] (`None`: not computed).
    pub uv: Option<&'a mut [[R; 2]]>,
}

/// The size of a sweep's mesh and of every spine's part of it, from [`layout`].
#[derive(Debug, Clone)]
pub struct Layout {
    sizes: Vec<Size>,
    pub vertices: usize,
    pub faces: usize,
}

impl Layout {
    /// Whether every vertex index of the mesh fits a 32-bit signed integer (the faces can be
    /// stored as int32): at most `i32::MAX` vertices, so 2³¹ vertices or more need int64.
    pub fn indices_fit_i32(&self) -> bool {
        indices_fit_i32(self.vertices)
    }
}

/// Whether the indices `0..vertices` of a mesh of `vertices` vertices fit an `i32`, counted
/// conservatively: at most `i32::MAX` (2³¹ − 1) vertices.
pub fn indices_fit_i32(vertices: usize) -> bool {
    vertices <= i32::MAX as usize
}

/// Output bytes at most per block of rings of [`sweep_one`], or per piece of the columns of
/// a ring larger than this (one poll of the cancel hook per block or piece). A cold output array is faulted in as it is written: on a loaded 2-core machine a
/// block of 4096 vertices (~0.5 MB with normals and uv) then took up to 0.12 s.
const BLOCK_BYTES: usize = 1 << 20;

/// What every spine of a sweep shares: the profile's stored columns, the side faces of a
/// segment, the caps' triangulation and the winding.
struct Shared<'a> {
    p: &'a Profile,
    /// The profile's stored columns, built by the first spine swept in whole rings (a
    /// sweep in pieces of rings builds the columns of each piece as it goes).
    column: OnceLock<Columns>,
    pattern: FacePattern,
    tris: Vec<[usize; 3]>,
    /// −1 where the faces are wound the other way (clockwise closed profiles).
    sign: f64,
    /// Profile edges: one per vertex of a closed profile, one fewer for an open one.
    edges: usize,
}

impl<'a> Shared<'a> {
    /// `cols`: the vertices of a stored ring (the same on every spine); `caps`: some spine
    /// has caps; `cancel` is polled while a non-convex profile's caps are triangulated.
    fn new(p: &'a Profile, cols: usize, caps: bool, cancel: Cancel<'_>) -> Result<Shared<'a>> {
        // Winding: normals to the right of the profile's direction, outward for closed
        // profiles.
        let sign = if p.closed && p.area < 0.0 { -1.0 } else { 1.0 };
        let edges = if p.closed { p.len() } else { p.len() - 1 };
        Ok(Shared {
            p,
            column: OnceLock::new(),
            pattern: FacePattern::of(cols, edges, sign),
            tris: match caps {
                true => p.triangulate_cancellable(cancel)?,
                false => Vec::new(),
            },
            sign,
            edges,
        })
    }
}

/// Sweep one spine into its share of the output buffers (`out.faces`: its side faces, then
/// its caps); returns the rows (global) that start a folded-over segment and the first
/// vertex (local) out of the output type's range. `ring`: scratch for the rings of a block.
#[allow(clippy::too_many_arguments)]
fn sweep_one<R: Real, I: Index>(
    s: &Spine,
    plan: &Plan,
    sh: &Shared,
    opts: &Options,
    vbase: usize,
    rowbase: usize,
    unscale: Option<i32>,
    out: MeshMut<R, I>,
    ring: &mut RingScratch,
    cancel: Cancel<'_>,
) -> (Vec<usize>, Option<usize>) {
    // Rings per parallel task (one poll of `cancel` each): enough work (~4k vertices) to pay
    // for the task, and at most `BLOCK_BYTES` of output, so that a stop waits for little
    // writing even where the writes fault in fresh pages of the output; a ring of more goes
    // in pieces of its columns of at most `BLOCK_BYTES` each
    let ring_bytes = plan.cols
        * (size_of::<[R; 3]>() * (1 + usize::from(out.normals.is_some()))
            + size_of::<[R; 2]>() * usize::from(out.uv.is_some()))
        + 2 * sh.edges * size_of::<[I; 3]>();
    let grain = (4096 / plan.cols).min(BLOCK_BYTES / ring_bytes).max(1);
    let piece = plan.cols.div_ceil(ring_bytes.div_ceil(BLOCK_BYTES));
    let rings = Rings {
        s,
        x: &s.points[..plan.rings],
        plan,
        p: sh.p,
        column: &sh.column,
        closed: opts.closed,
        miter_limit: opts.miter_limit,
        sign: sh.sign,
        rowbase,
    };
    let (side, caps) = out.faces.split_at_mut(2 * plan.segments * sh.edges);
    let side = MeshMut {
        vertices: out.vertices,
        faces: side,
        normals: out.normals,
        uv: out.uv,
    };
    let res = rings.write(
        side,
        &sh.pattern,
        vbase,
        unscale,
        (grain, piece),
        ring,
        cancel,
    );
    // a stopped sweep writes no caps: they lie apart, and each may be the first write to a
    // fresh page of the output
    if plan.caps && !cancel() {
        write_caps(caps, plan, &sh.tris, vbase);
    }
    res
}

/// One ring of the smooth swept surface.
#[derive(Clone, Copy)]
struct Geo {
    /// Spine sample.
    k: usize,
    /// Centre and profile axes of the smooth surface.
    b: (DVec3, DVec3, DVec3),
    /// The axes with the mitre stretch `M(a) = a + (f − 1)(a·k)k`: vertex `j` is
    /// `x + a_j·ma + b_j·mb`.
    ma: DVec3,
    mb: DVec3,
    t: DVec3,
}

/// The stored columns of a profile (`cols`: one more than the profile for split seams),
/// one array per quantity: the profile vertex `p`, the weights `w` of the ring's six cross
/// products in the normal (see [`Rings::normal_crosses`]), from the difference `dp` of the
/// vertex's neighbours (the derivative around the profile, central; one-sided at the ends of
/// an open profile), `(dp.x, dp.y, dp.x p.x, dp.x p.y, dp.y p.x, dp.y p.y)`, and v.
struct Columns {
    px: Vec<f64>,
    py: Vec<f64>,
    /// The edge from the column's profile vertex to the next (`p[j + 1] − p[j]`, wrapping).
    ex: Vec<f64>,
    ey: Vec<f64>,
    w: [Vec<f64>; 6],
    v: Vec<f64>,
}

impl Columns {
    fn of(p: &Profile, cols: usize) -> Columns {
        let mut c = Columns {
            px: Vec::with_capacity(cols),
            py: Vec::with_capacity(cols),
            ex: Vec::with_capacity(cols),
            ey: Vec::with_capacity(cols),
            w: Default::default(),
            v: Vec::with_capacity(cols),
        };
        c.fill(p, 0..cols);
        c
    }

    /// Stored columns `js` (replacing the ones held).
    fn fill(&mut self, p: &Profile, js: Range<usize>) {
        let m = p.len();
        let c = self;
        c.px.clear();
        c.py.clear();
        c.ex.clear();
        c.ey.clear();
        c.w.iter_mut().for_each(Vec::clear);
        c.v.clear();
        for j in js {
            let jj = if j == m { 0 } else { j };
            let (jp, jn) = if p.closed {
                ((jj + m - 1) % m, (jj + 1) % m)
            } else {
                (jj.saturating_sub(1), (jj + 1).min(m - 1))
            };
            let (pj, dp) = (p.points[jj], p.points[jn] - p.points[jp]);
            c.px.push(pj.x);
            c.py.push(pj.y);
            let e = p.points[if jj + 1 == m { 0 } else { jj + 1 }] - pj;
            c.ex.push(e.x);
            c.ey.push(e.y);
            let w = [
                dp.x,
                dp.y,
                dp.x * pj.x,
                dp.x * pj.y,
                dp.y * pj.x,
                dp.y * pj.y,
            ];
            for (a, wk) in c.w.iter_mut().zip(w) {
                a.push(wk);
            }
            c.v.push(if j == m { 1.0 } else { p.v[j] });
        }
    }

    /// The stored columns `r` (a piece of a ring, or all of it).
    #[inline(always)]
    fn view(&self, r: Range<usize>) -> Cols<'_> {
        let w = &self.w;
        Cols {
            px: &self.px[r.clone()],
            py: &self.py[r.clone()],
            ex: &self.ex[r.clone()],
            ey: &self.ey[r.clone()],
            w: [
                &w[0][r.clone()],
                &w[1][r.clone()],
                &w[2][r.clone()],
                &w[3][r.clone()],
                &w[4][r.clone()],
                &w[5][r.clone()],
            ],
            v: &self.v[r],
        }
    }
}

/// A range of the [`Columns`] (all of the same length).
#[derive(Clone, Copy)]
struct Cols<'a> {
    px: &'a [f64],
    py: &'a [f64],
    ex: &'a [f64],
    ey: &'a [f64],
    w: [&'a [f64]; 6],
    v: &'a [f64],
}

/// The side faces of a segment (ring `i` to ring `i + 1`), two triangles per quad of profile
/// edge `j` (`a b` on ring `i`, `d c` on ring `i + 1`, `a`, `d` in column `j`): split along
/// `a c`, or along `b d`, wound by `sign`. Without split seams the last edge of a closed
/// profile wraps to the first column. A profile of at most [`FacePattern::TABLE`] edges keeps
/// the two splits as tables of vertex offsets from ring `i`'s first vertex (ring `i + 1`
/// from `cols` on), which the faces copy; a larger one computes them per edge (no table of
/// the profile's size).
struct FacePattern {
    cols: usize,
    edges: usize,
    /// Wound the other way (clockwise closed profiles).
    flip: bool,
    /// The tables (empty for a large profile).
    ac: Vec<[usize; 3]>,
    bd: Vec<[usize; 3]>,
}

impl FacePattern {
    /// Edges at most of a profile whose faces come from tables (≤ 1.5 MiB of them).
    const TABLE: usize = 1 << 14;

    fn of(cols: usize, edges: usize, sign: f64) -> FacePattern {
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
        }
    }

    /// Faces per segment.
    #[inline(always)]
    fn per_segment(&self) -> usize {
        2 * self.edges
    }

    /// The faces of edges `e0..` (as many as `out` holds pairs) of the segment from the ring
    /// starting at vertex `b0` to the one starting at `b1`.
    #[inline(always)]
    fn write<I: Index>(&self, out: &mut [[I; 3]], bd: bool, b0: usize, b1: usize, e0: usize) {
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

/// One block of rings' share of the outputs (`f`: the faces of its segments): whole rings,
/// or one piece of the columns of one ring (see [`Rings::write`]).
struct Block<'a, R, I> {
    /// The block's first stored ring.
    i0: usize,
    /// The block's columns of every ring (`0..cols`: whole rings).
    j: Range<usize>,
    /// The split of every segment (true: along `b d`) when the block holds a piece of a
    /// ring, indexed by segment (`None`: whole rings, which test their segments here).
    bd: Option<&'a [bool]>,
    v: &'a mut [[R; 3]],
    n: Option<&'a mut [[R; 3]]>,
    u: Option<&'a mut [[R; 2]]>,
    f: &'a mut [[I; 3]],
}

/// One ring's vertices and normals, one array per coordinate, computed column by column
/// with the same operations in the same order as the vector forms `x + p.x ma + p.y mb`,
/// `Σ w_k c_k` and `n / |n|` (so the results are those of glam's `DVec3` arithmetic, bit
/// for bit), in loops without branches that the compiler turns into vector instructions.
struct RingScratch {
    vx: Vec<f64>,
    vy: Vec<f64>,
    vz: Vec<f64>,
    nx: Vec<f64>,
    ny: Vec<f64>,
    nz: Vec<f64>,
    /// `1 / |n|` (usable when finite and positive).
    rcp: Vec<f64>,
}

impl RingScratch {
    /// Room for `n` columns.
    #[inline(always)]
    fn fit(&mut self, n: usize) {
        if self.vx.len() < n {
            *self = RingScratch::new(n);
        }
    }

    fn new(cols: usize) -> RingScratch {
        let z = || vec![0.0; cols];
        RingScratch {
            vx: z(),
            vy: z(),
            vz: z(),
            nx: z(),
            ny: z(),
            nz: z(),
            rcp: z(),
        }
    }

    #[inline(always)]
    fn vertices(&mut self, c: &Cols, g: &Geo) {
        let n = c.px.len();
        let (px, py) = (&c.px[..n], &c.py[..n]);
        let (vx, vy, vz) = (&mut self.vx[..n], &mut self.vy[..n], &mut self.vz[..n]);
        let (x, ma, mb) = (g.b.0, g.ma, g.mb);
        for j in 0..n {
            vx[j] = (x.x + px[j] * ma.x) + py[j] * mb.x;
            vy[j] = (x.y + px[j] * ma.y) + py[j] * mb.y;
            vz[j] = (x.z + px[j] * ma.z) + py[j] * mb.z;
        }
    }

    /// The unit normals `Σ w_k c_k / |Σ w_k c_k|`.
    #[inline(always)]
    fn normals(&mut self, c: &Cols, cr: &[DVec3; 6]) {
        let n = c.px.len();
        let w = [
            &c.w[0][..n],
            &c.w[1][..n],
            &c.w[2][..n],
            &c.w[3][..n],
            &c.w[4][..n],
            &c.w[5][..n],
        ];
        let (nx, ny, nz) = (&mut self.nx[..n], &mut self.ny[..n], &mut self.nz[..n]);
        let rcp = &mut self.rcp[..n];
        for j in 0..n {
            let (w0, w1, w2, w3, w4, w5) = (w[0][j], w[1][j], w[2][j], w[3][j], w[4][j], w[5][j]);
            let x = w0 * cr[0].x
                + w1 * cr[1].x
                + w2 * cr[2].x
                + w3 * cr[3].x
                + w4 * cr[4].x
                + w5 * cr[5].x;
            let y = w0 * cr[0].y
                + w1 * cr[1].y
                + w2 * cr[2].y
                + w3 * cr[3].y
                + w4 * cr[4].y
                + w5 * cr[5].y;
            let z = w0 * cr[0].z
                + w1 * cr[1].z
                + w2 * cr[2].z
                + w3 * cr[3].z
                + w4 * cr[4].z
                + w5 * cr[5].z;
            let r = 1.0 / (x * x + y * y + z * z).sqrt();
            (nx[j], ny[j], nz[j], rcp[j]) = (x * r, y * r, z * r, r);
        }
    }

    /// Is the normal of column `j` usable (a finite, positive `1 / |n|`)?
    #[inline(always)]
    fn usable(&self, j: usize) -> bool {
        let r = self.rcp[j];
        r.is_finite() && r > 0.0
    }

    /// Store the normals; false if some column's normal is not usable (left to the caller).
    #[inline(always)]
    fn put_normals<R: Real>(&self, rn: &mut [[R; 3]]) -> bool {
        let n = rn.len();
        let (nx, ny, nz, rcp) = (&self.nx[..n], &self.ny[..n], &self.nz[..n], &self.rcp[..n]);
        for j in 0..n {
            rn[j] = [R::of(nx[j]), R::of(ny[j]), R::of(nz[j])];
        }
        rcp.iter()
            .fold(true, |a, &r| a & (r.is_finite() & (r > 0.0)))
    }

    /// Store the vertices (divided by `2^k` again for input scaled by it, see [`unscaled`]).
    #[inline(always)]
    fn put_vertices<R: Real>(&self, rv: &mut [[R; 3]], unscale: Option<i32>) {
        let n = rv.len();
        let (vx, vy, vz) = (&self.vx[..n], &self.vy[..n], &self.vz[..n]);
        match unscale {
            None => {
                for j in 0..n {
                    rv[j] = [R::of(vx[j]), R::of(vy[j]), R::of(vz[j])];
                }
            }
            Some(k) => {
                for j in 0..n {
                    let k = Some(k);
                    rv[j] = [unscaled(vx[j], k), unscaled(vy[j], k), unscaled(vz[j], k)];
                }
            }
        }
    }
}

/// The first vertex with a coordinate that is not finite.
#[inline(always)]
fn first_non_finite<R: Real>(rv: &[[R; 3]]) -> Option<usize> {
    let ok = rv.as_flattened().iter().fold(true, |a, x| a & x.finite());
    match ok {
        true => None,
        false => rv.iter().position(|v| !v.iter().all(|x| x.finite())),
    }
}

/// The vertices, normals and uv of one spine's rings, and its fold-over test.
///
/// One pass over the stored rings: positions (mitred), normals of the smooth surface
/// (un-mitred: the mitre is a discretisation correction and would tilt them), uv, and the
/// fold-over test of the segment starting there. Stored ring `i` is spine sample
/// `i mod rings`, stored column `j` is profile vertex `j mod m` (the duplicates of split
/// seams carry u = L and v = 1). Nothing is read back from the outputs but the ring just
/// written; rings go in blocks so that each ring's geometry is computed once (a ring of more
/// than [`BLOCK_BYTES`] goes in pieces of its columns, each with its ring's geometry).
struct Rings<'a> {
    s: &'a Spine<'a>,
    /// The distinct spine samples.
    x: &'a [DVec3],
    plan: &'a Plan,
    p: &'a Profile,
    column: &'a OnceLock<Columns>,
    closed: bool,
    miter_limit: f64,
    /// −1 where the faces are wound the other way (clockwise closed profiles).
    sign: f64,
    /// Global row of spine sample 0 (for the fold reports).
    rowbase: usize,
}

impl Rings<'_> {
    #[inline(always)]
    fn tangent(&self, k: usize) -> DVec3 {
        columns(&self.s.frames[k]).2
    }

    /// Ring `k` of the smooth swept surface: centre and the images of the profile axes.
    #[inline(always)]
    fn base(&self, k: usize) -> (DVec3, DVec3, DVec3) {
        let s = self.s;
        let (r, q, _) = columns(&s.frames[k]);
        let sc = s.scale[if s.scale.len() == 1 { 0 } else { k }];
        let (sn, cs) = if s.twist.is_empty() {
            (0.0, 1.0)
        } else {
            s.twist[k].sin_cos()
        };
        (
            self.x[k],
            sc.x * (cs * r + sn * q),
            sc.y * (cs * q - sn * r),
        )
    }

    /// The unit chord from spine sample `k` to the next ([`unit_chord`]; on a closed spine
    /// the last wraps to the first, on an open one it is zero).
    #[inline(always)]
    fn chord(&self, k: usize) -> DVec3 {
        let n = self.x.len();
        match k + 1 == n {
            false => unit_chord(self.x[k + 1] - self.x[k]),
            true if self.closed => unit_chord(self.x[0] - self.x[k]),
            true => DVec3::ZERO,
        }
    }

    /// Spine sample `k ± 1` (`k < rings`), wrapping around.
    #[inline(always)]
    fn after(&self, k: usize) -> usize {
        if k + 1 == self.x.len() { 0 } else { k + 1 }
    }

    #[inline(always)]
    fn before(&self, k: usize) -> usize {
        if k == 0 { self.x.len() - 1 } else { k - 1 }
    }

    #[inline(always)]
    fn geo(&self, k: usize) -> Geo {
        self.geo_between(k, self.chord(self.before(k)), self.chord(k))
    }

    /// Ring `k` of the mitred sweep, from the unit chords into and out of sample `k`
    /// ([`Rings::chord`] of `k − 1` and `k`: a pass along the spine computes each chord
    /// once).
    #[inline(always)]
    fn geo_between(&self, k: usize, din: DVec3, dout: DVec3) -> Geo {
        let b = self.base(k);
        let end = !self.closed && (k == 0 || k + 1 == self.x.len());
        let (mf, mk) = match end {
            true => (0.0, DVec3::ZERO),
            false => mitre(din, dout, self.tangent(k), self.miter_limit),
        };
        Geo {
            k,
            b,
            ma: b.1 + (mf * b.1.dot(mk)) * mk,
            mb: b.2 + (mf * b.2.dot(mk)) * mk,
            t: self.tangent(k),
        }
    }

    /// All stored rings and the side faces of their segments, `grain` rings per parallel
    /// task (or, for a ring larger than `piece` columns, pieces of `piece` columns of one
    /// ring per task), each output element written once; returns the fold-over rows and the
    /// first vertex (local) out of the output type's range. `vbase`: the spine's first
    /// vertex; `unscale`: see [`unscaled`]; `ring`: scratch for a spine of one block (the
    /// short streamlines of a bundle), which is written here without setting up parallel
    /// tasks.
    #[allow(clippy::too_many_arguments)]
    fn write<R: Real, I: Index>(
        &self,
        out: MeshMut<R, I>,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        (grain, piece): (usize, usize),
        ring: &mut RingScratch,
        cancel: Cancel<'_>,
    ) -> (Vec<usize>, Option<usize>) {
        let cols = self.plan.cols;
        if piece < cols {
            return self.write_pieces(out, pattern, vbase, unscale, piece, cancel);
        }
        let all = self.column.get_or_init(|| Columns::of(self.p, cols));
        let column = &all.view(0..cols);
        let block = grain * cols;
        if out.vertices.len() <= block {
            if cancel() {
                return (Vec::new(), None);
            }
            let b = Block {
                i0: 0,
                j: 0..cols,
                bd: None,
                v: out.vertices,
                n: out.normals,
                u: out.uv,
                f: out.faces,
            };
            return self.block(b, column, pattern, vbase, unscale, ring);
        }
        let blocks = out.vertices.len().div_ceil(block);
        let mut nb: Vec<Option<&mut [[R; 3]]>> = match out.normals {
            Some(a) => a.chunks_mut(block).map(Some).collect(),
            None => Vec::new(),
        };
        nb.resize_with(blocks, || None);
        let mut ub: Vec<Option<&mut [[R; 2]]>> = match out.uv {
            Some(a) => a.chunks_mut(block).map(Some).collect(),
            None => Vec::new(),
        };
        ub.resize_with(blocks, || None);
        let per_block = grain * pattern.per_segment();
        let mut fb: Vec<&mut [[I; 3]]> = out.faces.chunks_mut(per_block).collect();
        fb.resize_with(blocks, || &mut []);
        let jobs: Vec<_> = out
            .vertices
            .chunks_mut(block)
            .zip(nb)
            .zip(ub)
            .zip(fb)
            .enumerate()
            .map(|(bi, (((v, n), u), f))| Block {
                i0: bi * grain,
                j: 0..cols,
                bd: None,
                v,
                n,
                u,
                f,
            })
            .collect();
        let per_block: Vec<(Vec<usize>, Option<usize>)> = jobs
            .into_par_iter()
            .map_init(
                || RingScratch::new(cols),
                |ring, b| match cancel() {
                    true => (Vec::new(), None),
                    false => self.block(b, column, pattern, vbase, unscale, ring),
                },
            )
            .collect();
        let bad = per_block.iter().find_map(|b| b.1);
        (per_block.into_iter().flat_map(|b| b.0).collect(), bad)
    }

    /// [`Rings::write`] for rings of more than `piece` columns: first the split of every
    /// odd segment (is any quad twisted?) piece by piece, then every ring piece by piece,
    /// each piece a parallel task that polls `cancel`, so that no task writes much more
    /// than [`BLOCK_BYTES`] however large the profile. The same operations per column as a
    /// whole ring, so the same bits.
    fn write_pieces<R: Real, I: Index>(
        &self,
        out: MeshMut<R, I>,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        piece: usize,
        cancel: Cancel<'_>,
    ) -> (Vec<usize>, Option<usize>) {
        let (cols, segments) = (self.plan.cols, self.plan.segments);
        let edges = pattern.edges;
        let pieces = cols.div_ceil(piece);
        // the odd segments' splits: (segment, piece) tasks
        let twisted: Vec<bool> = (0..segments / 2 * pieces)
            .into_par_iter()
            .map(|t| {
                let (i, c) = (2 * (t / pieces) + 1, t % pieces);
                let e = (c * piece).min(edges)..((c + 1) * piece).min(edges);
                !cancel() && self.twisted(&self.geo(i), &self.geo(self.after(i)), e)
            })
            .collect();
        if cancel() {
            return (Vec::new(), None);
        }
        let bd: Vec<bool> = (0..segments)
            .map(|i| i % 2 == 1 && twisted[i / 2 * pieces..][..pieces].iter().any(|&t| t))
            .collect();
        // the output of every (ring, piece), in the order of the rings
        let stored = self.plan.stored_rings;
        let mut jobs = Vec::with_capacity(stored * pieces);
        let mut v = out.vertices.chunks_mut(cols);
        let mut n = out.normals.map(|a| a.chunks_mut(cols));
        let mut u = out.uv.map(|a| a.chunks_mut(cols));
        let mut f = out.faces.chunks_mut(pattern.per_segment());
        for i in 0..stored {
            let (Some(rv), rn, ru) = (
                v.next(),
                n.as_mut().and_then(|a| a.next()),
                u.as_mut().and_then(|a| a.next()),
            ) else {
                break;
            };
            let rf = if i < segments { f.next() } else { None };
            let mut rv = rv.chunks_mut(piece);
            let mut rn = rn.map(|a| a.chunks_mut(piece));
            let mut ru = ru.map(|a| a.chunks_mut(piece));
            let mut rf = rf.map(|a| a.chunks_mut(2 * piece));
            for c in 0..pieces {
                let (Some(pv), pn, pu) = (
                    rv.next(),
                    rn.as_mut().and_then(|a| a.next()),
                    ru.as_mut().and_then(|a| a.next()),
                ) else {
                    break;
                };
                let pf = rf.as_mut().and_then(|a| a.next()).unwrap_or(&mut []);
                jobs.push(Block {
                    i0: i,
                    j: c * piece..((c + 1) * piece).min(cols),
                    bd: Some(&bd),
                    v: pv,
                    n: pn,
                    u: pu,
                    f: pf,
                });
            }
        }
        let per_piece: Vec<(Vec<usize>, Option<usize>)> = jobs
            .into_par_iter()
            .map_init(
                || (RingScratch::new(piece), Columns::of(self.p, 0)),
                |(ring, column), b| match cancel() {
                    true => (Vec::new(), None),
                    false => {
                        column.fill(self.p, b.j.clone());
                        let view = &column.view(0..b.j.len());
                        self.block(b, view, pattern, vbase, unscale, ring)
                    }
                },
            )
            .collect();
        let bad = per_piece.iter().find_map(|b| b.1);
        // a folded segment is reported by each of its pieces that folds
        let mut folds: Vec<usize> = per_piece.into_iter().flat_map(|b| b.0).collect();
        folds.dedup();
        (folds, bad)
    }

    /// One block of rings, [`Rings::block_body`]; on x86-64 processors with AVX2 the same
    /// code compiled for 256-bit vectors (four columns per instruction in the column loops
    /// of [`RingScratch`]; the same IEEE operations, so the same bits), chosen at run time
    /// like the frames' scan (`crate::frames::fused`). Measured with one thread on a
    /// 10⁵-point float32 tube: 110 instead of 204 instructions per vertex in this kernel,
    /// 71–76 ms instead of 82–88 ms for the core call (best of 25, a loaded machine).
    fn block<R: Real, I: Index>(
        &self,
        b: Block<R, I>,
        column: &Cols,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        ring: &mut RingScratch,
    ) -> (Vec<usize>, Option<usize>) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `block_avx2` only needs the processor to support AVX2, checked just
            // above.
            return unsafe { self.block_avx2(b, column, pattern, vbase, unscale, ring) };
        }
        self.block_body(b, column, pattern, vbase, unscale, ring)
    }

    /// [`Rings::block_body`] compiled for AVX2. Safety: call only where AVX2 is available.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn block_avx2<R: Real, I: Index>(
        &self,
        b: Block<R, I>,
        column: &Cols,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        ring: &mut RingScratch,
    ) -> (Vec<usize>, Option<usize>) {
        self.block_body(b, column, pattern, vbase, unscale, ring)
    }

    /// The rings of a block and the faces of their segments: per ring, the vertices and
    /// normals column by column into [`RingScratch`], then stored (with the unscaling and
    /// the range check), uv, the fold-over test and the faces of the block's columns.
    #[inline(always)]
    fn block_body<R: Real, I: Index>(
        &self,
        b: Block<R, I>,
        column: &Cols,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        ring: &mut RingScratch,
    ) -> (Vec<usize>, Option<usize>) {
        let (r_n, cols, stored) = (self.plan.rings, self.plan.cols, self.plan.stored_rings);
        let arc = &self.plan.arc[..];
        let Block {
            i0,
            j: js,
            bd: given_bd,
            v: bv,
            n: mut bn,
            u: mut bu,
            f: bf,
        } = b;
        let width = js.len();
        ring.fit(width);
        // the block's edges of every segment and their faces
        let edges = js.start.min(pattern.edges)..js.end.min(pattern.edges);
        let per_segment = 2 * edges.len();
        let (mut folds, mut bad) = (Vec::new(), None);
        // the unit chords out of the previous, current and next ring's samples
        let k0 = if i0 >= r_n { i0 - r_n } else { i0 };
        let (kp, kn) = (self.before(k0), self.after(k0));
        let (cp, mut cc) = (self.chord(kp), self.chord(k0));
        let mut prev = self.geo_between(kp, self.chord(self.before(kp)), cp);
        let mut cur = self.geo_between(k0, cp, cc);
        let mut kn = kn;
        for (di, rv) in bv.chunks_mut(width).enumerate() {
            let i = i0 + di;
            let cn = self.chord(kn);
            let next = self.geo_between(kn, cc, cn);
            let span = di * width..(di + 1) * width;
            ring.vertices(column, &cur);
            ring.put_vertices(rv, unscale);
            if let Some(bn) = bn.as_deref_mut() {
                ring.normals(column, &self.normal_crosses([&prev, &cur, &next]));
                let rn = &mut bn[span.clone()];
                if !ring.put_normals(rn) {
                    // a degenerate spine derivative: the normal of the ring plane
                    for (j, n) in rn.iter_mut().enumerate() {
                        if !ring.usable(j) {
                            let e = column.w[0][j] * cur.b.1 + column.w[1][j] * cur.b.2;
                            let e = (self.sign * e.cross(cur.t)).try_normalize();
                            *n = put3(e.unwrap_or(cur.t));
                        }
                    }
                }
            }
            if bad.is_none() {
                bad = first_non_finite(rv).map(|j| i * cols + js.start + j);
            }
            if let Some(bu) = bu.as_deref_mut() {
                let u = unscaled::<R>(arc[i], unscale);
                for (w, &v) in bu[span].iter_mut().zip(column.v) {
                    *w = [u, R::of(v)];
                }
            }
            if i < self.plan.segments {
                if self.folds_over(&cur, &next, column) {
                    folds.push(self.rowbase + i);
                }
                // split along b d on the odd twisted segments
                let bd = match given_bd {
                    Some(bd) => bd[i],
                    None => i % 2 == 1 && self.twisted_ring(&cur, &next, column, pattern.edges),
                };
                let i1 = if i + 1 == stored { 0 } else { i + 1 };
                let faces = &mut bf[di * per_segment..(di + 1) * per_segment];
                let (b0, b1) = (vbase + i * cols, vbase + i1 * cols);
                pattern.write(faces, bd, b0, b1, edges.start);
            }
            (prev, cur, cc) = (cur, next, cn);
            kn = self.after(kn);
        }
        (folds, bad)
    }

    /// d/ds of ring `cur` (three-point rule in arc length): the same weights on centres and
    /// axes; the neighbouring rings are at hand.
    #[inline(always)]
    fn spine_derivative(&self, [prev, cur, next]: [&Geo; 3]) -> (DVec3, DVec3, DVec3) {
        let k = cur.k;
        let (idx, w) = spine_weights(&self.plan.arc, k, self.plan.rings, self.closed);
        let (mut dx, mut da, mut db) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        if idx == [prev.k, k, next.k] {
            // the rule on the neighbours at hand (inside the spine, or closed), in the same
            // order as below
            for (wi, bi) in w.into_iter().zip([prev.b, cur.b, next.b]) {
                dx += wi * bi.0;
                da += wi * bi.1;
                db += wi * bi.2;
            }
            return (dx, da, db);
        }
        for (&ii, &wi) in idx.iter().zip(&w) {
            let bi = match ii {
                _ if ii == k => cur.b,
                _ if ii == next.k => next.b,
                _ if ii == prev.k => prev.b,
                _ => self.base(ii),
            };
            dx += wi * bi.0;
            da += wi * bi.1;
            db += wi * bi.2;
        }
        (dx, da, db)
    }

    /// The normal S_v × S_u of ring `cur` with S_v ∝ e = dp.x b₁ + dp.y b₂ (around the
    /// profile) and S_u = dx + p.x da + p.y db (along the spine) is bilinear in a column's
    /// (dp, p): six cross products per ring (returned here), six weights per column.
    #[inline(always)]
    fn normal_crosses(&self, geo: [&Geo; 3]) -> [DVec3; 6] {
        let (b, sign) = (geo[1].b, self.sign);
        let (dx, da, db) = self.spine_derivative(geo);
        [
            sign * b.1.cross(dx),
            sign * b.2.cross(dx),
            sign * b.1.cross(da),
            sign * b.1.cross(db),
            sign * b.2.cross(da),
            sign * b.2.cross(db),
        ]
    }

    /// Are the quads of profile edges `edges` of the segment from `cur` to `next` twisted (not
    /// planar)? The quad of
    /// profile edge `p → p + e` has `b − a = A e`, `c − d = A′ e` and
    /// `d − a = Δx + (A′ − A) p`, with `A = (ma, mb)`; `τ = det(b − a, d − a, c − d)`.
    #[inline(always)]
    fn twisted(&self, cur: &Geo, next: &Geo, edges: Range<usize>) -> bool {
        let (dx, dma, dmb) = (next.b.0 - cur.b.0, next.ma - cur.ma, next.mb - cur.mb);
        let pts = &self.p.points;
        let m = pts.len();
        edges.into_iter().any(|j| {
            let (p, e) = (pts[j], pts[if j + 1 == m { 0 } else { j + 1 }] - pts[j]);
            let u = e.x * cur.ma + e.y * cur.mb;
            let w = e.x * next.ma + e.y * next.mb;
            let v = dx + p.x * dma + p.y * dmb;
            let tau = u.cross(v).dot(w);
            // |τ| > 10⁻⁹ |u| |v| |w| decided on the squares (no square roots) where they are
            // clear of it by 10⁻¹², far more than the few roundings of either side
            let (t2, s2) = (tau * tau, 1e-18 * (u.dot(u) * v.dot(v) * w.dot(w)));
            if s2 > 1e-290 && s2.is_finite() {
                if t2 > s2 * (1.0 + 1e-12) {
                    return true;
                }
                if t2 < s2 * (1.0 - 1e-12) {
                    return false;
                }
            }
            tau.abs() > 1e-9 * (u.length() * v.length() * w.length())
        })
    }

    /// [`Rings::twisted`] on edges `0..edges` of whole rings (`column`: all the stored
    /// columns): the same test on every edge without branches (a loop the compiler turns
    /// into vector instructions), deciding where every edge is clear of the threshold on
    /// the squares; where one is not, [`Rings::twisted`] decides (the test is an or over
    /// the edges, so the same answer).
    #[inline(always)]
    fn twisted_ring(&self, cur: &Geo, next: &Geo, column: &Cols, edges: usize) -> bool {
        let (dx, dma, dmb) = (next.b.0 - cur.b.0, next.ma - cur.ma, next.mb - cur.mb);
        let n = edges.min(column.px.len());
        let (px, py) = (&column.px[..n], &column.py[..n]);
        let (ex, ey) = (&column.ex[..n], &column.ey[..n]);
        let (mut yes, mut unsure) = (false, false);
        for j in 0..n {
            let u = ex[j] * cur.ma + ey[j] * cur.mb;
            let w = ex[j] * next.ma + ey[j] * next.mb;
            let v = dx + px[j] * dma + py[j] * dmb;
            let tau = u.cross(v).dot(w);
            let (t2, s2) = (tau * tau, 1e-18 * (u.dot(u) * v.dot(v) * w.dot(w)));
            let clear = (s2 > 1e-290) & s2.is_finite();
            let (hi, lo) = (t2 > s2 * (1.0 + 1e-12), t2 < s2 * (1.0 - 1e-12));
            yes |= clear & hi;
            unsure |= !(clear & (hi | lo));
        }
        yes || (unsure && self.twisted(cur, next, 0..edges))
    }

    /// Fold-over of the segment from `cur` to `next`: rail edges must advance along both
    /// tangents. The rail edge of profile vertex p is (x′ − x) + p_a (ma′ − ma) + p_b (mb′ − mb),
    /// so its components along t and t′ are affine in p.
    #[inline(always)]
    fn folds_over(&self, cur: &Geo, next: &Geo, column: &Cols) -> bool {
        let (dx0, dma, dmb) = (next.b.0 - cur.b.0, next.ma - cur.ma, next.mb - cur.mb);
        let along = |t: DVec3| (dx0.dot(t), DVec2::new(dma.dot(t), dmb.dot(t)));
        let ((c1, g1), (c2, g2)) = (along(cur.t), along(next.t));
        // over the stored columns (the profile's vertices; a seam's copy repeats the first),
        // without branches
        let (px, py) = (column.px, &column.py[..column.px.len()]);
        let ok = px.iter().zip(py).fold(true, |a, (&x, &y)| {
            a & (c1 + (x * g1.x + y * g1.y) > 0.0) & (c2 + (x * g2.x + y * g2.y) > 0.0)
        });
        !ok
    }
}

/// Caps: the profile's triangulation `tris` on the first ring (facing −t) and the last (+t).
fn write_caps<I: Index>(caps: &mut [[I; 3]], plan: &Plan, tris: &[[usize; 3]], vbase: usize) {
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

fn part<'a>(all: &Spine<'a>, offsets: &[usize], c: usize) -> Spine<'a> {
    let (a, b) = (offsets[c], offsets[c + 1]);
    Spine {
        points: &all.points[a..b],
        frames: if all.frames.is_empty() {
            &[]
        } else {
            &all.frames[a..b]
        },
        scale: if all.scale.len() == 1 {
            all.scale
        } else {
            &all.scale[a..b]
        },
        twist: if all.twist.is_empty() {
            &[]
        } else {
            &all.twist[a..b]
        },
    }
}

/// Where the frames of a sweep come from.
#[derive(Debug, Clone, Copy)]
pub enum FrameSource<'a> {
    /// The spine's `frames`, as given (checked: rotations whose tangents follow the spine).
    Given,
    /// The rotation-minimising frames of `spinal.frames(points)` with its defaults (double
    /// reflection, Wang et al. 2008, with the five-point tangents, or with the given
    /// `tangents`), computed for each spine as it is swept, into a buffer that the spines of
    /// one parallel task share: the frames of a whole bundle never exist at once. The
    /// spine's `frames` are then empty.
    Rmf { tangents: Option<&'a [DVec3]> },
}

/// The frames of spine `c` (rows `offsets[c]..offsets[c + 1]` of `points` and `tangents`)
/// as `spinal.frames` computes them for a bundle (the same call on the same rows, so the
/// same bits), into `buf` (grown as needed, fallibly).
fn rmf_into(
    points: &[DVec3],
    tangents: Option<&[DVec3]>,
    offsets: &[usize],
    c: usize,
    closed: bool,
    buf: &mut Vec<[f64; 9]>,
    cancel: Cancel<'_>,
) -> Result<()> {
    let (a, b) = (offsets[c], offsets[c + 1]);
    let n = b - a;
    if buf.len() < n {
        buf.try_reserve_exact(n - buf.len())
            .map_err(|_| InputError::out_of_memory("frames", n, 72))?;
        buf.resize(n, [0.0; 9]);
    }
    let req = crate::frames::Request {
        points: Some(&points[a..b]),
        tangents: tangents.map(|t| &t[a..b]),
        closed,
        ..crate::frames::Request::default()
    };
    crate::frames::compute_into_cancellable(&req, buf[..n].as_flattened_mut(), cancel)?;
    Ok(())
}

/// An error about spine `c` of a bundle, prefixed with the curve (as `spinal.frames` and
/// the sweep's checks name it).
fn in_curve(e: InputError, offsets: &[usize], c: usize) -> InputError {
    if offsets.len() > 2 {
        let (a, b) = (offsets[c], offsets[c + 1]);
        e.context(&format!("curve {c} (rows {a} to {})", b.max(1) - 1))
    } else {
        e
    }
}

/// Size the mesh of a bundle of spines (`offsets[c]..offsets[c+1]` are the rows of spine `c`
/// in the flat arrays): the sizes come from the row counts, and each spine is checked as it
/// is swept.
pub fn layout(all: &Spine, offsets: &[usize], profile: &Profile, opts: &Options) -> Result<Layout> {
    let lay = layout_cancellable(all, offsets, profile, opts, &cancel::never)?;
    Ok(lay.expect("a hook that never stops"))
}

/// [`layout`] that polls `cancel` before every block of curves, and returns `None` once it
/// says stop (see [`crate::cancel`]).
pub fn layout_cancellable(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
    cancel: Cancel<'_>,
) -> Result<Option<Layout>> {
    const BLOCK: usize = 1 << 14;
    let curves = offsets.len().saturating_sub(1);
    let n = all.points.len();
    validate::offsets(offsets, n)?;
    if !(opts.miter_limit >= 1.0) {
        return Err(InputError::new(
            "miter_limit",
            format!(
                "must be ≥ 1 (1 disables the mitre stretch), got {}",
                opts.miter_limit
            ),
        ));
    }
    let mut sizes = crate::alloc::with_capacity("sweep layout", curves)?;
    for c in 0..curves {
        if c % BLOCK == 0 && cancel() {
            return Ok(None);
        }
        let x = &all.points[offsets[c]..offsets[c + 1]];
        sizes.push(Size::of(x, opts, profile));
    }
    Ok(Some(Layout {
        vertices: sizes.iter().map(Size::vertices).sum(),
        faces: sizes.iter().map(|s| s.faces(profile)).sum(),
        sizes,
    }))
}

/// What sweeping one spine gave: its fold-over rows and first vertex out of range, or the
/// error of its frames or of its checks, or nothing (stopped).
enum Outcome {
    Swept(Vec<usize>, Option<usize>),
    Frames(InputError),
    Checks(InputError),
    Stopped,
}

/// The scratch of one parallel task, reused by the spines it sweeps: the frames of one
/// spine ([`FrameSource::Rmf`]) and the columns of one ring.
struct TaskScratch {
    frames: Vec<[f64; 9]>,
    ring: RingScratch,
}

/// A sized sweep, ready to be written: the spine as swept (`view`, brought near unit size
/// when far from it, see [`scaled_input`]), the points as given (the computed frames come
/// from them, as from `spinal.frames`), the frames' source, the layout and the per-call
/// set-up.
struct Sweep<'s> {
    view: Spine<'s>,
    points: &'s [DVec3],
    frames: FrameSource<'s>,
    offsets: &'s [usize],
    opts: &'s Options,
    layout: &'s Layout,
    sh: Shared<'s>,
    /// See [`unscaled`].
    unscale: Option<i32>,
}

impl Sweep<'_> {
    /// Every spine into its part of `out` (spines in parallel): per spine its frames (when
    /// computed here), its checks and its rings. Returns the rows starting a folded-over
    /// segment. Errors come in the order of the earlier two-call form (the frames of all
    /// curves, then the sweep's checks, each by curve): a frames error of any curve, else the
    /// first curve's check error, else a vertex beyond the range of the output type
    /// ([`out_of_range`]).
    fn write<R: Real, I: Index>(
        &self,
        out: MeshMut<R, I>,
        cancel: Cancel<'_>,
    ) -> Result<Vec<usize>> {
        let (nv, nf) = (self.layout.vertices, self.layout.faces);
        assert!(
            out.vertices.len() == nv
                && out.normals.as_ref().is_none_or(|a| a.len() == nv)
                && out.uv.as_ref().is_none_or(|a| a.len() == nv)
                && out.faces.len() == nf,
            "sweep_into: buffers must have the sizes of the layout"
        );
        let mut out = out;
        touch_pages(out.vertices, [R::of(0.0); 3], cancel);
        touch_pages(out.faces, [I::of(0); 3], cancel);
        if let Some(a) = out.normals.as_deref_mut() {
            touch_pages(a, [R::of(0.0); 3], cancel);
        }
        if let Some(a) = out.uv.as_deref_mut() {
            touch_pages(a, [R::of(0.0); 2], cancel);
        }
        // Split the buffers per spine.
        let sizes = &self.layout.sizes;
        let mut jobs = crate::alloc::with_capacity("sweep", sizes.len())?;
        let (mut v, mut nr, mut u, mut f) = (out.vertices, out.normals, out.uv, out.faces);
        let mut vbase = 0;
        for (c, size) in sizes.iter().enumerate() {
            let (k, kf) = (size.vertices(), size.faces(self.sh.p));
            let (v1, v2) = v.split_at_mut(k);
            let (n1, n2) = match nr {
                Some(a) => {
                    let (x, y) = a.split_at_mut(k);
                    (Some(x), Some(y))
                }
                None => (None, None),
            };
            let (u1, u2) = match u {
                Some(a) => {
                    let (x, y) = a.split_at_mut(k);
                    (Some(x), Some(y))
                }
                None => (None, None),
            };
            let (f1, f2) = f.split_at_mut(kf);
            let mine = MeshMut {
                vertices: v1,
                faces: f1,
                normals: n1,
                uv: u1,
            };
            jobs.push((c, vbase, mine));
            (v, nr, u, f) = (v2, n2, u2, f2);
            vbase += k;
        }
        let outcomes: Vec<Outcome> = jobs
            .into_par_iter()
            .map_init(
                || TaskScratch {
                    frames: Vec::new(),
                    ring: RingScratch::new(0),
                },
                |sc, (c, vbase, mine)| self.spine(c, vbase, mine, sc, cancel),
            )
            .collect();
        let (mut check, mut bad) = (None, None);
        for o in &outcomes {
            match o {
                Outcome::Frames(e) => return Err(e.clone()),
                Outcome::Checks(e) if check.is_none() => check = Some(e.clone()),
                Outcome::Swept(_, b) if bad.is_none() => bad = *b,
                _ => {}
            }
        }
        if let Some(e) = check {
            return Err(e);
        }
        if let Some(i) = bad {
            return Err(out_of_range::<R>(i));
        }
        let folds = outcomes.into_iter().flat_map(|o| match o {
            Outcome::Swept(f, _) => f,
            _ => Vec::new(),
        });
        Ok(folds.collect())
    }

    /// Spine `c` into its part of the buffers, starting at vertex `vbase`.
    fn spine<R: Real, I: Index>(
        &self,
        c: usize,
        vbase: usize,
        out: MeshMut<R, I>,
        sc: &mut TaskScratch,
        cancel: Cancel<'_>,
    ) -> Outcome {
        if cancel() {
            return Outcome::Stopped;
        }
        let TaskScratch { frames, ring } = sc;
        let mut s = part(&self.view, self.offsets, c);
        let given = match self.frames {
            FrameSource::Given => true,
            FrameSource::Rmf { tangents } => {
                let (o, closed) = (self.offsets, self.opts.closed);
                if let Err(e) = rmf_into(self.points, tangents, o, c, closed, frames, cancel) {
                    return Outcome::Frames(in_curve(e, o, c));
                }
                if cancel() {
                    return Outcome::Stopped;
                }
                s.frames = &frames[..s.points.len()];
                false
            }
        };
        let plan = match check_spine(&s, self.opts, self.sh.p, given, cancel) {
            Ok(Some(plan)) => plan,
            Ok(None) => return Outcome::Stopped,
            Err(e) => return Outcome::Checks(in_curve(e, self.offsets, c)),
        };
        let (rowbase, unscale) = (self.offsets[c], self.unscale);
        let (folds, bad) = sweep_one(
            &s, &plan, &self.sh, self.opts, vbase, rowbase, unscale, out, ring, cancel,
        );
        Outcome::Swept(folds, bad.map(|i| vbase + i))
    }
}

/// Write `value` into one element of every 4 KiB page of `buf` (the rest of the page is not
/// written), in parallel, polling `cancel` before every 1 MiB: the output's page faults all
/// come at the start of a sweep, from every thread, instead of spread over its writing. An
/// output of fresh pages costs its faults either way, but pages freed shortly before (by the
/// previous call) are then taken before the system hands them back: on a virtual machine with
/// free page reporting (2 MiB blocks handed back to the host from ~2 s after they are freed)
/// a sweep slowed down by other work faulted much of its output in from the host again.
/// Measured on the 2-core machine with three busy processes beside it, 100,000 streamlines
/// (4.3 GB of float32 output) right after the same call: 0.4–2.5 s of system time with
/// this, 2.1–3.8 s without (3 runs each).
fn touch_pages<T: Copy + Send + Sync>(buf: &mut [T], value: T, cancel: Cancel<'_>) {
    let step = (4096 / size_of::<T>()).max(1);
    buf.par_chunks_mut(256 * step).for_each(|c| {
        if !cancel() {
            c.iter_mut().step_by(step).for_each(|e| *e = value);
        }
    });
}

/// The first curve whose frames ([`FrameSource::Rmf`]) fail, with its error; `None` when
/// all can be computed (or `cancel` said stop).
fn first_frames_error(
    points: &[DVec3],
    tangents: Option<&[DVec3]>,
    offsets: &[usize],
    closed: bool,
    cancel: Cancel<'_>,
) -> Option<InputError> {
    let curves = offsets.len().saturating_sub(1);
    let errors: Vec<Option<InputError>> = (0..curves)
        .into_par_iter()
        .map_init(Vec::new, |buf, c| match cancel() {
            true => None,
            false => rmf_into(points, tangents, offsets, c, closed, buf, cancel)
                .err()
                .map(|e| in_curve(e, offsets, c)),
        })
        .collect();
    errors.into_iter().flatten().next()
}

/// Sweep `profile` along every spine of a bundle into buffers of the sizes in `layout`
/// (spines in parallel, each checked as it is swept). Returns the rows starting a
/// folded-over segment; refuses vertices beyond the range of the output type
/// ([`out_of_range`]).
pub fn sweep_into<R: Real, I: Index>(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
    layout: &Layout,
    out: MeshMut<R, I>,
) -> Result<Vec<usize>> {
    let caps = layout.sizes.iter().any(|s| s.caps);
    let cols = layout.sizes.first().map_or(profile.len(), |s| s.cols);
    let sweep = Sweep {
        view: *all,
        points: all.points,
        frames: FrameSource::Given,
        offsets,
        opts,
        layout,
        sh: Shared::new(profile, cols, caps, &cancel::never)?,
        unscale: None,
    };
    sweep.write(out, &cancel::never)
}

/// A sweep checked and sized, to be written into buffers of a chosen precision: the input
/// brought near unit size when it is far from it ([`scaled_input`]; the output is scaled
/// back as it is written), the profile and the [`Layout`]. The spines are checked as they
/// are swept ([`Prepared::write_into`]).
pub struct Prepared<'a> {
    /// The spine as given.
    spine: Spine<'a>,
    offsets: &'a [usize],
    scaled: Option<Scaled>,
    profile: Profile,
    opts: Options,
    frames: FrameSource<'a>,
    pub layout: Layout,
}

impl<'a> Prepared<'a> {
    /// Check a bundle of spines (`offsets` as in [`layout`]) with a profile polygon, and the
    /// spines' `frames`.
    pub fn new(
        spine: Spine<'a>,
        offsets: &'a [usize],
        profile: &[DVec2],
        profile_closed: bool,
        opts: Options,
    ) -> Result<Prepared<'a>> {
        let prep = Prepared::new_cancellable(
            spine,
            offsets,
            profile,
            profile_closed,
            opts,
            FrameSource::Given,
            &cancel::never,
        )?;
        Ok(prep.expect("a hook that never stops"))
    }

    /// [`Prepared::new`] with the frames from `frames`, polling `cancel` between its passes
    /// and before every block of rows within them; returns `None` once it says stop (see
    /// [`crate::cancel`]).
    ///
    /// With computed frames ([`FrameSource::Rmf`]) a bad profile or option is reported only
    /// when every curve's frames can be computed, as when the frames were a call of their
    /// own before the sweep.
    pub fn new_cancellable(
        spine: Spine<'a>,
        offsets: &'a [usize],
        profile: &[DVec2],
        profile_closed: bool,
        opts: Options,
        frames: FrameSource<'a>,
        cancel: Cancel<'_>,
    ) -> Result<Option<Prepared<'a>>> {
        let scaled = scaled_input(spine.points, profile, spine.scale, cancel);
        if cancel() {
            return Ok(None);
        }
        let (points, prof, scale) = match &scaled {
            Some(s) => (&s.points[..], &s.profile[..], &s.scale[..]),
            None => (spine.points, profile, spine.scale),
        };
        let view = Spine {
            points,
            scale,
            ..spine
        };
        let set_up = Profile::new_cancellable(prof, profile_closed, cancel).and_then(|p| {
            let lay = layout_cancellable(&view, offsets, &p, &opts, cancel)?;
            Ok(lay.map(|l| (p, l)))
        });
        let (p, layout) = match (set_up, frames) {
            (Ok(Some(pl)), _) => pl,
            (Ok(None), _) => return Ok(None),
            // a stopped check of the profile is no error
            (Err(e), FrameSource::Given) => {
                return match cancel() {
                    true => Ok(None),
                    false => Err(e),
                };
            }
            (Err(e), FrameSource::Rmf { tangents }) => {
                validate::offsets(offsets, spine.points.len())?;
                let (x, closed) = (spine.points, opts.closed);
                if let Some(fe) = first_frames_error(x, tangents, offsets, closed, cancel) {
                    return Err(fe);
                }
                return match cancel() {
                    true => Ok(None),
                    false => Err(e),
                };
            }
        };
        Ok(Some(Prepared {
            spine,
            offsets,
            scaled,
            profile: p,
            opts,
            frames,
            layout,
        }))
    }

    /// The number of faces of every spine's part of the mesh (its side faces, then its
    /// caps), in the order of the spines: the parts follow one another in the face array.
    pub fn faces_per_spine(&self) -> Vec<usize> {
        self.layout
            .sizes
            .iter()
            .map(|s| s.faces(&self.profile))
            .collect()
    }

    /// The spine the sweep runs on (scaled or as given).
    fn view(&self) -> Spine<'_> {
        match &self.scaled {
            Some(s) => Spine {
                points: &s.points,
                scale: &s.scale,
                ..self.spine
            },
            None => self.spine,
        }
    }

    /// Every spine swept into buffers of the sizes in `self.layout` (see
    /// [`sweep_into`]; with computed frames, each spine's frames first), polling `cancel`
    /// before every spine and every block of rings within them (see [`crate::cancel`]).
    pub fn write_into<R: Real, I: Index>(
        &self,
        out: MeshMut<R, I>,
        cancel: Cancel<'_>,
    ) -> Result<Vec<usize>> {
        let sizes = &self.layout.sizes;
        let caps = sizes.iter().any(|s| s.caps);
        let cols = sizes.first().map_or(self.profile.len(), |s| s.cols);
        let sweep = Sweep {
            view: self.view(),
            points: self.spine.points,
            frames: self.frames,
            offsets: self.offsets,
            opts: &self.opts,
            layout: &self.layout,
            sh: Shared::new(&self.profile, cols, caps, cancel)?,
            unscale: self.scaled.as_ref().map(|s| s.k),
        };
        sweep.write(out, cancel)
    }
}

/// [`layout`] and [`sweep_into`] with freshly allocated buffers.
pub fn sweep_many(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
) -> Result<Mesh> {
    let lay = layout(all, offsets, profile, opts)?;
    let mut mesh = Mesh {
        vertices: vec![DVec3::ZERO; lay.vertices],
        faces: vec![[0; 3]; lay.faces],
        normals: vec![DVec3::ZERO; lay.vertices],
        uv: vec![DVec2::ZERO; lay.vertices],
        folds: Vec::new(),
    };
    mesh.folds = sweep_into(
        all,
        offsets,
        profile,
        opts,
        &lay,
        MeshMut::<f64, i64> {
            vertices: bytemuck::cast_slice_mut(&mut mesh.vertices),
            faces: &mut mesh.faces,
            normals: Some(bytemuck::cast_slice_mut(&mut mesh.normals)),
            uv: Some(bytemuck::cast_slice_mut(&mut mesh.uv)),
        },
    )?;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;
    use std::f64::consts::{PI, TAU};

    /// A row-major frame with columns `r`, `s = t × r`, `t`.
    fn frame(r: DVec3, t: DVec3) -> [f64; 9] {
        let s = t.cross(r);
        [r.x, s.x, t.x, r.y, s.y, t.y, r.z, s.z, t.z]
    }

    /// A straight spine along z, unevenly sampled from 0 to `length`.
    fn straight(n: usize, length: f64) -> (Vec<DVec3>, Vec<[f64; 9]>) {
        let z = |i: usize| {
            let u = i as f64 / (n - 1) as f64;
            length * (u + 0.2 * u * (1.0 - u))
        };
        let x = (0..n).map(|i| DVec3::new(0.3, -0.2, z(i))).collect();
        (x, vec![frame(DVec3::X, DVec3::Z); n])
    }

    /// `n` samples of a circle of radius `radius` in the xy plane with its exact frames.
    fn circle(n: usize, radius: f64) -> (Vec<DVec3>, Vec<[f64; 9]>) {
        (0..n)
            .map(|i| {
                let (s, c) = (TAU * i as f64 / n as f64).sin_cos();
                let r = DVec3::new(c, s, 0.0);
                (radius * r, frame(r, DVec3::new(-s, c, 0.0)))
            })
            .unzip()
    }

    /// A regular polygon and a five-pointed star, both centred on the origin.
    fn polygon(m: usize) -> Vec<DVec2> {
        (0..m)
            .map(|j| DVec2::from_angle(TAU * j as f64 / m as f64))
            .collect()
    }

    fn star() -> Vec<DVec2> {
        (0..10)
            .map(|k| DVec2::from_angle(PI * k as f64 / 5.0) * if k % 2 == 0 { 1.0 } else { 0.4 })
            .collect()
    }

    fn options(closed: bool, caps: bool, split_seams: bool) -> Options {
        Options {
            closed,
            caps,
            miter_limit: 4.0,
            split_seams,
        }
    }

    fn sweep(
        x: &[DVec3],
        frames: &[[f64; 9]],
        scale: &[DVec2],
        profile: &Profile,
        opts: &Options,
    ) -> Mesh {
        let spine = Spine {
            points: x,
            frames,
            scale,
            twist: &[],
        };
        sweep_many(&spine, &[0, x.len()], profile, opts).expect("a valid sweep")
    }

    /// How often each directed edge occurs.
    fn directed(faces: &[[i64; 3]]) -> HashMap<(i64, i64), usize> {
        let mut e = HashMap::new();
        for f in faces {
            for k in 0..3 {
                *e.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
            }
        }
        e
    }

    /// Every undirected edge in exactly two faces, once in each direction: closed,
    /// edge-manifold and consistently wound.
    fn assert_watertight(faces: &[[i64; 3]]) {
        let e = directed(faces);
        for (&(a, b), &k) in &e {
            assert_eq!(k, 1, "edge {a}→{b} used {k} times");
            assert_eq!(e.get(&(b, a)), Some(&1), "edge {a}→{b} has no twin");
        }
    }

    /// Edges used once in one direction and never in the other.
    fn boundary_edges(faces: &[[i64; 3]]) -> usize {
        let e = directed(faces);
        assert!(e.values().all(|&k| k == 1), "a directed edge used twice");
        e.keys().filter(|&&(a, b)| !e.contains_key(&(b, a))).count()
    }

    fn signed_volume(m: &Mesh) -> f64 {
        m.faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| m.vertices[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Every side face's winding agrees with the vertex normals (the side faces come first;
    /// a cap's vertices carry the side's normals).
    fn assert_faces_follow_normals(m: &Mesh, side: usize) {
        for (k, f) in m.faces[..side].iter().enumerate() {
            let [a, b, c] = f.map(|i| m.vertices[i as usize]);
            let nf = (b - a).cross(c - a);
            let nv: DVec3 = f.iter().map(|&i| m.normals[i as usize]).sum();
            assert!(nf.dot(nv) > 0.0, "face {k} is wound against its normals");
        }
    }

    /// The sizes `layout` reports, from the closed forms: `(rings + seam) × (m + seam)`
    /// vertices, two triangles per quad and `m − 2` per cap.
    fn expected_counts(rings: usize, m: usize, pclosed: bool, opts: &Options) -> (usize, usize) {
        let split = usize::from(opts.split_seams);
        let stored = rings + if opts.closed { split } else { 0 };
        let cols = m + if pclosed { split } else { 0 };
        let segments = if opts.closed { rings } else { rings - 1 };
        let edges = if pclosed { m } else { m - 1 };
        let caps = opts.caps && !opts.closed && pclosed;
        let faces = 2 * segments * edges + if caps { 2 * (m - 2) } else { 0 };
        (stored * cols, faces)
    }

    fn assert_counts(x: &[DVec3], frames: &[[f64; 9]], p: &Profile, opts: &Options, rings: usize) {
        let scale = vec![DVec2::ONE; x.len()];
        let spine = Spine {
            points: x,
            frames,
            scale: &scale,
            twist: &[],
        };
        let lay = layout(&spine, &[0, x.len()], p, opts).expect("a valid sweep");
        let (v, f) = expected_counts(rings, p.len(), p.closed, opts);
        assert_eq!((lay.vertices, lay.faces), (v, f), "{opts:?}");
        let mesh = sweep(x, frames, &scale, p, opts);
        assert_eq!((mesh.vertices.len(), mesh.faces.len()), (v, f));
        assert_eq!((mesh.normals.len(), mesh.uv.len()), (v, v));
        let top = v as i64;
        assert!(mesh.faces.iter().flatten().all(|&i| (0..top).contains(&i)));
    }

    /// The faces of a float32 mesh are int32 up to 2³¹ − 1 vertices (its largest index,
    /// 2³¹ − 2, is an `i32`) and int64 from 2³¹ vertices on (the largest counts included).
    #[test]
    fn faces_are_int32_below_two_to_the_31_vertices() {
        for v in [0usize, 1, 3, 1 << 20, 2_147_483_646, 2_147_483_647] {
            assert!(indices_fit_i32(v), "{v}");
            assert!(v == 0 || i32::try_from(v - 1).is_ok());
        }
        for v in [2_147_483_648usize, 2_147_483_649, 4_294_967_295, usize::MAX] {
            assert!(!indices_fit_i32(v), "{v}");
        }
        let lay = |vertices| Layout {
            sizes: Vec::new(),
            vertices,
            faces: 0,
        };
        assert!(lay(2_147_483_647).indices_fit_i32());
        assert!(!lay(2_147_483_648).indices_fit_i32());
    }

    /// A capped straight tube is a closed, consistently wound surface whose volume is that of
    /// the prism (`area · length`) or, with a scale growing along it, of the frustums between
    /// the rings; clockwise and counter-clockwise profiles both face outwards.
    #[test]
    fn capped_straight_tube_is_watertight_with_the_prism_volume() {
        let (x, frames) = straight(17, 3.0);
        let length = x[16].z - x[0].z;
        for pts in [polygon(7), star()] {
            for reverse in [false, true] {
                let mut pts = pts.clone();
                if reverse {
                    pts.reverse();
                }
                let p = Profile::new(&pts, true).expect("a simple polygon");
                let opts = options(false, true, false);
                let mesh = sweep(&x, &frames, &vec![DVec2::ONE; 17], &p, &opts);
                assert_watertight(&mesh.faces);
                let side = 2 * 16 * p.len();
                assert_faces_follow_normals(&mesh, side);
                // the caps face −t at the start and +t at the end
                for (k, f) in mesh.faces[side..].iter().enumerate() {
                    let [a, b, c] = f.map(|i| mesh.vertices[i as usize]);
                    let nz = (b - a).cross(c - a).z;
                    assert!(
                        if k < p.len() - 2 { nz < 0.0 } else { nz > 0.0 },
                        "cap face {k}"
                    );
                }
                let (want, got) = (p.area.abs() * length, signed_volume(&mesh));
                assert!((got - want).abs() < 1e-12 * want, "prism: {got} vs {want}");
                // side normals point away from the axis
                for (v, nv) in mesh.vertices.iter().zip(&mesh.normals) {
                    let out = DVec3::new(v.x - 0.3, v.y + 0.2, 0.0);
                    assert!(out.dot(*nv) > 0.0, "inward normal at {v}");
                }
                // a uniform scale from 1 to 2.5: frustums h/3 (A₁ + A₂ + √(A₁A₂))
                let sigma: Vec<f64> = (0..17).map(|i| 1.0 + 1.5 * (x[i].z / length)).collect();
                let scale: Vec<DVec2> = sigma.iter().map(|&s| DVec2::splat(s)).collect();
                let mesh = sweep(&x, &frames, &scale, &p, &opts);
                assert_watertight(&mesh.faces);
                let want: f64 = (0..16)
                    .map(|i| {
                        let (a1, a2) = (
                            p.area.abs() * sigma[i].powi(2),
                            p.area.abs() * sigma[i + 1].powi(2),
                        );
                        (x[i + 1].z - x[i].z) / 3.0 * (a1 + a2 + (a1 * a2).sqrt())
                    })
                    .sum();
                let got = signed_volume(&mesh);
                assert!(
                    (got - want).abs() < 1e-12 * want,
                    "frustums: {got} vs {want}"
                );
            }
        }
    }

    /// A closed tube around a circle (a mitred polygonal torus) is watertight; each segment
    /// is a prism on its chord cut by the bisector planes, so the volume is the profile's
    /// area times the perimeter of the spine polygon (Pappus for the polygon).
    #[test]
    fn closed_tube_is_watertight_with_the_mitred_volume() {
        let (x, frames) = circle(24, 3.0);
        let perimeter: f64 = (0..24).map(|i| (x[(i + 1) % 24] - x[i]).length()).sum();
        for pts in [polygon(6), star()] {
            for reverse in [false, true] {
                let mut pts = pts.clone();
                if reverse {
                    pts.reverse();
                }
                let p = Profile::new(&pts, true).expect("a simple polygon");
                let opts = options(true, false, false);
                let mesh = sweep(&x, &frames, &vec![DVec2::splat(0.5); 24], &p, &opts);
                assert_watertight(&mesh.faces);
                assert_faces_follow_normals(&mesh, mesh.faces.len());
                assert!(mesh.folds.is_empty());
                let want = 0.25 * p.area.abs() * perimeter;
                let got = signed_volume(&mesh);
                assert!((got - want).abs() < 1e-12 * want, "torus: {got} vs {want}");
                // a repeated first point is dropped: the same mesh
                let (mut y, mut g) = (x.clone(), frames.clone());
                y.push(x[0]);
                g.push(frames[0]);
                let again = sweep(&y, &g, &vec![DVec2::splat(0.5); 25], &p, &opts);
                assert_eq!(again.faces, mesh.faces);
                assert_eq!(again.vertices, mesh.vertices);
            }
        }
    }

    /// Split seams duplicate the vertices on the texture seams: the mesh is then watertight
    /// by position (vertices merged where they coincide bit for bit), not by index.
    #[test]
    fn split_seams_stay_watertight_by_position() {
        let (x, frames) = circle(12, 2.0);
        let p = Profile::new(&polygon(5), true).expect("a pentagon");
        let scale = vec![DVec2::splat(0.4); 12];
        let mesh = sweep(&x, &frames, &scale, &p, &options(true, false, true));
        assert!(boundary_edges(&mesh.faces) > 0, "seams are open by index");
        let mut id: HashMap<[u64; 3], i64> = HashMap::new();
        let merged: Vec<i64> = mesh
            .vertices
            .iter()
            .map(|v| {
                let next = id.len() as i64;
                *id.entry(v.to_array().map(f64::to_bits)).or_insert(next)
            })
            .collect();
        assert_eq!(id.len(), 12 * 5, "one vertex per ring and profile vertex");
        let faces: Vec<[i64; 3]> = mesh
            .faces
            .iter()
            .map(|f| f.map(|i| merged[i as usize]))
            .collect();
        assert_watertight(&faces);
        let plain = sweep(&x, &frames, &scale, &p, &options(true, false, false));
        assert!(
            (signed_volume(&mesh) - signed_volume(&plain)).abs() < 1e-12 * signed_volume(&plain)
        );
        // the seam copies carry u = L (after the closing chord) and v = 1
        let cols = 6;
        for i in 0..=12 {
            assert_eq!(mesh.uv[i * cols + 5].y, 1.0);
        }
        let perimeter: f64 = (0..12).map(|i| (x[(i + 1) % 12] - x[i]).length()).sum();
        assert!((mesh.uv[12 * cols].x - perimeter).abs() < 1e-12);
    }

    /// An open profile sweeps a ribbon: its boundary is the rim of the `rings × m` grid
    /// (two rails and two end rows; on a closed spine, the two rails only).
    #[test]
    fn open_ribbon_has_its_rim_as_boundary() {
        let p = Profile::new(
            &[
                DVec2::new(-1.0, 0.0),
                DVec2::new(0.0, 0.3),
                DVec2::new(1.0, 0.1),
                DVec2::new(2.0, 0.0),
            ],
            false,
        )
        .expect("an open polyline");
        let (x, frames) = straight(9, 2.0);
        let mesh = sweep(
            &x,
            &frames,
            &[DVec2::ONE; 9],
            &p,
            &options(false, true, false),
        );
        assert_eq!(boundary_edges(&mesh.faces), 2 * 8 + 2 * 3);
        let (x, frames) = circle(10, 3.0);
        let mesh = sweep(
            &x,
            &frames,
            &[DVec2::ONE; 10],
            &p,
            &options(true, false, false),
        );
        assert_eq!(boundary_edges(&mesh.faces), 2 * 10);
        assert_faces_follow_normals(&mesh, mesh.faces.len());
    }

    /// `layout` sizes every kind of sweep by the closed forms, and the mesh fills it.
    #[test]
    fn vertex_and_face_counts_equal_the_layout() {
        let closed_p = Profile::new(&star(), true).expect("a star");
        let open_p = Profile::new(&polygon(6)[..4], false).expect("an open polyline");
        let (sx, sf) = straight(6, 1.0);
        let (cx, cf) = circle(8, 2.0);
        for p in [&closed_p, &open_p] {
            for caps in [false, true] {
                for split in [false, true] {
                    assert_counts(&sx, &sf, p, &options(false, caps, split), 6);
                    assert_counts(&cx, &cf, p, &options(true, caps, split), 8);
                }
            }
        }
    }

    /// The run-time choice of the AVX2 build of a block of rings changes no bit (on a
    /// processor without AVX2 both calls run the same code): a helix with a growing scale
    /// and a twist (mitres, tilted normals, twisted quads), a star with split seams.
    #[test]
    fn avx2_block_equals_baseline_block() {
        let n = 300;
        let (x, frames): (Vec<DVec3>, Vec<[f64; 9]>) = (0..n)
            .map(|i| {
                let u = 0.05 * i as f64;
                let t = DVec3::new(-u.sin(), u.cos(), 0.1).normalize();
                (
                    DVec3::new(u.cos(), u.sin(), 0.1 * u),
                    frame(DVec3::new(-u.cos(), -u.sin(), 0.0), t),
                )
            })
            .unzip();
        let scale: Vec<DVec2> = (0..n)
            .map(|i| DVec2::new(0.2 + 0.001 * i as f64, 0.3))
            .collect();
        let twist: Vec<f64> = (0..n).map(|i| 0.01 * i as f64).collect();
        let spine = Spine {
            points: &x,
            frames: &frames,
            scale: &scale,
            twist: &twist,
        };
        let p = Profile::new(&star(), true).expect("a star");
        let opts = options(false, true, true);
        let lay = layout(&spine, &[0, n], &p, &opts).expect("a sized sweep");
        let plan = check_spine(&spine, &opts, &p, true, &cancel::never)
            .expect("a valid sweep")
            .expect("not stopped");
        let plan = &plan;
        let column = OnceLock::from(Columns::of(&p, plan.cols));
        let rings = Rings {
            s: &spine,
            x: &x[..plan.rings],
            plan,
            p: &p,
            column: &column,
            closed: false,
            miter_limit: 4.0,
            sign: 1.0,
            rowbase: 0,
        };
        let pattern = FacePattern::of(plan.cols, p.len(), 1.0);
        type Out = (Vec<[u32; 3]>, Vec<[u32; 3]>, Vec<[u32; 2]>, Vec<[i32; 3]>);
        let run = |avx2: bool| -> (Out, (Vec<usize>, Option<usize>)) {
            let nv = lay.vertices;
            let (mut v, mut nn) = (vec![[0f32; 3]; nv], vec![[0f32; 3]; nv]);
            let mut u = vec![[0f32; 2]; nv];
            let mut f = vec![[0i32; 3]; 2 * plan.segments * p.len()];
            let b = Block {
                i0: 0,
                j: 0..plan.cols,
                bd: None,
                v: &mut v,
                n: Some(&mut nn),
                u: Some(&mut u),
                f: &mut f,
            };
            let ring = &mut RingScratch::new(plan.cols);
            let r = match avx2 {
                true => rings.block(
                    b,
                    &column.get().unwrap().view(0..plan.cols),
                    &pattern,
                    0,
                    None,
                    ring,
                ),
                false => rings.block_body(
                    b,
                    &column.get().unwrap().view(0..plan.cols),
                    &pattern,
                    0,
                    None,
                    ring,
                ),
            };
            let bits3 = |a: Vec<[f32; 3]>| a.iter().map(|t| t.map(f32::to_bits)).collect();
            let uv = u.iter().map(|t| t.map(f32::to_bits)).collect();
            ((bits3(v), bits3(nn), uv, f), r)
        };
        let (a, b) = (run(true), run(false));
        assert!(a.0.3.iter().flatten().any(|&i| i > 0), "faces written");
        assert!(a == b, "the AVX2 block differs from the baseline block");
    }

    /// Everything [`Rings::write`] gives for one spine, in `(grain, piece)` tasks: the bits
    /// of the vertices, normals, uv and faces, the fold rows and the first vertex out of
    /// range.
    fn written(
        spine: &Spine,
        p: &Profile,
        opts: &Options,
        tasks: (usize, usize),
    ) -> (Vec<u64>, Vec<i64>, Vec<usize>, Option<usize>) {
        let plan = check_spine(spine, opts, p, true, &cancel::never)
            .expect("a valid sweep")
            .expect("not stopped");
        let sh = Shared::new(p, plan.cols, false, &cancel::never).unwrap();
        let rings = Rings {
            s: spine,
            x: &spine.points[..plan.rings],
            plan: &plan,
            p,
            column: &sh.column,
            closed: opts.closed,
            miter_limit: opts.miter_limit,
            sign: sh.sign,
            rowbase: 7,
        };
        let nv = plan.vertices();
        let (mut v, mut n) = (vec![[0f64; 3]; nv], vec![[0f64; 3]; nv]);
        let mut u = vec![[0f64; 2]; nv];
        let mut f = vec![[0i64; 3]; 2 * plan.segments * sh.edges];
        let out = MeshMut {
            vertices: &mut v,
            faces: &mut f,
            normals: Some(&mut n),
            uv: Some(&mut u),
        };
        let ring = &mut RingScratch::new(0);
        let (folds, bad) = rings.write(out, &sh.pattern, 3, None, tasks, ring, &cancel::never);
        let bits: Vec<u64> = [v.as_flattened(), n.as_flattened(), u.as_flattened()]
            .concat()
            .iter()
            .map(|x| x.to_bits())
            .collect();
        (bits, f.concat(), folds, bad)
    }

    /// A ring written in pieces of its columns (each a parallel task) gives the bits of
    /// the ring written whole: vertices, normals, uv, faces with the twisted segments' split,
    /// folds and the first vertex out of range. A twisted helix with a star of split seams
    /// (and the same star clockwise), and a tight closed loop of an open profile, which
    /// folds over, with a scale so large at one sample that a ring's vertices overflow.
    #[test]
    fn rings_in_pieces_equal_whole_rings() {
        let n = 40;
        let (x, frames): (Vec<DVec3>, Vec<[f64; 9]>) = (0..n)
            .map(|i| {
                let u = 0.3 * i as f64;
                let t = DVec3::new(-u.sin(), u.cos(), 0.1).normalize();
                (
                    DVec3::new(u.cos(), u.sin(), 0.1 * u),
                    frame(DVec3::new(-u.cos(), -u.sin(), 0.0), t),
                )
            })
            .unzip();
        let scale: Vec<DVec2> = (0..n)
            .map(|i| DVec2::new(0.2 + 0.01 * i as f64, 0.3))
            .collect();
        let twist: Vec<f64> = (0..n).map(|i| 0.05 * i as f64).collect();
        let helix = Spine {
            points: &x,
            frames: &frames,
            scale: &scale,
            twist: &twist,
        };
        let mut cw = star();
        cw.reverse();
        let (cx, cf) = circle(9, 1.0);
        let ribbon: Vec<DVec2> = (0..13)
            .map(|j| DVec2::new(0.3 * j as f64 - 1.5, 0.1 * (j % 3) as f64))
            .collect();
        let mut scales = vec![DVec2::ONE; 9];
        scales[4] = DVec2::splat(1e308);
        let loop_ = Spine {
            points: &cx,
            frames: &cf,
            scale: &scales,
            twist: &[],
        };
        let cases = [
            (
                helix,
                Profile::new(&star(), true),
                options(false, false, true),
            ),
            (helix, Profile::new(&cw, true), options(false, false, false)),
            (
                loop_,
                Profile::new(&ribbon, false),
                options(true, false, true),
            ),
        ];
        for (k, (spine, p, opts)) in cases.into_iter().enumerate() {
            let p = p.expect("a valid profile");
            let cols = p.len() + usize::from(p.closed && opts.split_seams);
            let whole = written(&spine, &p, &opts, (3, cols));
            assert!(whole.1.iter().any(|&i| i > 0), "case {k}: faces written");
            if k == 2 {
                assert!(
                    !whole.2.is_empty() && whole.3.is_some(),
                    "folds and overflow"
                );
            }
            for piece in [1, 2, 3, cols - 1] {
                let pieces = written(&spine, &p, &opts, (3, piece));
                assert!(pieces == whole, "case {k}: pieces of {piece} differ");
            }
        }
    }

    /// The faces computed per edge (large profiles) are those of the tables (small ones):
    /// both splits and windings, with and without a seam column, consecutive rings and the
    /// last ring joined to the first, from every first edge.
    #[test]
    fn face_formula_equals_table() {
        for (cols, edges) in [(7, 7), (8, 7), (7, 6)] {
            for sign in [1.0, -1.0] {
                let table = FacePattern::of(cols, edges, sign);
                let formula = FacePattern {
                    ac: Vec::new(),
                    bd: Vec::new(),
                    ..FacePattern::of(cols, edges, sign)
                };
                assert_eq!(table.ac.len(), 2 * edges);
                for bd in [false, true] {
                    for (b0, b1) in [(30, 30 + cols), (30 + 5 * cols, 30)] {
                        for e0 in 0..edges {
                            let k = 2 * (edges - e0);
                            let (mut x, mut y) = (vec![[0i64; 3]; k], vec![[0i64; 3]; k]);
                            table.write(&mut x, bd, b0, b1, e0);
                            formula.write(&mut y, bd, b0, b1, e0);
                            assert_eq!(x, y, "{cols} {edges} {sign} {bd} {b0} {e0}");
                        }
                    }
                }
            }
        }
    }
}

/// Property tests (proptest) of the mitre stretch: the stretched ring is the cut of both
/// adjacent straight prisms.
#[cfg(test)]
mod proptests {
    use super::*;
    use proptest::prelude::*;

    fn unit() -> impl Strategy<Value = DVec3> {
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
            .prop_map(|(x, y, z)| DVec3::new(x, y, z))
            .prop_filter("not tiny", |v| v.length() > 1e-2)
            .prop_map(|v| v.normalize())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]

        /// At a corner between the unit chords `din`, `dout` (turn φ < 160°) with the
        /// bisector tangent, a profile point `p ⊥ t` stretched by the mitre lies at the
        /// distance |p| from both chord lines (the two prisms of radius |p| meet in the
        /// bisector plane), and the factor is `1/cos(φ/2)`, capped by the limit.
        #[test]
        fn mitre_ring_is_the_cut_of_both_prisms(
            din in unit(), dout in unit(), p in unit(), len in 1e-3..1e3f64,
            limit in 1.0..20.0f64,
        ) {
            prop_assume!(din.dot(dout) > (160f64.to_radians()).cos());
            let t = (din + dout).normalize();
            let p = len * (p - p.dot(t) * t);
            prop_assume!(p.length() > 1e-6 * len);
            let (f, k) = mitre(din, dout, t, 1e9);
            let q = p + f * p.dot(k) * k;
            let dist = |d: DVec3| (q - q.dot(d) * d).length();
            let r = p.length();
            prop_assert!((dist(din) - r).abs() < 1e-12 * r, "{} {}", dist(din), r);
            prop_assert!((dist(dout) - r).abs() < 1e-12 * r, "{} {}", dist(dout), r);
            let half = 0.5 * din.angle_between(dout);
            let (fl, _) = mitre(din, dout, t, limit);
            if f > 0.0 {
                prop_assert!(((1.0 + f) * half.cos() - 1.0).abs() < 1e-12);
            }
            prop_assert!(1.0 + fl <= limit + 1e-15);
            prop_assert!((1.0 + fl - (1.0 + f).min(limit)).abs() < 1e-15);
        }
    }
}

//! What a caller asks for: the method, the prescribed orientations, the analytic samples
//! and the [`Request`] that holds them, the public bounds and tolerances, and the
//! resolution of an orientation against a tangent.

use glam::{DMat3, DVec3};

use super::tangents::TangentRule;
use crate::error::{InputError, Result};

/// Frame method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    DoubleReflection,
    Projection,
    Rotation,
    Frenet,
    Rk4,
    /// RK4 on the φ-form `r′ = −(r·t′) t` without projection (Wang et al.'s Table III).
    Rk4Phi,
    /// The Frenet frame turned by `−∫τ ds` (analytic curves with `x‴`, `κ ≠ 0`).
    Torsion,
    /// Klok's projection onto the bisector planes of a polygon (points only).
    Bisector,
}

/// A prescribed orientation: a reference vector (projected onto the normal plane) or a
/// whole frame (a rotation matrix with columns `r, s, t`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientation {
    Vector(DVec3),
    Frame(DMat3),
}

/// Exact derivatives of an analytic curve at `u_0, (u_0+u_1)/2, u_1, …, u_m` (2m + 1 rows).
#[derive(Debug, Clone, Copy)]
pub struct Analytic<'a> {
    /// Parameter values `u_0 < … < u_m` of the samples.
    pub u: &'a [f64],
    /// First derivative `x′(u)` at the samples and midpoints (2m + 1 rows).
    pub d1: &'a [DVec3],
    /// Second derivative `x″(u)` at the samples and midpoints (2m + 1 rows).
    pub d2: &'a [DVec3],
    /// Third derivative `x‴(u)` at the same rows, or empty (only the torsion method reads it).
    pub d3: &'a [DVec3],
}

/// Everything one frame computation needs. Arrays have one row per input sample.
#[derive(Debug, Clone, Copy)]
pub struct Request<'a> {
    pub points: Option<&'a [DVec3]>,
    pub tangents: Option<&'a [DVec3]>,
    pub analytic: Option<Analytic<'a>>,
    pub closed: bool,
    pub method: Method,
    /// Tangents-only double reflection: chords from a quadrature of the tangents.
    pub tangent_chords: bool,
    pub tangent_rule: TangentRule,
    pub initial: Option<Orientation>,
    pub end: Option<Orientation>,
    /// Extra turns of the closing (or end) twist: `2π·turns` is added to it. A whole
    /// number, or on a closed curve without `end` also a half-integer (see
    /// [`super::check::turns`]).
    pub turns: f64,
    /// The names the user sees for the points and the tangents, which errors about them
    /// start with (`"points"`, `"tangents"` unless the caller passed them under other names,
    /// e.g. the steps of a curve moving in time as `points_t`).
    pub names: Names<'a>,
}

/// The names of a [`Request`]'s points and tangents as the user passed them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Names<'a> {
    pub points: &'a str,
    pub tangents: &'a str,
}

impl Default for Names<'_> {
    fn default() -> Self {
        Names {
            points: "points",
            tangents: "tangents",
        }
    }
}

impl Request<'_> {
    /// The points' name, for an error about them.
    pub(crate) fn points_arg(&self) -> String {
        self.names.points.to_owned()
    }

    /// The tangents' name, for an error about them.
    pub(crate) fn tangents_arg(&self) -> String {
        self.names.tangents.to_owned()
    }
}

impl Default for Request<'_> {
    fn default() -> Self {
        Request {
            points: None,
            tangents: None,
            analytic: None,
            closed: false,
            method: Method::DoubleReflection,
            tangent_chords: false,
            tangent_rule: TangentRule::FivePointBounded,
            initial: None,
            end: None,
            turns: 0.0,
            names: Names::default(),
        }
    }
}

/// Bytes a row that a frames call may hold at once besides its output (9 × 8 = 72 bytes a
/// row): the per-row working vectors of this module and of [`steer`], [`guide`],
/// [`constraints`], [`frenet`] and [`time`] are allocated infallibly within this bound, which
/// the bindings check is free before the call (`ensure_memory` of
/// `72 + WORKING_BYTES_PER_ROW` bytes a row, output included).
///
/// Measured: the peak resident memory of the compiled call alone, output included (VmHWM
/// reset through `/proc/self/clear_refs` just before it, less the resident set then), per
/// row, for 4·10⁶ and 10⁷ rows (`benchmarks/memory_frames.py`): an open curve 72 (the fused
/// scan keeps nothing per row; bundles too), a closed curve or given tangents 104, Frenet
/// 168–172 (address space 160–173), an analytic curve 112 (RK4 152–160), frames in time 104
/// (Frenet 157–167), `quaternion_frames` 136; steered: `previous` 136, constraints 144, the
/// minimum-angular-speed rule 152, a guide 192 (closed 208–216, analytic 200), a guide with
/// constraints on a closed curve 224, the most. `72 + 216 = 288` bytes a row is 29 % over it.
///
/// [`steer`]: super::steer
/// [`guide`]: super::guide
/// [`constraints`]: super::constraints
/// [`frenet`]: super::frenet
/// [`time`]: super::time
pub const WORKING_BYTES_PER_ROW: usize = 216;

/// Curvature below this (times the curve's bounding-box diagonal) counts as straight.
pub const STRAIGHT_TOL: f64 = 1e-9;
/// Largest accepted angle between a prescribed frame's third column and the tangent.
pub const FRAME_TANGENT_TOL: f64 = 1e-3;

pub(crate) fn resolve(o: &Orientation, t: DVec3, row: usize, arg: &'static str) -> Result<DVec3> {
    match *o {
        Orientation::Vector(v) => {
            if !v.is_finite() {
                return Err(InputError::new(arg, "contains a non-finite value"));
            }
            // a unit vector first, so that huge or tiny vectors neither overflow nor vanish
            let v = crate::math::scale::normalize(v).unwrap_or(DVec3::ZERO);
            let p = v - v.dot(t) * t;
            let l = p.length();
            if l == 0.0 || l <= 1e-8 {
                return Err(InputError::new(
                    arg,
                    format!(
                        "the vector is zero or parallel to the tangent at row {row}; it \
                         must have a component in the normal plane"
                    ),
                ));
            }
            Ok(p / l)
        }
        Orientation::Frame(m) => {
            if !m.is_finite() {
                return Err(InputError::new(arg, "contains a non-finite value"));
            }
            if !crate::math::rotation::is_rotation(&m) {
                return Err(InputError::new(
                    arg,
                    "is not a rotation matrix: its columns (r, s, t) must be orthonormal \
                     and right-handed (det = +1)",
                ));
            }
            let ang = m.z_axis.angle_between(t);
            if ang > FRAME_TANGENT_TOL {
                return Err(InputError::new(
                    arg,
                    format!(
                        "its third column (the frame's tangent) differs from the curve's \
                         tangent at row {row} by {ang:.3e} rad; pass a frame with t = \
                         tangent, or just a reference vector"
                    ),
                ));
            }
            resolve(&Orientation::Vector(m.x_axis), t, row, arg)
        }
    }
}

/// Per-curve orientations of a bundle: none, one shared by all curves, or one per curve.
pub fn pick<T: Copy>(v: &[T], c: usize) -> Option<T> {
    match v.len() {
        0 => None,
        1 => Some(v[0]),
        _ => v.get(c).copied(),
    }
}

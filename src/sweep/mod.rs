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

mod caps;
mod check;
mod corners;
mod faces;
pub mod join;
mod kernel;
mod layout;
mod monotone;
pub mod profile;
mod rings;
mod run;
mod scale;
pub mod seam;

#[cfg(test)]
mod proptests;
#[cfg(test)]
mod tests;

use glam::{DVec2, DVec3};

pub use corners::Join;
pub use layout::{Layout, indices_fit_i32, layout};
pub use profile::Profile;
pub use run::{FrameSource, Prepared, Written, sweep_into, sweep_many};
pub use scale::{Index, Real};

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
pub struct Options<'a> {
    pub closed: bool,
    pub caps: bool,
    pub miter_limit: f64,
    /// Duplicate the vertices on the texture seams (see [`sweep_many`]).
    pub split_seams: bool,
    /// The outer side of the corners that get joins ([`join`]).
    pub join: Join,
    /// Extra turns of a closed spine's computed frames (`2π·turns` added to the closing
    /// twist); a half number joins the seam with a half turn ([`seam`]; with given frames,
    /// it says they close up to a half turn).
    pub turns: f64,
    /// The scale's name as the user passed it (`"scale"`, `"radius"` for a tube), which
    /// errors about it start with.
    pub scale_name: &'a str,
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

//! The size of a sweep's mesh and of every spine's part of it, from the row counts alone, and
//! the rows of one spine of a bundle.

use rayon::prelude::*;

use super::corners::{self, Corner};
use super::{Options, Profile, Spine};
use crate::error::{InputError, Result};
use crate::frames::validate;
use crate::run::cancel::Cancel;

/// The size of one spine's part of the mesh, from its rows alone (and, on a closed spine,
/// whether its last point repeats the first); [`check_spine`] checks the spine.
///
/// [`check_spine`]: super::check::check_spine
#[derive(Debug, Clone, Copy)]
pub(super) struct Size {
    /// Distinct spine samples.
    pub(super) rings: usize,
    pub(super) segments: usize,
    pub(super) caps: bool,
    /// Rings stored (one more than `rings` for a closed spine with split seams).
    pub(super) stored_rings: usize,
    /// Vertices per stored ring (one more than the profile for a closed profile with split
    /// seams).
    pub(super) cols: usize,
    /// Rings of the corner joins, stored after the spine's rings (see [`super::join`]).
    pub(super) extra: usize,
}

impl Size {
    /// The size of the sweep of spine `x` (a spine too short to sweep gets a size, which its
    /// check refuses) and the corners that get joins (those of a spine with join rings or
    /// with mitred joins; none otherwise), found once for the layout and the sweep.
    pub(super) fn with_corners(s: &Spine, opts: &Options, p: &Profile) -> (Size, Vec<Corner>) {
        let x = s.points;
        let n = x.len();
        let mut rings = n;
        if opts.closed && n >= 2 && validate::coincide(x[0], x[n - 1]) {
            rings -= 1;
        }
        let scale = if s.scale.len() > 1 {
            &s.scale[..rings.min(s.scale.len())]
        } else {
            s.scale
        };
        let mut corners = Vec::new();
        if scale.len() == 1 || scale.len() == rings {
            corners::corners(&x[..rings], scale, opts.closed, p, opts, |c| {
                corners.push(c)
            });
        } // (else refused by the checks)
        let extra = corners.iter().map(|c| c.extra).sum();
        if !(extra > 0 || opts.join == super::Join::Miter) {
            corners = Vec::new();
        }
        let size = Size {
            extra,
            rings,
            segments: if opts.closed {
                rings
            } else {
                rings.saturating_sub(1)
            },
            caps: opts.caps && !opts.closed && p.closed,
            stored_rings: rings + usize::from(opts.closed && opts.split_seams),
            cols: p.len() + usize::from(p.closed && opts.split_seams),
        };
        (size, corners)
    }
    pub(super) fn vertices(&self) -> usize {
        (self.stored_rings + self.extra) * self.cols
    }
    /// Faces at most: the side faces, the caps, and the faces of the joins (of which those
    /// that the joins' welds flatten are left out).
    pub(super) fn faces(&self, p: &Profile) -> usize {
        let edges = if p.closed { p.len() } else { p.len() - 1 };
        2 * (self.segments + self.extra) * edges + if self.caps { 2 * (p.len() - 2) } else { 0 }
    }
}

/// A checked spine: its [`Size`] and the arc length of the spine polyline at every ring
/// (and after the closing chord).
#[derive(Debug, Clone)]
pub(super) struct Plan {
    pub(super) size: Size,
    pub(super) arc: Vec<f64>,
    /// The corners that get joins.
    pub(super) corners: Vec<Corner>,
}

impl std::ops::Deref for Plan {
    type Target = Size;
    fn deref(&self) -> &Size {
        &self.size
    }
}

/// The size of a sweep's mesh and of every spine's part of it, from [`layout`].
#[derive(Debug, Clone)]
pub struct Layout {
    pub(super) sizes: Vec<Size>,
    /// The corners of every spine that get joins (see [`Size::with_corners`]).
    pub(super) corners: Vec<Vec<Corner>>,
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

pub(super) fn part<'a>(all: &Spine<'a>, offsets: &[usize], c: usize) -> Spine<'a> {
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

/// An error about spine `c` of a bundle, prefixed with the curve (as `spinal.frames` and
/// the sweep's checks name it).
pub(super) fn in_curve(e: InputError, offsets: &[usize], c: usize) -> InputError {
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
///
/// Polls `cancel` before every block of curves and fails with [`InputError::stopped`] once
/// it says stop (see [`crate::run::cancel`]).
pub fn layout(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
    cancel: Cancel<'_>,
) -> Result<Layout> {
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
    let mut sizes = crate::run::alloc::with_capacity("sweep layout", curves)?;
    let mut corners = crate::run::alloc::with_capacity("sweep layout", curves)?;
    // blocks of curves in parallel (the joins' corners are found from the points)
    type Block = Vec<(Size, Vec<Corner>)>;
    let blocks: Vec<Option<Block>> = (0..curves.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| match cancel() {
            true => None,
            false => Some(
                (b * BLOCK..((b + 1) * BLOCK).min(curves))
                    .map(|c| Size::with_corners(&part(all, offsets, c), opts, profile))
                    .collect(),
            ),
        })
        .collect();
    for b in blocks {
        match b {
            Some(b) => {
                for (s, c) in b {
                    sizes.push(s);
                    corners.push(c);
                }
            }
            None => return Err(InputError::stopped()),
        }
    }
    Ok(Layout {
        vertices: sizes.iter().map(Size::vertices).sum(),
        faces: sizes.iter().map(|s| s.faces(profile)).sum(),
        sizes,
        corners,
    })
}

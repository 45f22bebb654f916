//! Running a sweep: the set-up its spines share, and every spine's frames, checks and rings in
//! parallel into its part of the output, polling the cancel hook; the public entry points.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

use super::caps::write_caps;
use super::check::check_spine;
use super::corners::Corner;
use super::faces::FacePattern;
use super::join::write_joins;
use super::kernel::{Columns, RingScratch};
use super::layout::{Layout, Plan, in_curve, layout, part};
use super::rings::Rings;
use super::scale::{Index, Real, Scaled, out_of_range, scaled_input};
use super::{Mesh, MeshMut, Options, Profile, Spine};
use crate::error::{ErrorKind, InputError, Result};
use crate::frames::validate;
use crate::run::cancel::{self, Cancel};

/// Output bytes at most per block of rings of [`sweep_one`], or per piece of the columns of
/// a ring larger than this (one poll of the cancel hook per block or piece). A cold output array is faulted in as it is written: on a loaded 2-core machine a
/// block of 4096 vertices (~0.5 MB with normals and uv) then took up to 0.12 s.
pub(super) const BLOCK_BYTES: usize = 1 << 20;

/// What every spine of a sweep shares: the profile's stored columns, the side faces of a
/// segment, the caps' triangulation and the winding.
pub(super) struct Shared<'a> {
    p: &'a Profile,
    /// The profile's stored columns, built by the first spine swept in whole rings (a
    /// sweep in pieces of rings builds the columns of each piece as it goes).
    pub(super) column: OnceLock<Columns>,
    pub(super) pattern: FacePattern,
    tris: Vec<[usize; 3]>,
    /// −1 where the faces are wound the other way (clockwise closed profiles).
    pub(super) sign: f64,
    /// Profile edges: one per vertex of a closed profile, one fewer for an open one.
    pub(super) edges: usize,
}

impl<'a> Shared<'a> {
    /// `cols`: the vertices of a stored ring (the same on every spine); `caps`: some spine
    /// has caps; `cancel` is polled while a non-convex profile's caps are triangulated.
    pub(super) fn new(
        p: &'a Profile,
        cols: usize,
        caps: bool,
        opts: &Options,
        cancel: Cancel<'_>,
    ) -> Result<Shared<'a>> {
        // Winding: normals to the right of the profile's direction, outward for closed
        // profiles.
        let sign = if p.closed && p.area < 0.0 { -1.0 } else { 1.0 };
        let edges = if p.closed { p.len() } else { p.len() - 1 };
        let mut pattern = FacePattern::of(cols, edges, sign);
        pattern.seam = super::seam::shift(p, opts.closed, opts.turns)?;
        Ok(Shared {
            p,
            column: OnceLock::new(),
            pattern,
            tris: match caps {
                true => p.triangulate(cancel)?,
                false => Vec::new(),
            },
            sign,
            edges,
        })
    }
}

/// What sweeping one spine wrote: the rows (global) that start a folded-over segment, the
/// first vertex (local) out of the output type's range, and the faces kept (at the front of
/// its share of the face buffer).
struct SpineOut {
    folds: Vec<usize>,
    bad: Option<usize>,
    faces: usize,
}

/// Sweep one spine into its share of the output buffers (`out.faces`: its side faces, its
/// caps, then the faces of its joins); `ring`: scratch for the rings of a block.
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
) -> SpineOut {
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
        seam: sh.pattern.seam,
    };
    let mut out = out;
    let nv = plan.stored_rings * plan.cols;
    let n_side = 2 * plan.segments * sh.edges;
    let n_caps = if plan.caps { sh.tris.len() * 2 } else { 0 };
    let (side, rest) = out.faces.split_at_mut(n_side);
    let plain = MeshMut {
        vertices: &mut out.vertices[..nv],
        faces: side,
        normals: out.normals.as_deref_mut().map(|a| &mut a[..nv]),
        uv: out.uv.as_deref_mut().map(|a| &mut a[..nv]),
    };
    let (mut folds, bad) = rings.write(
        plain,
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
        write_caps(&mut rest[..n_caps], plan, &sh.tris, vbase);
    }
    if plan.corners.is_empty() || cancel() {
        return SpineOut {
            folds,
            bad,
            faces: out.faces.len(),
        };
    }
    let all = sh.column.get_or_init(|| Columns::of(sh.p, plan.cols));
    let (faces, bad_join) = write_joins(
        &rings,
        &plan.corners,
        &all.view(0..plan.cols),
        &sh.pattern,
        out,
        n_side + n_caps,
        vbase,
        unscale,
        &mut folds,
        cancel,
    );
    SpineOut {
        folds,
        bad: bad.or(bad_join),
        faces,
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
    (closed, turns): (bool, f64),
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
        turns,
        ..crate::frames::Request::default()
    };
    crate::frames::compute_into(&req, buf[..n].as_flattened_mut(), cancel)?;
    Ok(())
}

/// What sweeping one spine gave: what it wrote and its joins' corners, or the error of its
/// frames or of its checks, or nothing (stopped).
enum Outcome {
    Swept(SpineOut, Vec<Corner>),
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
    opts: &'s Options<'s>,
    layout: &'s Layout,
    sh: Shared<'s>,
    /// See [`unscaled`].
    ///
    /// [`unscaled`]: super::scale::unscaled
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
        done: Option<&AtomicUsize>,
    ) -> Result<Written> {
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
        let mut jobs = crate::run::alloc::with_capacity("sweep", sizes.len())?;
        let all_faces = out.faces;
        let (mut v, mut nr, mut u, mut f) = (out.vertices, out.normals, out.uv, &mut *all_faces);
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
                |sc, (c, vbase, mine)| {
                    let o = self.spine(c, vbase, mine, sc, cancel);
                    if let Some(d) = done {
                        d.fetch_add(self.offsets[c + 1] - self.offsets[c], Ordering::Relaxed);
                    }
                    o
                },
            )
            .collect();
        let (mut check, mut bad) = (None, None);
        for o in &outcomes {
            match o {
                Outcome::Frames(e) => return Err(e.clone()),
                Outcome::Checks(e) if check.is_none() => check = Some(e.clone()),
                Outcome::Swept(d, _) if bad.is_none() => bad = d.bad,
                _ => {}
            }
        }
        if let Some(e) = check {
            return Err(e);
        }
        if let Some(i) = bad {
            return Err(out_of_range::<R>(i, self.opts.scale_name));
        }
        let mut w = Written {
            folds: Vec::new(),
            faces_per_spine: Vec::with_capacity(sizes.len()),
            faces: 0,
            join_rows: Vec::new(),
        };
        // each spine's faces kept, after those of the spine before it
        let mut start = 0;
        for (c, (o, size)) in outcomes.into_iter().zip(sizes).enumerate() {
            let bound = size.faces(self.sh.p);
            let kept = match o {
                Outcome::Swept(d, corners) => {
                    w.folds.extend(d.folds);
                    for k in corners {
                        let row = self.offsets[c] + k.k;
                        w.join_rows.extend(std::iter::repeat_n(row, k.extra));
                    }
                    d.faces
                }
                _ => bound,
            };
            if w.faces != start {
                all_faces.copy_within(start..start + kept, w.faces);
            }
            w.faces += kept;
            w.faces_per_spine.push(kept);
            start += bound;
        }
        Ok(w)
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
                let (o, ct) = (self.offsets, (self.opts.closed, self.opts.turns));
                if let Err(e) = rmf_into(self.points, tangents, o, c, ct, frames, cancel) {
                    return Outcome::Frames(in_curve(e, o, c));
                }
                if cancel() {
                    return Outcome::Stopped;
                }
                s.frames = &frames[..s.points.len()];
                false
            }
        };
        // the size and corners that the layout found (from the same rows)
        let found = (self.layout.sizes[c], self.layout.corners[c].clone());
        let plan = match check_spine(&s, self.opts, self.sh.p, given, Some(found), cancel) {
            Ok(Some(plan)) => plan,
            Ok(None) => return Outcome::Stopped,
            Err(e) => return Outcome::Checks(in_curve(e, self.offsets, c)),
        };
        if self.sh.pattern.seam > 0 {
            // a half turn at the seam: given frames must close that way, and no corner join
            // may reach across the seam's column shift
            let seam = match given {
                true => super::seam::check_given(s.frames, plan.size.rings),
                false => Ok(()),
            };
            if let Err(e) = seam.and_then(|_| super::seam::no_corners(&plan.corners)) {
                return Outcome::Checks(in_curve(e, self.offsets, c));
            }
        }
        let (rowbase, unscale) = (self.offsets[c], self.unscale);
        let mut done = sweep_one(
            &s, &plan, &self.sh, self.opts, vbase, rowbase, unscale, out, ring, cancel,
        );
        done.bad = done.bad.map(|i| vbase + i);
        Outcome::Swept(done, plan.corners)
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
    closed: (bool, f64),
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

/// What a sweep wrote into buffers of the sizes of its [`Layout`].
#[derive(Debug, Clone, Default)]
pub struct Written {
    /// The rows starting a folded-over segment.
    pub folds: Vec<usize>,
    /// The faces of every spine, in the order of the spines (they follow one another).
    pub faces_per_spine: Vec<usize>,
    /// The faces written, at the front of the face buffer: the layout's count less those
    /// the joins' welds flattened.
    pub faces: usize,
    /// For every ring stored after a spine's rings for a corner join, in order, the row of
    /// the corner's sample.
    pub join_rows: Vec<usize>,
}

/// Sweep `profile` along every spine of a bundle into buffers of the sizes in `layout`
/// (spines in parallel, each checked as it is swept). Refuses vertices beyond the range of
/// the output type ([`out_of_range`]).
pub fn sweep_into<R: Real, I: Index>(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
    layout: &Layout,
    out: MeshMut<R, I>,
) -> Result<Written> {
    let caps = layout.sizes.iter().any(|s| s.caps);
    let cols = layout.sizes.first().map_or(profile.len(), |s| s.cols);
    let sweep = Sweep {
        view: *all,
        points: all.points,
        frames: FrameSource::Given,
        offsets,
        opts,
        layout,
        sh: Shared::new(profile, cols, caps, opts, &cancel::never)?,
        unscale: None,
    };
    sweep.write(out, &cancel::never, None)
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
    opts: Options<'a>,
    frames: FrameSource<'a>,
    pub layout: Layout,
}

impl<'a> Prepared<'a> {
    /// Check a bundle of spines (`offsets` as in [`layout`]) with a profile polygon, and the
    /// spines' frames from `frames`, polling `cancel` between its passes and before every
    /// block of rows within them; fails with [`InputError::stopped`] once it says stop (see
    /// [`crate::run::cancel`]).
    ///
    /// With computed frames ([`FrameSource::Rmf`]) a bad profile or option is reported only
    /// when every curve's frames can be computed, as when the frames were a call of their
    /// own before the sweep.
    pub fn new(
        spine: Spine<'a>,
        offsets: &'a [usize],
        profile: &[DVec2],
        profile_closed: bool,
        opts: Options<'a>,
        frames: FrameSource<'a>,
        cancel: Cancel<'_>,
    ) -> Result<Prepared<'a>> {
        let scaled = scaled_input(spine.points, profile, spine.scale, cancel);
        if cancel() {
            return Err(InputError::stopped());
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
        let set_up = Profile::new(prof, profile_closed, cancel).and_then(|p| {
            super::seam::shift(&p, opts.closed, opts.turns)?;
            let lay = layout(&view, offsets, &p, &opts, cancel)?;
            Ok((p, lay))
        });
        let (p, layout) = match (set_up, frames) {
            (Ok(pl), _) => pl,
            (Err(e), _) if e.kind == ErrorKind::Stopped => return Err(e),
            // a stopped check of the profile is no error
            (Err(e), FrameSource::Given) => {
                return match cancel() {
                    true => Err(InputError::stopped()),
                    false => Err(e),
                };
            }
            (Err(e), FrameSource::Rmf { tangents }) => {
                validate::offsets(offsets, spine.points.len())?;
                let (x, closed) = (spine.points, (opts.closed, opts.turns));
                if let Some(fe) = first_frames_error(x, tangents, offsets, closed, cancel) {
                    return Err(fe);
                }
                return match cancel() {
                    true => Err(InputError::stopped()),
                    false => Err(e),
                };
            }
        };
        Ok(Prepared {
            spine,
            offsets,
            scaled,
            profile: p,
            opts,
            frames,
            layout,
        })
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
    /// before every spine and every block of rings within them (see [`crate::run::cancel`]),
    /// and adding each spine's row count to `done` once it is swept (a progress count).
    pub fn write_into<R: Real, I: Index>(
        &self,
        out: MeshMut<R, I>,
        cancel: Cancel<'_>,
        done: Option<&AtomicUsize>,
    ) -> Result<Written> {
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
            sh: Shared::new(&self.profile, cols, caps, &self.opts, cancel)?,
            unscale: self.scaled.as_ref().map(|s| s.k),
        };
        sweep.write(out, cancel, done)
    }
}

/// [`layout`] and [`sweep_into`] with freshly allocated buffers.
pub fn sweep_many(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
) -> Result<Mesh> {
    let lay = layout(all, offsets, profile, opts, &cancel::never)?;
    let mut mesh = Mesh {
        vertices: vec![DVec3::ZERO; lay.vertices],
        faces: vec![[0; 3]; lay.faces],
        normals: vec![DVec3::ZERO; lay.vertices],
        uv: vec![DVec2::ZERO; lay.vertices],
        folds: Vec::new(),
    };
    let w = sweep_into(
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
    mesh.faces.truncate(w.faces);
    mesh.folds = w.folds;
    Ok(mesh)
}

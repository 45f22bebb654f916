//! Steered frames: the RMF of a request turned about its tangents to meet constraints
//! ([`constraints`](super::constraints)), to follow a guide ([`guide`](super::guide)) or to
//! stay close to the frames of the previous time step ([`time`](super::time)).
//!
//! Pins. `initial` and `end` are constraints at the first and last rows. When `end` is given
//! the first row is pinned too, to `initial` or to the default start, so that `end` alone
//! keeps its meaning (the twist spread from the start to the end); a closed curve without any
//! constraint is pinned at row 0 to its start (the closing twist, spread round the loop). With
//! these pins and the arc-length rule the result is the plain `end=`/`closed=` result.

use glam::DVec3;
use rayon::prelude::*;

use super::carry::turn_frame;
use super::constraints::{self, TwistRule};
use super::guide::{self, Guide};
use super::{Method, Orientation, Request, resolve, rmf_parts, time};
use crate::error::{InputError, Result};

/// A prescribed orientation at a row of the curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constraint {
    pub row: usize,
    pub orientation: Orientation,
}

/// How the frames of one curve are steered.
#[derive(Debug, Clone, Copy, Default)]
pub struct Steering<'a> {
    pub constraints: &'a [Constraint],
    pub rule: TwistRule,
    /// Extra turns: none (the request's `turns`), one for every interval, or one per interval
    /// (whole numbers; one half number is the closing twist of a closed curve, see
    /// [`super::check::turns`]).
    pub turns: &'a [f64],
    pub guide: Option<Guide<'a>>,
    /// Frames of the same curve at the previous time step (one per row).
    pub previous: Option<&'a [[f64; 9]]>,
}

/// `turns` are whole numbers, or (`closing`: the one closing twist of a closed curve) half
/// numbers; an error naming `turns` otherwise.
fn half_turns(turns: &[f64], closing: bool) -> Result<()> {
    for &t in turns {
        if !t.is_finite() || !super::check::whole(2.0 * t) {
            return Err(InputError::new(
                "turns",
                format!("expected a whole or half number of turns, got {t}"),
            ));
        }
        if !closing && !super::check::whole(t) {
            return Err(InputError::new(
                "turns",
                format!(
                    "a half number of turns ({t}) applies only to the closing twist of a \
                     closed curve without constraints, end or guide (those are met exactly, \
                     so the twist between them takes whole turns)"
                ),
            ));
        }
    }
    Ok(())
}

fn col(f: &[f64], k: usize) -> DVec3 {
    DVec3::new(f[k], f[3 + k], f[6 + k])
}

/// The steering's own checks, before any work: what method='frenet' cannot use, what
/// `previous` cannot be combined with, the guide, and the rows of `previous` and of the
/// constraints against the curve's `rows`.
fn check_steering(req: &Request, st: &Steering, rows: usize) -> Result<()> {
    if req.method == Method::Frenet {
        let arg = if !st.constraints.is_empty() {
            "constraints"
        } else if st.guide.is_some() {
            "guide"
        } else {
            "previous"
        };
        return Err(InputError::new(
            arg,
            "is not used by method='frenet': the Frenet frame is fixed by the curve",
        ));
    }
    if st.previous.is_some() {
        let other = if !st.constraints.is_empty() {
            Some("constraints")
        } else if st.guide.is_some() {
            Some("guide")
        } else if req.initial.is_some() {
            Some("initial")
        } else if req.end.is_some() {
            Some("end")
        } else {
            None
        };
        if let Some(o) = other {
            return Err(InputError::new(
                "previous",
                format!(
                    "cannot be combined with {o} (they fix the frames that previous would \
                     choose)"
                ),
            ));
        }
    }
    if let Some(g) = &st.guide {
        guide::check(g)?;
    }
    if let Some(p) = st.previous {
        time::check_previous(p, rows)?;
    }
    // constraints: rows in range, distinct
    for c in st.constraints {
        if c.row >= rows {
            return Err(InputError::new(
                "constraints",
                format!("row {} is out of range for a curve of {rows} rows", c.row),
            ));
        }
    }
    Ok(())
}

/// The fixed orientations of one curve's twist, sorted by row: the constraints, `initial`
/// and `end` (each row given once), and row 0's own vector where `end` or a closed curve
/// needs an anchor. `t`, `r`: the RMF's tangents and reference vectors, one per distinct
/// sample.
fn pins_of(req: &Request, st: &Steering, t: &[DVec3], r: &[DVec3]) -> Result<Vec<(usize, DVec3)>> {
    let n = t.len();
    let mut pins: Vec<(usize, DVec3)> = Vec::new();
    for c in st.constraints {
        if c.row >= n {
            return Err(InputError::new(
                "constraints",
                format!(
                    "row {} repeats row 0 of the closed curve; constrain row 0 instead",
                    c.row
                ),
            ));
        }
        pins.push((
            c.row,
            resolve(&c.orientation, t[c.row], c.row, "constraints")?,
        ));
    }
    let mut add = |row: usize, v: DVec3, arg: &'static str| -> Result<()> {
        if pins.iter().any(|p| p.0 == row) {
            return Err(InputError::new(
                arg,
                format!("row {row} is also given in constraints; give it once"),
            ));
        }
        pins.push((row, v));
        Ok(())
    };
    let constrained = !st.constraints.is_empty() || st.guide.is_some();
    if let Some(o) = &req.initial {
        if constrained || req.end.is_some() {
            add(0, resolve(o, t[0], 0, "initial")?, "initial")?;
        }
    }
    if let Some(o) = &req.end {
        add(n - 1, resolve(o, t[n - 1], n - 1, "end")?, "end")?;
        if req.initial.is_none() && !pins.iter().any(|p| p.0 == 0) {
            pins.push((0, r[0]));
        }
    }
    if req.closed && pins.is_empty() && st.guide.is_none() {
        pins.push((0, r[0]));
    }
    pins.sort_by_key(|p| p.0);
    Ok(pins)
}

/// Frames of one curve, steered; `out` holds `9·rows` values.
///
/// Polls `cancel` inside the rotation-minimising frames and between the stages after them, and
/// returns at once (with `out` incomplete) when it says stop (see [`crate::run::cancel`]).
pub fn compute_steered(
    req: &Request,
    st: &Steering,
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<()> {
    let rows = out.len() / 9;
    check_steering(req, st, rows)?;
    let parts = rmf_parts(req, out, cancel)?;
    if cancel() {
        return Ok(());
    }
    let n = parts.n;
    if let Some(g) = &st.guide {
        if g.vectors.len() != 1 && g.vectors.len() != rows {
            return Err(InputError::new(
                "guide",
                format!(
                    "expected shape (3,) or ({rows}, 3) (one vector per sample), got ({}, 3)",
                    g.vectors.len()
                ),
            ));
        }
        if !g.previous.is_empty() && g.previous.len() != rows {
            return Err(InputError::new(
                "previous",
                format!(
                    "expected shape ({rows}, 3, 3) (the frames of the same curve at the \
                     previous time step), got {} rows",
                    g.previous.len()
                ),
            ));
        }
    }
    let t: Vec<DVec3> = out.chunks_exact(9).take(n).map(|f| col(f, 2)).collect();
    let r: Vec<DVec3> = out.chunks_exact(9).take(n).map(|f| col(f, 0)).collect();
    let pins = pins_of(req, st, &t, &r)?;
    if cancel() {
        return Ok(());
    }
    let alpha = if let Some(g) = &st.guide {
        half_turns(st.turns, req.closed && req.end.is_none())?;
        let turns = match st.turns {
            [] => req.turns,
            [k] => *k,
            _ => {
                return Err(InputError::new(
                    "turns",
                    "with guide: one count (the extra turns across a closed curve's seam)",
                ));
            }
        };
        guide::twist(
            &r,
            &t,
            &parts.seg,
            req.closed,
            parts.closing,
            g,
            &pins,
            turns,
            cancel,
        )?
    } else {
        let own = [req.turns];
        let turns = if st.turns.is_empty() {
            &own[..]
        } else {
            st.turns
        };
        // a half turn only as the closing twist: one interval, from row 0 round the seam
        let closing = req.closed && req.end.is_none() && pins.len() == 1 && pins[0].0 == 0;
        half_turns(turns, closing && turns.len() == 1)?;
        constraints::twist(
            &r,
            &t,
            &parts.seg,
            req.closed,
            parts.closing,
            &pins,
            st.rule,
            turns,
        )?
    };
    if cancel() {
        return Ok(());
    }
    out[..9 * n]
        .par_chunks_mut(9)
        .zip(alpha.par_iter())
        .for_each(|(f, &a)| {
            if a != 0.0 {
                let (sin, cos) = a.sin_cos();
                turn_frame(f, cos, sin);
            }
        });
    if rows > n {
        let (head, tail) = out.split_at_mut(9 * n);
        tail[..9].copy_from_slice(&head[..9]);
    }
    if let Some(p) = st.previous {
        if cancel() {
            return Ok(());
        }
        time::align(out, p, cancel)?;
    }
    Ok(())
}

/// [`compute_steered`] over a bundle (`offsets` as in [`super::compute_many`]); `steer[c]`
/// steers curve `c` (one entry: all curves), `initial`/`end` hold 0, 1 or one entry per
/// curve.
///
/// Polls `cancel` before each curve and inside each (see [`compute_steered`]).
pub fn compute_steered_many(
    template: &Request,
    offsets: &[usize],
    initial: &[Orientation],
    end: &[Orientation],
    steer: &[Steering],
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<()> {
    let curves = offsets.len().saturating_sub(1);
    if steer.len() != 1 && steer.len() != curves {
        return Err(InputError::new("out", "one steering per curve expected"));
    }
    let slices = super::bundle_slices(template, offsets, initial, end, out)?;
    let results: Vec<Result<()>> = slices
        .into_par_iter()
        .enumerate()
        .map(|(c, buf)| {
            if cancel() {
                return Ok(());
            }
            let (a, b) = (offsets[c], offsets[c + 1]);
            let req = Request {
                points: template.points.map(|p| &p[a..b]),
                tangents: template.tangents.map(|t| &t[a..b]),
                initial: super::pick(initial, c),
                end: super::pick(end, c),
                ..*template
            };
            let st = steer[if steer.len() == 1 { 0 } else { c }];
            compute_steered(&req, &st, buf, cancel).map_err(|e| {
                if curves > 1 {
                    e.context(&format!("curve {c} (rows {a} to {})", b.max(1) - 1))
                } else {
                    e
                }
            })
        })
        .collect();
    results.into_iter().collect()
}

/// The constraints of all curves of a bundle, given flat (curve `curve[j]`, local row
/// `row[j]`, `orientation[j]`), grouped by curve; a curve or row out of range and a row
/// given twice are refused (named `constraints`).
pub fn constraints_by_curve(
    curves: usize,
    curve: &[i64],
    row: &[i64],
    orientation: Vec<Orientation>,
) -> Result<Vec<Vec<Constraint>>> {
    let bad = |msg: String| InputError::new("constraints", msg);
    let mut per_curve: Vec<Vec<Constraint>> = vec![Vec::new(); curves.max(1)];
    for ((&cj, &rj), orientation) in curve.iter().zip(row).zip(orientation) {
        let c = usize::try_from(cj)
            .ok()
            .filter(|&c| c < curves.max(1))
            .ok_or_else(|| bad(format!("curve {cj} out of range")))?;
        let row = usize::try_from(rj).map_err(|_| bad(format!("row {rj} is out of range")))?;
        if per_curve[c].iter().any(|x| x.row == row) {
            let which = if curves > 1 {
                format!(" (curve {c})")
            } else {
                String::new()
            };
            return Err(bad(format!("row {row} is given twice{which}")));
        }
        per_curve[c].push(Constraint { row, orientation });
    }
    Ok(per_curve)
}

/// The guide holds one vector or one per sample, `previous` one frame per sample.
pub fn check_lengths(rows: usize, guide: Option<usize>, previous: Option<usize>) -> Result<()> {
    if let Some(g) = guide.filter(|&g| g != 1 && g != rows) {
        return Err(InputError::new(
            "guide",
            format!("expected shape (3,) or ({rows}, 3) (one vector per sample), got ({g}, 3)"),
        ));
    }
    if let Some(p) = previous.filter(|&p| p != rows) {
        return Err(InputError::new(
            "previous",
            format!(
                "expected shape ({rows}, 3, 3) (the frames of the same curve at the previous \
                 time step), got ({p}, 3, 3)"
            ),
        ));
    }
    Ok(())
}

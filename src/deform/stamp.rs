//! The contact "stamper" (Zheng, *Studies on Motion and Deformation in Graphics*, thesis
//! 2008, §11.2.6): a sphere tool pressed into a closed mesh frame by frame, in contact only
//! (no gap), with the dented volume given back as a protrusion around the contact.
//!
//! Per frame, the tool centre advances from `c_{k−1}` to `c_k` (straight from `start` to
//! `end` in `frames` equal moves, direction `û`):
//!
//! 1. vertices inside the tool (`d = |X − c_k| − ρ < 0`) snap to its surface,
//!    `X ← c_k + ρ (X − c_k)/|X − c_k|`; the dent `δv = V_before − V_snapped` is measured as
//!    the change of the mesh's signed volume `Σ X₀·(X₁ × X₂)/6` (summed about the mean
//!    vertex, [`crate::math::mesh::signed_volume`]);
//! 2. over the triangles with no contact vertex, the protrusion rate uses the tool's curl
//!    translation field `v` (Zheng Ch. 12, eq. 12.1–12.2, see [`super::fields`]; static tool
//!    at `c_k`, velocity `û`, `R` = reach): `Σ A_tri v_bary`,
//!    `v_bary = max(v(barycentre)·n_tri, 0)` (a choice of ours: the thesis calls `v_bary` the
//!    field speed at the barycentre without saying whether it is a magnitude or a normal
//!    component; the outward normal flux is what makes the protrusion volume);
//! 3. the vertices of the triangles with `v_bary > 0` move along `v` for the "moving time"
//!    `t = δv / Σ(A_tri v_bary)` (one RK4 step), the others stay;
//! 4. `iterations` secant corrections `t ← t · δv / (V_t − V_snapped)` on the measured volume
//!    (the gain is close to linear in `t`), each restarting from the snapped mesh.
//!
//! This is a volume *balance*, not a divergence-free flow: the snap is not a flow, and only
//! the protruding vertices move; what is tested is the mesh volume change per frame (the
//! residual after the secant steps) and that no vertex ends inside the tool.
//!
//! A frame that cannot give the dent back is refused rather than reported with a silent
//! volume change: a tool containing every vertex (the snap would wrap the mesh around the
//! tool; nothing is left outside to protrude), no triangle free of contact, or a dent with
//! protrusion rate `Σ A_tri v_bary = 0` (no free triangle within `reach` of the tool facing
//! the field).

use glam::DVec3;

use super::Field;
use super::advect::{Method, integrate};
use super::fields::Translation;
use crate::error::{InputError, Result};
use crate::math::mesh::signed_volume as volume;
use crate::run::alloc;

/// What one frame did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StampFrame {
    /// Volume removed by snapping the penetrating vertices (≥ 0).
    pub dent: f64,
    /// Moving time of the protrusion (0 without contact).
    pub time: f64,
    /// Volume after the frame minus volume before it.
    pub residual: f64,
    /// Vertices in contact (snapped this frame).
    pub contact: usize,
}

/// Press a sphere of `radius` from `start` to `end` into the mesh `(v, f)` in `frames` moves
/// (see the module docs). `v` is modified in place; face indices must be valid.
/// `tick(done, frames)` is called after every frame; when it returns `false` the stamper
/// stops there and returns the frames done so far.
#[allow(clippy::too_many_arguments)]
pub fn stamp(
    v: &mut [DVec3],
    f: &[[usize; 3]],
    start: DVec3,
    end: DVec3,
    radius: f64,
    reach: f64,
    frames: usize,
    iterations: usize,
    tick: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<Vec<StampFrame>> {
    let travel = end - start;
    let len = travel.length();
    if !(len > 0.0 && len.is_finite()) {
        return Err(InputError::new("end", "must differ from start"));
    }
    if let Some(t) = f.iter().find(|t| t.iter().any(|&i| i >= v.len())) {
        return Err(InputError::new(
            "faces",
            format!("index out of range in face {t:?}"),
        ));
    }
    for (x, name) in [(radius, "radius"), (reach, "reach")] {
        if !(x > 0.0 && x.is_finite()) {
            return Err(InputError::new(name, format!("must be positive, got {x}")));
        }
    }
    if !start.is_finite() {
        return Err(InputError::new("start", "must be finite"));
    }
    if frames == 0 {
        return Err(InputError::new("frames", "must be at least 1"));
    }
    let u = travel / len;
    // `frames` is a user number: the list grows with the frames done, not reserved from it
    let mut out = alloc::with_capacity("stamp", frames.min(1024))?;
    let mut contact = alloc::filled("stamp", v.len(), false)?;
    let mut movable = alloc::filled("stamp", v.len(), false)?;
    for k in 1..=frames {
        let c = start + travel * (k as f64 / frames as f64);
        let before = volume(v, f);
        contact.fill(false);
        let mut nc = 0;
        for (x, hit) in v.iter_mut().zip(contact.iter_mut()) {
            let y = *x - c;
            let r = y.length();
            if r < radius {
                *x = if r > 0.0 {
                    c + y * (radius / r)
                } else {
                    c - u * radius
                };
                *hit = true;
                nc += 1;
            }
        }
        if nc > 0 && nc == v.len() {
            return Err(InputError::new(
                "radius",
                format!(
                    "the tool (radius {radius}) swallows the whole mesh at frame {k}: every \
                     vertex is inside it, none is left to carry the dented volume"
                ),
            ));
        }
        let snapped = volume(v, f);
        let dent = before - snapped;
        let field = Field::single(Translation {
            center: c,
            velocity: u,
            radius,
            reach,
            power: 2,
            moving: false,
        });
        movable.fill(false);
        let mut rate = 0.0;
        let mut free = 0;
        for t in f {
            if t.iter().any(|&i| contact[i]) {
                continue;
            }
            free += 1;
            let (a, b, cc) = (v[t[0]], v[t[1]], v[t[2]]);
            let an = 0.5 * (b - a).cross(cc - a); // area × unit normal
            let w = field.eval((a + b + cc) / 3.0, 0.0).dot(an);
            if w > 0.0 {
                rate += w;
                for &i in t {
                    movable[i] = true;
                }
            }
        }
        if nc > 0 && free == 0 {
            return Err(InputError::new(
                "radius",
                format!(
                    "the tool (radius {radius}) leaves no triangle free of contact at frame \
                     {k}: nothing can protrude to give the dented volume back"
                ),
            ));
        }
        if dent > 0.0 && !(rate > 0.0) {
            return Err(InputError::new(
                "reach",
                format!(
                    "no triangle free of contact within reach ({reach}) of the tool faces \
                     its field at frame {k}: nothing can protrude to give the dented volume \
                     back (use a larger reach, or a finer mesh)"
                ),
            ));
        }
        if !(dent > 0.0) {
            alloc::push(
                "stamp",
                &mut out,
                StampFrame {
                    dent: dent.max(0.0),
                    time: 0.0,
                    residual: snapped - before,
                    contact: nc,
                },
            )?;
            if !tick(k, frames) {
                break;
            }
            continue;
        }
        let moving = movable.iter().filter(|&&m| m).count();
        let mut idx = alloc::with_capacity("stamp", moving)?;
        idx.extend((0..v.len()).filter(|&i| movable[i]));
        let rest = alloc::collect("stamp", idx.iter().map(|&i| v[i]))?;
        let mut time = dent / rate;
        let mut after = snapped;
        for it in 0..=iterations {
            for (&i, &x) in idx.iter().zip(&rest) {
                v[i] = integrate(&field, x, 0.0, time, 1, Method::Rk4);
            }
            after = volume(v, f);
            let gained = after - snapped;
            if it < iterations && gained > 0.0 && gained.is_finite() {
                time *= dent / gained;
            }
        }
        alloc::push(
            "stamp",
            &mut out,
            StampFrame {
                dent,
                time,
                residual: after - before,
                contact: nc,
            },
        )?;
        if !tick(k, frames) {
            break;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::mesh::fixtures::octahedron;

    fn go(z1: f64, radius: f64, reach: f64, frames: usize) -> Result<Vec<StampFrame>> {
        let (mut v, f) = octahedron();
        let start = DVec3::new(0.0, 0.0, 1.5);
        let end = DVec3::new(0.0, 0.0, z1);
        stamp(
            &mut v,
            &f,
            start,
            end,
            radius,
            reach,
            frames,
            2,
            &mut |_, _| true,
        )
    }

    #[test]
    fn a_tool_swallowing_the_mesh_is_refused() {
        let e = go(0.1, 10.0, 10.0, 1).unwrap_err();
        assert_eq!(e.arg, "radius");
        assert!(e.msg.contains("swallows the whole mesh at frame 1"), "{e}");
    }

    #[test]
    fn a_tool_touching_every_triangle_is_refused() {
        // at the origin with radius 0.9 the tool holds no vertex; at (0, 0, 0.3) with radius
        // 0.9 it holds +Z and, at distance √(1 + 0.09) > 0.9, none of the equator: the top
        // four triangles touch it, the bottom four are free. With radius 1.1 the equator is
        // inside too (√1.09 < 1.1), −Z is not (1.3): every triangle touches the tool.
        let e = go(0.3, 1.1, 1.0, 1).unwrap_err();
        assert_eq!(e.arg, "radius");
        assert!(
            e.msg.contains("no triangle free of contact at frame 1"),
            "{e}"
        );
    }

    #[test]
    fn a_dent_with_nothing_in_reach_to_protrude_is_refused() {
        // the tool dents +Z (moved in by 0.05); the free (bottom) triangles are beyond reach
        let (mut v, f) = octahedron();
        let (a, b) = (DVec3::new(0.0, 0.0, 1.5), DVec3::new(0.0, 0.0, 1.05));
        let e = stamp(&mut v, &f, a, b, 0.1, 0.2, 1, 2, &mut |_, _| true).unwrap_err();
        assert_eq!(e.arg, "reach");
        assert!(e.msg.contains("at frame 1"), "{e}");
    }

    #[test]
    fn the_tick_stops_between_frames() {
        let (mut v, f) = octahedron();
        let (a, b) = (DVec3::new(0.0, 0.0, 3.0), DVec3::new(0.0, 0.0, 2.0));
        let mut seen = Vec::new();
        let out = stamp(&mut v, &f, a, b, 0.3, 0.3, 10, 2, &mut |d, n| {
            seen.push((d, n));
            d < 3
        })
        .unwrap();
        assert_eq!(out.len(), 3);
        assert_eq!(seen, vec![(1, 10), (2, 10), (3, 10)]);
    }
}

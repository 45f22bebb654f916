//! The discrete spine model: linear positions, normalised-lerp tangents and RMF reference
//! vectors between samples (see the module docs of [`crate::flesh`]).

use glam::{DVec2, DVec3};

use crate::error::{InputError, Result};

/// A sampled spine with its frames (`t` and `r` columns of `spinal.frames`).
#[derive(Clone, Debug)]
pub struct Spine {
    pub c: Vec<DVec3>,
    pub t: Vec<DVec3>,
    pub r: Vec<DVec3>,
}

/// The spine evaluated at `(k, a)`.
#[derive(Clone, Copy, Debug)]
pub struct Local {
    pub q: DVec3,
    pub t: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    /// `E_k · t(a)`: the speed `dl/da` of the model.
    pub sigma: f64,
    /// Curvature vector (1/length) in the `(u, v)` coordinates.
    pub kappa: DVec2,
}

impl Spine {
    /// `frames` is row-major `(n, 3, 3)` with columns `(r, s, t)` (the layout of the crate).
    pub fn new(arg: &'static str, points: &[DVec3], frames: &[f64]) -> Result<Spine> {
        let n = points.len();
        if n < 2 {
            return Err(InputError::new(
                arg,
                format!("need at least 2 points, got {n}"),
            ));
        }
        if frames.len() != 9 * n {
            return Err(InputError::new(arg, "frames do not match the points"));
        }
        let mut t = Vec::with_capacity(n);
        let mut r = Vec::with_capacity(n);
        for (i, f) in frames.chunks_exact(9).enumerate() {
            let ri = DVec3::new(f[0], f[3], f[6]);
            let ti = DVec3::new(f[2], f[5], f[8]);
            if !(ri.is_finite() && ti.is_finite() && points[i].is_finite()) {
                return Err(InputError::new(arg, format!("row {i} is not finite")));
            }
            t.push(ti);
            r.push(ri);
        }
        for k in 0..n - 1 {
            let e = points[k + 1] - points[k];
            // σ = E·t(a) > 0 on the whole edge iff it is at both ends
            if !(e.dot(t[k]) > 0.0 && e.dot(t[k + 1]) > 0.0) {
                return Err(InputError::new(
                    arg,
                    format!(
                        "rows {k} and {}: the tangent turns 90° or more within one edge \
                         (repeated points or a cusp); sample the spine more finely",
                        k + 1
                    ),
                ));
            }
            if r[k].dot(r[k + 1]) <= -0.5 {
                return Err(InputError::new(
                    arg,
                    format!("rows {k} and {}: the frame rolls too fast", k + 1),
                ));
            }
        }
        Ok(Spine {
            c: points.to_vec(),
            t,
            r,
        })
    }

    pub fn len(&self) -> usize {
        self.c.len()
    }

    pub fn is_empty(&self) -> bool {
        self.c.is_empty()
    }

    /// The model at edge `k`, `a ∈ [0, 1]`.
    #[inline]
    pub fn eval(&self, k: usize, a: f64) -> Local {
        let (c0, c1) = (self.c[k], self.c[k + 1]);
        let (t0, t1) = (self.t[k], self.t[k + 1]);
        let e = c1 - c0;
        let q = c0 + a * e;
        let dt = t1 - t0;
        let m = t0 + a * dt;
        let ml = m.length();
        let t = m / ml;
        let ta = (dt - t * t.dot(dt)) / ml;
        let sigma = e.dot(t);
        let um = self.r[k] + a * (self.r[k + 1] - self.r[k]);
        let u = (um - t * t.dot(um)).normalize();
        let v = t.cross(u);
        let kv = ta / sigma;
        Local {
            q,
            t,
            u,
            v,
            sigma,
            kappa: DVec2::new(kv.dot(u), kv.dot(v)),
        }
    }
}

//! Volume-preserving deformation by divergence-free vector fields (issue 4).
//!
//! A [`Field`] is a sum of elements, each a closed-form divergence-free velocity field
//! `v(X, t)`: the curl fields of Zheng's thesis Ch. 12 ([`fields`]: translation, rotation,
//! twist, bend) and the cross-product fields `∇p × ∇q` of Ch. 11 / von Funck et al. 2006
//! ([`cross`]). Sums keep `div v = 0`. Vertices are carried along the flow `dX/dt = v(X, t)`
//! by [`advect`] (RK4, explicit Euler for comparison), path lines in parallel.
//!
//! Elements cross the binding as rows of [`ROW`] floats (`row[0]` the kind, the rest the
//! parameters, see [`Element::parse`]) so that a Python field object is just an array; the
//! rows are validated here again (finite, positive radii, unit axes), so a malformed row is an
//! [`InputError`] naming `field`, never a panic.

pub mod advect;
pub mod cross;
pub mod fields;
pub mod grid;
pub mod path;
pub mod refine;
pub mod stamp;
pub mod tube;

use glam::DVec3;

use crate::error::{InputError, Result};
pub use cross::{Capsule, Sphere, StripAcross, Torus};
pub use fields::{Rotation, Swirl, SwirlKind, Translation};

/// Floats per element row.
pub const ROW: usize = 16;

/// One element of a field.
#[derive(Debug, Clone, PartialEq)]
pub enum Element {
    Translation(Translation),
    Rotation(Rotation),
    Swirl(Swirl),
    Sphere(Sphere),
    Capsule(Capsule),
    Torus(Torus),
    StripAcross(StripAcross),
    /// A tool moving along a spine ([`path`]); shared, as it owns its samples.
    Path(std::sync::Arc<path::PathTool>),
    /// A strip of type I along a curved axis ([`tube`]).
    StripAlong(std::sync::Arc<tube::StripAlong>),
    /// A free-form tool from a signed-distance grid ([`grid`]).
    Grid(std::sync::Arc<grid::GridTool>),
}

fn v3(r: &[f64], i: usize) -> DVec3 {
    DVec3::new(r[i], r[i + 1], r[i + 2])
}

fn positive(x: f64, what: &str) -> Result<f64> {
    if x > 0.0 && x.is_finite() {
        Ok(x)
    } else {
        Err(InputError::new(
            "field",
            format!("{what} must be positive and finite, got {x}"),
        ))
    }
}

fn power(x: f64) -> Result<u8> {
    match x {
        2.0 => Ok(2),
        3.0 => Ok(3),
        4.0 => Ok(4),
        _ => Err(InputError::new(
            "field",
            format!("falloff power must be 2, 3 or 4, got {x}"),
        )),
    }
}

fn unit(a: DVec3, what: &str) -> Result<DVec3> {
    let l = a.length();
    if l > 0.0 && l.is_finite() {
        Ok(a / l)
    } else {
        Err(InputError::new(
            "field",
            format!("{what} must be a non-zero finite vector"),
        ))
    }
}

impl Element {
    /// Parse one row. Layouts (`c` centre, `u` velocity, `ρ` tool radius, `R` reach,
    /// `p` falloff power, flags 0/1):
    ///
    /// | kind | element | row\[1..\] |
    /// |---|---|---|
    /// | 0 | curl translation | `c, u, ρ, R, p, moving` |
    /// | 1 | curl rotation | `c, pivot, Ω = ω a, ρ, R, p` |
    /// | 2 | twist/bend | `pivot, axis, rate, R, bend?, curl_form?` |
    /// | 3 | sphere `∇p×∇q` | `c, u, ρ, R_f, linear?, moving` |
    /// | 4 | capsule `∇p×∇q` (distance-field extension) | `a, b, u, ρ, R_f, linear?, moving` |
    /// | 5 | torus `∇p×∇q` | `c, k, speed, R_t, r_t, R_f, linear?, moving` |
    /// | 6 | strip across `∇p×∇q` | `a, b, m (velocity ⟂ b − a), ρ, R_f, linear?` |
    /// | 7 | path tool header ([`path`]) | `t0, T, ρ, R, p, carry?, linear?, rotate?, twist, bend, n` |
    /// | 8 | path sample (`n` rows after a header) | `x, r, s, t, S` (frame columns, arc length) |
    /// | 9 | strip along a curved axis, header ([`tube`]) | `speed, ρ, R_f, linear?, n` |
    /// | 10 | axis sample (`n` rows after a header) | `x, m = dγ/dS, S` |
    /// | 11 | distance-grid tool, header ([`grid`]) | `o, h, nx, ny, nz, u, R_f, linear? + 2 moving?, C` |
    /// | 12 | grid coefficients (`⌈(nx+2)(ny+2)(nz+2)/15⌉` rows after a header) | 15 numbers |
    pub fn parse(r: &[f64]) -> Result<Element> {
        if r.len() != ROW {
            return Err(InputError::new(
                "field",
                format!("element rows have {ROW} numbers"),
            ));
        }
        if let Some(i) = r.iter().position(|x| !x.is_finite()) {
            return Err(InputError::new(
                "field",
                format!("element parameter {i} is not finite"),
            ));
        }
        let flag = |x: f64| x != 0.0;
        Ok(match r[0] {
            0.0 => Element::Translation(Translation {
                center: v3(r, 1),
                velocity: v3(r, 4),
                radius: positive(r[7], "radius")?,
                reach: positive(r[8], "reach")?,
                power: power(r[9])?,
                moving: flag(r[10]),
            }),
            1.0 => Element::Rotation(Rotation {
                center: v3(r, 1),
                pivot: v3(r, 4),
                omega: v3(r, 7),
                radius: positive(r[10], "radius")?,
                reach: positive(r[11], "reach")?,
                power: power(r[12])?,
            }),
            2.0 => Element::Swirl(Swirl {
                pivot: v3(r, 1),
                axis: unit(v3(r, 4), "axis")?,
                rate: r[7],
                reach: positive(r[8], "radius")?,
                kind: if flag(r[9]) {
                    SwirlKind::Bend
                } else {
                    SwirlKind::Twist
                },
                curl_form: flag(r[10]),
            }),
            3.0 => Element::Sphere(Sphere {
                center: v3(r, 1),
                velocity: v3(r, 4),
                radius: positive(r[7], "radius")?,
                reach: positive(r[8], "reach")?,
                linear: flag(r[9]),
                moving: flag(r[10]),
            }),
            4.0 => Element::Capsule(Capsule::new(
                v3(r, 1),
                v3(r, 4),
                v3(r, 7),
                positive(r[10], "radius")?,
                positive(r[11], "reach")?,
                flag(r[12]),
                flag(r[13]),
            )?),
            5.0 => Element::Torus(Torus::new(
                v3(r, 1),
                unit(v3(r, 4), "axis")?,
                r[7],
                positive(r[8], "major")?,
                positive(r[9], "minor")?,
                positive(r[10], "reach")?,
                flag(r[11]),
                flag(r[12]),
            )?),
            6.0 => Element::StripAcross(StripAcross::new(
                v3(r, 1),
                v3(r, 4),
                v3(r, 7),
                positive(r[10], "radius")?,
                positive(r[11], "reach")?,
                flag(r[12]),
            )?),
            7.0..=12.0 if r[0].fract() == 0.0 => {
                return Err(InputError::new(
                    "field",
                    "path, strip-axis and grid rows must come as a header (kind 7, 9, 11) \
                     followed by its data rows (kind 8, 10, 12)",
                ));
            }
            k => {
                return Err(InputError::new(
                    "field",
                    format!("unknown element kind {k}"),
                ));
            }
        })
    }

    /// Parse a path header row `h` and its sample rows.
    fn parse_path(h: &[f64], rows: &[f64]) -> Result<Element> {
        let flag = |x: f64| x != 0.0;
        let samples = rows
            .chunks_exact(ROW)
            .map(|r| {
                if r[0] != 8.0 {
                    return Err(InputError::new(
                        "field",
                        "expected a path sample row (kind 8)",
                    ));
                }
                Ok(path::Sample {
                    x: v3(r, 1),
                    frame: glam::DMat3::from_cols(v3(r, 4), v3(r, 7), v3(r, 10)),
                    s: r[13],
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let spec = path::PathToolSpec {
            t0: h[1],
            duration: h[2],
            radius: positive(h[3], "radius")?,
            reach: positive(h[4], "reach")?,
            power: power(h[5])?,
            carry: flag(h[6]),
            linear: flag(h[7]),
            rotate: flag(h[8]),
            twist: h[9],
            bend: h[10],
        };
        Ok(Element::Path(std::sync::Arc::new(path::PathTool::new(
            samples, spec,
        )?)))
    }

    /// Parse a strip-axis header row `h` (kind 9) and its sample rows (kind 10).
    fn parse_strip(h: &[f64], rows: &[f64]) -> Result<Element> {
        let samples = rows
            .chunks_exact(ROW)
            .map(|r| {
                if r[0] != 10.0 {
                    return Err(InputError::new(
                        "field",
                        "expected a strip-axis sample row (kind 10)",
                    ));
                }
                Ok(tube::AxisSample {
                    x: v3(r, 1),
                    m: v3(r, 4),
                    s: r[7],
                })
            })
            .collect::<Result<Vec<_>>>()?;
        // the axis checks name `points` (the samples of `spinal.fields.strip_curve`, checked
        // there through `tube::strip_axis`); here they are about rows, which name `field`
        let axis = tube::StripAlong::new(
            samples,
            h[1],
            positive(h[2], "radius")?,
            positive(h[3], "reach")?,
            h[4] != 0.0,
        )
        .map_err(|e| InputError::new("field", e.msg))?;
        Ok(Element::StripAlong(std::sync::Arc::new(axis)))
    }

    /// Parse a grid header row `h` (kind 11) and its coefficient rows (kind 12).
    fn parse_grid(h: &[f64], n: [usize; 3], rows: &[f64]) -> Result<Element> {
        let total = (n[0] + 2) * (n[1] + 2) * (n[2] + 2);
        let mut coef = Vec::with_capacity(rows.len() / ROW * (ROW - 1));
        for r in rows.chunks_exact(ROW) {
            if r[0] != 12.0 {
                return Err(InputError::new(
                    "field",
                    "expected a grid coefficient row (kind 12)",
                ));
            }
            coef.extend_from_slice(&r[1..]);
        }
        coef.truncate(total);
        let flags = h[12];
        if !(flags == 0.0 || flags == 1.0 || flags == 2.0 || flags == 3.0) {
            return Err(InputError::new(
                "field",
                format!("grid flags must be 0, 1, 2 or 3, got {flags}"),
            ));
        }
        Ok(Element::Grid(std::sync::Arc::new(grid::GridTool::new(
            v3(h, 1),
            positive(h[4], "grid spacing")?,
            n,
            coef,
            v3(h, 8),
            v3(h, 13),
            positive(h[11], "reach")?,
            flags == 1.0 || flags == 3.0,
            flags >= 2.0,
        )?)))
    }

    /// The velocity at `x`, time `t`, within an integration step containing `tm` (only path
    /// tools use `tm`: it picks the piece of their piecewise-smooth motion).
    #[inline]
    pub fn eval(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        match self {
            Element::Translation(e) => e.eval(x, t),
            Element::Rotation(e) => e.eval(x, t),
            Element::Swirl(e) => e.eval(x),
            Element::Sphere(e) => e.eval(x, t),
            Element::Capsule(e) => e.eval(x, t),
            Element::Torus(e) => e.eval(x, t),
            Element::StripAcross(e) => e.eval(x),
            Element::Path(e) => e.eval(x, t, tm),
            Element::StripAlong(e) => e.eval(x),
            Element::Grid(e) => e.eval(x, t),
        }
    }

    /// An upper bound (or a sampled estimate with margin) of |v| and of the tool speed.
    pub fn max_speed(&self) -> f64 {
        match self {
            Element::Translation(e) => e.max_speed(),
            Element::Rotation(e) => e.max_speed(),
            Element::Swirl(e) => e.max_speed(),
            Element::Sphere(e) => e.max_speed(),
            Element::Capsule(e) => e.max_speed(),
            Element::Torus(e) => e.max_speed(),
            Element::StripAcross(e) => e.max_speed(),
            Element::Path(e) => e.max_speed(),
            Element::StripAlong(e) => e.max_speed(),
            Element::Grid(e) => e.max_speed(),
        }
    }

    /// The length over which the field changes: the reach (curl fields, swirls) or the
    /// width of the blend region (cross-product fields).
    pub fn length_scale(&self) -> f64 {
        match self {
            Element::Translation(e) => e.reach,
            Element::Rotation(e) => e.reach,
            Element::Swirl(e) => e.reach,
            Element::Sphere(e) => e.reach,
            Element::Capsule(e) => e.reach,
            Element::Torus(e) => e.reach,
            Element::StripAcross(e) => e.reach,
            Element::Path(e) => e.spec.reach,
            Element::StripAlong(e) => e.reach,
            Element::Grid(e) => e.reach,
        }
    }
}

/// A sum of elements (an empty sum is the zero field).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Field {
    pub elements: Vec<Element>,
}

impl Field {
    /// Parse `k` rows of [`ROW`] floats.
    pub fn parse(rows: &[f64]) -> Result<Field> {
        if rows.len() % ROW != 0 {
            return Err(InputError::new(
                "field",
                format!("expected rows of {ROW} numbers"),
            ));
        }
        let mut elements = Vec::new();
        let mut i = 0;
        while i * ROW < rows.len() {
            let r = &rows[i * ROW..(i + 1) * ROW];
            let at = |e: InputError| e.context(&format!("element {i}"));
            // a header row and the `k` data rows after it (paths, strips, grids), all finite
            let header = || match r.iter().position(|x| !x.is_finite()) {
                Some(j) => Err(at(InputError::new(
                    "field",
                    format!("element parameter {j} is not finite"),
                ))),
                None => Ok(()),
            };
            let body = |k: usize, what: &str| {
                let body = &rows[(i + 1) * ROW..(i + 1 + k) * ROW];
                match body.iter().position(|x| !x.is_finite()) {
                    Some(j) => Err(at(InputError::new(
                        "field",
                        format!("{what} {} is not finite", j / ROW),
                    ))),
                    None => Ok(body),
                }
            };
            if r[0] == 7.0 {
                header()?;
                let n = r[11];
                let avail = (rows.len() / ROW - i - 1) as f64;
                if !(n >= 2.0 && n <= avail && n.fract() == 0.0) {
                    return Err(at(InputError::new(
                        "field",
                        format!("path header announces {n} samples, {avail} rows follow"),
                    )));
                }
                let n = n as usize;
                elements.push(Element::parse_path(r, body(n, "path sample")?).map_err(at)?);
                i += n + 1;
            } else if r[0] == 9.0 || r[0] == 11.0 {
                header()?;
                let avail = rows.len() / ROW - i - 1;
                let count = |x: f64, what: &str| {
                    if (1.0..=1e6).contains(&x) && x.fract() == 0.0 {
                        Ok(x as usize)
                    } else {
                        Err(at(InputError::new(
                            "field",
                            format!("{what} must be a whole number in [1, 1e6], got {x}"),
                        )))
                    }
                };
                let (k, grid_n) = if r[0] == 9.0 {
                    (count(r[5], "strip axis sample count")?, None)
                } else {
                    let n = [
                        count(r[5], "grid size")?,
                        count(r[6], "grid size")?,
                        count(r[7], "grid size")?,
                    ];
                    let total = (n[0] + 2)
                        .checked_mul(n[1] + 2)
                        .and_then(|m| m.checked_mul(n[2] + 2))
                        .filter(|&m| m <= 1 << 31)
                        .ok_or_else(|| {
                            at(InputError::new("field", format!("grid {n:?} is too large")))
                        })?;
                    (total.div_ceil(ROW - 1), Some(n))
                };
                if k > avail {
                    return Err(at(InputError::new(
                        "field",
                        format!("header announces {k} data rows, {avail} follow"),
                    )));
                }
                let body = body(k, "data row")?;
                elements.push(
                    match grid_n {
                        None => Element::parse_strip(r, body),
                        Some(n) => Element::parse_grid(r, n, body),
                    }
                    .map_err(at)?,
                );
                i += k + 1;
            } else {
                elements.push(Element::parse(r).map_err(at)?);
                i += 1;
            }
        }
        Ok(Field { elements })
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        self.eval_in(x, t, t)
    }

    /// [`Self::eval`] for a stage of an integration step containing `tm` ([`Element::eval`]).
    #[inline]
    pub fn eval_in(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        match self.elements.as_slice() {
            [e] => e.eval(x, t, tm),
            es => es.iter().fold(DVec3::ZERO, |s, e| s + e.eval(x, t, tm)),
        }
    }

    /// The common velocity of the tools if they all move with the same one (a frame in which
    /// the field is steady), else zero.
    pub fn frame_velocity(&self) -> DVec3 {
        let mut w = None;
        for e in &self.elements {
            let u = match e {
                Element::Translation(tr) if tr.moving => tr.velocity,
                _ => DVec3::ZERO,
            };
            match w {
                None => w = Some(u),
                Some(v) if v != u => return DVec3::ZERO,
                _ => {}
            }
        }
        w.unwrap_or(DVec3::ZERO)
    }

    /// Whether every element has a potential for the splitting scheme.
    pub fn has_potential(&self) -> bool {
        self.elements
            .iter()
            .all(|e| matches!(e, Element::Translation(_)))
    }

    /// Jacobian of the summed curl potentials (columns `∂A/∂x_j`); zero for elements
    /// without one (see [`Self::has_potential`]).
    #[inline]
    pub fn potential_jacobian(&self, x: DVec3, t: f64) -> glam::DMat3 {
        self.elements
            .iter()
            .fold(glam::DMat3::ZERO, |s, e| match e {
                Element::Translation(tr) => s + tr.potential_jacobian(x, t),
                _ => s,
            })
    }

    /// Sum of the elements' speed bounds.
    pub fn max_speed(&self) -> f64 {
        self.elements.iter().map(Element::max_speed).sum()
    }

    /// Times at which a path tool passes a spine sample (where its velocity is only C⁰ in t).
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b: Vec<f64> = self
            .elements
            .iter()
            .filter_map(|e| match e {
                Element::Path(p) => Some(p.breakpoints()),
                _ => None,
            })
            .flatten()
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }

    /// Smallest length scale of the elements (∞ for the zero field).
    pub fn length_scale(&self) -> f64 {
        self.elements
            .iter()
            .map(Element::length_scale)
            .fold(f64::INFINITY, f64::min)
    }

    /// The step rule for `steps=None` (brief §3.4): a step moves a point by at most 1/8 of
    /// the field's length scale, `h = ℓ / (8 v_max)`, and never fewer than 4 steps.
    pub fn default_steps(&self, duration: f64) -> usize {
        let v = self.max_speed();
        let l = self.length_scale();
        let n = (duration.abs() * 8.0 * v / l).ceil();
        if n.is_finite() && n > 4.0 {
            n.min(1e9) as usize
        } else {
            4
        }
    }
}

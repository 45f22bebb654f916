//! Velocity fields as compiled objects (`spinal.fields`): each constructor validates its
//! arguments and builds its tool once in the core ([`crate::deform`]); a [`PyField`] holds
//! the built tools (shared, never re-parsed) and the constructor calls that made them, so that
//! it pickles by rebuilding.

use glam::{DMat3, DVec3};
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use super::coerce;
use super::convert::{
    Stop, detach_stoppable, empty, option_string, real, slice_mut, slice_of, vec3s,
};
use super::options::Options;
use crate::deform::{
    self, Capsule, Field, Rotation, Sphere, Swirl, SwirlKind, Torus, Translation, curl, grid,
    keyframe, path, rod, tube,
};
use crate::run::alloc;

/// A divergence-free velocity field: a sum of tools built by the constructors of
/// `spinal.fields` (see its module docstring for the maths).
///
/// `field(points, t=0.0)` returns the `(n, 3)` velocities at time `t`; `f + g` (and the
/// builtin `sum`) is the sum field; `max_speed` bounds `|v|`, `length_scale` is the smallest
/// reach, `steps(duration)` the default RK4 step count of `spinal.advect`, `breakpoints()`
/// the times at which a path tool passes a spine sample or a keyframed tool a key. Fields are
/// immutable and pickle by rebuilding from their constructor arguments.
#[pyclass(frozen, name = "Field", module = "spinal.fields")]
pub struct PyField {
    /// The built tools.
    pub field: Field,
    /// One name per constructor call, for `repr`.
    names: Vec<String>,
    /// One `(constructor name, args, kwargs)` per constructor call, for pickling.
    recipe: Vec<Py<PyAny>>,
    /// Terms built without a recorded call (a constructor that forgot to record itself):
    /// such a field refuses to pickle rather than coming back as a different field.
    unrecorded: usize,
}

impl PyField {
    fn new(field: Field, name: &str) -> PyField {
        PyField {
            field,
            names: vec![name.to_string()],
            recipe: Vec::new(),
            unrecorded: 1,
        }
    }

    fn plus(&self, py: Python<'_>, other: &PyField) -> PyField {
        PyField {
            field: self.field.plus(&other.field),
            names: self.names.iter().chain(&other.names).cloned().collect(),
            recipe: self
                .recipe
                .iter()
                .chain(&other.recipe)
                .map(|r| r.clone_ref(py))
                .collect(),
            unrecorded: self.unrecorded + other.unrecorded,
        }
    }
}

#[pymethods]
impl PyField {
    /// Velocities `(n, 3)` at `points` and time `t`.
    #[pyo3(signature = (points, t = None))]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        t: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let arr = coerce::points(points, "points")?;
        let t = match t {
            Some(t) => coerce::real(t, "t")?,
            None => 0.0,
        };
        let x = vec3s("points", &arr)?;
        deform::finite_rows("points", x)?;
        let t = deform::finite("t", t)?;
        let out = empty::<f64, numpy::Ix2>(py, "Field", &[x.len(), 3])?;
        {
            let mut w = out.readwrite();
            let o: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
            let field = &self.field;
            let stop = Stop::default();
            detach_stoppable(py, &stop, || {
                deform::advect::eval_into(field, x, t, o, &|| stop.requested())
            })??;
        }
        Ok(out)
    }

    fn __add__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        match other.cast::<PyField>() {
            Ok(o) => Ok(Py::new(py, self.plus(py, o.get()))?.into_any()),
            Err(_) => Ok(py.NotImplemented()),
        }
    }

    /// `0 + field` (the builtin `sum` starts from 0).
    fn __radd__(slf: &Bound<'_, Self>, other: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let py = slf.py();
        if let Ok(o) = other.cast::<PyField>() {
            return Ok(Py::new(py, o.get().plus(py, slf.get()))?.into_any());
        }
        let zero = other
            .extract::<f64>()
            .is_ok_and(|x| x == 0.0 && !other.is_instance_of::<pyo3::types::PyBool>());
        Ok(if zero {
            slf.clone().into_any().unbind()
        } else {
            py.NotImplemented()
        })
    }

    /// The number of tools.
    fn __len__(&self) -> usize {
        self.field.tools.len()
    }

    /// Times at which a path tool passes a spine sample or a keyframed tool a key, sorted:
    /// the velocity is only continuous in time there, so `spinal.advect` ends steps at them.
    fn breakpoints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(
            py,
            self.field.breakpoints("Field.breakpoints")?,
        ))
    }

    /// A bound of the speed `|v|` (length/time): the sum over the tools of each tool's
    /// bound (closed form where one exists, else a maximum sampled over its support); 0 for
    /// the zero field. Used by `steps`.
    #[getter]
    fn max_speed(&self) -> f64 {
        self.field.max_speed()
    }

    /// The smallest length over which a tool's field falls from its tool value to zero: its
    /// reach (for twist and bend, their radius), the minimum over the tools; inf for the zero
    /// field. Used by `steps`.
    #[getter]
    fn length_scale(&self) -> f64 {
        self.field.length_scale()
    }

    /// Default step count. Without `points`, the a priori bound
    /// `max(4, ⌈|duration|·8·max_speed/length_scale⌉)` (a step moves a point by at most 1/8
    /// of the length scale). With `points` (an (n, 3) array, integrated from `t0`), the count
    /// `spinal.advect` and `spinal.deform` take by default: the first of 8, 16, 32, … steps
    /// whose RK4 run agrees with the run at half as many on every point to 1e-5 of the
    /// length scale (Richardson's estimate of its error), at most the bound; fields with
    /// breakpoints keep the bound. More than 10⁸ steps raises `ValueError`; Ctrl-C stops it.
    #[pyo3(signature = (duration, points=None, t0=None))]
    fn steps(
        &self,
        py: Python<'_>,
        duration: &Bound<'_, PyAny>,
        points: Option<PyReadonlyArray2<'_, f64>>,
        t0: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<usize> {
        let d = deform::finite("duration", real(duration, "duration")?)?;
        let t0 = match t0 {
            Some(t) => deform::finite("t0", real(t, "t0")?)?,
            None => 0.0,
        };
        let Some(points) = points else {
            return Ok(self.field.default_steps(d)?);
        };
        let x = vec3s("points", &points)?;
        deform::finite_rows("points", x)?;
        let stop = Stop::default();
        let field = &self.field;
        let n = detach_stoppable(py, &stop, || {
            deform::steps::measured_steps(field, x, t0, d, &|| stop.requested())
        })?;
        Ok(n?)
    }

    fn __repr__(&self) -> String {
        let names = if self.names.is_empty() {
            "zero".to_string()
        } else {
            self.names.join(" + ")
        };
        format!("spinal.fields.Field({names})")
    }

    /// Pickle support: rebuilt by calling the constructors again.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        if self.unrecorded > 0 {
            let pickling = py.import("pickle")?.getattr("PicklingError")?;
            return Err(PyErr::from_value(pickling.call1((format!(
                "{}: {} of its terms were not built by a recorded constructor of \
                 spinal.fields, so it cannot be rebuilt",
                self.__repr__(),
                self.unrecorded
            ),))?));
        }
        let rebuild = py.import("spinal.fields")?.getattr("_rebuild")?;
        let recipe: Vec<Py<PyAny>> = self.recipe.iter().map(|r| r.clone_ref(py)).collect();
        PyTuple::new(
            py,
            [
                rebuild.unbind(),
                PyTuple::new(py, [recipe])?.into_any().unbind(),
            ],
        )
    }

    /// The same field, remembering that `name(*args, **kwargs)` made it (for pickling).
    fn _with_recipe(
        &self,
        py: Python<'_>,
        name: &str,
        args: Bound<'_, PyTuple>,
        kwargs: Bound<'_, PyDict>,
    ) -> PyResult<PyField> {
        let entry = PyTuple::new(
            py,
            [
                name.into_pyobject(py)?.into_any(),
                args.into_any(),
                kwargs.into_any(),
            ],
        )?;
        Ok(PyField {
            field: self.field.clone(),
            names: self.names.clone(),
            recipe: vec![entry.into_any().unbind()],
            unrecorded: 0,
        })
    }
}

/// A two-way option string as a `bool` newtype: `$false_name` gives `false`.
macro_rules! two_way {
    ($(#[$doc:meta])* $ty:ident, $arg:literal, $false_name:literal, $true_name:literal) => {
        $(#[$doc])*
        #[derive(Clone, Copy)]
        pub struct $ty(bool);

        option_string!($ty, $arg, $arg, [($false_name, $ty(false)), ($true_name, $ty(true))]);

        impl Core<bool> for $ty {
            fn core(self) -> bool {
                self.0
            }
        }
    };
}

two_way!(
    /// Region function of the cross-product fields: the C¹ blend or the linear one.
    Blend, "blend", "c1", "linear"
);
two_way!(
    /// Twist and bend: the rate form or the thesis's curl form.
    CurlForm, "form", "rate", "curl"
);
two_way!(
    /// A straight strip along its axis or across it.
    Across, "kind", "along", "across"
);
two_way!(
    /// A path tool that pushes (curl tool) or carries (region translation).
    Carry, "tool", "push", "carry"
);

option_string!(
    path::PathKind,
    "kind",
    "kind",
    [
        ("translate", path::PathKind::Translate),
        ("rotate", path::PathKind::Rotate),
        ("twist", path::PathKind::Twist),
        ("bend", path::PathKind::Bend),
    ]
);

/// An argument as the core's constructors take it (vectors as [`DVec3`], option strings as
/// their `bool`).
trait Core<T> {
    fn core(self) -> T;
}

impl Core<DVec3> for [f64; 3] {
    fn core(self) -> DVec3 {
        self.into()
    }
}

impl Core<Option<DVec3>> for Option<[f64; 3]> {
    fn core(self) -> Option<DVec3> {
        self.map(DVec3::from)
    }
}

/// Numbers and flags pass as they are.
macro_rules! core_as_is {
    ($($ty:ty),+) => {
        $(impl Core<$ty> for $ty {
            fn core(self) -> $ty {
                self
            }
        })+
    };
}
core_as_is!(f64, Option<f64>, i64, bool);

/// A constructor of one tool with a fixed name: `tool_binding!(field_x, "x", X::new, (arg:
/// Type, …))` converts each argument with [`Core`] and passes them to `X::new` in order.
macro_rules! tool_binding {
    ($(#[$doc:meta])* $fn:ident, $name:literal, $new:path, ($($arg:ident: $ty:ty),+ $(,)?)) => {
        $(#[$doc])*
        #[pyfunction]
        #[allow(clippy::too_many_arguments)]
        pub fn $fn($($arg: $ty),+) -> PyResult<PyField> {
            let tool = $new($($arg.core()),+)?;
            Ok(PyField::new(Field::single(tool), $name))
        }
    };
}

tool_binding!(
    /// `spinal.fields.translation`.
    field_translation, "translation", Translation::new,
    (center: [f64; 3], radius: f64, velocity: [f64; 3], reach: Option<f64>,
     falloff_power: i64, moving: bool)
);

tool_binding!(
    /// `spinal.fields.rotation`.
    field_rotation, "rotation", Rotation::new,
    (center: [f64; 3], radius: f64, axis: [f64; 3], angular_speed: f64,
     pivot: Option<[f64; 3]>, reach: Option<f64>, falloff_power: i64)
);

tool_binding!(
    /// `spinal.fields.sphere`.
    field_sphere, "sphere", Sphere::new,
    (center: [f64; 3], radius: f64, velocity: [f64; 3], reach: Option<f64>, blend: Blend,
     moving: bool)
);

tool_binding!(
    /// `spinal.fields.capsule`.
    field_capsule, "capsule", Capsule::new,
    (start: [f64; 3], end: [f64; 3], radius: f64, velocity: [f64; 3], reach: Option<f64>,
     blend: Blend, moving: bool)
);

tool_binding!(
    /// `spinal.fields.torus`.
    field_torus, "torus", Torus::new,
    (center: [f64; 3], axis: [f64; 3], major: f64, minor: f64, speed: f64,
     reach: Option<f64>, blend: Blend, moving: bool)
);

/// `spinal.fields.twist` (`bend = false`) and `spinal.fields.bend`.
#[pyfunction]
pub fn field_swirl(
    center: [f64; 3],
    axis: [f64; 3],
    rate: f64,
    radius: f64,
    form: CurlForm,
    bend: bool,
) -> PyResult<PyField> {
    let kind = if bend {
        SwirlKind::Bend
    } else {
        SwirlKind::Twist
    };
    let s = Swirl::new(center.into(), axis.into(), rate, radius, kind, form.0)?;
    Ok(PyField::new(
        Field::single(s),
        if bend { "bend" } else { "twist" },
    ))
}

/// `spinal.fields.strip`.
#[pyfunction]
pub fn field_strip(
    start: [f64; 3],
    end: [f64; 3],
    radius: f64,
    velocity: [f64; 3],
    kind: Across,
    reach: Option<f64>,
    blend: Blend,
) -> PyResult<PyField> {
    let f = deform::cross::strip(
        start.into(),
        end.into(),
        radius,
        velocity.into(),
        kind.0,
        reach,
        blend.0,
    )?;
    Ok(PyField::new(
        f,
        if kind.0 {
            "strip(across)"
        } else {
            "strip(along)"
        },
    ))
}

/// `spinal.fields.strip_curve` from its axis samples `(n, 3)`.
#[pyfunction]
pub fn field_strip_curve(
    py: Python<'_>,
    points: PyReadonlyArray2<'_, f64>,
    radius: f64,
    speed: f64,
    reach: Option<f64>,
    blend: Blend,
) -> PyResult<PyField> {
    let x = vec3s("points", &points)?;
    let stop = Stop::default();
    let tool = detach_stoppable(py, &stop, || {
        tube::strip_curve(x, radius, speed, reach, blend.0, &|| stop.requested())
    })??;
    Ok(PyField::new(Field::single(tool), "strip_curve"))
}

/// The grid of a sampled distance and where its tool sits, read from a grid constructor's
/// `options`: `origin`, `spacing`, `center`, `reach` and `name` (the constructor's, for
/// `repr`).
struct GridPlace {
    origin: DVec3,
    spacing: f64,
    center: DVec3,
    reach: f64,
    name: String,
}

impl GridPlace {
    fn read(o: &Options<'_>) -> PyResult<GridPlace> {
        Ok(GridPlace {
            origin: o.get::<[f64; 3]>("origin")?.into(),
            spacing: o.get("spacing")?,
            center: o.get::<[f64; 3]>("center")?.into(),
            reach: o.get("reach")?,
            name: o.get("name")?,
        })
    }

    /// The region tool of the B-spline `coefficients` at this place ([`grid::grid_tool`]).
    fn tool(
        &self,
        py: Python<'_>,
        coefficients: &PyReadonlyArray3<'_, f64>,
        velocity: DVec3,
        blend: Blend,
        moving: bool,
    ) -> PyResult<grid::GridTool> {
        let sh = coefficients.shape();
        let shape = [sh[0], sh[1], sh[2]];
        let coef = slice_of("grid", coefficients)?;
        let stop = Stop::default();
        let tool = detach_stoppable(py, &stop, || {
            let (o, c) = (self.origin, self.center);
            let cancel = || stop.requested();
            grid::grid_tool(
                o,
                self.spacing,
                shape,
                coef,
                velocity,
                c,
                self.reach,
                blend.0,
                moving,
                &cancel,
            )
        })??;
        Ok(tool)
    }
}

/// `spinal.fields.sdf_tool` / `mesh_tool` from the B-spline coefficients `(nx+2, ny+2,
/// nz+2)` of the distance sampled on `(nx, ny, nz)` nodes. `options`: the grid's (see
/// [`GridPlace`]), `velocity`, `blend` and `moving`.
#[pyfunction]
pub fn field_grid(
    py: Python<'_>,
    coefficients: PyReadonlyArray3<'_, f64>,
    options: Options<'_>,
) -> PyResult<PyField> {
    let place = GridPlace::read(&options)?;
    let velocity: [f64; 3] = options.get("velocity")?;
    let blend: Blend = options.get("blend")?;
    let moving: bool = options.get("moving")?;
    let tool = place.tool(py, &coefficients, velocity.into(), blend, moving)?;
    Ok(PyField::new(Field::single(tool), &place.name))
}

/// `spinal.fields.along_path`: spine samples `(n, 3)` and their frames `(n, 3, 3)` (columns
/// `r, s, t`).
/// `options`: `radius`, `duration`, `kind`, `tool`, `rate`, `t0`, `reach` (`None`: the
/// radius), `falloff_power` and `blend`.
#[pyfunction]
pub fn field_path(
    py: Python<'_>,
    points: PyReadonlyArray2<'_, f64>,
    frames: PyReadonlyArray3<'_, f64>,
    options: Options<'_>,
) -> PyResult<PyField> {
    let radius: f64 = options.get("radius")?;
    let duration: f64 = options.get("duration")?;
    let kind: path::PathKind = options.get("kind")?;
    let tool: Carry = options.get("tool")?;
    let rate: f64 = options.get("rate")?;
    let t0: f64 = options.get("t0")?;
    let reach: Option<f64> = options.opt("reach")?;
    let falloff_power: i64 = options.get("falloff_power")?;
    let blend: Blend = options.get("blend")?;
    let x = vec3s("points", &points)?;
    let rows: &[[f64; 9]] = bytemuck::cast_slice(slice_of("frames", &frames)?);
    // row-major (n, 3, 3) -> glam's column-major: transpose
    let fr: Vec<DMat3> = crate::run::alloc::collect(
        "along_path",
        rows.iter().map(|r| DMat3::from_cols_array(r).transpose()),
    )?;
    let args = path::PathArgs {
        points: x,
        frames: &fr,
        radius,
        duration,
        kind,
        carry: tool.0,
        rate,
        t0,
        reach,
        power: falloff_power,
        linear: blend.0,
    };
    let name = format!(
        "along_path({}, {})",
        match kind {
            path::PathKind::Translate => "translate",
            path::PathKind::Rotate => "rotate",
            path::PathKind::Twist => "twist",
            path::PathKind::Bend => "bend",
        },
        if tool.0 { "carry" } else { "push" }
    );
    let stop = Stop::default();
    let p = detach_stoppable(py, &stop, || {
        path::PathTool::from_args(args, &|| stop.requested())
    })??;
    Ok(PyField::new(Field::single(p), &name))
}

/// The zero field (an empty sum).
#[pyfunction]
pub fn field_zero() -> PyField {
    PyField {
        field: Field::default(),
        names: Vec::new(),
        recipe: Vec::new(),
        unrecorded: 0,
    }
}

/// The B-spline coefficients `(nx+2, ny+2, nz+2)` interpolating distances sampled on
/// `(nx, ny, nz)` nodes ([`grid::spline_coefficients`]).
#[pyfunction]
pub fn field_grid_coefficients<'py>(
    py: Python<'py>,
    values: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let sh = values.shape();
    let n = [sh[0], sh[1], sh[2]];
    let v = slice_of("grid", &values)?;
    let p = n.map(|k| k.saturating_add(2));
    let out = empty::<f64, numpy::Ix3>(py, "grid coefficients", &p)?;
    {
        let mut rw = out.readwrite();
        let o = slice_mut(&mut rw)?;
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            grid::spline_coefficients(v, n, o, &|| stop.requested())
        })??;
    }
    Ok(out)
}

/// A field of one curl tool of `shape` (shared by the tool's copies).
fn curl_field<D>(
    shape: D,
    m: curl::Motion,
    power: i64,
    moving: bool,
    name: &str,
) -> PyResult<PyField>
where
    std::sync::Arc<D>: curl::Distance + Clone + Into<curl::Shape>,
    curl::CurlTool<std::sync::Arc<D>>: crate::deform::Tool + 'static,
{
    let tool = curl::CurlTool::new(std::sync::Arc::new(shape), m, power, moving)?;
    Ok(PyField::new(Field::single(tool), name))
}

/// The motion of a curl tool, read from its `options`: `velocity`, `angular_velocity`,
/// `pivot` (each `None` when not given), `falloff_power` and `moving`.
struct MotionOptions {
    velocity: Option<[f64; 3]>,
    angular_velocity: Option<[f64; 3]>,
    pivot: Option<[f64; 3]>,
    falloff_power: i64,
    moving: bool,
}

impl MotionOptions {
    fn read(o: &Options<'_>) -> PyResult<MotionOptions> {
        Ok(MotionOptions {
            velocity: o.opt("velocity")?,
            angular_velocity: o.opt("angular_velocity")?,
            pivot: o.opt("pivot")?,
            falloff_power: o.get("falloff_power")?,
            moving: o.get("moving")?,
        })
    }

    /// The motion about the tool's `center`.
    fn motion(&self, center: DVec3) -> PyResult<curl::Motion> {
        Ok(curl::Motion::new(
            self.velocity.map(DVec3::from),
            self.angular_velocity.map(DVec3::from),
            self.pivot.map(DVec3::from),
            center,
        )?)
    }
}

/// `spinal.fields.sdf_curl` / `mesh_curl`: a curl tool shaped by the sampled distance of
/// [`field_grid`] (the same `coefficients`). `options`: the grid's (see [`GridPlace`]) and
/// the motion's (see [`MotionOptions`]).
#[pyfunction]
pub fn field_grid_curl(
    py: Python<'_>,
    coefficients: PyReadonlyArray3<'_, f64>,
    options: Options<'_>,
) -> PyResult<PyField> {
    let place = GridPlace::read(&options)?;
    let m = MotionOptions::read(&options)?;
    let shape = place.tool(py, &coefficients, DVec3::ZERO, Blend(false), false)?;
    let mo = m.motion(shape.center)?;
    curl_field(shape, mo, m.falloff_power, m.moving, &place.name)
}

/// `spinal.fields.rod`: a curl tool shaped as the tube about the axis through `points`.
/// `options`: `radius`, `center`, `reach` (`None`: defaults), `velocity`, `angular_velocity`,
/// `pivot` (the motion, each `None` when not given), `falloff_power` and `moving`.
#[pyfunction]
pub fn field_rod(
    py: Python<'_>,
    points: PyReadonlyArray2<'_, f64>,
    options: Options<'_>,
) -> PyResult<PyField> {
    let radius: f64 = options.get("radius")?;
    let center: Option<[f64; 3]> = options.opt("center")?;
    let reach: Option<f64> = options.opt("reach")?;
    let m = MotionOptions::read(&options)?;
    let x = vec3s("points", &points)?;
    let stop = Stop::default();
    let rod = detach_stoppable(py, &stop, || {
        let c = center.map(DVec3::from);
        rod::Rod::from_points(x, radius, reach, c, &|| stop.requested())
    })??;
    let mo = m.motion(rod.center)?;
    curl_field(rod, mo, m.falloff_power, m.moving, "rod")
}

/// `spinal.fields.keyframed`: `tool` (a field) following keys — its shape when it is one tool
/// with a shape, else the whole field carried rigidly about `center`; orientations as
/// rotation matrices `(k, 3, 3)` or quaternions `(k, 4)` `(x, y, z, w)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn field_keyframed(
    py: Python<'_>,
    tool: &PyField,
    times: PyReadonlyArray1<'_, f64>,
    positions: PyReadonlyArray2<'_, f64>,
    matrices: Option<PyReadonlyArray3<'_, f64>>,
    quaternions: Option<PyReadonlyArray2<'_, f64>>,
    falloff_power: Option<i64>,
    center: Option<[f64; 3]>,
) -> PyResult<PyField> {
    let t = slice_of("times", &times)?;
    let x = vec3s("positions", &positions)?;
    let orientations = match (matrices, quaternions) {
        (Some(m), _) => {
            let rows: &[[f64; 9]] = bytemuck::cast_slice(slice_of("orientations", &m)?);
            Some(keyframe::Orientations::Matrices(alloc::collect(
                "keyframed",
                rows.iter().map(|r| DMat3::from_cols_array(r).transpose()),
            )?))
        }
        (None, Some(q)) => {
            let q = super::convert::quats("orientations", &q)?;
            Some(keyframe::Orientations::Quaternions(alloc::copied(
                "keyframed",
                q,
            )?))
        }
        (None, None) => None,
    };
    let stop = Stop::default();
    let f = detach_stoppable(py, &stop, || {
        let cancel = || stop.requested();
        let keys = keyframe::Keys::new(t, x, orientations, &cancel)?;
        keyframe::keyframed(
            &tool.field,
            keys,
            falloff_power,
            center.map(DVec3::from),
            &cancel,
        )
    })??;
    Ok(PyField::new(f, "keyframed"))
}

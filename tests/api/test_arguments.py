"""Every scalar and flag argument of every public callable is checked, and its error is named.

The walk covers the public callables of ``spinal``, ``spinal.fields``, ``spinal.quaternions``,
``spinal.ph`` and ``spinal.curves`` (and the public methods of their classes). The parameters
come from :func:`inspect.signature`; each is classified by its annotation or default
(``bool``, ``int``, ``float``, ``str``) or by the table below (arrays are not walked here: their
checks are in the per-module tests). Each scalar parameter gets bad values — a string, a list
``[1, 2]``, NaN, ±inf, a bool where a number is expected, a number where a bool is expected,
``2**70`` and ``-1`` for integers, a number and an unknown word for a string choice — on top
of a valid call from the table, and the call must raise ``TypeError`` or ``ValueError`` (or
``MemoryError`` for a size) whose message names the parameter. A parameter the walk cannot
classify fails the test, so a new argument needs an entry here.
"""

from __future__ import annotations

import inspect
import math
import re

import numpy as np
import pytest
import trimesh

import spinal
from spinal import curves, fields, ph, quaternions

# ---- valid base arguments ---------------------------------------------------------------

_u = np.linspace(0.0, 1.0, 12)
PTS = np.c_[np.cos(2 * _u), np.sin(2 * _u), 0.5 * _u]
PROFILE = 0.1 * np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
SPHERE = trimesh.creation.icosphere(1)
MESH = spinal.Mesh(SPHERE.vertices, SPHERE.faces)
FIELD = fields.sphere((0.0, 0.0, 0.0), 0.5, (0.1, 0.0, 0.0))
TRANS = fields.translation((0.0, 0.0, 0.0), 0.5, (0.1, 0.0, 0.0))
GRID = np.linalg.norm(np.stack(np.meshgrid(*[np.linspace(-3, 3, 16)] * 3, indexing="ij"),
                               -1), axis=-1) - 0.5
FR = spinal.frames(PTS)
RZ = np.array([[np.cos(0.3), -np.sin(0.3), 0], [np.sin(0.3), np.cos(0.3), 0], [0, 0, 1]])
Q = quaternions.to_quaternions(spinal.frames(PTS))
SPLINE = ph.fit(curves.Helix(), segments=3)
CP = SPLINE.control_points[0]
REST = np.c_[np.zeros(6), np.zeros(6), np.linspace(0, 1, 6)]
BEND = np.c_[0.2 * np.linspace(0, 1, 6) ** 2, np.zeros(6), np.linspace(0, 1, 6)]
CLOUD = np.random.default_rng(0).uniform(-0.1, 0.1, (20, 3)) + [0, 0, 0.5]
SHEET = np.stack([*np.meshgrid(np.linspace(-1, 1, 5), np.linspace(-1, 1, 5), indexing="ij"),
                  np.zeros((5, 5))], -1)
SHEET2 = SHEET + [0, 0, 0.1]
SHEET2[..., 2] += 0.1 * SHEET[..., 0] ** 2
SBIND = spinal.SpineBinding(CLOUD, REST)
SHEET_PTS = CLOUD * [5, 5, 1] - [0, 0, 0.5]
SURF = spinal.SurfaceBinding(SHEET_PTS, SHEET)


def _threads(n):
    with spinal.threads(n):
        pass


#: name -> (callable, positional args, keyword args). Methods are bound to a base object.
BASE = {
    # spinal
    "spinal.advect": (spinal.advect, (PTS, FIELD, 0.1), {}),
    "spinal.closing_angle": (spinal.closing_angle, (curves.Viviani().sample(40)[:-1],), {}),
    "spinal.deform": (spinal.deform, (SPHERE, FIELD, 0.01), {"steps": 1}),
    "spinal.estimate_tangents": (spinal.estimate_tangents, (PTS,), {}),
    "spinal.flesh": (spinal.flesh, (CLOUD, REST, BEND), {}),
    "spinal.flesh_surface": (spinal.flesh_surface, (SHEET_PTS, SHEET, SHEET2), {}),
    "spinal.frames": (spinal.frames, (PTS,), {}),
    "spinal.frames_in_time": (spinal.frames_in_time, (np.stack([PTS, PTS + 0.01]),), {}),
    "spinal.get_num_threads": (spinal.get_num_threads, (), {}),
    "spinal.set_num_threads": (spinal.set_num_threads, (None,), {}),
    "spinal.threads": (_threads, (2,), {}),
    "spinal.stamp": (spinal.stamp, (SPHERE, (-2, 0, 0), (-1.5, 0, 0), 0.2), {}),
    "spinal.sweep": (spinal.sweep, (PTS, PROFILE), {}),
    "spinal.tube": (spinal.tube, (PTS, 0.1), {}),
    "spinal.Mesh": (spinal.Mesh, (SPHERE.vertices, SPHERE.faces), {}),
    "spinal.Mesh.edge_stats": (MESH.edge_stats, (), {}),
    "spinal.Mesh.self_intersections": (MESH.self_intersections, (), {"limit": 100}),
    "spinal.Mesh.concatenate": (spinal.Mesh.concatenate, ([MESH, MESH],), {}),
    "spinal.SpineBinding": (spinal.SpineBinding, (CLOUD, REST), {}),
    "spinal.SpineBinding.deform": (SBIND.deform, (BEND,), {}),
    "spinal.SpineBinding.animate": (SBIND.animate, (np.stack([BEND, BEND]),), {}),
    "spinal.SpineBinding.posed_spine": (SBIND.posed_spine, (BEND,), {}),
    "spinal.SurfaceBinding": (spinal.SurfaceBinding, (SHEET_PTS, SHEET), {}),
    "spinal.SurfaceBinding.deform": (SURF.deform, (SHEET2,), {}),
    # spinal.fields
    "spinal.fields.Field.steps": (FIELD.steps, (1.0,), {}),
    "spinal.fields.Field.breakpoints": (FIELD.breakpoints, (), {}),
    "spinal.fields.along_path": (fields.along_path, (PTS, 0.2, 1.0), {}),
    "spinal.fields.bend": (fields.bend, ((0, 0, 0), (0, 0, 1), 0.5, 1.0), {}),
    "spinal.fields.capsule": (fields.capsule, ((0, 0, 0), (1, 0, 0), 0.2, (0, 0.1, 0)), {}),
    "spinal.fields.keyframed": (fields.keyframed, (TRANS, [0.0, 1.0], [[0, 0, 0], [1, 0, 0]]),
                                {}),
    "spinal.fields.mesh_curl": (fields.mesh_curl, (SPHERE,), {"velocity": (0.1, 0, 0),
                                                             "resolution": 24, "reach": 2.5}),
    "spinal.fields.mesh_tool": (fields.mesh_tool, (SPHERE, (0.1, 0, 0)), {"resolution": 24, "reach": 2.5}),
    "spinal.fields.rod": (fields.rod, (PTS, 0.1), {"velocity": (0.1, 0, 0)}),
    "spinal.fields.rotation": (fields.rotation, ((0, 0, 0), 0.5, (0, 0, 1), 1.0), {}),
    "spinal.fields.sdf_curl": (fields.sdf_curl, (GRID, (-3, -3, -3), 0.4),
                               {"velocity": (0.1, 0, 0), "reach": 1.6}),
    "spinal.fields.sdf_tool": (fields.sdf_tool, (GRID, (-1, -1, -1), 2 / 7, (0.1, 0, 0)),
                              {"reach": 1.6}),
    "spinal.fields.sphere": (fields.sphere, ((0, 0, 0), 0.5, (0.1, 0, 0)), {}),
    "spinal.fields.strip": (fields.strip, ((0, 0, 0), (1, 0, 0), 0.2, (0.1, 0, 0)), {}),
    "spinal.fields.strip_curve": (fields.strip_curve, (PTS, 0.2, 0.1), {}),
    "spinal.fields.sum": (fields.sum, ([FIELD, TRANS],), {}),
    "spinal.fields.torus": (fields.torus, ((0, 0, 0), (0, 0, 1), 1.0, 0.2, 0.1), {}),
    "spinal.fields.translation": (fields.translation, ((0, 0, 0), 0.5, (0.1, 0, 0)), {}),
    "spinal.fields.twist": (fields.twist, ((0, 0, 0), (0, 0, 1), 0.5, 1.0), {}),
    # spinal.quaternions
    "spinal.quaternions.camera_frames": (quaternions.camera_frames, (PTS,), {}),
    "spinal.quaternions.from_quaternions": (quaternions.from_quaternions, (Q,), {}),
    "spinal.quaternions.make_continuous": (quaternions.make_continuous, (Q,), {}),
    "spinal.quaternions.quaternion_frames": (quaternions.quaternion_frames, (PTS,), {}),
    "spinal.quaternions.quaternion_length": (quaternions.quaternion_length, (Q,), {}),
    "spinal.quaternions.slerp": (quaternions.slerp, (Q[0], Q[1], 0.5), {}),
    "spinal.quaternions.slerp_frames": (quaternions.slerp_frames,
                                        (spinal.frames(PTS), np.linspace(0, 1, 5)), {}),
    "spinal.quaternions.spin": (quaternions.spin, (FR[0], FR[0] @ RZ), {}),
    "spinal.quaternions.to_quaternions": (quaternions.to_quaternions,
                                          (spinal.frames(PTS),), {}),
    "spinal.quaternions.walk_mesh": (quaternions.walk_mesh,
                                     (SPHERE.vertices, SPHERE.faces, 0,
                                      SPHERE.vertices[SPHERE.faces[0]].mean(0), [[0.1, 0]]),
                                     {}),
    "spinal.quaternions.walk_mesh_many": (quaternions.walk_mesh_many,
                                          (SPHERE.vertices, SPHERE.faces, [0],
                                           SPHERE.vertices[SPHERE.faces[[0]]].mean(1),
                                           [[0.1, 0]]), {}),
    # spinal.ph
    "spinal.ph.PHSpline": (ph.PHSpline, (SPLINE.control_points,), {}),
    "spinal.ph.PHSpline.angle": (SPLINE.angle, ([0.5],), {}),
    "spinal.ph.PHSpline.angle_fit": (SPLINE.angle_fit, (), {}),
    "spinal.ph.PHSpline.evaluate": (SPLINE.evaluate, ([0.5],), {}),
    "spinal.ph.PHSpline.frenet": (SPLINE.frenet, ([0.5],), {}),
    "spinal.ph.PHSpline.parameter": (SPLINE.parameter, ([0.5],), {}),
    "spinal.ph.PHSpline.points": (SPLINE.points, (), {}),
    "spinal.ph.PHSpline.rational_frames": (SPLINE.rational_frames, (), {}),
    "spinal.ph.PHSpline.rmf": (SPLINE.rmf, (), {}),
    "spinal.ph.PHSpline.samples": (SPLINE.samples, (), {}),
    "spinal.ph.PHSpline.surface": (SPLINE.surface, ([[0, 0], [0.1, 0]],), {}),
    "spinal.ph.PHSpline.sweep": (SPLINE.sweep, (PROFILE,), {"n_per_segment": 4}),
    "spinal.ph.angle_fit": (ph.angle_fit, (CP,), {}),
    "spinal.ph.evaluate": (ph.evaluate, (CP, 0.5), {}),
    "spinal.ph.fit": (ph.fit, (curves.Helix(),), {"segments": 2}),
    "spinal.ph.from_quaternions": (ph.from_quaternions, ([0, 0, 0, 1], [0, 0, 0.1, 1]), {}),
    "spinal.ph.hermite": (ph.hermite, ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)), {}),
    "spinal.ph.invariants": (ph.invariants, (CP,), {}),
    "spinal.ph.is_ph": (ph.is_ph, (CP,), {}),
    "spinal.ph.preimage": (ph.preimage, (CP,), {}),
    # spinal.curves
    "spinal.curves.Bezier": (curves.Bezier, (PTS[:4],), {}),
    "spinal.curves.Helix": (curves.Helix, (), {}),
    "spinal.curves.Polynomial": (curves.Polynomial, (PTS[:3],), {}),
    "spinal.curves.TorusKnot": (curves.TorusKnot, (), {}),
    "spinal.curves.Viviani": (curves.Viviani, (), {}),
    "spinal.curves.Spline": (curves.Spline, (PTS,), {}),  # domain [0, 2.06] holds _u
}
for _cls in ("Bezier", "Helix", "Polynomial", "TorusKnot", "Viviani", "Spline", "Curve"):
    _obj = curves.Helix() if _cls == "Curve" else BASE[f"spinal.curves.{_cls}"][0](
        *BASE[f"spinal.curves.{_cls}"][1])
    for _m in ("curvature", "d1", "d2", "d3", "frenet", "point", "speed", "tangent", "torsion"):
        BASE[f"spinal.curves.{_cls}.{_m}"] = (getattr(_obj, _m), (_u,), {})
    BASE[f"spinal.curves.{_cls}.parameters"] = (_obj.parameters, (5,), {})
    BASE[f"spinal.curves.{_cls}.sample"] = (_obj.sample, (5,), {})
BASE["spinal.curves.Helix.rmf"] = (curves.Helix().rmf, (_u,), {})
_spline = curves.Spline(PTS)
BASE["spinal.curves.Spline.arc_length_parameters"] = (_spline.arc_length_parameters, (5,), {})
BASE["spinal.curves.Spline.sample_arc_length"] = (_spline.sample_arc_length, (5,), {})
BASE["spinal.compensate_volume"] = (spinal.compensate_volume, (SPHERE, 4.0), {})
PROFILE_OPEN = 0.1 * np.c_[np.cos(np.linspace(0, 1, 8)), np.sin(np.linspace(0, 1, 8))]
PSURF = spinal.profile_surface(PTS, PROFILE_OPEN)
BASE["spinal.profile_surface"] = (spinal.profile_surface, (PTS, PROFILE_OPEN), {})
BASE["spinal.ProfileSurface.parabolic_lines"] = (PSURF.parabolic_lines, (), {})
BASE["spinal.ProfileSurface.mesh"] = (PSURF.mesh, (), {})

#: Callables that take no user arguments worth walking, with the reason.
NOT_WALKED = {
    "spinal.DeformReport": "a result record built by deform, not an input",
    "spinal.StampReport": "a result record built by stamp, not an input",
    "spinal.CompensationReport": "a result record built by compensate_volume, not an input",
    "spinal.ProfileSurface": "a result record built by profile_surface, not an input",
    "spinal.FoldOverWarning": "a warning class raised by the library",
    "spinal.SkippedCurvesWarning": "a warning class raised by the library",
    "spinal.PrecisionWarning": "a warning class raised by the library",
    "spinal.RefinementWarning": "a warning class raised by the library",
    "spinal.quaternions.WalkResult": "a result record (named tuple)",
    "spinal.quaternions.WalksResult": "a result record (named tuple)",
    "spinal.fields.Field": "not constructible from Python (the constructors make fields)",
    "spinal.curves.Curve": "the abstract base class (no parameters)",
    "spinal.Mesh.plot": "needs pyvista and a display; its options go to pyvista",
    "spinal.Mesh.save": "path: a str is the valid type (any path-like)",
    "spinal.Mesh.load": "path: a file (its errors are tested in test_io.py)",
    "spinal.Mesh.to_pyvista": "no parameters",
    "spinal.Mesh.to_trimesh": "no parameters",
}

#: Parameters that are arrays (or objects) — not scalars; checked by the modules' own tests.
ARRAYS = {
    "points", "tangents", "initial", "end", "u", "lengths", "offsets", "constraints", "guide",
    "previous", "vertices", "faces", "normals", "uv", "fold_over", "point_data", "cell_data",
    "sample_of", "curve_of", "skipped_curves", "meshes", "mesh", "field", "rest_spine",
    "posed_spine", "posed_spines_t", "posed_frames", "posed_up", "twist", "rest_surface", "posed_surface",
    "points_t", "tangents_t", "profile", "frames", "scale", "start", "center", "axis",
    "velocity", "angular_velocity", "pivot", "grid", "origin", "tool", "times", "positions",
    "orientations", "fields", "quaternions", "q", "q0", "q1", "new_u", "key_u", "a", "b",
    "face", "point", "moves", "direction", "directions", "control_points", "knots", "s", "v",
    "section_ctrl", "section_weights", "curve", "domain", "A0", "A1", "p0", "t0", "p1", "t1",
    "coefficients", "up", "bank", "kwargs", "spine", "out",
}

#: Parameters whose kind is not in the annotation/default: name -> kind, per callable
#: (``"*"`` for every callable). Kinds: real, finite, count (int >= 0 or >= 1), int, bool, str.
KINDS = {
    "*": {"max_passes": "count", "max_segments": "count", "n_per_segment": "count",
          "sides": "count", "resolution": "count", "iterations": "count",
          "derivative": "count", "duration": "finite", "radius": "finite", "reach": "real", "rate": "finite",
          "steps": "count", "max_vertices": "count", "refine": "real", "progress": "bool",
          "angular_speed": "finite", "spacing": "finite", "speed": "finite", "major": "finite",
          "minor": "finite", "tol": "real", "segments": "count", "phi": "finite",
          "falloff_power": "count", "n": "count", "dtype": "str", "blend": "finite"},
    "spinal.advect": {"t0": "finite"},
    "spinal.deform": {"t0": "finite"},
    "spinal.fields.along_path": {"t0": "finite"},
    "spinal.set_num_threads": {"n": "count"},
    "spinal.threads": {"n": "count"},
    "spinal.stamp": {"frames": "count"},
    "spinal.tube": {"radius": "array"},  # a scalar or one per point
    "spinal.fields.rod": {"radius": "array"},  # a scalar or one per sample
    "spinal.quaternions.slerp": {"u": "array"},
    "spinal.ph.evaluate": {"v": "array"},
    "spinal.curves.Helix": {"a": "finite", "b": "finite"},
    "spinal.curves.Viviani": {"a": "finite"},
    "spinal.curves.TorusKnot": {"R": "finite", "r": "finite"},
}

#: (callable, parameter) -> {bad value label: reason it is legitimately accepted}.
ACCEPTED = {
    ("*", "turns"): {"-1": "a negative number of turns is a turn the other way"},
    ("spinal.SpineBinding.animate", "slide"): {"[1, 2]": "one slide per pose (two here)",
                                               "-1": "a slide backwards along the spine"},
    ("spinal.SpineBinding.deform", "slide"): {"-1": "a slide backwards along the spine"},
    ("spinal.frames", "turns"): {"-1": "a turn the other way",
                                 "[1, 2]": "a sequence: the turns per steered interval"},
    ("*", "reach"): {"inf": "an infinite reach: the field reaches everywhere"},
    ("*", "refine"): {"inf": "no refinement"},
    ("spinal.ph.is_ph", "tol"): {"inf": "every polygon passes an infinite tolerance"},
    ("*", "rate"): {"-1": "a negative rate turns the other way"},
    ("*", "speed"): {"-1": "a negative speed moves the other way"},
    ("*", "angular_speed"): {"-1": "a negative speed turns the other way"},
    ("*", "duration"): {"-1": "a negative duration runs backwards"},
    ("*", "t0"): {"-1": "any start time"},
    ("*", "phi"): {"-1": "any angle"},
    ("*", "omega_start"): {"-1": "any angle"},
    ("*", "angle"): {"-1": "any angle"},
    ("*", "b"): {"-1": "a left-handed helix"},
    ("spinal.fields.bend", "radius"): {},
    ("*", "miter_limit"): {"inf": "no mitre limit"},
    ("*", "singular_angle"): {},
    ("*", "guide_weight"): {"inf": "the guide alone"},
    ("*", "dtype"): {"5": "a numpy dtype-like; checked by numpy with the name"},
    ("*", "n"): {"None": "the default (all threads)"},
    ("*", "max_vertices"): {"None": "the default",
                            "10**12": "a cap on the refinement: nothing is allocated for it"},
    ("*", "segments"): {"None": "the default (adaptive)"},
}


def _kind(qual: str, p: inspect.Parameter) -> str | None:
    for key in (qual, "*"):
        if p.name in KINDS.get(key, {}):
            return KINDS[key][p.name]
    ann = p.annotation if isinstance(p.annotation, str) else getattr(
        p.annotation, "__name__", "")
    ann = ann.replace(" | None", "")
    if ann in ("bool", "int", "float", "str"):
        return {"float": "real"}.get(ann, ann)
    d = p.default
    if isinstance(d, bool):
        return "bool"
    if isinstance(d, int):
        return "int"
    if isinstance(d, float):
        return "real"
    if isinstance(d, str):
        return "str"
    if p.name in ARRAYS:
        return "array"
    return None


def _bad_values(kind: str):
    num = [("'x'", "x"), ("[1, 2]", [1, 2]), ("True", True)]
    if kind == "bool":
        return [("'x'", "x"), ("[1, 2]", [1, 2]), ("1", 1), ("0.5", 0.5), ("None", None)]
    if kind == "str":
        return [("5", 5), ("[1, 2]", [1, 2]), ("'no-such-choice'", "no-such-choice")]
    if kind in ("real", "finite"):
        return num + [("nan", math.nan), ("inf", math.inf), ("-inf", -math.inf)] + (
            [("-1", -1.0)] if kind == "finite" else [])
    if kind in ("int", "count"):
        return num + [("1.5", 1.5), ("nan", math.nan), ("2**70", 2**70), ("-1", -1)] + (
            [("10**12", 10**12)] if kind == "count" else [])
    raise AssertionError(kind)


def _public():
    """(qualified name, callable) of every public callable and public method."""
    for mod in (spinal, fields, quaternions, ph, curves):
        for name in mod.__all__:
            obj = getattr(mod, name)
            if inspect.ismodule(obj) or not callable(obj):
                continue
            qual = f"{mod.__name__}.{name}"
            yield qual, obj
            if inspect.isclass(obj) and not issubclass(obj, (Warning, tuple)):
                for m in dir(obj):
                    if not m.startswith("_") and callable(getattr(obj, m)):
                        yield f"{qual}.{m}", getattr(obj, m)


def _cases():
    return [qual for qual, _ in _public() if qual not in NOT_WALKED]


CASES = _cases()


def test_every_public_callable_has_a_base_call():
    missing = [q for q in CASES if q not in BASE]
    assert not missing, f"add a base call (or a NOT_WALKED reason) for {missing}"


@pytest.mark.parametrize("qual", CASES)
def test_bad_scalars_raise_named_errors(qual):
    fn, args, kwargs = BASE[qual]
    fn(*args, **kwargs)  # the base call is valid
    target = BASE[qual][0]
    sig = inspect.signature(getattr(target, "__wrapped__", target))
    params = [p for p in sig.parameters.values() if p.name != "self"
              and p.kind not in (p.VAR_POSITIONAL,)]
    unknown = []
    failures = []
    for i, p in enumerate(params):
        kind = _kind(qual, p)
        if kind is None:
            unknown.append(p.name)
            continue
        if kind == "array":
            continue
        accepted = {**ACCEPTED.get(("*", p.name), {}), **ACCEPTED.get((qual, p.name), {})}
        for label, bad in _bad_values(kind):
            if label in accepted:
                continue
            if label == "None" and p.default is None:
                continue  # the default itself
            a, kw = list(args), dict(kwargs)
            if p.kind is p.POSITIONAL_ONLY or (i < len(a) and p.kind is not p.KEYWORD_ONLY):
                a[i] = bad
            else:
                kw[p.name] = bad
            try:
                fn(*a, **kw)
            except (TypeError, ValueError, MemoryError) as e:
                if not re.search(rf"(^|\W){re.escape(p.name)}\W", str(e) + " "):
                    failures.append(f"{p.name}={label}: {type(e).__name__} {str(e)[:90]!r}")
            except Exception as e:  # noqa: BLE001
                failures.append(f"{p.name}={label}: {type(e).__name__} {str(e)[:90]!r}")
            else:
                failures.append(f"{p.name}={label}: accepted")
    assert not unknown, f"{qual}: classify {unknown} in KINDS or ARRAYS"
    assert not failures, f"{qual}:\n  " + "\n  ".join(failures)


# ---- the audit's reproducers -------------------------------------------------------------

def _named(exc, name, call):
    with pytest.raises(exc) as got:
        call()
    assert str(got.value).startswith(f"{name}:"), str(got.value)


@pytest.mark.parametrize("bad", [math.nan, -1.0, 0.0, None, [1, 2]])
def test_preimage_tol_is_blamed_not_control_points(bad):
    _named((TypeError, ValueError), "tol", lambda: ph.preimage(CP, tol=bad))


def test_audit_counts_are_bounded_and_named():
    """Before: a numpy MemoryError without a name (10**12 samples), a > 200 s fit, 10**12
    refinement passes accepted, ``u:`` for a count ``n``."""
    import time

    _named(ValueError, "n_per_segment", lambda: SPLINE.samples(10**12))
    _named(ValueError, "n_per_segment", lambda: SPLINE.rmf(n_per_segment=10**12))
    _named(ValueError, "n", lambda: curves.Helix().sample(10**12))
    _named(ValueError, "n", lambda: curves.Helix().parameters(1))
    t = time.process_time()  # CPU time: a loaded machine does not stretch it
    _named(ValueError, "max_segments",
           lambda: ph.fit(curves.Helix(), tol=1e-300, max_segments=10**9))
    assert time.process_time() - t < 1.0
    _named(ValueError, "max_passes", lambda: spinal.deform(SPHERE, FIELD, 0.01, max_passes=10**12))


def test_audit_types_and_values_are_named():
    _named(TypeError, "duration", lambda: FIELD.steps("x"))
    _named(TypeError, "duration", lambda: FIELD.steps(True))
    _named(TypeError, "kind", lambda: fields.strip((0, 0, 0), (1, 0, 0), 0.2, (0.1, 0, 0),
                                                   kind=5))
    for call in (lambda: ph.is_ph(CP, tol=[1, 2]), lambda: ph.fit(curves.Helix(), tol=[1, 2])):
        _named(TypeError, "tol", call)
    for call in (lambda: SPLINE.rmf(omega_start=[1, 2]),
                 lambda: SPLINE.angle([0.5], omega_start=[1, 2]),
                 lambda: SPLINE.sweep(PROFILE, omega_start=[1, 2])):
        _named(TypeError, "omega_start", call)
    for p in (1.5, 0, -2, 2**70):
        _named((TypeError, ValueError), "p", lambda p=p: curves.TorusKnot(p, 7))
        _named((TypeError, ValueError), "q", lambda p=p: curves.TorusKnot(2, p))
    _named(ValueError, "angle", lambda: curves.Helix().rmf(_u, angle=math.nan))


def test_lengths_and_offsets_errors_name_the_argument_given():
    """T3-10: errors about the bundle layout name the argument the caller passed: uint64
    lengths that would wrap, decreasing or short offsets."""
    t = np.linspace(0, 4 * np.pi, 50)
    h = np.c_[np.cos(t), np.sin(t), 0.2 * t]
    x = np.r_[h, h]
    cases = [
        ({"offsets": [0, 60, 200]}, "^offsets: the last offset is 200 but the input has 100"),
        ({"offsets": [0, 60, 50, 100]}, "^offsets: must never decrease, got 50 after 60"),
        ({"offsets": [5, 100]}, "^offsets: must start at 0, got 5"),
        ({"lengths": np.array([2**64 - 1, 1], np.uint64)}, "^lengths: 18446744073709551615 is"),
        ({"lengths": [60, 50]}, "^lengths: the curves cover 110 rows but the input has 100"),
        ({"lengths": [-10, 110]}, "^lengths: must be non-negative, curve 0 has length -10"),
    ]
    for call in (spinal.estimate_tangents, spinal.frames, lambda p, **k: spinal.tube(p, 0.1, **k)):
        for kw, msg in cases:
            with pytest.raises(ValueError, match=msg):
                call(x, **kw)


def test_mesh_objects_where_an_array_is_expected_say_what_to_pass():
    """Item 4 of the second review: a trimesh.Trimesh, spinal.Mesh or pyvista.PolyData passed
    where points are expected names the argument, what was passed and which array to pass,
    instead of numpy's "got dtype object"."""
    trimesh = pytest.importorskip("trimesh")
    pv = pytest.importorskip("pyvista")
    ico = trimesh.creation.icosphere(1)
    field = spinal.fields.translation([0, 0, 0], 0.1, [0, 0, 1])
    cases = [
        (lambda: spinal.frames(ico), r"^points: .*got a trimesh\.Trimesh; pass its vertices"),
        (lambda: spinal.tube(spinal.Mesh(ico.vertices, ico.faces), 0.1),
         r"^points: .*got a spinal\.Mesh; pass its vertices"),
        (lambda: spinal.estimate_tangents(pv.Sphere()),
         r"^points: .*got a pyvista\.PolyData; pass its points \(data\.points\)"),
        (lambda: spinal.advect(ico, field, 1.0), r"^vertices: .*trimesh\.Trimesh"),
    ]
    for call, words in cases:
        with pytest.raises(TypeError, match=words):
            call()
    # other objects keep the plain message
    with pytest.raises(TypeError, match=r"^points: expected an array of real numbers, got "
                                        r"dtype object$"):
        spinal.frames(object())

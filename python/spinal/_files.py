"""Mesh files: the writers behind :meth:`spinal.Mesh.save` and the reader behind
:meth:`spinal.Mesh.load`.

* PLY (binary little-endian; Bourke, "PLY — Polygon File Format"), VTK XML PolyData
  (Kitware, "VTK File Formats"), Wavefront OBJ and binary STL are written here with NumPy
  alone; binary glTF 2.0 (``.glb``; Khronos, "glTF 2.0 Specification", §4.4 "GLB File
  Format") too: one buffer with float32 positions (and their bounds, as the specification
  requires), normals, ``COLOR_0`` as normalised unsigned bytes and uint32 indices.
* Reading goes through trimesh (``.ply``, ``.obj``, ``.stl``, ``.glb``, ``.off``) or
  pyvista (``.vtp``, ``.vtk``), whichever the format needs.
"""

from __future__ import annotations

import json
import os
import pathlib
import struct
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ._mesh import Mesh

#: The suffixes :func:`write` writes.
WRITES = (".ply", ".vtp", ".obj", ".stl", ".glb")
#: The suffixes :func:`read` reads.
READS = (".ply", ".obj", ".stl", ".glb", ".gltf", ".off", ".vtp", ".vtk")


def _path(path: str | os.PathLike[str], formats: tuple[str, ...], kind: str) -> tuple[pathlib.Path, str]:
    """``path`` as a Path and its lower-case suffix, one of ``formats`` (errors name
    ``path``)."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a str or os.PathLike, got {type(path).__name__}")
    path = pathlib.Path(path)
    suffix = path.suffix.lower()
    if suffix not in formats:
        raise ValueError(f"path: unknown {kind}format {suffix!r}; use one of "
                         f"{', '.join(formats)}")
    return path, suffix


def write(mesh: Mesh, path: str | os.PathLike[str], colors: object = None) -> pathlib.Path:
    """Write ``mesh`` (a :class:`spinal.Mesh`) to ``path`` in the format of its suffix."""
    path, suffix = _path(path, WRITES, "")
    rgb, rest = vertex_colors(mesh, colors)
    if suffix == ".vtp":
        _write_vtp(mesh, path, rgb, rest)
        out: pathlib.Path = path
        return out
    if suffix == ".stl":
        _write_stl(mesh, path)
        out = path
        return out
    if len(mesh.vertices) >= 2**31:
        raise ValueError(f"path: {suffix[1:].upper()} indices here are 32-bit; the mesh is too "
                         f"large (save as .vtp)")
    if suffix == ".ply":
        _write_ply(mesh, path, rgb, rest)
    elif suffix == ".glb":
        _write_glb(mesh, path, rgb)
    else:
        _write_obj(mesh, path, rgb)
    out = path
    return out


def _write_obj(mesh: Mesh, path: pathlib.Path, rgb: np.ndarray | None) -> None:
    with open(path, "w") as f:
        f.write("# spinal mesh\n")
        if rgb is None:
            np.savetxt(f, mesh.vertices, fmt="v %.17g %.17g %.17g")
        else:
            np.savetxt(f, np.c_[mesh.vertices, rgb[:, :3] / 255.0],
                       fmt="v %.17g %.17g %.17g %.6g %.6g %.6g")
        if mesh.normals is not None:
            np.savetxt(f, mesh.normals, fmt="vn %.17g %.17g %.17g")
        if mesh.uv is not None:
            np.savetxt(f, mesh.uv, fmt="vt %.17g %.17g")
        k = mesh.faces + 1
        if mesh.normals is not None and mesh.uv is not None:
            fmt, data = "f %d/%d/%d %d/%d/%d %d/%d/%d", np.repeat(k, 3, axis=1)
        elif mesh.normals is not None:
            fmt, data = "f %d//%d %d//%d %d//%d", np.repeat(k, 2, axis=1)
        elif mesh.uv is not None:
            fmt, data = "f %d/%d %d/%d %d/%d", np.repeat(k, 2, axis=1)
        else:
            fmt, data = "f %d %d %d", k
        np.savetxt(f, data, fmt=fmt)


def _write_stl(mesh: Mesh, path: pathlib.Path) -> None:
    """Binary STL: an 80-byte header, the triangle count, then per triangle its unit
    normal (from the corners' cross product; zero for a degenerate triangle), its three
    corners (float32) and a zero attribute word. STL holds positions only."""
    if len(mesh.faces) >= 2**32:
        raise ValueError("path: STL counts triangles in 32 bits; the mesh is too large")
    V = np.asarray(mesh.vertices, dtype=np.float64)
    tri = V[mesh.faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    rec = np.zeros(len(tri), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"], rec["v"] = n, tri
    with open(path, "wb") as f:
        f.write(b"binary STL written by spinal".ljust(80, b" "))
        f.write(struct.pack("<I", len(tri)))
        f.write(rec.tobytes())


def _write_glb(mesh: Mesh, path: pathlib.Path, rgb: np.ndarray | None) -> None:
    """Binary glTF 2.0: a JSON chunk describing one mesh primitive (triangles) whose
    attributes live in one binary buffer, each view aligned to 4 bytes."""
    V = np.ascontiguousarray(mesh.vertices, dtype="<f4")
    parts, views, accessors, attributes = [], [], [], {}
    offset = 0

    def add(a: np.ndarray, component: int, kind: str, target: int, **extra: Any) -> int:
        nonlocal offset
        raw = np.ascontiguousarray(a).tobytes()
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(raw),
                      "target": target})
        parts.append(raw + b"\0" * (-len(raw) % 4))
        offset += len(raw) + (-len(raw) % 4)
        accessors.append({"bufferView": len(views) - 1, "componentType": component,
                          "count": len(a), "type": kind, **extra})
        return len(accessors) - 1

    ARRAY, ELEMENTS, FLOAT, UBYTE, UINT = 34962, 34963, 5126, 5121, 5125
    attributes["POSITION"] = add(V, FLOAT, "VEC3", ARRAY, min=V.min(0).tolist() if len(V)
                                 else [0, 0, 0], max=V.max(0).tolist() if len(V) else [0, 0, 0])
    if mesh.normals is not None:
        attributes["NORMAL"] = add(np.asarray(mesh.normals, dtype="<f4"), FLOAT, "VEC3", ARRAY)
    if mesh.uv is not None:
        # glTF's texture origin is the top left: v flipped
        uv = np.asarray(mesh.uv, dtype="<f4") * [1, -1] + [0, 1]
        attributes["TEXCOORD_0"] = add(uv.astype("<f4"), FLOAT, "VEC2", ARRAY)
    if rgb is not None:
        attributes["COLOR_0"] = add(rgb, UBYTE, "VEC4" if rgb.shape[1] == 4 else "VEC3",
                                    ARRAY, normalized=True)
    indices = add(np.asarray(mesh.faces, dtype="<u4").reshape(-1), UINT, "SCALAR", ELEMENTS)
    doc = {
        "asset": {"version": "2.0", "generator": "spinal"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": indices,
                                    "mode": 4}]}],
        "buffers": [{"byteLength": offset}],
        "bufferViews": views, "accessors": accessors,
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary = b"".join(parts)
    total = 12 + 8 + len(text) + 8 + len(binary)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(text), b"JSON") + text)
        f.write(struct.pack("<I4s", len(binary), b"BIN\0") + binary)


def read(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The arrays of the mesh file ``path``: ``vertices``, ``faces`` and, where the file has
    them, ``normals``, ``uv``, ``point_data`` (vertex colours as ``"colors"``) and
    ``cell_data``; the keyword arguments of :class:`spinal.Mesh`."""
    path, suffix = _path(path, READS, "mesh ")
    if not path.exists():
        raise FileNotFoundError(f"path: no such file: {os.fspath(path)!r}")
    if suffix in (".vtp", ".vtk"):
        return _read_vtk(path)
    return _read_trimesh(path)


def _need(module: str) -> Any:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(
            f"reading this format needs {module}: pip install 'spinal[io]' (from the package "
            f"index once published; from a clone: pip install -e '.[io]')") from None


def _read_trimesh(path: pathlib.Path) -> dict[str, Any]:
    trimesh = _need("trimesh")
    m = trimesh.load(os.fspath(path), process=False, force="mesh")
    if path.suffix.lower() == ".stl":
        # STL repeats every corner: shared corners become shared vertices, as a closed
        # mesh needs
        m.merge_vertices(merge_tex=True, merge_norm=True)
    out: dict[str, Any] = {"vertices": np.asarray(m.vertices, dtype=np.float64),
           "faces": np.asarray(m.faces, dtype=np.int64), "point_data": {}}
    raw = m.metadata.get("_ply_raw")
    if raw is not None and "vertex" in raw:
        return _from_ply(raw, out)
    visual = m.visual
    uv = getattr(visual, "uv", None)
    if uv is not None and len(uv) == len(m.vertices):
        out["uv"] = np.asarray(uv, dtype=np.float64)
    if visual.kind == "vertex":
        out["point_data"]["colors"] = np.asarray(visual.vertex_colors, dtype=np.uint8)
    for k, v in m.vertex_attributes.items():
        v = np.asarray(v)
        if k == "color" and v.ndim == 2 and v.shape[1] in (3, 4):
            # OBJ vertex colours beside texture coordinates (floats in [0, 1] or bytes)
            k = "colors"
            if v.dtype.kind == "f":
                v = np.rint(np.clip(v, 0, 1) * 255)
            v = v.astype(np.uint8)
        if len(v) == len(m.vertices) and v.dtype.kind in "biuf" and k not in out["point_data"]:
            out["point_data"][k] = v
    return out


def _grouped(data: np.ndarray, names: list[Any]) -> dict[str, Any]:
    """PLY properties ``name`` or ``name_0 … name_{k-1}`` as arrays ``(n,)`` or ``(n, k)``
    (the inverse of :func:`_columns`)."""
    out, seen = {}, set()
    for n in names:
        base, _, j = n.rpartition("_")
        if base and j.isdigit():
            if base in seen:
                continue
            cols: list[Any] = []
            while f"{base}_{len(cols)}" in names:
                cols.append(data[f"{base}_{len(cols)}"])
            if cols:
                seen.add(base)
                out[base] = np.stack(cols, axis=1)
                continue
        out[n] = np.asarray(data[n])
    return out


def _from_ply(raw: dict[str, Any], out: dict[str, Any]) -> dict[str, Any]:
    """The arrays of a PLY file from trimesh's raw elements: every vertex property (the
    positions read by trimesh are kept), normals ``nx ny nz``, texture coordinates ``s t``
    (or ``u v``, ``texture_u texture_v``), colours ``red green blue (alpha)`` and the other
    vertex and face properties as ``point_data`` and ``cell_data``."""
    data = raw["vertex"]["data"]
    names = list(data.dtype.names or ())
    taken = {"x", "y", "z"}
    # a triangles-only file: its own rows (trimesh leaves out vertices no face uses)
    lists = raw.get("face", {}).get("data")
    tri = None
    if lists is not None and "vertex_indices" in (lists.dtype.names or ()):
        v = lists["vertex_indices"]
        if v.dtype.names and len(v.dtype.names) == 2 and v[v.dtype.names[1]].ndim == 2 \
                and v[v.dtype.names[1]].shape[1] == 3:
            tri = np.asarray(v[v.dtype.names[1]], dtype=np.int64)
    if tri is not None and taken <= set(names):
        out["vertices"] = np.stack([np.asarray(data[c], dtype=np.float64) for c in "xyz"], 1)
        out["faces"] = tri

    def columns(*cols: str) -> np.ndarray | None:
        if all(c in names for c in cols):
            taken.update(cols)
            return np.stack([np.asarray(data[c]) for c in cols], axis=1)
        return None

    normals = columns("nx", "ny", "nz")
    if normals is not None and len(normals) == len(out["vertices"]):
        out["normals"] = normals.astype(np.float64)
    for pair in (("s", "t"), ("u", "v"), ("texture_u", "texture_v")):
        uv = columns(*pair)
        if uv is not None:
            out["uv"] = uv.astype(np.float64)
            break
    rgb = columns("red", "green", "blue", "alpha")
    if rgb is None:
        rgb = columns("red", "green", "blue")
    if rgb is not None:
        out["point_data"]["colors"] = rgb.astype(np.uint8)
    rest = [n for n in names if n not in taken]
    out["point_data"].update(_grouped(data, rest))
    faces = raw.get("face", {}).get("data")
    if faces is not None and faces.dtype.names:
        extra = [n for n in faces.dtype.names if n not in ("vertex_indices", "vertex_index")]
        cells = _grouped(faces, extra)
        if cells and all(len(v) == len(out["faces"]) for v in cells.values()):
            out["cell_data"] = cells
    return out


def _read_vtk(path: pathlib.Path) -> dict[str, Any]:
    pv = _need("pyvista")
    data = pv.read(os.fspath(path))
    poly = data if isinstance(data, pv.PolyData) else data.extract_surface()
    tri = poly.triangulate() if not poly.is_all_triangles else poly
    faces = np.asarray(tri.faces, dtype=np.int64).reshape(-1, 4)[:, 1:]
    out: dict[str, Any] = {"vertices": np.asarray(tri.points, dtype=np.float64), "faces": faces,
           "point_data": {}, "cell_data": {}}
    for k in tri.point_data:
        a = np.asarray(tri.point_data[k])
        if k == "Normals" and a.shape == out["vertices"].shape:
            out["normals"] = a.astype(np.float64)
        elif k == tri.point_data.active_texture_coordinates_name and a.ndim == 2 \
                and a.shape[1] == 2:
            out["uv"] = a.astype(np.float64)
        elif a.dtype.kind in "biuf":
            out["point_data"][k] = a
    if tri.n_cells == len(faces):
        for k in tri.cell_data:
            a = np.asarray(tri.cell_data[k])
            if a.dtype.kind in "biuf":
                out["cell_data"][k] = a
    return out


# PLY property types by NumPy dtype (int64 is written as int when it fits, else double)
_PLY_TYPES = {"f8": "double", "f4": "float", "i1": "char", "u1": "uchar", "i2": "short",
              "u2": "ushort", "i4": "int", "u4": "uint"}
# VTK XML type names by NumPy dtype
_VTK_TYPES = {"f8": "Float64", "f4": "Float32", "i1": "Int8", "u1": "UInt8", "i2": "Int16",
              "u2": "UInt16", "i4": "Int32", "u4": "UInt32", "i8": "Int64", "u8": "UInt64"}


def _plain(a: np.ndarray, kinds: dict[str, Any]) -> np.ndarray:
    """``a`` in a little-endian dtype of ``kinds`` (bools as uint8; int64 as int32 where the
    format has no 64-bit integers and the values fit, else float64)."""
    a = np.asarray(a)
    if a.dtype.kind == "b":
        a = a.astype(np.uint8)
    code = f"{a.dtype.kind}{a.dtype.itemsize}"
    if code not in kinds:
        fits = a.dtype.kind in "iu" and (a.size == 0 or (
            a.min() >= np.iinfo(np.int32).min and a.max() <= np.iinfo(np.int32).max))
        a = a.astype(np.int32 if fits else np.float64)
        code = f"{a.dtype.kind}{a.dtype.itemsize}"
    return a.astype(a.dtype.newbyteorder("<"), copy=False)


def _columns(data: dict[str, Any], kinds: dict[str, Any], taken: set[str], what: str) -> list[Any]:
    """``(property name, 1-D little-endian array)`` of every column of the attribute
    arrays (``name`` or ``name_0 … name_{k-1}``)."""
    cols = []
    for k, a in data.items():
        a = _plain(a, kinds)
        key = "_".join(k.split()) or "_"
        if not key.isascii():
            raise ValueError(f"{what}: the name {k!r} is not ASCII, which PLY property names "
                             f"must be; rename it, or save as .vtp (UTF-8 names)")
        names = [key] if a.ndim == 1 else [f"{key}_{j}" for j in range(a.shape[1])]
        for j, nm in enumerate(names):
            if nm in taken:
                raise ValueError(f"{what}: the name {nm!r} is taken in the PLY file")
            taken.add(nm)
            cols.append((nm, a if a.ndim == 1 else a[:, j]))
    return cols


def vertex_colors(mesh: Mesh, colors: object) -> tuple[np.ndarray | None, dict[str, Any]]:
    """The vertex colours to write, ``(V, 3|4)`` uint8 or None, and the ``point_data``
    arrays written besides them (all but the one the colours came from)."""
    rest = dict(mesh.point_data)
    if colors is None:
        if "colors" not in rest:
            return None, rest
        colors = "colors"
    name = None
    if isinstance(colors, str):
        if colors not in rest:
            raise ValueError(f"colors: no point_data array named {colors!r} (the mesh has "
                             f"{sorted(rest) or 'none'})")
        name, colors = colors, rest.pop(colors)
    what = "colors" if name is None else f"colors: point_data[{name!r}]"
    c = np.asarray(colors)
    if c.ndim != 2 or c.shape[1] not in (3, 4) or len(c) != len(mesh.vertices):
        raise ValueError(f"{what}: expected shape ({len(mesh.vertices)}, 3) or "
                         f"({len(mesh.vertices)}, 4) (RGB or RGBA per vertex), got "
                         f"{c.shape}")
    if c.dtype == np.uint8:
        return np.ascontiguousarray(c), rest
    if c.dtype.kind == "f":
        inside = (c >= 0) & (c <= 1)  # NaN is outside
        if not inside.all():
            row = int(np.argwhere(~inside)[0][0])
            raise ValueError(f"{what}: float colours must lie in [0, 1]; row {row} is "
                             f"{c[row].tolist()}")
        return np.rint(c * 255.0).astype(np.uint8), rest
    raise ValueError(f"{what}: expected uint8 (0 … 255) or floats in [0, 1], got dtype "
                     f"{c.dtype}")


def _ply_chunk(mesh: Mesh, rgb: np.ndarray | None, point_data: dict[str, Any], base: int = 0
               ) -> tuple[np.ndarray, np.ndarray]:
    """The vertex and face records of ``mesh`` as PLY stores them (structured arrays, the
    property declarations in their dtypes' order); face indices shifted by ``base``."""
    V, F = mesh.vertices, mesh.faces
    cols = [(n, V[:, j]) for j, n in enumerate("xyz")]
    if mesh.normals is not None:
        cols += [(n, mesh.normals[:, j]) for j, n in enumerate(("nx", "ny", "nz"))]
    if mesh.uv is not None:
        cols += [(n, mesh.uv[:, j]) for j, n in enumerate("st")]
    if rgb is not None:
        cols += [(n, rgb[:, j]) for j, n in enumerate(("red", "green", "blue", "alpha")[
            :rgb.shape[1]])]
    cols = [(n, _plain(c, _PLY_TYPES)) for n, c in cols]
    cols += _columns(point_data, _PLY_TYPES, {n for n, _ in cols}, "point_data")
    fcols = _columns(mesh.cell_data, _PLY_TYPES, {"vertex_indices"}, "cell_data")
    vert = np.empty(len(V), dtype=[(n, c.dtype) for n, c in cols])
    for n, c in cols:
        vert[n] = c
    face = np.empty(len(F), dtype=[("n", "u1"), ("v", "<i4", (3,))]
                    + [(n, c.dtype) for n, c in fcols])
    face["n"] = 3
    face["v"] = F if base == 0 else F + base
    for n, c in fcols:
        face[n] = c
    return vert, face


def _ply_header(vert_dtype: np.dtype[Any], face_dtype: np.dtype[Any], nv: int, nf: int) -> bytes:
    def decl(dt: np.dtype[Any]) -> str:
        return _PLY_TYPES[f"{dt.kind}{dt.itemsize}"]

    header = ["ply", "format binary_little_endian 1.0", "comment written by spinal",
              f"element vertex {nv}"]
    header += [f"property {decl(vert_dtype[n])} {n}" for n in vert_dtype.names or ()]
    header += [f"element face {nf}", "property list uchar int vertex_indices"]
    header += [f"property {decl(face_dtype[n])} {n}" for n in (face_dtype.names or ())[2:]]
    header += ["end_header"]
    return ("\n".join(header) + "\n").encode("ascii")


def _write_ply(mesh: Mesh, path: pathlib.Path, rgb: np.ndarray | None,
               point_data: dict[str, Any]) -> None:
    vert, face = _ply_chunk(mesh, rgb, point_data)
    with open(path, "wb") as f:
        f.write(_ply_header(vert.dtype, face.dtype, len(vert), len(face)))
        f.write(vert.tobytes())
        f.write(face.tobytes())


def _vtp_chunk(mesh: Mesh, rgb: np.ndarray | None, point_data: dict[str, Any], vbase: int = 0,
               fbase: int = 0) -> list[Any]:
    """``(section, name, array)`` of every array of ``mesh`` in the order of the appended
    blocks; connectivity shifted by ``vbase`` vertices, offsets by ``fbase`` faces."""
    nf = len(mesh.faces)
    out = [("Points", "Points", mesh.vertices),
           ("Polys", "connectivity", mesh.faces.reshape(-1).astype(np.int64) + vbase),
           ("Polys", "offsets", 3 * np.arange(fbase + 1, fbase + nf + 1, dtype=np.int64))]
    if mesh.normals is not None:
        out.append(("PointData", "Normals", mesh.normals))
    if mesh.uv is not None:
        out.append(("PointData", "uv", mesh.uv))
    if rgb is not None:
        if "colors" in point_data:
            raise ValueError("colors: the name 'colors' is taken by another point_data array")
        out.append(("PointData", "colors", rgb))
    out += [("PointData", k, v) for k, v in point_data.items()]
    out += [("CellData", k, v) for k, v in mesh.cell_data.items()]
    return [(sec, name, np.ascontiguousarray(_plain(a, _VTK_TYPES))) for sec, name, a in out]


def _vtp_header(arrays: list[Any], sizes: list[Any], nv: int, nf: int) -> bytes:
    """The XML of a VTK PolyData file whose appended blocks hold ``arrays`` (as
    :func:`_vtp_chunk` gives them; only names, dtypes and shapes are read) of ``sizes``
    bytes each."""
    from xml.sax.saxutils import quoteattr

    tags: dict[str, list[str]] = {"Points": [], "Polys": [], "PointData": [], "CellData": []}
    offset = 0
    for (sec, name, a), size in zip(arrays, sizes, strict=True):
        comps = 1 if a.ndim == 1 else a.shape[1]
        tags[sec].append(
            f'<DataArray type="{_VTK_TYPES[f"{a.dtype.kind}{a.dtype.itemsize}"]}" '
            f'Name={quoteattr(name)} NumberOfComponents="{comps}" '
            f'format="appended" offset="{offset}"/>')
        offset += 8 + size
    names = [name for sec, name, _ in arrays if sec == "PointData"]
    active = [f'{role}="{name}"' for role, name in (("Normals", "Normals"), ("TCoords", "uv"),
                                                    ("Scalars", "colors")) if name in names]
    xml = [
        '<?xml version="1.0"?>',
        ('<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
         'header_type="UInt64">'),
        "<PolyData>",
        (f'<Piece NumberOfPoints="{nv}" NumberOfVerts="0" NumberOfLines="0" '
         f'NumberOfStrips="0" NumberOfPolys="{nf}">'),
        f"<PointData {' '.join(active)}>", *tags["PointData"], "</PointData>",
        "<CellData>", *tags["CellData"], "</CellData>",
        "<Points>", *tags["Points"], "</Points>",
        "<Polys>", *tags["Polys"], "</Polys>",
        "</Piece>", "</PolyData>",
        '<AppendedData encoding="raw">',
    ]
    return ("\n".join(xml) + "\n_").encode("utf-8")


_VTP_END = b"\n</AppendedData>\n</VTKFile>\n"


def _write_vtp(mesh: Mesh, path: pathlib.Path, rgb: np.ndarray | None,
               point_data: dict[str, Any]) -> None:
    """VTK XML PolyData, format 'appended' raw: every array is a UInt64 byte count followed
    by its bytes after the ``_`` of ``<AppendedData>`` (VTK file formats, "XML File
    Formats", Kitware)."""
    arrays = _vtp_chunk(mesh, rgb, point_data)
    with open(path, "wb") as f:
        f.write(_vtp_header(arrays, [a.nbytes for _, _, a in arrays], len(mesh.vertices),
                            len(mesh.faces)))
        for _, _, a in arrays:
            f.write(np.uint64(a.nbytes).astype("<u8").tobytes())
            f.write(a.tobytes())
        f.write(_VTP_END)


class Spool:
    """A mesh file written chunk by chunk in bounded memory: every chunk's records go to
    temporary files (one per PLY element or VTK array) beside ``path``, and :meth:`finish`
    writes the header (now that the counts are known) and the spooled bytes to a temporary
    name that replaces ``path`` only when complete. The bytes equal :meth:`Mesh.save` of
    the chunks concatenated."""

    def __init__(self, path: pathlib.Path):
        suffix = path.suffix.lower()
        if suffix not in (".ply", ".vtp"):
            raise ValueError(f"dst: streamed meshes are written as .ply or .vtp, got "
                             f"{suffix!r}")
        self.path, self.kind = path, suffix
        self.parts: list[Any] = []  # temporary files, one per block of the file
        self.layout: Any = None  # the dtypes (and names) of the first chunk, kept by the others
        self.nv = self.nf = 0

    def _files(self, n: int) -> list[Any]:
        import tempfile

        while len(self.parts) < n:
            # closed by close(), which finish() and the caller's finally call
            self.parts.append(tempfile.TemporaryFile(dir=self.path.parent))  # noqa: SIM115
        return self.parts

    def add(self, mesh: Mesh, rgb: np.ndarray | None, point_data: dict[str, Any]) -> None:
        """Append ``mesh`` (its faces shifted past the vertices so far)."""
        if self.kind == ".ply":
            vert, face = _ply_chunk(mesh, rgb, point_data, self.nv)
            if self.layout is None:
                self.layout = (vert.dtype, face.dtype)
            elif (vert.dtype, face.dtype) != self.layout:
                vert, face = vert.astype(self.layout[0]), face.astype(self.layout[1])
            v, f = self._files(2)
            v.write(vert.tobytes())
            f.write(face.tobytes())
        else:
            arrays = _vtp_chunk(mesh, rgb, point_data, self.nv, self.nf)
            shape = [(sec, name, a.dtype, a.shape[1:]) for sec, name, a in arrays]
            if self.layout is None:
                self.layout = (shape, arrays)
            elif shape != self.layout[0]:
                raise ValueError("dst: every chunk must have the same arrays; got "
                                 f"{[s[:2] for s in shape]} after {[s[:2] for s in self.layout[0]]}")
            for t, (_, _, a) in zip(self._files(len(arrays)), arrays, strict=True):
                t.write(a.tobytes())
        self.nv += len(mesh.vertices)
        self.nf += len(mesh.faces)

    def finish(self) -> pathlib.Path:
        """Write the file (to a temporary name, renamed at the end) and drop the spool."""
        import shutil
        import tempfile

        if self.layout is None:
            raise ValueError("src: no streamline could be swept (nothing to write)")
        fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", dir=self.path.parent)
        try:
            with os.fdopen(fd, "wb") as out:
                sizes = []
                for t in self.parts:
                    sizes.append(t.tell())
                    t.seek(0)
                if self.kind == ".ply":
                    vert_dtype, face_dtype = self.layout
                    out.write(_ply_header(vert_dtype, face_dtype, self.nv, self.nf))
                    for t in self.parts:
                        shutil.copyfileobj(t, out, 1 << 22)
                else:
                    out.write(_vtp_header(self.layout[1], sizes, self.nv, self.nf))
                    for t, size in zip(self.parts, sizes, strict=True):
                        out.write(np.uint64(size).astype("<u8").tobytes())
                        shutil.copyfileobj(t, out, 1 << 22)
                    out.write(_VTP_END)
            # mkstemp made it private (0600): the permissions an open() would have given
            os.chmod(tmp, 0o666 & ~_umask())
            os.replace(tmp, self.path)
        except BaseException:
            os.unlink(tmp)
            raise
        finally:
            self.close()
        return self.path

    def close(self) -> None:
        for t in self.parts:
            t.close()
        self.parts = []


def _umask() -> int:
    """The process's file-creation mask (read by setting it and putting it back)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask

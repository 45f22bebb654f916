"""The benchmark scripts keep working: a quick run of run_all.py on small sizes (timings are
not checked here; speed is reported by the benchmarks, not asserted by tests). The summary
table must hold one row per case of every timing script, with numbers that are those of the
scripts' own tables in the same report (one run, not a second measurement)."""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import numpy as np
import pytest
import run_all

pytestmark = pytest.mark.slow  # runs the benchmark scripts

def section(text, heading):
    """The report's text under ``## heading...`` up to the next ``## ``."""
    start = text.index(f"## {heading}")
    end = text.find("\n## ", start + 3)
    return text[start:end if end > 0 else None]


def test_run_all_quick_writes_a_report(tmp_path):
    report = tmp_path / "report.md"
    r = subprocess.run(
        [sys.executable, "benchmarks/run_all.py", "--quick", "--report", str(report)],
        check=False, cwd=ROOT, capture_output=True, text=True, timeout=600,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    text = report.read_text()
    for name in ("bench_frames.py", "bench_sweep.py", "bench_advect.py", "bench_flesh.py",
                 "bench_deform.py", "accuracy_frames.py"):
        assert f"benchmarks/{name}" in text
    assert "| 1,000 points |" in text  # the sweep table
    assert "double_reflection" in text
    assert "| curl translation |" in text or "| translation" in text

    # the summary: printed, written before the per-script sections, one row per case
    assert "=== summary" in r.stdout
    assert text.index("## Summary") < text.index("## `python benchmarks/")
    (summary,) = run_all.md_tables(section(text, "Summary"))
    by = {}
    for row in summary:
        by.setdefault(row["benchmark"], []).append(row)
    assert set(by) == {"frames", "tubes", "advect", "flesh", "deform"}
    assert len(by["frames"]) == 2 * 3  # 10^3..10^5 points, tangents estimated and given
    assert [row["case"] for row in by["tubes"]] == ["1,000 points", "10,000 points"]
    assert len(by["advect"]) == 3 and len(by["flesh"]) == 2
    assert [row["case"].split(" →")[0] for row in by["deform"]] == ["drag, 642", "drag, 2,562"]
    for row in summary:
        assert float(row["spinal"].replace(",", "")) > 0
    peers = " ".join(row["peers: time (peer / spinal)"] for row in summary)
    for peer in ("NumPy write floor", "NumPy loop", "VTK strips", "VTK triangles", "NumPy RK4"):
        assert peer in peers

    # the same run: spinal's and the peers' numbers are those of the scripts' tables
    (sweep,) = run_all.md_tables(section(text, "`python benchmarks/bench_sweep.py"))
    for srow, trow in zip(by["tubes"], sweep, strict=True):
        assert srow["spinal"] == run_all.fmt(float(trow["spinal"]))
        strips = run_all.num(trow["vtk strips"])
        assert f"VTK strips {run_all.fmt(strips)} (" in srow["peers: time (peer / spinal)"]
    # the first table has the NumPy peer (the second: fields without a NumPy version)
    adv = run_all.md_tables(section(text, "`python benchmarks/bench_advect.py"))[0]
    col = next(c for c in adv[0] if c.startswith("spinal") and c.endswith("threads"))
    for srow, trow in zip(by["advect"], adv, strict=True):
        ns, t_np = float(trow[col]), float(trow["NumPy"])
        assert srow["spinal"] == run_all.fmt(ns)
        ratio = float(re.search(r"NumPy RK4 [\d,.]+ \(([\d,.e+-]+)×\)",
                                srow["peers: time (peer / spinal)"]).group(1).replace(",", ""))
        assert abs(ratio / (t_np / ns) - 1) < 0.05  # two significant digits
    # bench_deform.py: every drag row, converged or not, with a volume and a verdict
    (deform,) = run_all.md_tables(section(text, "`python benchmarks/bench_deform.py"))
    drags = [r for r in deform if r["case"] == "drag"]
    for srow, trow in zip(by["deform"], drags, strict=True):
        assert srow["spinal"] == run_all.fmt(1e3 * float(trow["time s"]))
        assert abs(float(trow["volume change"])) < 0.05 and trow["targets"]


def test_summary_reads_tables_with_pipes_in_headers():
    text = ("| field | vertices | spinal 2 threads | NumPy | max |Δ| vs NumPy |\n"
            "|---|---|---|---|---|\n"
            "| twist | 40,962 | 20.0 | 300 | 2.2e-16 |\n")
    (table,) = run_all.md_tables(text)
    assert table == [{"field": "twist", "vertices": "40,962", "spinal 2 threads": "20.0",
                      "NumPy": "300", "max |Δ| vs NumPy": "2.2e-16"}]
    out, unreadable = run_all.summary_table({"bench_advect.py": text})
    assert not unreadable
    assert "| advect | twist, 40,962 vertices (2 threads) | ns/vertex/step | 20 | " \
           "NumPy RK4 300 (15×) |" in out
    # a table the summary cannot read is reported, not skipped silently
    _, unreadable = run_all.summary_table({"bench_sweep.py": "no table here\n"})
    assert unreadable == ["bench_sweep.py"]


def test_deform_table_quick():
    """bench_deform_table.py --quick: the cow (skipped and named when the shared meshes are
    absent) and a small icosphere. The volumes are the meshes' (trimesh here), the relative
    change is after/before − 1, the rest crossing pairs are libigl's count, every missed case
    has its diagnosis row, and the thesis's Table 13.1 is printed beside it."""
    import bench_deform_table as table

    r = subprocess.run([sys.executable, "benchmarks/bench_deform_table.py", "--quick"],
                       check=False, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    main, *rest = run_all.md_tables(r.stdout)
    cow = table.MESHES / "cow.obj"
    expect = ([("cow", "press"), ("cow", "twist")] if cow.exists() else []) + [
        ("icosphere(3)", "drag")]
    assert [(row["mesh"], row["tool"]) for row in main] == expect
    if not cow.exists():
        assert f"skipped cow: {cow} not found" in r.stdout
    for row in main:
        mesh = table.load(row["mesh"], table.MESHES)
        before, after = float(row["volume before"]), float(row["volume after"])
        assert abs(before / mesh.volume - 1) < 1e-5  # 6 significant digits
        assert abs(float(row["relative change"]) - (after / before - 1)) < 2e-5
        faces, out = (int(x.replace(",", "")) for x in row["faces"].split(" → "))
        assert faces == len(mesh.faces) and out >= faces
        rest_pairs = int(row["crossing pairs"].split(" → ")[0].replace(",", ""))
        if row["mesh"] == "cow":
            import igl.predicates

            hit = igl.predicates.find_self_intersections(
                np.ascontiguousarray(mesh.vertices, dtype=np.float64),
                np.ascontiguousarray(mesh.faces, dtype=np.int64))
            assert rest_pairs == len(hit[1]) > 0
        else:
            assert rest_pairs == 0
        assert row["target"] == ("met" if abs(float(row["relative change"])) <= 5e-4
                                 else "missed")
    missed = [(row["mesh"], row["tool"]) for row in main if row["target"] == "missed"]
    thesis = rest[-1]
    assert [row["relative change"] for row in thesis][3] == "-0.70%"  # rocker-arm (C)
    if missed:
        diagnosis = rest[0]
        assert [(row["mesh"], row["tool"]) for row in diagnosis] == missed
        for row in diagnosis:  # the flat-face error falls with the edge: one subdivision
            default = abs(run_all.num(row["default"]))
            sub = abs(run_all.num(row["subdivided rest mesh"]))
            assert sub < default / 2, row


def test_deform_table_twist_turns_up_to_its_angle():
    """The benchmark's curl twist turns every sphere about the centroid rigidly by
    ``κ z (1 − r/R)(1 − 3r/(2R))``: the largest angle an advected vertex turns about the long
    axis is the 1.5 rad the script asks for (RK4 with many steps for the exact flow)."""
    import bench_deform_table as table

    import spinal

    m = table.load("icosphere(3)", table.MESHES)
    m.apply_scale([1.0, 1.6, 0.7])  # a long axis (y) and a flank (z)
    f, T = table.tool("twist", m)
    c, axis, _, _ = table.frame(m)
    assert np.array_equal(axis, [0, 1, 0])
    V = np.asarray(m.vertices)
    W = spinal.advect(V, f, T, 64)  # RK4 error ~1e-9 (7e-5 at the default 4 steps)
    a, b = (V - c)[:, [2, 0]], (W - c)[:, [2, 0]]  # turned about +y: z, x
    turned = np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], np.einsum("ij,ij->i", a, b))
    assert abs(np.abs(turned).max() - 1.5) < 1e-6

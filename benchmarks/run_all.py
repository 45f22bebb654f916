"""Run every benchmark of the project and collect their tables into one markdown report.

Each ``benchmarks/bench_*.py`` (and ``accuracy_*.py``) script prints its own table, with the
peers installed beside spinal (VTK/PyVista, trimesh, NumPy implementations) timed in the
same run and the ratios computed from that run. This script runs them one after the other
in fresh processes, prints their output, then one summary table with a row per case
(spinal's time beside every peer's time and the ratio peer / spinal, all read from the
tables of this run), and writes ``benchmarks/report.md``: the machine, the versions, the
summary and every script's table under the exact command that produced it.

    python benchmarks/run_all.py            # full sizes (several minutes)
    python benchmarks/run_all.py --quick    # small sizes, a smoke run
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

# Arguments for --quick (scripts not listed get "--quick" if their --help mentions it).
QUICK = {
    "bench_frames.py": ["--max", "1e5", "--repeat", "3"],
    "bench_sweep.py": ["--max", "1e4", "--no-bundle"],
    "bench_advect.py": ["--max", "1e5", "--repeat", "1"],
    "bench_deform.py": ["--quick"],
}


def versions() -> str:
    out = [f"python {platform.python_version()}"]
    from importlib import metadata

    for mod, dist in (("spinal", "spinal"), ("numpy", "numpy"), ("pyvista", "pyvista"),
                      ("vtk", "vtk"), ("trimesh", "trimesh"), ("igl", "libigl"),
                      ("scipy", "scipy"), ("shapely", "shapely")):
        try:
            m = __import__(mod)
        except Exception:  # noqa: BLE001 - a missing peer is reported, not fatal
            out.append(f"{mod} (not installed)")
            continue
        version = getattr(m, "__version__", None)
        if version is None:
            try:
                version = metadata.version(dist)
            except metadata.PackageNotFoundError:
                version = "?"
        out.append(f"{mod} {version}")
    return ", ".join(out)


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def args_for(script: Path, quick: bool) -> list[str]:
    if not quick:
        return []
    if script.name in QUICK:
        return QUICK[script.name]
    try:
        h = subprocess.run([sys.executable, str(script), "--help"], check=False,
                           capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired:
        return []
    return ["--quick"] if "--quick" in h.stdout else []


# ---- the summary: one row per case, read back from the scripts' markdown tables -----------

def md_tables(text: str) -> list[list[dict[str, str]]]:
    """The markdown tables in ``text``: for each, its rows as {header: cell}. Cells are split
    at " | " only, so a header such as "max |Δ| vs NumPy" stays one cell."""
    out, block = [], []
    for line in [*text.splitlines(), ""]:
        if line.startswith("|"):
            inner = line.strip()[1:-1].strip()
            block.append([c.strip() for c in re.split(r"\s\|\s", inner)])
            continue
        if len(block) >= 2:
            head = block[0]
            out.append([dict(zip(head, row, strict=True)) for row in block[2:]])
        block = []
    return out


def num(cell: str) -> float:
    """The first number in a cell ("1.3", "0.8 (1.7×)", "19×", "1,000")."""
    m = re.search(r"[-+]?\d[\d,]*(?:\.\d+)?(?:[eE][-+]?\d+)?", cell)
    if not m:
        raise ValueError(f"no number in table cell {cell!r}")
    return float(m.group(0).replace(",", ""))


def paren_ratio(cell: str) -> float | None:
    """The ratio in parentheses of a cell like "27.7 (1.1×)", or None."""
    m = re.search(r"\(([\d.]+)×\)", cell)
    return float(m.group(1)) if m else None


def frames_rows(text):
    table = md_tables(text)[0]
    rows = []
    for n in dict.fromkeys(r["n"] for r in table):
        at = {(r["method"], r["tangents"]): r for r in table if r["n"] == n}
        floor = at[("numpy write floor", "-")]
        fcol = "× write floor (all)"
        for tangents in ("estimated", "given"):
            dr = at[("double_reflection", tangents)]
            ms = num(dr["ms, all cores"])
            # ratios through the floor column (both timed against the same floor, unrounded)
            peers = [("NumPy write floor", num(floor["ms, all cores"]), 1 / num(dr[fcol]))]
            loop = at.get(("numpy loop (DR)", tangents))
            if loop:
                peers.append(("NumPy loop (double reflection)", num(loop["ms, all cores"]),
                              num(loop[fcol]) / num(dr[fcol])))
            rows.append((f"{n} points, double reflection, tangents {tangents}", "ms", ms, peers))
    return rows


def sweep_rows(text):
    table = md_tables(text)[0]
    rows = []
    for r in table:
        ms = num(r["spinal"])
        peers = []
        for col, cell in r.items():
            if col in ("case", "spinal") or col.startswith("spinal ") or cell in ("–", "-", ""):
                continue
            ratio = paren_ratio(cell)
            if col == "NumPy write floor":  # that column prints spinal / floor
                ratio = 1 / ratio if ratio else None
            t = num(cell)
            peers.append((col.replace("vtk", "VTK"), t, ratio if ratio else t / ms))
        rows.append((r["case"], "ms", ms, peers))
    return rows


def advect_rows(text):
    table = md_tables(text)[0]
    spinal_col = next(c for c in table[0] if c.startswith("spinal") and "threads" in c)
    rows = []
    for r in table:
        ns, t_np = num(r[spinal_col]), num(r["NumPy"])
        rows.append((f"{r['field']}, {r['vertices']} vertices ({spinal_col.split()[1]} threads)",
                     "ns/vertex/step", ns, [("NumPy RK4", t_np, t_np / ns)]))
    return rows


def flesh_rows(text):
    table = md_tables(text)[0]
    rows = []
    for r in table:
        if r["threads"] != "all cores":
            continue
        n = int(num(r["vertices"]))
        note = ("published (not this run): thesis, Java 2013, 10 ms" if n == 6082 else None)
        rows.append((f"radial deform, {n:,} vertices (all cores)", "ms", num(r["radial ms"]),
                     [(note, None, None)] if note else []))
    return rows


def deform_rows(text):
    """The drag rows of bench_deform.py (no peer: the time of spinal.deform, refinement
    included)."""
    table = md_tables(text)[0]
    return [(f"drag, {r['input vertices']} → {r['output vertices']} vertices", "ms",
             1e3 * num(r["time s"]), []) for r in table if r["case"] == "drag"]


SUMMARY = {"bench_frames.py": ("frames", frames_rows), "bench_sweep.py": ("tubes", sweep_rows),
           "bench_advect.py": ("advect", advect_rows), "bench_flesh.py": ("flesh", flesh_rows),
           "bench_deform.py": ("deform", deform_rows)}


def fmt(x: float) -> str:
    """A time: three significant digits (thousands separated)."""
    return f"{x:,.0f}" if abs(x) >= 1000 else f"{x:.3g}"


def fmt_ratio(x: float) -> str:
    """A ratio of two timings: two significant digits (their noise is larger than that)."""
    return f"{x:,.0f}" if abs(x) >= 100 else f"{x:.2g}"


def summary_table(outputs: dict[str, str]) -> tuple[str, list[str]]:
    """The side-by-side table from the scripts' outputs, and the scripts it could not read."""
    lines = ["| benchmark | case | unit | spinal | peers: time (peer / spinal) |",
             "|---|---|---|---|---|"]
    unreadable = []
    for script, (label, rows_of) in SUMMARY.items():
        if script not in outputs:
            continue
        try:
            rows = rows_of(outputs[script])
        except (IndexError, KeyError, ValueError, StopIteration, ZeroDivisionError):
            unreadable.append(script)
            continue
        if not rows:
            unreadable.append(script)
        for case, unit, t, peers in rows:
            cells = [name if time is None else f"{name} {fmt(time)} ({fmt_ratio(ratio)}×)"
                     for name, time, ratio in peers]
            lines.append(f"| {label} | {case} | {unit} | {fmt(t)} | "
                         f"{'; '.join(cells) or '–'} |")
    if len(lines) == 2:
        return "(no timing benchmark was run)", unreadable
    return "\n".join(lines), unreadable


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    ap.add_argument("--only", nargs="*", help="run only scripts whose name contains these")
    ap.add_argument("--report", default=str(HERE / "report.md"))
    a = ap.parse_args()
    scripts = sorted(HERE.glob("bench_*.py")) + sorted(HERE.glob("accuracy_*.py"))
    if a.only:
        scripts = [s for s in scripts if any(k in s.name for k in a.only)]
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    parts = [
        "# spinal benchmark report",
        "",
        f"- date: {now}",
        f"- machine: {machine()}",
        f"- versions: {versions()}",
        (f"- command: `python benchmarks/run_all.py{' --quick' if a.quick else ''}"
         f"{' --only ' + ' '.join(a.only) if a.only else ''}`"),
        "",
        ("Every table below comes from one run of the script named above it; ratios compare "
         "timings from that same run. Timings on shared or virtual machines vary between runs."),
    ]
    failed = []
    outputs: dict[str, str] = {}
    sections: list[str] = []
    for s in scripts:
        extra = args_for(s, a.quick)
        cmd = ["python", f"benchmarks/{s.name}", *extra]
        print(f"\n=== {' '.join(cmd)}", flush=True)
        r = subprocess.run([sys.executable, str(s), *extra], check=False, capture_output=True,
                           text=True, cwd=HERE.parent)
        print(r.stdout, end="")
        if r.returncode != 0:
            print(r.stderr, file=sys.stderr)
            failed.append(s.name)
        else:
            outputs[s.name] = r.stdout
        sections += ["", f"## `{' '.join(cmd)}`", "", r.stdout.strip() or "(no output)"]
        if r.returncode != 0:
            sections += ["", f"**failed** (exit {r.returncode}):", "", "```",
                         r.stderr.strip()[-2000:], "```"]
    table, unreadable = summary_table(outputs)
    note = ("One row per case, every number read from the tables below (one run each); "
            "ratio = peer time / spinal time (> 1: spinal is faster). Times are the best of "
            "the repeats; the advect rows are per vertex and step. accuracy_frames.py measures "
            "errors, not time: its table is only below.")
    print(f"\n=== summary\n\n{note}\n\n{table}")
    parts += ["", "## Summary", "", note, "", table]
    if unreadable:
        msg = "could not read the table of: " + ", ".join(unreadable)
        print(msg, file=sys.stderr)
        parts += ["", f"**{msg}**"]
        failed += unreadable
    Path(a.report).write_text("\n".join(parts + sections) + "\n")
    print(f"\nreport written to {a.report}")
    if failed:
        print("failed:", ", ".join(failed), file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

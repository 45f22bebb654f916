"""Run every benchmark of the project and collect their tables into one markdown report.

Each ``benchmarks/bench_*.py`` (and ``accuracy_*.py``) script prints its own table, with the
peers installed beside spinal (VTK/PyVista, trimesh, NumPy implementations) timed in the
same run and the ratios computed from that run. This script runs them one after the other
in fresh processes, prints their output and writes ``benchmarks/report.md`` with the
machine, the versions and the exact command of every table.

    python benchmarks/run_all.py            # full sizes (several minutes)
    python benchmarks/run_all.py --quick    # small sizes, a smoke run
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

# Arguments for --quick (scripts not listed get "--quick" if their --help mentions it).
QUICK = {
    "bench_frames.py": ["--max", "1e5", "--repeat", "3"],
    "bench_sweep.py": ["--max", "1e4", "--no-bundle"],
    "bench_advect.py": ["--max", "1e5", "--repeat", "1"],
}


def versions() -> str:
    out = [f"python {platform.python_version()}"]
    for mod in ("spinal", "numpy", "pyvista", "vtk", "trimesh", "igl", "scipy"):
        try:
            m = __import__(mod)
            out.append(f"{mod} {getattr(m, '__version__', '?')}")
        except Exception:  # noqa: BLE001 - a missing peer is reported, not fatal
            out.append(f"{mod} (not installed)")
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
        f"- command: `python benchmarks/run_all.py{' --quick' if a.quick else ''}`",
        "",
        ("Every table below comes from one run of the script named above it; ratios compare "
         "timings from that same run. Timings on shared or virtual machines vary between runs."),
    ]
    failed = []
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
        parts += ["", f"## `{' '.join(cmd)}`", "", r.stdout.strip() or "(no output)"]
        if r.returncode != 0:
            parts += ["", f"**failed** (exit {r.returncode}):", "", "```",
                      r.stderr.strip()[-2000:], "```"]
    Path(a.report).write_text("\n".join(parts) + "\n")
    print(f"\nreport written to {a.report}")
    if failed:
        print("failed:", ", ".join(failed), file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""The benchmark scripts keep working: a quick run of run_all.py on small sizes (timings are
not checked here; speed is reported by the benchmarks, not asserted by tests)."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_run_all_quick_writes_a_report(tmp_path):
    report = tmp_path / "report.md"
    r = subprocess.run(
        [sys.executable, "benchmarks/run_all.py", "--quick", "--report", str(report)],
        check=False, cwd=ROOT, capture_output=True, text=True, timeout=600,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    text = report.read_text()
    for name in ("bench_frames.py", "bench_sweep.py", "bench_advect.py", "bench_flesh.py",
                 "accuracy_frames.py"):
        assert f"benchmarks/{name}" in text
    assert "| 1,000 points |" in text  # the sweep table
    assert "double_reflection" in text
    assert "| curl translation |" in text or "| translation" in text

"""The README's Python examples run as written: in order, sharing one namespace, and each
block on its own (every block is self-contained). The set-up commands: the first installs the
picture extras and runs the demo; .ci/run ends with the README's test command, verbatim."""

import pathlib

import pytest

ROOT = pathlib.Path(__file__).parents[2]
TEXT = (ROOT / "README.md").read_text()
BLOCKS = [b.split("```", 1)[0] for b in TEXT.split("```python\n")[1:]]


def test_readme_example_runs():
    assert len(BLOCKS) >= 2
    ns: dict = {}
    for code in BLOCKS:
        exec(compile(code, "README.md", "exec"), ns)  # noqa: S102 (our own README)


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_block_is_self_contained(index):
    exec(compile(BLOCKS[index], f"README.md block {index + 1}", "exec"), {})  # noqa: S102


def test_readme_commands():
    commands = [b.split("```", 1)[0].strip() for b in TEXT.split("```bash\n")[1:]]
    first, test = commands[0], commands[1]
    assert "pip install '.[viz]'" in first and first.endswith("python -m spinal demo")
    last = (ROOT / ".ci" / "run").read_text().rstrip("\n").splitlines()[-1]
    assert last == test

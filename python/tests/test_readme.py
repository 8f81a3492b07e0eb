"""The README's Python snippets run as pasted: every ```python block, as a
script of its own, in a directory holding the repository's bags/ and
launch-config/ (the paths the snippets use). A block marked
`<!-- fragment: ... -->` just above its fence is part of something else (a
ROS 2 launch file) and is not run."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _blocks():
    text = (REPO / "README.md").read_text()
    out = []
    for m in re.finditer(r"(<!-- fragment[^>]*-->\n)?```python\n(.*?)```\n", text, re.S):
        if m.group(1):
            continue
        line = text.count("\n", 0, m.start()) + 1
        out.append(pytest.param(m.group(2), id=f"README.md:{line}"))
    return out


def test_the_readme_has_python_snippets_to_run():
    assert len(_blocks()) >= 2


@pytest.mark.parametrize("code", _blocks())
def test_a_readme_python_snippet_runs_as_pasted(code, tmp_path):
    for d in ("bags", "launch-config"):
        (tmp_path / d).symlink_to(REPO / d, target_is_directory=True)
    script = tmp_path / "snippet.py"
    script.write_text(code)
    r = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, f"--- stdout\n{r.stdout[-3000:]}\n--- stderr\n{r.stderr[-3000:]}"

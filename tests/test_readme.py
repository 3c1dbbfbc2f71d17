"""Every ```python block of README.md runs as written: each block on its own, in a fresh namespace,
from the repository root. A failure names the block's line and first line, and the error."""

from __future__ import annotations

import re
import traceback
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def python_blocks(text: str) -> list[tuple[int, str]]:
    """(line number of the opening fence, code) of every ```python block of a Markdown text."""
    blocks = []
    for m in re.finditer(r"^```python[ \t]*\n(.*?)^```[ \t]*$", text, flags=re.S | re.M):
        blocks.append((text.count("\n", 0, m.start()) + 1, m.group(1)))
    return blocks


BLOCKS = python_blocks(README.read_text(encoding="utf-8"))


def test_the_extractor_finds_the_blocks():
    """Fences of other languages are skipped, and the code is taken verbatim between the fences."""
    text = "a\n```bash\nls\n```\n```python\nx = 1\ny = 2\n```\n\n```python\nz = 3\n```\n"
    assert python_blocks(text) == [(5, "x = 1\ny = 2\n"), (10, "z = 3\n")]
    assert len(BLOCKS) == README.read_text(encoding="utf-8").count("```python")


@pytest.mark.parametrize("line, code", BLOCKS, ids=[f"README.md:{n}" for n, _ in BLOCKS])
def test_readme_block_runs(line, code, monkeypatch):
    monkeypatch.chdir(ROOT)
    first = next((ln for ln in code.splitlines() if ln.strip()), "")
    error = None
    try:
        exec(compile(code, f"README.md:{line}", "exec"), {"__name__": "__readme__"})
    except Exception as e:  # noqa: BLE001 - any error fails the block, with its place and message
        error = "".join(traceback.format_exception_only(type(e), e)).strip()
    if error is not None:
        pytest.fail(f"README.md block at line {line} ({first!r}) failed: {error}", pytrace=False)


def test_readme_is_a_short_guide_whose_links_exist():
    """About 250 lines (it was 848, mostly history), no commit hashes, every relative link to a file
    of the repository."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert text.count("\n") < 300
    assert not re.findall(r"\b[0-9a-f]{7,40}\b(?=[^`]*?(?:commit|`))", text.split("## Data and licences")[0]), \
        "commit hashes belong in docs/history.md"
    for target in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text):
        assert (ROOT / target).exists(), f"README links to {target}, which does not exist"


"""Writing a pipeline's report: the markdown printed and saved, and matplotlib for its plot (or None
where matplotlib is not installed: the report is written all the same)."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def write_report(out: str | Path, name: str, report: str) -> Path:
    """Print ``report`` and write it to ``out``/``name`` (the directory made if needed); the directory."""
    print(report)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / name).write_text(report)
    return out


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend, or None without matplotlib."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt

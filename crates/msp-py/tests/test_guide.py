"""Every Python example of the user guide (docs/guide/src/*.md) and of README.md runs against the
installed module, each in a directory of its own with matplotlib drawing off screen."""
import os
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
PAGES = sorted((ROOT / "docs" / "guide" / "src").glob("*.md")) + [ROOT / "README.md"]


def _examples():
    for page in PAGES:
        text = page.read_text()
        for m in re.finditer(r"^```python\n(.*?)^```", text, flags=re.S | re.M):
            line = text[: m.start()].count("\n") + 1
            yield pytest.param(m.group(1), id=f"{page.name}:{line}")


EXAMPLES = list(_examples())


def test_the_guide_has_python_examples() -> None:
    assert len(EXAMPLES) >= 2, EXAMPLES


@pytest.mark.parametrize("code", EXAMPLES)
def test_every_python_example_of_the_guide_runs(code: str, tmp_path: pathlib.Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "<guide example>", "exec"), {"__name__": "__guide__"})
    import matplotlib.pyplot as plt

    plt.close("all")
    assert os.getcwd() == str(tmp_path)

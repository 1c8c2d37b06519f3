"""docs/LIBRARY.md shows the examples CI runs, unchanged."""
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]


def code_blocks(language):
    text = (ROOT / "docs" / "LIBRARY.md").read_text(encoding="utf-8")
    return re.findall(rf"```{language}\n(.*?)```", text, flags=re.S)


def test_library_doc_shows_the_examples_ci_runs():
    assert (ROOT / "examples" / "consumer" / "main.cc").read_text() in code_blocks("cpp")
    assert (ROOT / "examples" / "python" / "calibrate.py").read_text() in code_blocks("python")
    assert (ROOT / "examples" / "consumer" / "CMakeLists.txt").read_text().split("\n", 1)[1] \
        in code_blocks("cmake")

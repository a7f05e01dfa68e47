"""The package's types: the installed wheel carries `py.typed` and the stub of the compiled module,
the stub says what the module is (`mypy.stubtest`), and every ```python example of the README and
the docs type-checks against it (mypy, default strictness), as does the package's own Python."""

import pathlib
import re
import subprocess
import sys

import pytest

import taction

pytest.importorskip("mypy")

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKAGE = pathlib.Path(taction.__file__).resolve().parent
DOCS = [ROOT / "README.md", ROOT / "python" / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```python[ \t]*\n(.*?)^```", re.MULTILINE | re.DOTALL)


def run(*args, cwd):
    """`python -m ARGS` in `cwd`; its exit code and everything it printed."""
    done = subprocess.run([sys.executable, "-m", *args], cwd=cwd, capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


def stubtest(cwd, *args):
    # Run outside the checkout, so that the installed package is what is checked.
    return run("mypy.stubtest", "taction", "--mypy-config-file", str(cwd / "mypy.ini"), *args, cwd=cwd)


def write_config(folder, *lines):
    """mypy's defaults, its cache in `folder`; mujoco ships no types (no stubs exist to install)."""
    (folder / "mypy.ini").write_text(
        "\n".join(["[mypy]", f"cache_dir = {folder / 'cache'}", *lines,
                   "[mypy-mujoco.*]", "ignore_missing_imports = True", ""])
    )


@pytest.fixture
def outside(tmp_path):
    write_config(tmp_path)
    return tmp_path


def test_the_installed_package_carries_its_types():
    assert (PACKAGE / "py.typed").is_file()
    assert (PACKAGE / "_taction.pyi").is_file()


def test_the_stub_says_what_the_compiled_module_is(outside):
    code, out = stubtest(outside)
    assert code == 0, out


def test_stubtest_catches_a_wrong_stub(outside):
    """The check above can fail: a stub whose signature differs from the module's is refused."""
    stubs = outside / "stubs" / "taction"
    stubs.mkdir(parents=True)
    for name in ("__init__.py", "env.py", "py.typed"):
        (stubs / name).write_text((PACKAGE / name).read_text())
    right = (PACKAGE / "_taction.pyi").read_text()
    # A parameter the module does not have (`readings` renamed).
    wrong = right.replace("def evaluate(self, dataset: Dataset, readings: int = 30)",
                          "def evaluate(self, dataset: Dataset, trials: int = 30)")
    assert wrong != right
    (stubs / "_taction.pyi").write_text(wrong)
    write_config(outside, f"mypy_path = {outside / 'stubs'}")
    code, out = stubtest(outside)
    assert code != 0, out
    assert "Model.evaluate" in out, out


def python_blocks():
    for doc in DOCS:
        for n, match in enumerate(BLOCK.finditer(doc.read_text()), start=1):
            yield doc, n, match.group(1)


def test_the_docs_have_python_examples():
    named = {doc.relative_to(ROOT).as_posix() for doc, _, _ in python_blocks()}
    assert {"README.md", "docs/python.md"} <= named


def test_every_python_example_of_the_docs_type_checks(outside):
    blocks = outside / "blocks"
    blocks.mkdir()
    files = []
    for doc, n, code in python_blocks():
        stem = re.sub(r"\W", "_", doc.relative_to(ROOT).with_suffix("").as_posix())
        path = blocks / f"{stem}_{n}.py"
        path.write_text(code)
        files.append(str(path))
    code, out = run("mypy", "--config-file", str(outside / "mypy.ini"), *files, cwd=outside)
    assert code == 0, out


def test_the_packages_python_type_checks(outside):
    """The checkout's `taction` package (its Python beside the stub), as mypy sees it from python/."""
    code, out = run("mypy", "--config-file", str(outside / "mypy.ini"), "-p", "taction", cwd=ROOT / "python")
    assert code == 0, out

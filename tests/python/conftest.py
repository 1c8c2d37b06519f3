"""pytest set-up for the Python module's tests (tests/python).

The module under test is whichever `import lrcal` finds: scripts/setup.sh test runs these tests
against the installed package (PYTHONPATH=P/lib/python3.X/site-packages), CTest against the build
tree (PYTHONPATH=build/python). LRCAL_CLI names the lrcal program to compare with (the installed
one, or build/lrcal).
"""
import os
import shutil
import subprocess

import pytest


@pytest.fixture(scope="session")
def cli():
    """Runs the lrcal program: cli("identify", "--data", path) -> CompletedProcess."""
    program = os.environ.get("LRCAL_CLI") or shutil.which("lrcal")
    if not program:
        pytest.fail("set LRCAL_CLI to the lrcal program the module is compared with")

    def run(*args, check=True):
        done = subprocess.run([program, *map(str, args)], capture_output=True, text=True,
                              check=False)
        if check and done.returncode != 0:
            raise AssertionError(f"lrcal {' '.join(map(str, args))} exited {done.returncode}:\n"
                                 f"{done.stderr}")
        return done

    return run


@pytest.fixture(scope="session")
def paper():
    import lrcal
    return lrcal.Robot.load("paper")

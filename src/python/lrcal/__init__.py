"""lrcal: kinematic calibration of robot arms with a laser ranger, and its Monte-Carlo studies.

The C++ library's core on numpy arrays (SI units: m, rad; joint arrays are N x joints, one row per
configuration), and the study runner:

    import lrcal
    robot = lrcal.Robot.load("paper")                      # a robot file or a shipped name
    q = lrcal.sample_configurations(robot, 60, seed=7)      # (60, 6) rad
    readings = lrcal.simulate(robot, q, sigma_mm=0.2, repetitions=10, seed=7)
    result = lrcal.identify(robot, readings.q, readings.h)
    print(result)                                           # the full report
    run = lrcal.run_study("quick", "output/quick")          # what `lrcal run quick` does
    tables = lrcal.load_run("output/quick").tables          # pandas DataFrames

Errors are lrcal.InputError (a ValueError; bad input, with the command line's message naming the
file, line or argument) and lrcal.StorageError (an OSError; results could not be written).
See docs/LIBRARY.md.
"""
import os as _os

from . import _config

try:
    from ._lrcal import (Design, Dependency, Error, Identifiability, Identification, InputError,
                         Plane, PriorInformation, Ranger, Readings, Robot, RunProgress, RunResult,
                         StorageError, __version__, accuracy, data_directory, design, export,
                         forward_kinematics, identifiability, identify, kinematics,
                         laser_readings, merge, aggregate, paper, plan, plan_accuracy,
                         prior_information, replay_trial, run_study, sample_configurations,
                         simulate, simulate_tracker, identify_tracker, status,
                         simulate_sockets, identify_sockets, socket_consistency,
                         simulate_contacts, identify_contacts, simulate_scanner,
                         identify_scanner, identify_mixed, compensate,
                         Tree, identify_tree, identify_in_environment,
                         identifiability_in_environment)
    from ._lrcal import set_data_directory as _set_data_directory
except ModuleNotFoundError as _missing:
    # Only the Python files are installed (a build without pybind11, e.g. a sanitizer build):
    # lrcal.report's drawing and lrcal.load_run work; the rest says what is missing.
    if _missing.name != __name__ + "._lrcal":
        raise
    _MODULE_MISSING = str(_missing)

    class Error(Exception):
        """lrcal's errors (the compiled module's classes when it is installed)."""

    class InputError(Error, ValueError):
        """Bad input: a missing or malformed file, with the file named."""

    class StorageError(Error, OSError):
        """Results could not be written."""

    def __getattr__(name):
        raise ImportError(f"lrcal.{name} needs lrcal's compiled module, which is not installed "
                          f"({_MODULE_MISSING}): build lrcal with pybind11-dev and python3-dev "
                          "(LRCAL_PYTHON=ON)")
else:
    _set_data_directory(_os.path.normpath(_os.path.join(_os.path.dirname(__file__),
                                                        _config.DATA_DIR_FROM_PACKAGE)))
    # Named like the command (lrcal sample); sample_configurations is the earlier name.
    sample = sample_configurations
from ._run import Run, load_run
# The function, not the package of the same name, is lrcal.report; the package's modules are
# imported by name (from lrcal.report import figures) and run with python3 -m lrcal.report.
from .report import report

__all__ = ["Design", "Dependency", "Error", "Identifiability", "Identification", "InputError",
           "Plane", "PriorInformation", "Ranger", "Readings", "Robot", "Run", "RunProgress", "RunResult",
           "StorageError", "__version__", "accuracy", "aggregate", "data_directory", "design", "export",
           "forward_kinematics", "identifiability", "identify", "kinematics", "laser_readings",
           "load_run", "merge", "paper", "plan", "plan_accuracy", "prior_information", "replay_trial", "report", "run_study", "sample",
           "sample_configurations", "simulate", "simulate_tracker", "identify_tracker", "status",
           "simulate_sockets", "identify_sockets", "socket_consistency",
           "simulate_contacts", "identify_contacts", "simulate_scanner", "identify_scanner",
           "identify_mixed", "compensate", "Tree", "identify_tree", "identify_in_environment",
           "identifiability_in_environment"]

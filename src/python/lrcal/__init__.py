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
from ._lrcal import (Design, Dependency, Error, Identifiability, Identification, InputError,
                     Plane, PriorInformation, Ranger, Readings, Robot, RunProgress, RunResult,
                     StorageError, __version__, accuracy, data_directory, design, export,
                     forward_kinematics, identifiability, identify, kinematics, laser_readings,
                     plan, plan_accuracy, prior_information, replay_trial, run_study,
                     sample_configurations, simulate, status)
from ._lrcal import set_data_directory as _set_data_directory
from ._report import report
from ._run import Run, load_run

# Named like the command (lrcal sample); sample_configurations is the earlier name.
sample = sample_configurations

_set_data_directory(_os.path.normpath(_os.path.join(_os.path.dirname(__file__),
                                                    _config.DATA_DIR_FROM_PACKAGE)))

__all__ = ["Design", "Dependency", "Error", "Identifiability", "Identification", "InputError",
           "Plane", "PriorInformation", "Ranger", "Readings", "Robot", "Run", "RunProgress", "RunResult",
           "StorageError", "__version__", "accuracy", "data_directory", "design", "export",
           "forward_kinematics", "identifiability", "identify", "kinematics", "laser_readings",
           "load_run", "plan", "plan_accuracy", "prior_information", "replay_trial", "report", "run_study", "sample",
           "sample_configurations", "simulate", "status"]

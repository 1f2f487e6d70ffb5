# The package `buckle`: the compiled module buckle._core (python/*.cpp) and the result object
# run_scene returns (_result.py), with its DataFrames and plots (_plot.py). NumPy is required;
# pandas and matplotlib only by the methods that use them.
from . import _core
from ._core import (Chain, CorrectorOptions, DetectionOptions, EndCondition, LocationOptions, SceneError, Segment,
                    StepOptions, StepRule, TracerOptions, __version__, all_equilibria, linear_buckling, run_scene, trace)
from ._result import RunResult

__doc__ = _core.__doc__
__all__ = ["Chain", "CorrectorOptions", "DetectionOptions", "EndCondition", "LocationOptions", "RunResult", "SceneError",
           "Segment", "StepOptions", "StepRule", "TracerOptions", "all_equilibria", "linear_buckling", "run_scene", "trace"]

# Shown as buckle.Segment, not buckle._core.Segment (reprs of the classes, help(), tracebacks)
for _name in __all__:
    globals()[_name].__module__ = __name__
del _name

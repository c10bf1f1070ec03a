"""steadystep: frame-rate independent constraint softness for the Open Dynamics Engine, from Python.

On a program's own ODE world (built with odepy, PyPI ode-python, or PyODE, ``import ode``: ``steadystep.core.pyode``):
``Registry`` (bind springs, adopt what the program tuned), ``Stepper`` (one call per frame: substeps or fixed steps,
mappings, forces held until the next frame, per-step logic in ``before_step``, failures refused until reset),
``Stepper.soften_contact`` in the near callback or a ``ContactRule`` applied in C, and ``Stepping`` for how frames
become steps. The conversions (``implicit_euler_softness`` ..., scalars or numpy arrays), the lab's profiles and runs
on built-in scenes (``steadystep.lab.runs``, ``steadystep.lab.profiles``), the article's model
(``steadystep.lab.article``), metrics, ``sweep`` of independent runs over any ``concurrent.futures.Executor``
(``make_executor``: a process pool, Dask); figures and the HTML report need the ``report`` extra (``pip install
steadystep[report]``). Every failure raises ``SteadystepError`` naming the value at fault, with ``code`` the C status
(``Status``) and ``status`` its name: ``InvalidValue`` (also a ValueError) for a refused value, ``SimulationFailure``
for a simulation that failed (a blow-up, a speed or position limit, a frame after a failure). Importing the package
changes no global state and parses nothing (the cffi declarations were prepared from the headers when the package was
built). Imported after a PyODE whose joint parameter numbers are ODE 0.15's, it warns once (steadystep.core.pyode).

The package, by family, each depending only on those before it: ``core`` (the binding of the C library: what this
module exports), ``lab`` (the built-in scenes, profiles, runs and studies), ``report`` (``steadystep compare``: the
comparison, its page and figures) and ``audit`` (``steadystep audit``: a user's own program); ``cli`` is the command
line over them, ``files`` how every command writes its output.
"""

from steadystep.core._native import InvalidValue, SimulationFailure, SteadystepError
from steadystep.core.convert import (Softness, Spring, exact_softness, frequency_from_spring, implicit_euler_softness,
                                     matched_softness, softness_for, spring_from_frequency, spring_from_softness)
from steadystep.core.enums import FrameCut, JointParam, Mapping, Solver, Status
from steadystep.core.registry import (AdoptReport, ApplyReport, Registry, ServedCounts, contact_soften,
                                      joint_effective_mass, joint_supports)
from steadystep.core.stepper import ContactRule, ContactRuleReport, FrameReport, Stepper, StepInfo
from steadystep.core.stepping import Stepping, policy_names
from steadystep.lab.profiles import Profile, frame_times
from steadystep.lab.study import grid, make_executor, sweep

__all__ = [
    "AdoptReport", "ApplyReport", "ContactRule", "ContactRuleReport", "FrameCut", "FrameReport", "InvalidValue",
    "JointParam", "Mapping", "Profile", "Registry", "ServedCounts", "SimulationFailure", "Softness", "Solver", "Spring",
    "Status", "StepInfo", "Stepper", "SteadystepError", "Stepping", "contact_soften",
    "exact_softness", "frame_times", "frequency_from_spring", "grid", "implicit_euler_softness",
    "joint_effective_mass", "joint_supports", "make_executor", "matched_softness", "policy_names", "softness_for",
    "spring_from_frequency", "spring_from_softness", "sweep",
]

from steadystep.core import pyode as _pyode  # noqa: E402 - after the binding: it checks a PyODE already imported

_pyode.warn_if_mismatched()


def __getattr__(name: str):
    # __version__ on demand: importlib.metadata costs about as much as the rest of the binding's import.
    if name == "__version__":
        try:  # the installed package's version, which the build read from CMakeLists.txt's project()
            from importlib.metadata import version

            return version("steadystep")
        except Exception:  # a source tree without installed metadata
            return "unknown"
    raise AttributeError(f"module 'steadystep' has no attribute {name!r}")

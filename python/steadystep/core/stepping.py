"""How frames become physics steps (stepping.h): the cut of a frame and the mapping of each step, as one dataclass.

    Stepping(solver=Solver.QUICK)                     # the library's defaults: substeps of at most the tuned
                                                      # step, implicit Euler (the article's method), and the
                                                      # ODE step the program calls (no default)
    Stepping.for_policy("exact")                      # a named preset: substeps, exact mapping
    Stepping(cut=FrameCut.FIXED, mapping=Mapping.MATCHED, fixed_step_s=1 / 120)   # any combination

Times in s, speeds in m/s and rad/s. The library validates (ssValidateStepping): a Stepper refuses a bad one with
SteadystepError naming the field.
"""

from __future__ import annotations

from dataclasses import dataclass

from steadystep.core._native import SteadystepError, c_string, check, ffi, integer, lib, number, shown, text
from steadystep.core.enums import FrameCut, Mapping, Solver, Status

_DEFAULT = lib.ssDefaultStepping()
_INT_RANGE = (-2**31, 2**31 - 1)
# The C struct's fields and their C types, from the binding (the headers): the conversions below follow them, so the
# dataclass spells each field once, with its unit and default (tests/python/test_api.py: the same fields in order).
_C_FIELDS = {name: field.type.cname for name, field in ffi.typeof("ssStepping").fields}
_ENUMS = {"cut": FrameCut, "mapping": Mapping, "solver": Solver}  # the enum fields' Python enums (enums.py)


def policy_names() -> list[str]:
    """The library's named presets, in its order (stepping.h: ssSteppingPolicyNameAt), read from the library so that
    no list here goes stale: naive first, the lab's control substeps-frozen among them."""
    return [text(lib.ssSteppingPolicyNameAt(i)) for i in range(lib.ssSteppingPolicyCount())]


@dataclass(frozen=True)
class Stepping:
    """Everything about stepping that needs no ODE handle (ssStepping); defaults are the library's."""

    cut: FrameCut = FrameCut(_DEFAULT.cut)             # how a frame becomes steps
    mapping: Mapping = Mapping(_DEFAULT.mapping)       # how each spring becomes ERP/CFM for a step
    # s; > 0 freezes the softness at that step (naive); -1 (SS_FROZEN_AT_TUNED_STEP): at the stepper's tuned step;
    # 0 (default): each step's own length
    frozen_step_s: float = _DEFAULT.frozen_step_s
    solver: Solver = Solver(_DEFAULT.solver)           # dWorldQuickStep or dWorldStep; UNSET (default) is refused
    quick_iterations: int = _DEFAULT.quick_iterations  # QuickStep iterations set before each frame; 0: the world's
    max_step_s: float = _DEFAULT.max_step_s            # SUBSTEPS: the longest substep (s); 0 (default): the tuned
    fixed_step_s: float = _DEFAULT.fixed_step_s        # FIXED: the constant step (s); 0 (default): the tuned step
    # SUBSTEPS: a frame up to (1 + max_step_slack)·max_step_s long is one step (a longer one: equal substeps of at
    # most max_step_s), in [0, 1], a fraction (no unit); default 0.25; 0: every frame longer than max_step_s is split
    max_step_slack: float = _DEFAULT.max_step_slack
    # QuickStep's row order: >= 0 (default 0) sets ODE's random generator before every step from this seed and the
    # step's simulated start time (s), and puts it back after, so a step depends only on the world and its time;
    # -1: ODE's generator left alone, as the program's own loop leaves it (the naive policy)
    step_seed: int = _DEFAULT.step_seed
    max_steps_per_frame: int = _DEFAULT.max_steps_per_frame  # steps a frame at most (the rest dropped, reported)
    max_speed: float = _DEFAULT.max_speed              # m/s above which a known body is a runaway; 0: ODE's guard
    max_angular_speed: float = _DEFAULT.max_angular_speed  # rad/s, likewise

    @classmethod
    def for_policy(cls, policy: str, reference_step_s: float = 0.0, **fields) -> "Stepping":
        """The named preset's cut, mapping, frozen step and step_seed use (policy_names()) over Stepping(**fields):
        naive sets step_seed to -1 (ODE's generator left alone), every other preset a negative step_seed to 0 and
        keeps one chosen. reference_step_s (s) is the step naive freezes its softness at: 0 (the default) for the
        stepper's tuned step, what an adopted program's numbers mean (a stepper with a tuned step refuses any
        other), or a step for springs bound by hand.
        Raises SteadystepError ("parse error") naming an unknown policy."""
        out = ffi.new("ssStepping*", cls(**fields).as_c_fields())
        check(lib.ssSteppingForPolicy(c_string("policy", policy), number("reference_step_s", reference_step_s, "s"),
                                      out))
        return cls.from_c(out[0])

    @classmethod
    def from_c(cls, cdata) -> "Stepping":
        """The Stepping of a C ssStepping: every field of the struct (the binding's), an enum as its Python enum."""
        return cls(**{name: _ENUMS[name](getattr(cdata, name)) if name in _ENUMS else getattr(cdata, name)
                      for name in _C_FIELDS})

    def as_c_fields(self) -> dict:
        """The fields as the C struct takes them, each checked by its C type (the binding's): a double as a finite
        or infinite number, an int or enum within C's int; SteadystepError naming a field whose value C cannot
        hold."""
        return {name: number(f"stepping.{name}", getattr(self, name)) if _C_FIELDS[name] == "double"
                else integer(f"stepping.{name}", getattr(self, name), *_INT_RANGE) for name in _C_FIELDS}

    def validate(self) -> None:
        """Raises SteadystepError naming the first field out of range (ssValidateStepping)."""
        check(lib.ssValidateStepping(ffi.new("ssStepping*", self.as_c_fields())))

    @property
    def policy(self) -> str | None:
        """The name of the preset this stepping is (step_seed not looked at), or None (e.g. the whole frame with
        matched)."""
        return text(lib.ssSteppingPolicyName(ffi.new("ssStepping*", self.as_c_fields())))


def stepping_from(stepping: Stepping | None, policy: str | None, reference_step_s: float) -> Stepping:
    """One stepping from a Stepper's arguments: stepping, or the named policy, or the defaults (not both)."""
    if stepping is not None and policy is not None:
        raise SteadystepError(Status.OUT_OF_RANGE,
                              f"policy = {shown(policy)}: give either stepping or policy, not both")
    if policy is not None:
        return Stepping.for_policy(policy, reference_step_s)
    if stepping is None:
        return Stepping()
    if not isinstance(stepping, Stepping):
        raise SteadystepError(Status.OUT_OF_RANGE, f"stepping = {shown(stepping)}: must be a steadystep.Stepping")
    return stepping

"""The lines of code to write for a policy, in C and in Python: what the audit's recommendation and the report's first
screen end with.

Two shapes, by how the policy cuts a frame (the library's own presets, stepping.h):
- the fixed cut (fixed, fixed-matched, fixed-exact): set the policy, move the logic the loop ran once a frame into
  before_step, where it reads the step's simulated start time (time_s) and length (step_s), and draw the poses the
  stepper interpolates between its last two steps (ssStepper_InterpolatedPose, Stepper.interpolated_pose). Motion
  is then the same at every frame rate.
- every other cut (implicit-euler, matched, exact, naive): set the policy and keep the loop.

A snippet's parts are what tests/python/test_snippets.py compiles (C, against the installed headers) and runs
(Python, on an odepy world): `top` (functions, at file level), `once` (statements where the stepper is made) and
`frame` (statements in the frame loop). The C parts take the program's own `ssStepperDef def` (filled as it fills
it), `ssStepper* stepper`, `ssFrameReport report`, `double frame_s` and a `dBodyID body` to draw; the Python parts
the program's odepy `world`, `space`, `collide`, `contacts`, `frame_s` and `body`, with `import steadystep as ss`.
"""

from __future__ import annotations

from dataclasses import dataclass

LANGUAGES = ("C", "Python")
FIXED_POLICIES = ("fixed", "fixed-matched", "fixed-exact")


@dataclass(frozen=True)
class Snippet:
    """The code to write for one policy in one language, in three parts (the module's docstring)."""

    policy: str
    language: str   # "C" or "Python"
    top: str        # file level: the per-step callback (fixed cut), else ""
    once: str       # where the stepper is made
    frame: str      # in the frame loop

    @property
    def text(self) -> str:
        """The parts as one block, each after a comment that says where it goes."""
        comment = "/* {} */" if self.language == "C" else "# {}"
        blocks = [self.top] if self.top else []
        blocks.append(comment.format("where the stepper is made:") + "\n" + self.once)
        blocks.append(comment.format("every frame:") + "\n" + self.frame)
        return "\n\n".join(blocks)


def is_fixed(policy: str) -> bool:
    """Whether policy cuts frames into fixed steps from an accumulator (identical motion at every frame rate)."""
    return policy in FIXED_POLICIES


def summary(policy: str) -> str:
    """One sentence: what to do for policy."""
    if is_fixed(policy):
        return (f"set the policy to {policy}, move the logic the loop runs once a frame (inputs that change with "
                "time, controllers, scripts) into before_step, computed from the step's time_s and step_s, and "
                "draw the interpolated poses")
    return f"set the policy to {policy} and keep the loop as it is"


def _c(policy: str) -> Snippet:
    if is_fixed(policy):
        top = ("static void beforeStep(void* context, ssStepper* stepper) { /* before every physics step */\n"
               "  ssStepInfo step = ssStepper_CurrentStep(stepper); /* step.time_s: its start, step.step_s: its "
               "length (s) */\n"
               "  /* here: what the loop did once a frame (inputs that change with time, controllers, scripts),\n"
               "     computed for step.time_s and step.step_s */\n"
               "}")
        once = (f'ssSteppingForPolicy("{policy}", def.tuned_step_s, &def.stepping);\n'
                "def.before_step = beforeStep;\n"
                "ssStepper_Create(&def, &stepper);")
        frame = ("ssStepper_Step(stepper, frame_s, &report); /* input added once a frame is held over its steps */\n"
                 "double position[3], quaternion[4];\n"
                 "ssStepper_InterpolatedPose(stepper, body, position, quaternion); /* draw the body there, not at "
                 "ODE's pose */")
        return Snippet(policy, "C", top, once, frame)
    once = (f'ssSteppingForPolicy("{policy}", def.tuned_step_s, &def.stepping); /* the rest as it is */\n'
            "ssStepper_Create(&def, &stepper);")
    frame = "ssStepper_Step(stepper, frame_s, &report); /* the loop as it is */"
    return Snippet(policy, "C", "", once, frame)


def _python(policy: str) -> Snippet:
    if is_fixed(policy):
        top = ("def before_step(stepper, step):  # before every physics step: step.time_s its start, step.step_s "
               "its length (s)\n"
               "    pass  # here: what the loop did once a frame (inputs that change with time, controllers, "
               "scripts)")
        once = ("stepper = ss.Stepper(world, space=space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK,\n"
                f'                     policy="{policy}", before_step=before_step, collide=collide, '
                "contact_group=contacts)")
        frame = ("stepper.step(frame_s)  # input added once a frame is held over its steps\n"
                 "position, quaternion = stepper.interpolated_pose(body)  # draw the body there, not at ODE's pose")
        return Snippet(policy, "Python", top, once, frame)
    once = ("stepper = ss.Stepper(world, space=space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK,\n"
            f'                     policy="{policy}", collide=collide, contact_group=contacts)')
    frame = "stepper.step(frame_s)  # the loop as it is"
    return Snippet(policy, "Python", "", once, frame)


def for_policy(policy: str, first: str = "C") -> list[Snippet]:
    """The C and the Python snippet for policy, the language first given first."""
    made = [_c(policy), _python(policy)]
    return sorted(made, key=lambda snippet: snippet.language != first)


def as_text(policy: str, first: str = "C") -> str:
    """The plain-text ending of a recommendation (the audit's command line): what to do, then each snippet."""
    lines = [f"The code to write for {policy}: {summary(policy)}."]
    for snippet in for_policy(policy, first):
        lines += ["", f"{snippet.language}:", *("    " + line if line else "" for line in snippet.text.splitlines())]
    return "\n".join(lines)

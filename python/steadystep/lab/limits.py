"""The bound on the size of one run: the lab's own (lab/include/steadystep/lab/scene.h, read through cffi), so that
Python, the command line and the lab's C runs refuse the same runs.

A run records every physics step in memory and steps every frame of its profile, so its cost grows with
duration_s / step and with the profile's frame rate. Without a bound, `--duration 1e9` or `--profile fixed:1e12`
runs until memory or patience runs out. MAX_RUN_STEPS (SS_MAX_RUN_STEPS, 10^7) bounds both counts of one run:

- duration_s / step_s, with step_s the policy's step (fixed_step_s under policy fixed, max_step_s otherwise): the
  physics steps the duration needs at the longest step allowed;
- the frames the profile hands out within duration_s (counted on the profile itself, with the run's seed; the lab's
  bound on frames, SS_MAX_RUN_FRAMES, is the same number).

Each is refused above MAX_RUN_STEPS before anything runs, with SteadystepError naming the value. The C run stops
recording at SS_MAX_RUN_STEPS steps (2 + 4 doubles a step: about 480 MB), which a random profile's unlucky draw can
reach; the run then ends with SteadystepError naming the bound.
"""

from steadystep.core._native import lib

MAX_RUN_STEPS: int = int(lib.SS_MAX_RUN_STEPS)
MAX_RUN_FRAMES: int = int(lib.SS_MAX_RUN_FRAMES)

# The shortest duration (s) that figure, compare and probe measure: every one of their runs needs samples to
# compare (the reference's 1 ms steps, a profile's frames of up to 1/15 s), and a tenth of a second holds them.
MIN_MEASURED_DURATION_S = 0.1

"""The bound on the size of one run, defined once for the package and the command line.

A run records every physics step in memory and steps every frame of its profile, so its cost grows with
duration_s / step and with the profile's frame rate. Without a bound, `--duration 1e9` or `--profile fixed:1e12`
runs until memory or patience runs out. MAX_RUN_STEPS bounds both counts of one run:

- duration_s / step_s, with step_s the policy's step (fixed_step_s under policy fixed, max_step_s otherwise): the
  physics steps the duration needs at the longest step allowed;
- the frames the profile hands out within duration_s (counted on the profile itself, with the run's seed).

Each is refused above MAX_RUN_STEPS before anything runs, with SteadystepError naming the value. A run therefore
records at most 2 * MAX_RUN_STEPS steps (substeps of a frame are at most its length / max_step_s, plus one), about
100 MB for a scene with four quantities.
"""

MAX_RUN_STEPS = 1_000_000

# The shortest duration (s) that figure, compare and probe measure: every one of their runs needs samples to
# compare (the reference's 1 ms steps, a profile's frames of up to 1/15 s), and a tenth of a second holds them.
MIN_MEASURED_DURATION_S = 0.1

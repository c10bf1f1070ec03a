"""The colours the figures and the pages share: one per policy everywhere, and the article's own for its figure.
Plain strings, without matplotlib, so that a page can colour its tables without importing it (report/figures.py draws
with them)."""

from __future__ import annotations

from steadystep.lab import runs

# One colour per policy, in the library's order of its policies (naive, substeps-frozen, implicit-euler, matched,
# exact, fixed, fixed-matched, fixed-exact): orange, light orange (naive's softness, implicit-euler's cut), purple,
# brown, cyan, grey, rose, green. A policy the library adds beyond these is drawn dark grey until it gets its own.
_POLICY_PALETTE = ("#e6550d", "#fdae6b", "#756bb1", "#8c6d31", "#17becf", "#636363", "#d6616b", "#31a354")
POLICY_COLORS = dict(zip(runs.policy_names(), _POLICY_PALETTE))
REFERENCE_COLOR = "#000000"
EXACT_COLOR = "#1f5fbf"      # the article's blue
FIXED_30_COLOR = "#d62728"   # the article's red
VARIABLE_COLOR = "#2ca02c"   # the article's green


def policy_color(policy: str) -> str:
    return POLICY_COLORS.get(policy, "#333333")

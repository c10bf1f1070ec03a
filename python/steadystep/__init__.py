"""steadystep: frame-rate independent constraint softness for the Open Dynamics Engine, from Python.

The conversions (``softness_from_spring`` ...), the article's own model (``steadystep.article``), frame-time
profiles, scenes and runs on real ODE (``steadystep.runs``), metrics, figures and the report. Every failure of the
C library raises ``SteadystepError`` (a ValueError) naming the value at fault.
"""

from steadystep._native import SteadystepError

__all__ = ["SteadystepError"]
__version__ = "0.1.0"

"""The lab: the built-in scenes run on real ODE (``runs``), frame-time profiles (``profiles``), the bounds on a run
(``limits``), studies of independent runs over any executor (``study``), the largest stable step (``probe``), what a
policy costs (``cost``), the article's own model (``article``) and the measures (``metrics``, ``consistency``).
The C side of it is lab/ (libsteadystep_lab); the report and the audit build on it, the binding (``core``) never.
"""

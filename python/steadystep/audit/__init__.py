"""`steadystep audit`: how much a user's own program depends on the frame rate, under each policy (docs/audit.md).

    from steadystep import audit
    result = audit.audit(audit.Executable(("build/my_game_steadystep",), own=("build/my_game",)))
    audit.write(result, Path("audit-out"), "my audit")

One module a concept: the program and its runs, the protocol it speaks (run.py, and worker.py for a Python program),
the numbers of each run against the reference (measure.py), the claims made from them (claims.py), the page
(page.py, templates.py), the command line's arguments (cli.py), and comparison.py, which ties them together:
audit() and write(), re-exported here.
"""

from steadystep.audit.comparison import (DEFAULT_PROFILES, DEFAULT_SEEDS, Audit, BadProgram, Executable,
                                         PythonProgram, PythonWorld, audit, write)

__all__ = ["Audit", "BadProgram", "Executable", "PythonProgram", "PythonWorld", "audit", "write",
           "DEFAULT_PROFILES", "DEFAULT_SEEDS"]

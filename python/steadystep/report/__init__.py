"""The report (`steadystep compare`): scenes x frame-time profiles x policies on real ODE against a reference run,
written as report.html, metrics.json and metrics.csv (docs/metrics.md).

    from steadystep import report
    made = report.compare(scenes=["chain"], profiles=["fixed:30", "uniform:15:45"])
    report.write(made, Path("report"), "my comparison")

One module a concept: the inputs checked (validate.py), the task graph run through any executor (tasks.py, with its
progress lines in progress.py), the numbers aggregated from the finished runs (aggregate.py, into model.py's Report),
the data exported as JSON and CSV (export.py), and the page: html.py fills templates.py's Jinja2 templates (autoescape
on; the audit's page shares their environment), recommendation.py writes its opening, answer.py its first picture,
figures.py and animation.py draw, palette.py colours, snippets.py gives the code to write. comparison.py ties them
together: compare() and write(), re-exported here. Jinja2 and matplotlib (the report extra) are imported only where
a page is written or a figure drawn.
"""

from steadystep.report.comparison import (CSV_COLUMNS, GRID_AXES, NOT_PROBED, REPORT_PARAMS, Report, Row, compare,
                                          write)

__all__ = ["CSV_COLUMNS", "GRID_AXES", "NOT_PROBED", "REPORT_PARAMS", "Report", "Row", "compare", "write"]

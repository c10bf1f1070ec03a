"""The cells and images the two pages share (report.html, audit.html): numbers as shown, a failure in red, a PNG
embedded. markupsafe alone, no matplotlib, so that the process that writes a page whose figures were drawn elsewhere
(the audit's, drawn in its pool's workers) need not import it: report/html.py imports the whole report."""

from __future__ import annotations

import base64
import math
from pathlib import Path

from markupsafe import Markup


def number(value, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, float) and math.isinf(value):
        return "failed"
    return f"{value:.{digits}g}"


def bad(text: str) -> Markup:
    return Markup("<span class=bad>{}</span>").format(text)


def cell(value, status: str = "ok", digits: int = 3):
    """A number, or the run's status when the run failed (blew up, ran away, broke)."""
    return bad(status) if status != "ok" else number(value, digits)


def status_cell(status: str):
    """A run's status: ok, or what went wrong (blow-up, speed limit, broken) in red: a failure either way."""
    return "ok" if status == "ok" else bad(status)


def embed(path: Path, anchor: str | None = None) -> Markup:
    data = base64.b64encode(Path(path).read_bytes()).decode()
    return Markup('<img{} src="data:image/png;base64,{}" alt="{}">').format(
        Markup(" id='{}'").format(anchor) if anchor else "", data, Path(path).name)


def embed_png(data: bytes, anchor: str, alt: str) -> Markup:
    """PNG bytes as an image in the page (a data URI), with its id and alternative text."""
    return Markup('<img id="{}" src="data:image/png;base64,{}" alt="{}">').format(
        anchor, base64.b64encode(data).decode(), alt)

"""Python objects document every field (issue 28): help() on a report view shows each field's meaning and unit,
never the getter's own docstring (operator.attrgetter's, before), and a field the C struct has is never left out."""

import pydoc

import pytest

import steadystep
from steadystep.core._structs import StructView

VIEWS = [steadystep.FrameReport, steadystep.StepInfo, steadystep.ContactRuleReport, steadystep.ServedCounts,
         steadystep.ApplyReport, steadystep.AdoptReport]


@pytest.mark.parametrize("view", VIEWS, ids=lambda view: view.__name__)
def test_every_field_is_documented(view):
    assert issubclass(view, StructView) and view.FIELDS
    for name in view.FIELDS:
        doc = getattr(view, name).__doc__
        assert doc.startswith(f"{name} (") and "read-only): " in doc, (name, doc)
        assert "see ss" not in doc, f"{view.__name__}.{name}: no docs entry (a field the C struct gained?)"
    text = pydoc.render_doc(view, renderer=pydoc.plaintext)
    assert "attrgetter" not in text and "Return an attrgetter" not in text


def test_help_shows_units():
    text = pydoc.render_doc(steadystep.FrameReport, renderer=pydoc.plaintext)
    assert "step_s (double, read-only): length of the last step taken (s)" in text
    assert "failed_body (read-only): the address of the body" in text

"""Fixtures the Python tests share."""

import pytest


@pytest.fixture(scope="module")
def odepy_initialised():
    """ODE initialised through odepy for one module's tests, and closed after them (a module that leaves closing to
    the process, since others may still hold worlds, initialises ODE itself)."""
    import odepy

    odepy.dInitODE2(0)
    yield
    odepy.dCloseODE()

"""The functions of the compiled core take at most eight arguments: the settings of a call
beyond its arrays and callbacks travel as one options dict (read by the core's
``options.rs``), so no binding grows a long positional list that its callers must keep in
order."""

import inspect

import pytest

from spinal import _core

MAX_ARGUMENTS = 8


def core_functions():
    return sorted(n for n in dir(_core) if not n.startswith("_")
                  and callable(getattr(_core, n)) and not inspect.isclass(getattr(_core, n)))


@pytest.mark.parametrize("name", core_functions())
def test_core_function_takes_at_most_eight_arguments(name):
    params = inspect.signature(getattr(_core, name)).parameters
    assert len(params) <= MAX_ARGUMENTS, (name, list(params))

"""Repository-wide pytest set-up: the notebooks under ``notebooks/`` are executed as tests by
the nbmake plugin whenever it is installed (the ``test`` extra installs it), without forcing
``--nbmake`` on the command line, so a run of one test file also works without the plugin
(or with ``-p no:nbmake``). Notebooks are marked ``slow`` (``pytest -m "not slow"`` skips
them)."""

import pytest


def pytest_configure(config):
    if config.pluginmanager.hasplugin("nbmake"):
        config.option.nbmake = True


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.suffix == ".ipynb":
            item.add_marker(pytest.mark.slow)

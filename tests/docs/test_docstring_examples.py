"""The usage examples in the docstrings of the functions a user calls first run and print what
they say (doctest): ``help(EkmanABL)``, ``help(optimize_yaw)``."""

from __future__ import annotations

import doctest

import pytest

import floris_ekman_veer

#: The objects whose docstrings carry a usage example, by their public name.
DOCUMENTED = ["EkmanABL", "optimize_yaw", "fit_site"]


def examples(name):
    """The docstring examples of ``floris_ekman_veer.<name>`` (its methods' included)."""
    finder = doctest.DocTestFinder(recurse=True)
    obj = getattr(floris_ekman_veer, name)
    return [t for t in finder.find(obj, name, globs={}) if t.examples]


@pytest.mark.parametrize("name", DOCUMENTED)
def test_docstring_examples_run_as_written(name):
    tests = examples(name)
    assert tests, f"{name} has no usage example in its docstring"
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    for test in tests:
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0 and result.attempted >= 2, result


def test_help_shows_the_user_methods_before_the_solver_internals():
    import pydoc

    text = pydoc.render_doc(floris_ekman_veer.EkmanABL, renderer=pydoc.plaintext)
    for user, internal in (("from_reference_wind(", "set_state("), ("fit_profile(", "state_at("),
                           ("velocity(", "condition_parameters(")):
        assert text.index(user) < text.index(internal), (user, internal)

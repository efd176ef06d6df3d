"""The Examples sections of the main entry points run as written (doctest, as a reader would).

Each entry point must have one (a test that fails when it is taken out): ``simulate``,
``track_video``, ``fit_restitution``, ``overturning_spectrum``, ``run_experiment``; a few smaller
functions have one too and are run here as well.
"""

from __future__ import annotations

import doctest
import tempfile

import pytest

FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _entry_points():
    from rocklab.fitting import fit_restitution
    from rocklab.models import column_overturning_spectrum, overturning_spectrum, simulate
    from rocklab.pipelines import run_experiment
    from rocklab.tracking import track_video
    from rocklab.tracking.video.targets._observability import turn_share
    from rocklab.tracking.video.targets._occlusion import roundness

    return {
        "simulate": simulate,
        "track_video": track_video,
        "fit_restitution": fit_restitution,
        "overturning_spectrum": overturning_spectrum,
        "column_overturning_spectrum": column_overturning_spectrum,
        "run_experiment": run_experiment,
        "turn_share": turn_share,
        "roundness": roundness,
    }


@pytest.mark.parametrize("name", sorted(_entry_points()))
def test_examples_run_as_written(name, tmp_path, monkeypatch):
    obj = _entry_points()[name]
    tests = [t for t in doctest.DocTestFinder(recurse=False).find(obj, name) if t.examples]
    assert tests, f"{name} has no Examples section"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # the examples' temporary folders land here
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    for t in tests:
        runner.run(t, out=lambda s: pytest.fail(f"{name}: example failed:\n{s}"))
    assert runner.summarize(verbose=False).failed == 0

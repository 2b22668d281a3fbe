"""A remeshed scheme (``NAME+remesh``) through the matrix pipeline, for real, in a
temporary copy of the workflow: its run store paths, frames, tables, findings and page
carry the ``+`` of its name, and a second run has nothing to do.

The anisotropic sphere at levels 1-2: its thin triangles (smallest angle 5.5 and 2.8
degrees) fire the remesher's trigger (10 degrees) at the start of both levels."""

import json

import numpy as np
import pandas as pd
import pytest

from mcfbench.storage.frames import frame_mesh, load_frames
from test_pipeline import copy_workflow, env, snakemake  # noqa: F401  (env: a fixture)

pytestmark = pytest.mark.e2e

PROBLEM = "anisotropic_sphere"
SELECT = (f"matrix={{select: {{schemes: [cotan, cotan+remesh], "
          f"problems: {{{PROBLEM}: [1, 2]}}}}}}")


def test_a_remeshed_scheme_goes_through_the_matrix(tmp_path, env):
    work = copy_workflow(tmp_path / "work")
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config", SELECT)
    assert code == 0, out[-3000:]
    store = work / "results" / "runs" / PROBLEM
    for level in (1, 2):
        (record,) = (store / "cotan+remesh" / f"level{level}").glob("*.json")
        data = json.loads(record.read_text())
        assert (data["scheme"], data["status"]) == ("cotan+remesh", "ok")
        frames = load_frames(record.with_suffix(".npz"))
        # remeshed: the last frame has its own faces (the changing layout)
        assert "frame_sizes" in frames
        first, last = (frame_mesh(frames, k)[1] for k in (0, -1))
        assert first.shape != last.shape or not np.array_equal(first, last)
        (plain,) = (store / "cotan" / f"level{level}").glob("*.json")
        assert "frame_sizes" not in load_frames(plain.with_suffix(".npz"))
    matrix = work / "results" / "matrix"
    long = pd.read_csv(matrix / "tables" / "matrix.csv")
    main = long[long["main"] & (long["problem"] == PROBLEM)]
    remeshed = main[main["scheme"] == "cotan+remesh"].sort_values("level")
    assert list(remeshed["level"]) == [1, 2] and (remeshed["status"] == "ok").all()
    assert np.isfinite(remeshed["value"]).all() and np.isfinite(remeshed["eoc"].iloc[1])
    summary = pd.read_csv(matrix / "tables" / "summary.csv")
    assert set(summary["scheme"]) == {"cotan", "cotan+remesh"}
    findings = (matrix / "findings.md").read_text()
    section = findings.split("## With remeshing against without")[1]
    assert f"| {PROBLEM} (l2_error) | cotan |" in section
    assert "- **cotan** against **cotan+remesh** on 1 problem(s)" in section
    assert "With remeshing against without" in (matrix / "index.html").read_text()
    code, out = snakemake(work, env, "-n", "--cores", "2", "matrix", "--config", SELECT)
    assert code == 0 and "Nothing to be done" in out, out[-3000:]

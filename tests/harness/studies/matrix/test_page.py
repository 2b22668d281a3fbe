"""The pieces of the matrix's results page (mcfbench.studies.matrix.page)
without a browser: sort keys, the table cells and the findings' headings.
The page in Chromium: tests/workflow/test_results_page.py."""

import math

import numpy as np
import pandas as pd
import pytest

from mcfbench.studies.matrix import page as matrix_page


@pytest.mark.parametrize("value, key", [
    (1.5e-3, "0.0015"), (0.1 + 0.2, "0.30000000000000004"), (3, "3"), (np.int64(45), "45"),
    (2.0, "2"), (float("nan"), ""), (None, ""), (math.inf, "Infinity"),
    (-math.inf, "-Infinity"), ("t_escaped", "t_escaped"), (True, "True")])
def test_sort_key_is_the_exact_value_in_javascripts_spelling(value, key):
    assert matrix_page.sort_key(value) == key
    if key not in ("", "t_escaped", "True") and isinstance(value, float):
        assert float(key.replace("Infinity", "inf")) == value   # round trip


def test_table_cells_keep_the_value_and_show_the_format():
    frame = pd.DataFrame({"scheme": ["a", "b"], "level": [1, 2], "value": [1.25e-3, np.nan],
                          "status": ["ok", "t_escaped"]})
    t = matrix_page.html_table(frame, matrix_page.RUN_COLUMNS, "runs-x", "x")
    assert [h["column"] for h in t["header"]] == ["scheme", "level", "value", "status"]
    assert [h["numeric"] for h in t["header"]] == [False, True, True, False]
    assert t["rows"][0][2] == {"text": "1.250e-03", "key": "0.00125"}
    assert t["rows"][1][2] == {"text": "–", "key": ""}


def test_findings_headings_go_under_the_pages_section():
    html = matrix_page.findings_html("# Findings\n\n## Per problem\n\ntext `x`\n", ".")
    assert "<h3" in html and "<h4" in html and "<h1" not in html and "<h2" not in html
    assert "<code>x</code>" in html


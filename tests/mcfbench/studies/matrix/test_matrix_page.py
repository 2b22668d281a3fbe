"""The pieces of the matrix's results page (mcfbench.studies.matrix.page)
without a browser: the table cells and the findings' headings (the sort keys:
tests/mcfbench/presentation/test_tables.py).
The page in Chromium: tests/workflow/test_results_page.py."""

import re

import numpy as np
import pandas as pd

from mcfbench.studies.matrix import page as matrix_page


def test_table_cells_keep_the_value_and_show_the_format():
    frame = pd.DataFrame({"scheme": ["a", "b"], "level": [1, 2], "value": [1.25e-3, np.nan],
                          "status": ["ok", "t_escaped"]})
    t = matrix_page.html_table(frame, matrix_page.RUN_COLUMNS, "runs-x", "x")
    columns = re.findall(r'<th data-column="([^"]*)"', t)
    assert columns == ["scheme", "level", "value", "status"]
    assert re.findall(r'<th data-column="(\w+)" data-type="num"', t) == ["level", "value"]
    assert '<td data-sort="0.00125">1.250e-03</td>' in t
    assert '<td data-sort="">–</td>' in t


def test_findings_headings_go_under_the_pages_section():
    html = matrix_page.findings_html("# Findings\n\n## Per problem\n\ntext `x`\n", ".")
    assert "<h3" in html and "<h4" in html and "<h1" not in html and "<h2" not in html
    assert "<code>x</code>" in html


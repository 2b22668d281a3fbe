"""The one table value and its writers (mcfbench.presentation.tables): each medium
against a small text written by hand from the module's spec (escaping, alignment,
number formats, missing values, captions, labels and notes)."""

import math

import numpy as np
import pandas as pd
import pytest

from mcfbench.presentation.formats import sci, tex_escape
from mcfbench.presentation.tables import Table, csv, html, latex, markdown, sort_key

RESIZE = r"\resizebox{\ifdim\width>\linewidth\linewidth\else\width\fi}{!}{%"


def errors():
    """Two schemes, an error in scientific notation (one missing), a text column
    with a pipe and an underscore, centred."""
    return Table(["scheme", "L2 error", "note"],
                 [["ddfv", 1.25e-3, "a|b"], ["cotan", float("nan"), "x_1"]],
                 formats=[None, sci, None], align="lrc", caption="Errors & more",
                 label="tab:errors", notes=["Level 2.", "Timings differ."])


def test_markdown_escapes_pipes_aligns_and_adds_the_notes():
    assert markdown(errors()) == (
        "| scheme | L2 error | note |\n"
        "|---|---:|:---:|\n"
        "| ddfv | 1.250e-03 | a\\|b |\n"
        "| cotan | – | x_1 |\n"
        "\n"
        "Level 2.\n"
        "\n"
        "Timings differ.")


def test_markdown_default_alignment_and_line_breaks():
    table = Table(["level", "status"], [[1, "two\nlines"], [2, None]])
    assert markdown(table) == ("| level | status |\n|---|---:|\n| 1 | two lines |\n"
                               "| 2 | – |")


def test_latex_float_with_caption_label_and_notes():
    text = latex(errors(), text=tex_escape)
    assert text == "\n".join([
        r"\begin{table}[ht]",
        r"\caption{Errors \& more}",
        r"\label{tab:errors}",
        r"{\centering\footnotesize",
        RESIZE,
        r"\begin{tabular}{lrc}",
        r"\toprule",
        r"scheme & $L_2$ error & note \\",
        r"\midrule",
        r"ddfv & $1.250\cdot 10^{-3}$ & a\ensuremath{|}b \\",
        r"cotan & -- & x\_1 \\",
        r"\bottomrule",
        r"\end{tabular}}\par}",
        r"\par\smallskip{\footnotesize Level 2.}",
        r"\par\smallskip{\footnotesize Timings differ.}",
        r"\end{table}"])


def test_latex_plain_text_caption_below_and_a_bare_tabular():
    table = Table(["a_b", "n"], [["1.5e-03", "x&y"]], caption="C_1")
    assert latex(table, head=tex_escape, cell=tex_escape, text=tex_escape,
                 caption_below=True) == "\n".join([
        r"\begin{table}[ht]", r"{\centering\footnotesize", RESIZE, r"\begin{tabular}{lr}",
        r"\toprule", r"a\_b & n \\", r"\midrule", r"1.5e-03 & x\&y \\", r"\bottomrule",
        r"\end{tabular}}\par}", r"\caption{C\_1}", r"\end{table}"])
    # no caption, label or notes: the tabular alone; cells already LaTeX kept as they are
    bare = Table(["$x$", ""], [[r"\texttt{a}", "1"]], align="ll")
    assert latex(bare, head=str, cell=str) == "\n".join([
        r"{\centering\footnotesize", RESIZE, r"\begin{tabular}{ll}", r"\toprule",
        r"$x$ &  \\", r"\midrule", r"\texttt{a} & 1 \\", r"\bottomrule",
        r"\end{tabular}}\par}"])


def test_html_keeps_values_as_sort_keys_and_escapes_text():
    table = Table(["scheme", "value", "note"],
                  [["a<b", 1.25e-3, 'say "hi" & go'], ["c", float("nan"), ""]],
                  formats=[None, sci, None], caption="x & y")
    assert html(table, "runs-x", ["scheme", "value", "note"]) == "\n".join([
        '<div class="table-scroll">',
        '<table class="sortable" id="runs-x">',
        "<caption>x &amp; y</caption>",
        "<thead><tr>",
        '<th data-column="scheme" tabindex="0" aria-sort="none" title="sort by scheme">'
        "scheme</th>",
        '<th data-column="value" data-type="num" tabindex="0" aria-sort="none" '
        'title="sort by value">value</th>',
        '<th data-column="note" tabindex="0" aria-sort="none" title="sort by note">note</th>',
        "</tr></thead>",
        "<tbody>",
        '<tr data-row="0"><td data-sort="a&lt;b" class="text">a&lt;b</td>'
        '<td data-sort="0.00125">1.250e-03</td>'
        '<td data-sort="say &#34;hi&#34; &amp; go" class="text">say &#34;hi&#34; &amp; go</td>'
        "</tr>",
        '<tr data-row="1"><td data-sort="c" class="text">c</td><td data-sort="">–</td>'
        '<td data-sort="" class="text">–</td></tr>',
        "</tbody>",
        "</table>",
        "</div>"])


def test_html_columns_default_to_the_headers():
    text = html(Table(["n"], [[3]]), "t")
    assert '<th data-column="n" data-type="num"' in text and '<td data-sort="3">3</td>' in text


@pytest.mark.parametrize("value, key", [
    (1.5e-3, "0.0015"), (0.1 + 0.2, "0.30000000000000004"), (3, "3"), (np.int64(45), "45"),
    (2.0, "2"), (float("nan"), ""), (None, ""), (math.inf, "Infinity"),
    (-math.inf, "-Infinity"), ("t_escaped", "t_escaped"), (True, "True")])
def test_sort_key_is_the_exact_value_in_javascripts_spelling(value, key):
    assert sort_key(value) == key
    if key not in ("", "t_escaped", "True") and isinstance(value, float):
        assert float(key.replace("Infinity", "inf")) == value   # round trip


def test_numeric_columns_exclude_bools_text_and_empty_tables():
    table = Table(["n", "ok", "mixed", "nan"], [[1, True, 1.0, float("nan")],
                                                [np.float64(2.5), False, "x", float("nan")]])
    assert table.numeric() == [True, False, False, True]
    assert Table(["n"], []).numeric() == [False]


def test_of_frame_takes_the_named_columns_in_order_and_skips_absent_ones():
    frame = pd.DataFrame({"level": [1, 2], "value": [0.5, np.nan], "status": ["ok", "t"]})
    table = Table.of_frame(frame, [("status", "Status", None), ("missing", "M", None),
                                   ("value", "v", lambda x: f"{x:.1f}")], caption="c")
    assert table.header == ("Status", "v") and table.caption == "c"
    assert table.cells() == [["ok", "0.5"], ["t", "nan"]]
    assert Table.of_frame(frame).header == ("level", "value", "status")
    assert Table.of_frame(frame).cells()[1] == ["2", "–", "t"]


def test_bad_tables_are_named():
    with pytest.raises(ValueError, match="row 1 has 1 cells, the header 2"):
        Table(["a", "b"], [[1, 2], [3]])
    with pytest.raises(ValueError, match="letters \\['x'\\]"):
        Table(["a", "b"], [[1, 2]], align="lx")
    with pytest.raises(ValueError, match="2 formats and alignments"):
        Table(["a", "b"], [[1, 2]], formats=[None])


def test_csv_is_exact_or_rounded_with_newline_line_ends():
    frame = pd.DataFrame({"a": [0.1 + 0.2, np.nan], "b": ["x,y", "z"]})
    assert csv(frame) == 'a,b\n0.30000000000000004,"x,y"\n,z\n'
    assert csv(frame, "%.10g") == 'a,b\n0.3,"x,y"\n,z\n'

"""One table value and one writer per medium: CSV, Markdown, LaTeX and HTML.

Every table of the suite is a :class:`Table` (header, rows, the format of each
column, the alignment, a caption, a label and notes) written by
:func:`markdown`, :func:`latex` or :func:`html`; a data table (a
``pandas.DataFrame`` of the values themselves) is written by :func:`csv`.

A cell's text is its column's format applied to its value (:meth:`Table.cells`;
without a format: :data:`~mcfbench.presentation.formats.MISSING` for None or
NaN, the value's ``str`` otherwise). The writers only escape it for their
medium:

- Markdown: a pipe table, ``|`` escaped and line breaks removed
  (:func:`md_cell`), the alignment as ``---`` (left), ``---:`` (right),
  ``:---:`` (centre); the notes follow as paragraphs.
- LaTeX: a booktabs ``tabular``, header and cells converted by the functions
  the caller names (default: :func:`~mcfbench.presentation.formats.tex_header`
  and :func:`~mcfbench.presentation.formats.tex_number`, cells in inline
  Markdown with numbers in scientific notation set as powers of ten); with a
  caption, a label or notes, inside a floating ``table``.
- HTML: a sortable ``<table>`` (the matrix's results page): every cell keeps
  its value as ``data-sort`` (:func:`sort_key`), a column of numbers is marked
  ``data-type="num"``, an empty cell shows
  :data:`~mcfbench.presentation.formats.MISSING`, text is escaped as Jinja2 does.
"""

import math
from dataclasses import dataclass

from mcfbench.presentation.formats import MISSING, tex_header, tex_number

ALIGNMENTS = {"l": "---", "r": "---:", "c": ":---:"}
"""Alignment letter (LaTeX's column spec) -> Markdown separator."""


def default_text(value):
    """A cell without a format: :data:`MISSING` for None or NaN, else ``str``."""
    missing = value is None or (_is_number(value) and math.isnan(value))
    return MISSING if missing else str(value)


def _is_number(value):
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    return getattr(value, "dtype", None) is not None and value.dtype.kind in "iuf"


@dataclass(frozen=True)
class Table:
    """A table to present.

    Parameters
    ----------
    header : sequence of str
        The column headers, ``k`` of them.
    rows : sequence of sequences
        The values, each row of length ``k``.
    formats : sequence of callable or None, optional
        Per column: value -> text (None: :func:`default_text`).
    align : str, optional
        One of ``l``, ``r``, ``c`` per column (default: the first column
        left, the others right).
    caption, label : str
        The caption (LaTeX and HTML) and the LaTeX label.
    notes : sequence of str
        Paragraphs under the table (Markdown and LaTeX).

    Raises
    ------
    ValueError
        A row, ``formats`` or ``align`` whose length is not the header's, or an
        alignment letter other than ``l``, ``r``, ``c``.
    """

    header: tuple
    rows: tuple
    formats: tuple = None
    align: str = None
    caption: str = ""
    label: str = ""
    notes: tuple = ()

    def __post_init__(self):
        k = len(self.header)
        object.__setattr__(self, "header", tuple(str(h) for h in self.header))
        object.__setattr__(self, "rows", tuple(tuple(r) for r in self.rows))
        object.__setattr__(self, "notes", tuple(self.notes))
        formats = tuple(self.formats) if self.formats is not None else (None,) * k
        object.__setattr__(self, "formats", formats)
        if self.align is None:
            object.__setattr__(self, "align", ("l" + "r" * (k - 1)) if k else "")
        for i, row in enumerate(self.rows):
            if len(row) != k:
                raise ValueError(f"table row {i} has {len(row)} cells, the header {k}: "
                                 f"{row!r}")
        if len(formats) != k or len(self.align) != k:
            raise ValueError(f"a table of {k} columns needs {k} formats and alignments, got "
                             f"{len(formats)} and {self.align!r}")
        wrong = set(self.align) - set(ALIGNMENTS)
        if wrong:
            raise ValueError(f"table alignment {self.align!r}: letters {sorted(wrong)} are "
                             f"none of {', '.join(ALIGNMENTS)}")

    @classmethod
    def of_frame(cls, frame, columns=None, **kw):
        """The columns of ``frame`` as a table.

        Parameters
        ----------
        frame : pandas.DataFrame
        columns : sequence of (name, header, format), optional
            The columns shown, in order (a name ``frame`` lacks is left out);
            default: every column, its name as header, no format.
        **kw
            ``align``, ``caption``, ``label``, ``notes``.
        """
        columns = [c for c in columns if c[0] in frame.columns] if columns is not None \
            else [(name, name, None) for name in frame.columns]
        names = [name for name, _, _ in columns]
        return cls([header for _, header, _ in columns],
                   frame[names].itertuples(index=False, name=None),
                   [fmt for _, _, fmt in columns], **kw)

    def cells(self):
        """The rows as text, each column's format applied."""
        formats = [fmt or default_text for fmt in self.formats]
        return [[fmt(v) for fmt, v in zip(formats, row)] for row in self.rows]

    def numeric(self):
        """Per column: every value is a number (bools are not), and there is one at least."""
        return [bool(self.rows) and all(_is_number(row[j]) for row in self.rows)
                for j in range(len(self.header))]


# -- CSV -------------------------------------------------------------------------------


def csv(frame, float_format=None):
    """A data table as CSV, ``\\n`` line ends, no index; floats in their shortest
    round-trip form (exact and deterministic: two runs differ in the timing
    columns only) unless ``float_format`` (``"%.10g"``) rounds them."""
    return frame.to_csv(index=False, lineterminator="\n", float_format=float_format)


# -- Markdown --------------------------------------------------------------------------


def md_cell(text):
    """Text for a Markdown table cell: pipes escaped, no line breaks."""
    return str("" if text is None else text).replace("|", "\\|").replace("\n", " ")


def markdown(table):
    """The table as a Markdown pipe table, then its notes as paragraphs (no final newline)."""
    lines = ["| " + " | ".join(md_cell(h) for h in table.header) + " |",
             "|" + "|".join(ALIGNMENTS[a] for a in table.align) + "|"]
    lines += ["| " + " | ".join(md_cell(c) for c in row) + " |" for row in table.cells()]
    lines += [f"\n{note}" for note in table.notes]
    return "\n".join(lines)


# -- LaTeX -----------------------------------------------------------------------------


def _tabular(header, rows, spec):
    """A booktabs ``tabular`` of cells already in LaTeX (see :func:`latex`)."""
    lines = [rf"\begin{{tabular}}{{{spec}}}", r"\toprule", " & ".join(header) + r" \\",
             r"\midrule"]
    lines += [" & ".join(r) + r" \\" for r in rows]
    lines += [r"\bottomrule", r"\end{tabular}"]
    return ("{\\centering\\footnotesize\n"
            "\\resizebox{\\ifdim\\width>\\linewidth\\linewidth\\else\\width\\fi}{!}{%\n"
            + "\n".join(lines) + "}\\par}")


def latex(table, head=tex_header, cell=tex_number, text=str, caption_below=False):
    """The table as LaTeX (no final newline).

    Parameters
    ----------
    table : Table
    head, cell : callable
        Header text -> LaTeX, cell text -> LaTeX (``str``: already LaTeX).
    text : callable
        Caption and note -> LaTeX (default: already LaTeX).
    caption_below : bool
        The caption under the ``tabular`` instead of above it.

    Returns
    -------
    str
        The booktabs ``tabular``, centred and shrunk to the line width when
        wider; with a caption, a label or notes, in a ``table`` float: the
        caption, the label, the ``tabular``, the notes in small print.
    """
    body = _tabular([head(h) for h in table.header],
                   [[cell(c) for c in row] for row in table.cells()], table.align)
    if not (table.caption or table.label or table.notes):
        return body
    caption = [rf"\caption{{{text(table.caption)}}}"] if table.caption else []
    lines = [r"\begin{table}[ht]", *([] if caption_below else caption)]
    lines += [rf"\label{{{table.label}}}"] if table.label else []
    lines += [body, *(caption if caption_below else [])]
    lines += [r"\par\smallskip{\footnotesize " + text(note) + "}" for note in table.notes]
    return "\n".join(lines + [r"\end{table}"])


# -- HTML ------------------------------------------------------------------------------


def sort_key(value):
    """The ``data-sort`` of a cell: a number in its shortest round-trip form
    (``Infinity`` for inf, JavaScript's spelling), ``""`` for NaN or None, text as is."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, (int, float)) or hasattr(value, "dtype"):
        value = float(value)
        if math.isnan(value):
            return ""
        if math.isinf(value):
            return "Infinity" if value > 0 else "-Infinity"
        return str(int(value)) if value.is_integer() and abs(value) < 2 ** 53 else repr(value)
    return str(value)


def html(table, table_id, columns=None):
    """The table as a sortable HTML ``<table>`` in a scrolling ``<div>``.

    Parameters
    ----------
    table : Table
    table_id : str
        The ``id`` of the ``<table>``.
    columns : sequence of str, optional
        Each column's ``data-column`` (what ``#sort=COLUMN`` names; default:
        the headers).
    """
    from markupsafe import escape

    columns = list(columns) if columns is not None else list(table.header)
    numeric = table.numeric()
    lines = ['<div class="table-scroll">', f'<table class="sortable" id="{escape(table_id)}">',
             f"<caption>{escape(table.caption)}</caption>", "<thead><tr>"]
    lines += [f'<th data-column="{escape(c)}"' + (' data-type="num"' if num else "")
              + f' tabindex="0" aria-sort="none" title="sort by {escape(c)}">{escape(h)}</th>'
              for c, h, num in zip(columns, table.header, numeric)]
    lines += ["</tr></thead>", "<tbody>"]
    for i, (row, texts) in enumerate(zip(table.rows, table.cells())):
        lines.append(f'<tr data-row="{i}">' + "".join(
            f'<td data-sort="{escape(sort_key(v))}"' + ("" if num else ' class="text"')
            + f">{escape(t or MISSING)}</td>" for v, t, num in zip(row, texts, numeric)) + "</tr>")
    return "\n".join(lines + ["</tbody>", "</table>", "</div>"])

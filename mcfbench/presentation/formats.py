"""Number formats and LaTeX text: the cells of every table of the suite
(:mod:`mcfbench.presentation.tables` writes the tables)."""

import math
import re

MISSING = "–"             # a missing value in Markdown and HTML


def finite_value(x):
    """``x`` as a finite float, or None."""
    if x is None or isinstance(x, bool):
        return None
    try:
        value = float(x)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def formatted(x, spec, scale=1, unit="", missing=MISSING):
    """``scale * x`` formatted with ``spec``, then ``unit``; ``missing`` for None or a
    value that is not a finite number (:func:`finite_value`).

    Examples
    --------
    >>> formatted(0.5, ".2f", 100, " %"), formatted(float("nan"), ".3g")
    ('50.00 %', '–')
    """
    v = finite_value(x)
    return missing if v is None else f"{scale * v:{spec}}{unit}"


def sci(x, digits=3):
    """``1.311e-02``; :data:`MISSING` for None or NaN."""
    return formatted(x, f".{digits}e")


def fix(x, digits=3):
    """``0.013``: ``digits`` after the point."""
    return formatted(x, f".{digits}f")


def sig(x, digits=3):
    """``0.0131``: ``digits`` significant digits (``%g``)."""
    return formatted(x, f".{digits}g")


def signed(x, digits=3):
    """``+0.013``: with its sign."""
    return formatted(x, f"+.{digits}f")


def pct(x, digits=2):
    """A relative deviation as a signed percentage: 0.0123 -> '+1.23 %'."""
    return formatted(x, f"+.{digits}f", 100, " %")


def pct0(x):
    """A tolerance as a percentage: 0.01 -> '1 %'."""
    return formatted(x, "g", 100, " %")


def num(x):
    """A number with ``%g``, other values as text."""
    if isinstance(x, bool) or x is None:
        return MISSING if x is None else str(x)
    if isinstance(x, (int, float)):
        return f"{x:g}"
    return str(x)


def int_or(x, fallback=None):
    """``x`` (else ``fallback``) rounded to a whole number, or :data:`MISSING`."""
    v = finite_value(x)
    if v is None:
        v = finite_value(fallback)
    return MISSING if v is None else str(int(round(v)))


_TEX_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
                "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                "^": r"\textasciicircum{}", "<": r"\ensuremath{<}", ">": r"\ensuremath{>}",
                "|": r"\ensuremath{|}"}


_TEX_UNICODE = {
    "–": "--", "—": "---", "−": r"\ensuremath{-}", "×": r"\ensuremath{\times}",
    "±": r"\ensuremath{\pm}", "≤": r"\ensuremath{\le}", "≥": r"\ensuremath{\ge}",
    "≠": r"\ensuremath{\neq}", "≈": r"\ensuremath{\approx}", "∼": r"\ensuremath{\sim}",
    "√": r"\ensuremath{\surd}", "∂": r"\ensuremath{\partial}", "²": r"\ensuremath{^2}",
    "³": r"\ensuremath{^3}", "·": r"\ensuremath{\cdot}", "→": r"\ensuremath{\to}",
    "✓": r"\ensuremath{\checkmark}", "✗": r"\ensuremath{\times}",
    "○": r"\ensuremath{\circ}", "…": r"\ldots{}", "“": "``", "”": "''", "’": "'",
    "τ": r"\ensuremath{\tau}", "φ": r"\ensuremath{\varphi}", "Δ": r"\ensuremath{\Delta}",
    "χ": r"\ensuremath{\chi}", "γ": r"\ensuremath{\gamma}", "ω": r"\ensuremath{\omega}",
    "ν": r"\ensuremath{\nu}", "λ": r"\ensuremath{\lambda}", "μ": r"\ensuremath{\mu}",
    "α": r"\ensuremath{\alpha}", "β": r"\ensuremath{\beta}", "δ": r"\ensuremath{\delta}",
    "ρ": r"\ensuremath{\rho}", "κ": r"\ensuremath{\kappa}", "π": r"\ensuremath{\pi}",
}


def tex_escape(text):
    """Plain text as LaTeX: special characters escaped, common Unicode as commands
    (anything else beyond Latin-1 becomes ``?``)."""
    out = []
    for ch in str(text):
        if ch in _TEX_SPECIAL:
            out.append(_TEX_SPECIAL[ch])
        elif ch in _TEX_UNICODE:
            out.append(_TEX_UNICODE[ch])
        elif ord(ch) > 255:
            out.append("?")
        else:
            out.append(ch)
    return "".join(out)


_INLINE = re.compile(r"`([^`]+)`|<code>(.*?)</code>|\*\*(.+?)\*\*|(?<![\w*])\*([^*\s][^*]*?)\*"
                     r"|!\[([^\]]*)\]\([^)]*\)|\[([^\]]+)\]\([^)]*\)|<sub>(.*?)</sub>"
                     r"|<sup>(.*?)</sup>|<[^>]+>", re.S)


def _unescape(text):
    return (text.replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&")
            .replace("\\|", "|"))


def tex_inline(text):
    """Inline Markdown (code, bold, emphasis, links, sub/superscripts) as LaTeX."""
    out, pos = [], 0
    for m in _INLINE.finditer(text):
        out.append(tex_escape(_unescape(text[pos:m.start()])))
        code = m[1] if m[1] is not None else m[2]
        if code is not None:
            # no "--" ligature (an en dash in some fonts) inside commands
            code = re.sub(r"-(?=-)", "-{}", tex_escape(_unescape(code)))
            out.append(r"\texttt{" + code + "}")
        elif m[3] is not None:
            out.append(r"\textbf{" + tex_inline(m[3]) + "}")
        elif m[4] is not None:
            out.append(r"\emph{" + tex_inline(m[4]) + "}")
        elif m[5] is not None:
            out.append(tex_inline(m[5]))
        elif m[6] is not None:
            out.append(tex_inline(m[6]))
        elif m[7] is not None:
            out.append(r"\ensuremath{_{\mathrm{" + tex_escape(m[7]) + "}}}")
        elif m[8] is not None:
            out.append(r"\ensuremath{^{\mathrm{" + tex_escape(m[8]) + "}}}")
        pos = m.end()
    out.append(tex_escape(_unescape(text[pos:])))
    return "".join(out)


_SCI = re.compile(r"^(-?\d\.\d+)e([+-]\d+)$")


def tex_number(text):
    """A formatted cell as LaTeX: ``'1.311e-02'`` -> ``$1.311\\cdot 10^{-2}$``,
    :data:`MISSING` -> ``--``, other text through :func:`tex_inline`."""
    text = str(text)
    match = _SCI.match(text)
    if match:
        return f"${match[1]}\\cdot 10^{{{int(match[2])}}}$"
    if text == MISSING:
        return "--"
    return tex_inline(text)


_TEX_WORDS = {"n_V": "$n_V$", "n_F": "$n_F$", "n_T": "$n_T$", "tau": r"$\tau$", "h": "$h$",
              "N": "$N$", "L2": "$L_2$", "t_f": "$t_f$"}


def tex_header(text):
    """A column header as LaTeX: ``n_V``, ``tau``, ``L2``, ``t_f``, ... as math."""
    return " ".join(_TEX_WORDS.get(word, tex_inline(word)) for word in str(text).split(" "))

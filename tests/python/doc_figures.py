"""The check behind every figure the docs print (README.md, the crates' READMEs, docs/*.md).

A test computes the figure now and calls `check(doc, template, value, ...)`: `template` is the
doc's text around the number, with `{}` where each number stands and `{*}` for text that is
not checked (e.g. a measured time in the same table row); whitespace matches any run of
whitespace, so a figure may be wrapped over two lines. Every place the template occurs in
the doc is read; each printed number is compared with the value rendered at the printed
precision and in the printed style (`0.0413564788` -> 10 decimals, `4.205e-2` -> 4 significant
digits, `10,080` with thousands separators). Two ways to fail, each naming the doc:

- "README.md no longer prints ...": the text is gone, so the check must move with the edit
  (a doc edit cannot silently drop the check);
- "README.md prints '... 0.041361359441 ...' where the code now gives '... 0.041356478780 ...'":
  the figure is stale; the fix is the doc (or, if the code is wrong, the code).

With DOC_FIGURES_UPDATE=1 a stale figure is rewritten in the doc instead (the value the code
gives now, in the printed style), for a review of `git diff` before committing; text that is
gone still fails.

`require(doc, text)` asks for a whole line of text (e.g. a table row a command prints).
No pytest dependency: the test folders import it (tests/python directly, the others by path).
"""
import functools
import os
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

# a printed number: optional sign, thousands separators, decimals, exponent
NUMBER = r"[-+]?(?:\d{1,3}(?:,\d{3})+|\d+)(?:\.\d+)?(?:[eE][-+]?\d+)?"


class DocFigureError(AssertionError):
    pass


@functools.lru_cache(maxsize=None)
def doc(path):
    """The text of `path` (relative to the repository root)."""
    p = REPO / path
    if not p.exists():
        raise DocFigureError(f"{path} is gone: its figures' checks must move with it")
    return p.read_text()


def _pattern(template):
    """`{}` a number (captured), `{*}` any text within one line, whitespace any whitespace."""
    out = []
    for token in re.split(r"(\{\}|\{\*\})", template):
        if token == "{}":
            out.append(rf"(?<![\d.,])({NUMBER})(?![\d])")
        elif token == "{*}":
            out.append(r"[^\n]*?")
        elif token:
            words = token.split()
            text = r"\s+".join(re.escape(w) for w in words)
            if token[:1].isspace():
                text = r"\s+" + text if text else r"\s+"
            if token[-1:].isspace() and words:
                text += r"\s+"
            out.append(text)
    return re.compile("".join(out))


def format_like(printed, value):
    """`value` rendered as `printed` is: the same style, the same number of digits."""
    if isinstance(value, str):
        return value
    if isinstance(value, int) and not isinstance(value, bool) and re.fullmatch(r"[-+]?[\d,]+", printed):
        s = f"{value:,}" if "," in printed else f"{value}"
        return ("+" + s) if printed.startswith("+") and value >= 0 else s
    value = float(value)
    m = re.fullmatch(r"([-+]?)([\d,]+)(?:\.(\d+))?(?:[eE]([-+]?)(\d+))?", printed)
    if not m:
        raise DocFigureError(f"cannot read {printed!r} as a number")
    sign, whole, decimals, exp_sign, exp_digits = m.groups()
    n = len(decimals or "")
    if exp_digits is not None:
        mantissa, exponent = f"{value:.{n}e}".split("e")
        e = int(exponent)
        digits = f"{abs(e):0{len(exp_digits)}d}" if exp_digits.startswith("0") and len(exp_digits) > 1 else f"{abs(e)}"
        marker = printed[len(sign) + len(whole) + (n + 1 if decimals is not None else 0)]
        s = f"{mantissa}{marker}{'-' if e < 0 else ('+' if exp_sign == '+' else '')}{digits}"
    else:
        s = f"{value:,.{n}f}" if "," in whole else f"{value:.{n}f}"
    if sign == "+" and not s.startswith("-"):
        s = "+" + s
    return s


def check(path, template, *values):
    """Every occurrence of `template` in the doc `path` prints `values` (one per `{}`) at its
    printed precision. A value may be a string (compared as it stands)."""
    if template.count("{}") != len(values):
        raise DocFigureError(f"{template!r} has {template.count('{}')} places for {len(values)} values")
    text = doc(path)
    found = list(_pattern(template).finditer(text))
    if not found:
        raise DocFigureError(f"{path} no longer prints {template!r} (`{{}}` a number): "
                             "change this check with the text")
    stale, edits = [], []
    for m in found:
        printed = m.groups()
        want = [format_like(p, v) for p, v in zip(printed, values)]
        if list(printed) != want:
            edits += [(m.start(i), m.end(i), w) for i, w in enumerate(want, start=1)]
            now, at = "", m.start()
            for i, w in enumerate(want, start=1):
                now += text[at:m.start(i)] + w
                at = m.end(i)
            now += text[at:m.end()]
            stale.append(f"{path} prints {' '.join(m.group(0).split())!r} where the code now gives "
                         f"{' '.join(now.split())!r}")
    if stale and os.environ.get("DOC_FIGURES_UPDATE") == "1":
        for start, end, w in sorted(edits, reverse=True):
            text = text[:start] + w + text[end:]
        (REPO / path).write_text(text)
        doc.cache_clear()
        print("updated:", *stale, sep="\n  ")
    elif stale:
        raise DocFigureError("\n".join(stale))


def check_at_most(path, template, value, room=10):
    """The doc prints a bound `{}` on `value` (e.g. "the two agree to 6e-11") for a figure
    that is rounding noise (its last digit follows the BLAS kernel or the summation order):
    the bound must hold and be tight, `value <= printed <= room * value` (any bound holds for
    0); a larger `room` for a figure whose rounding varies more between machines."""
    text = doc(path)
    found = list(_pattern(template).finditer(text))
    if not found:
        raise DocFigureError(f"{path} no longer prints {template!r} (`{{}}` a number): "
                             "change this check with the text")
    for m in found:
        printed = float(m.group(1).replace(",", ""))
        if not (value <= printed and (value == 0 or printed <= room * value)):
            raise DocFigureError(f"{path} prints {' '.join(m.group(0).split())!r} as a bound on {value:.2g}: "
                                 f"{'exceeded' if value > printed else 'not tight'}")


def require(path, text):
    """The doc `path` holds `text` (whitespace runs match any whitespace)."""
    if not re.search(r"\s+".join(re.escape(w) for w in text.split()), doc(path)):
        raise DocFigureError(f"{path} no longer prints {text!r} (what the code gives now)")


def python_blocks(path):
    """The fenced ```python blocks of a doc that say what they print (a `# prints ...` line),
    as (line number, code, expected output): the output is the text after `# prints ` up to
    the first `: ` or ` (` of that line (the rest of the comment explains it)."""
    text = doc(path)
    blocks = []
    for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M):
        code = m.group(1)
        p = re.search(r"^# prints (.*)$", code, re.M)
        if p:
            expected = re.split(r": | \(", p.group(1), maxsplit=1)[0].strip()
            line = text[: m.start()].count("\n") + 1
            blocks.append((line, code, expected))
    return blocks

#!/usr/bin/env python3
"""Import circles between the files of a Rust crate.

Usage: module-cycles.py CRATE/src [...]

Reads every `crate::a::b` and `super::x` path in each file (in `use` lines and inline,
comments and doc comments skipped), and in a parent module each `child::Item` path,
resolves it to the file of the module it names
(`crate::a::b::Item` -> src/a/b.rs, else src/a.rs, else src/a/mod.rs; `crate::Item` -> the
file lib.rs re-exports it from), and prints each strongly connected component of more
than one file. Exit status 1 when there is one. A file's own `mod tests` (`use super::*`)
names the file itself and is no edge.
"""
import os
import re
import sys

PATH = re.compile(r"\b(crate|super)((?:::[A-Za-z_][A-Za-z0-9_]*)+|::\{[^}]*\})")


def module_of(src, path):
    """The module path (list) of a file: src/a/b.rs -> [a, b]; mod.rs, lib.rs -> parent."""
    rel = os.path.relpath(path, src)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib", "main"):
        rel = rel[:-1]
    return rel


def file_of(src, module):
    """The file that holds `module` (list), or None."""
    base = os.path.join(src, *module) if module else os.path.join(src, "lib")
    for cand in (base + ".rs", os.path.join(base, "mod.rs")):
        if os.path.isfile(cand):
            return cand
    return None


def resolve(src, segments, reexports):
    """The longest prefix of `segments` that is a file's module, else the re-export."""
    for n in range(len(segments), 0, -1):
        f = file_of(src, segments[:n])
        if f:
            return f
    if segments and segments[0] in reexports:
        return reexports[segments[0]]
    return file_of(src, [])


def strip_comments(text):
    out = []
    for line in text.splitlines():
        s = line.lstrip()
        if s.startswith("//"):
            continue
        out.append(line.split(" // ")[0])
    return "\n".join(out)


def graph(src):
    files = []
    for d, _, names in os.walk(src):
        files += [os.path.join(d, n) for n in names if n.endswith(".rs")]
    lib = file_of(src, [])
    reexports = {}
    if lib:
        for m in re.finditer(r"pub(?:\(crate\))? use (\w+)::([^;]+);", strip_comments(open(lib).read())):
            f = file_of(src, [m.group(1)])
            for name in re.findall(r"\b(\w+)\b", m.group(2)):
                if f:
                    reexports[name] = f
    edges = {f: set() for f in files}
    for f in files:
        here = module_of(src, f)
        text = strip_comments(open(f).read())
        # a module's own submodules named by a relative path (`child::Item`)
        declared = re.findall(r"^\s*(?:pub(?:\([\w:]+\))? )?mod (\w+);", text, re.M)
        for child in declared:
            if re.search(r"(?<![\w:])" + child + r"::", text):
                target = file_of(src, here + [child])
                if target:
                    edges[f].add(target)
        for m in PATH.finditer(text):
            tail = m.group(2)
            if tail.startswith("::{"):
                names = [re.split(r"::", n.strip())[0] for n in tail[3:-1].split(",") if n.strip()]
                paths = [[n] for n in names]
            else:
                paths = [tail[2:].split("::")]
            for segs in paths:
                if m.group(1) == "crate":
                    base = []
                else:
                    # `super` in a file's `mod tests` names the file itself
                    before = text[: m.start()]
                    in_inline_mod = re.search(r"\bmod \w+ \{", before) is not None
                    base = here if in_inline_mod else here[:-1]
                    while segs and segs[0] == "super":
                        segs, base = segs[1:], base[:-1]
                target = resolve(src, base + segs, reexports if not base else {})
                if target and target != f and not (target == lib):
                    edges[f].add(target)
    return edges


def cycles(edges):
    """Tarjan's strongly connected components of more than one node."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in edges:
        if v not in index:
            visit(v)
    return out


def main():
    bad = False
    for src in sys.argv[1:]:
        edges = graph(src)
        found = cycles(edges)
        if found:
            bad = True
            for comp in found:
                print(f"{src}: circle through {len(comp)} files: " + ", ".join(os.path.relpath(c, src) for c in comp))
        else:
            print(f"{src}: no import circle ({len(edges)} files, {sum(map(len, edges.values()))} edges)")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()

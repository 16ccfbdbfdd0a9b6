#!/usr/bin/env python3
"""Finds import circles between the files of each crate of the workspace.

A file depends on another when it names a path into it: `use crate::a::b::X`,
`use super::X`, `use self::child::X`, a child module in a `use` of the file declaring it
(`pub use child::X`), or a `crate::a::f()` / `super::g()` path in its code (comments and
strings are left out). A path is resolved to the longest prefix that is a module of its own
file (`src/a/b.rs`, `src/a/b/mod.rs`); inline modules (`mod tests { use super::*; }`) count
as their file. A re-export (`pub use child::X`) is a module's public face, not a use of its
own: a path through it (`crate::X`, `super::X`) leads to the file that defines `X`.

Usage: import-cycles.py [WORKSPACE_ROOT]       (exit 1 when any crate has a circle)
       import-cycles.py --self-test
"""

import re
import sys
import tempfile
from pathlib import Path

# Circles reported but not failing the check, by a path prefix of a file in them, each with
# its reason; remove an entry when its reason is gone.
KNOWN = {}

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"


def strip_comments_and_strings(text):
    """The code of `text` with comments, strings and char literals blanked (same length)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 260]) and (i == 0 or not re.match(r"\w", text[i - 1])):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            end = text.find('"' + hashes, i + len(hashes) + 2)
            j = n if end < 0 else end + 1 + len(hashes)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "'" and re.match(r"'(\\.|[^\\'])'|'\\u\{[0-9a-fA-F]+\}'", text[i:i + 12]):
            m = re.match(r"'(\\.|[^\\'])'|'\\u\{[0-9a-fA-F]+\}'", text[i:i + 12])
            out.append(" " * len(m.group(0)))
            i += len(m.group(0))
        else:
            out.append(c)
            i += 1
    return "".join(out)


def expand_use_tree(tree):
    """The paths of a `use` tree: `a::{b, c::{d, e}}` gives a::b, a::c::d, a::c::e."""
    tree = re.sub(r"\s+", "", tree)
    tree = re.sub(r"\bas\w+", "", tree)  # `x as y` (whitespace gone: `xasy` never matters)
    m = re.match(r"^(.*?)\{(.*)\}$", tree)
    if not m:
        return [tree]
    prefix, inner = m.group(1), m.group(2)
    parts, depth, start = [], 0, 0
    for i, c in enumerate(inner):
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(inner[start:i])
            start = i + 1
    parts.append(inner[start:])
    return [p for part in parts if part for p in expand_use_tree(prefix + part)]


def module_of(path, src):
    """The module path (a tuple) of a file under `src`: lib.rs is (), a/b.rs and a/b/mod.rs are (a, b)."""
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] == "mod" or (len(parts) == 1 and parts[0] in ("lib", "main")):
        parts = parts[:-1]
    return tuple(parts)


def crate_roots(crate_dir):
    """The crates of a package: its library (src/lib.rs) and its binaries (src/main.rs,
    src/bin/*.rs, src/bin/*/main.rs), each as (name, root file, source folder)."""
    src = crate_dir / "src"
    roots = []
    for root in (src / "lib.rs", src / "main.rs"):
        if root.exists():
            roots.append((f"{crate_dir.name} ({root.name})", root, src))
    bin_dir = src / "bin"
    if bin_dir.is_dir():
        for f in sorted(bin_dir.glob("*.rs")):
            roots.append((f"{crate_dir.name} (bin {f.stem})", f, None))
        for f in sorted(bin_dir.glob("*/main.rs")):
            roots.append((f"{crate_dir.name} (bin {f.parent.name})", f, f.parent))
    return roots


def crate_files(root, src):
    """The files of the crate rooted at `root`, by module path (the modules `mod x;` declares)."""
    files = {(): root}
    if src is None:
        return files
    todo = [root]
    while todo:
        f = todo.pop()
        module = module_of(f, src) if f != root else ()
        code = strip_comments_and_strings(f.read_text())
        for m in re.finditer(rf"(?:#\[path\s*=[^\]]*\]\s*)?\bmod\s+({IDENT})\s*;", code):
            if "#[path" in m.group(0):
                continue  # a #[path] module: not followed
            name = m.group(1)
            here = src.joinpath(*module)
            for candidate in (here / f"{name}.rs", here / name / "mod.rs"):
                if candidate.exists():
                    files[module + (name,)] = candidate
                    todo.append(candidate)
                    break
    return files


def references(code, module, children):
    """The module paths `code` (of the file of `module`) names, each with the inline module
    it is named in, as absolute module paths (tuples)."""
    # the inline module at each offset: `mod name {` opens one, its `}` closes it
    inline_at = []
    stack, depth = [], 0
    tokens = re.finditer(rf"\bmod\s+({IDENT})\s*\{{|[{{}}]", code)
    events = []
    for t in tokens:
        if t.group(0) == "{":
            depth += 1
        elif t.group(0) == "}":
            depth -= 1
            if stack and stack[-1][1] == depth:
                stack.pop()
        else:
            stack.append((t.group(1), depth))
            depth += 1
        events.append((t.end(), tuple(s[0] for s in stack)))

    def inline(offset):
        current = ()
        for end, names in events:
            if end > offset:
                break
            current = names
        return current

    def resolve(path, offset):
        segments = [s for s in path.split("::") if s]
        base = module + inline(offset)
        if not segments:
            return None
        if segments[0] == "crate":
            base, segments = (), segments[1:]
        elif segments[0] in ("self", "super"):
            while segments and segments[0] in ("self", "super"):
                if segments[0] == "super":
                    base = base[:-1]
                segments = segments[1:]
        elif segments[0] in children and not inline(offset):
            pass  # a child module of this file, named relative
        else:
            return None
        return base + tuple(segments)

    out = []
    for m in re.finditer(r"(\bpub(?:\s*\([^)]*\))?\s+)?\buse\s+([^;]*);", code):
        for path in expand_use_tree(m.group(2)):
            target = resolve(path.lstrip(":"), m.start())
            if target is not None:
                out.append((target, bool(m.group(1)) and not inline(m.start())))
    code_without_uses = re.sub(r"\buse\s+[^;]*;", lambda m: " " * len(m.group(0)), code)
    for m in re.finditer(rf"\b(?:crate|super|self)(?:\s*::\s*{IDENT})+", code_without_uses):
        target = resolve(re.sub(r"\s", "", m.group(0)), m.start())
        if target is not None:
            out.append((target, False))
    return out


def file_graph(root, src):
    """The dependencies between the files of one crate: {file: set of files}."""
    files = crate_files(root, src)
    by_module = {m: f for m, f in files.items()}
    refs, reexports = {}, {f: {} for f in files.values()}
    for module, f in files.items():
        children = {m[-1] for m in files if len(m) == len(module) + 1 and m[:-1] == module}
        code = strip_comments_and_strings(f.read_text())
        refs[f] = references(code, module, children)
        for target, is_reexport in refs[f]:
            if is_reexport and target and target[-1] != "*":
                reexports[f][target[-1]] = target

    def file_of(target, hops=0):
        """The file defining `target`: the longest prefix that is a file of its own, and
        through that file's re-export of the next name, the file it re-exports from."""
        for k in range(len(target), -1, -1):
            if target[:k] in by_module:
                dest = by_module[target[:k]]
                if k < len(target) and hops < 8:
                    via = reexports[dest].get(target[k])
                    if via is not None:
                        return file_of(via + target[k + 1:], hops + 1)
                return dest
        return root

    graph = {f: set() for f in files.values()}
    for f in files.values():
        for target, is_reexport in refs[f]:
            # a re-export (`pub use`) is the module's public face, no use of its own: paths
            # through it lead to the file defining the item
            dest = file_of(target)
            if not is_reexport and dest != f and dest != root:
                graph[f].add(dest)
    return graph


def cycles(graph):
    """The strongly connected components of more than one file (Tarjan), each sorted."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def workspace_crates(workspace):
    toml = (workspace / "Cargo.toml").read_text()
    members = re.search(r"members\s*=\s*\[(.*?)\]", toml, re.S).group(1)
    return [workspace / m for m in re.findall(r'"([^"]+)"', members)]


def check(workspace):
    """Prints every circle; returns the number of failing ones (known crates excepted)."""
    failing = 0
    for crate_dir in workspace_crates(workspace):
        for name, root, src in crate_roots(crate_dir):
            for component in cycles(file_graph(root, src)):
                files = ", ".join(str(f.relative_to(workspace)) for f in component)
                known = next((why for prefix, why in KNOWN.items() if prefix in files), None)
                if known:
                    print(f"{name}: known exception ({known}): import circle between {files}")
                else:
                    print(f"{name}: import circle between {files}")
                    failing += 1
    return failing


def self_test():
    """A made-up crate with one circle (a -> b -> c -> a through crate::, super:: and an
    inline path) and files that are no circle (a re-export in lib.rs, a test module's
    `use super::*`, a doc comment naming crate::a)."""
    with tempfile.TemporaryDirectory() as d:
        ws = Path(d)
        (ws / "Cargo.toml").write_text('[workspace]\nmembers = ["k"]\n')
        src = ws / "k" / "src"
        (src / "n").mkdir(parents=True)
        (src / "lib.rs").write_text("pub mod a;\npub mod n;\npub mod free;\npub use a::A;\n")
        (src / "a.rs").write_text("use crate::n::{b::B, c};\npub struct A;\n#[cfg(test)]\nmod tests {\n    use super::*;\n}\n")
        (src / "n" / "mod.rs").write_text("pub mod b;\npub mod c;\n")
        (src / "n" / "b.rs").write_text("pub struct B;\npub fn f() -> super::c::C { super::c::C }\n")
        (src / "n" / "c.rs").write_text("pub struct C;\n/// see [crate::free]\nfn g() { let _ = crate::A; let _ = crate::a::A; }\n")
        (src / "free.rs").write_text('use crate::n::b::B;\nconst S: &str = "crate::a::A";\n')
        found = cycles(file_graph(src / "lib.rs", src))
        expected = [sorted([src / "a.rs", src / "n" / "b.rs", src / "n" / "c.rs"])]
        assert found == expected, f"self-test: found {found}, expected {expected}"
        # breaking the circle (c no longer names a) leaves none
        (src / "n" / "c.rs").write_text("pub struct C;\n")
        assert cycles(file_graph(src / "lib.rs", src)) == [], "self-test: a circle where there is none"
        # a crate without the exception fails the check
        (src / "n" / "c.rs").write_text("use crate::a::A;\npub struct C;\n")
        assert check(ws) == 1, "self-test: the check passed a circle"
    print("import-cycles self-test: ok")


def main():
    if sys.argv[1:] == ["--self-test"]:
        self_test()
        return 0
    workspace = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent)
    failing = check(workspace)
    if failing:
        print(f"{failing} import circle(s) between files (a type lives where it is defined: move it so the arrows run one way)")
        return 1
    print("no import circle between the files of any crate (outside the known exceptions above)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

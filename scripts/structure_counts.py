#!/usr/bin/env python3
"""Counts the structure figures of issue 31 over src/ (tests excluded):

  - functions whose body is longer than 80 lines (from the `fn` line to its closing brace);
  - the dependency edges between top-level modules (`crate::x` paths, `use crate::{x, ..}`),
    and the cycles among them (strongly connected components of more than one module);
  - the lengths of src/main.rs and README.md.

    scripts/structure_counts.py [--list]     (--list names every long function and edge)

Code inside `#[cfg(test)]` items is not counted. Braces, `fn` and `crate::` inside strings,
characters and comments are ignored. Exit status 0 always: this reports, it does not judge.
"""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
LIMIT = 80


def strip(text):
    """The source with comments, strings and char literals blanked (newlines kept)."""
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
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and not (i and (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'r(#*)"', text[i:])
            close = '"' + m.group(1)
            j = text.find(close, i + len(m.group(0)))
            j = n if j < 0 else j + len(close)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "'":
            m = re.match(r"'(\\.[^']*|[^\\'])'", text[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:  # a lifetime
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def matching(code, open_at):
    depth = 0
    for j in range(open_at, len(code)):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code) - 1


def blank_tests(code):
    """Blanks every item that follows a #[cfg(test)] attribute."""
    while True:
        m = re.search(r"#\[cfg\(test\)\]", code)
        if not m:
            return code
        # the item's end: its braced block, or a `;` for `mod tests;`
        j = m.end()
        brace = code.find("{", j)
        semi = code.find(";", j)
        if semi >= 0 and (brace < 0 or semi < brace):
            end = semi
        else:
            end = matching(code, brace)
        code = code[:m.start()] + re.sub(r"[^\n]", " ", code[m.start():end + 1]) + code[end + 1:]


def rust_files():
    for d, _, files in os.walk(os.path.join(ROOT, "src")):
        for f in sorted(files):
            if f.endswith(".rs"):
                yield os.path.join(d, f)


def top_module(path):
    rel = os.path.relpath(path, os.path.join(ROOT, "src"))
    parts = rel.split(os.sep)
    if len(parts) == 1:
        name = parts[0][:-3]
        return None if name in ("lib", "main") else name
    return parts[0]


def long_functions(path, code):
    found = []
    for m in re.finditer(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)", code):
        # the body: the first `{` after the signature, unless a `;` comes first (a declaration)
        j = m.end()
        depth = 0
        while j < len(code):
            ch = code[j]
            if ch in "(<[":
                depth += 1
            elif ch in ")>]":
                depth -= 1
            elif ch == ";" and depth <= 0:
                j = -1
                break
            elif ch == "{" and depth <= 0:
                break
            j += 1
        if j < 0 or j >= len(code):
            continue
        end = matching(code, j)
        first = code.count("\n", 0, m.start()) + 1
        last = code.count("\n", 0, end) + 1
        lines = last - first + 1
        if lines > LIMIT:
            found.append((lines, os.path.relpath(path, ROOT), first, m.group(1)))
    return found


def edges(path, code):
    me = top_module(path)
    out = set()
    if me is None:
        return out
    for m in re.finditer(r"\bcrate::([a-z_][a-z0-9_]*)", code):
        out.add(m.group(1))
    for m in re.finditer(r"\bcrate::\{([^}]*)\}", code):
        for name in re.findall(r"(?:^|,)\s*([a-z_][a-z0-9_]*)", m.group(1)):
            out.add(name)
    modules = {top_module(p) for p in rust_files()} - {None}
    return {(me, o) for o in out if o != me and o in modules}


def sccs(nodes, graph):
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
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
            comps.append(sorted(comp))

    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return comps


def main():
    listing = "--list" in sys.argv
    longs, all_edges = [], set()
    for path in rust_files():
        with open(path, encoding="utf-8") as f:
            code = blank_tests(strip(f.read()))
        longs += long_functions(path, code)
        all_edges |= edges(path, code)
    graph = {}
    for a, b in all_edges:
        graph.setdefault(a, set()).add(b)
    nodes = {a for a, _ in all_edges} | {b for _, b in all_edges}
    cycles = [c for c in sccs(nodes, graph) if len(c) > 1]
    # back edges: edges inside a cycle component
    in_cycle = {m: i for i, c in enumerate(cycles) for m in c}
    cyc_edges = sorted((a, b) for a, b in all_edges if a in in_cycle and in_cycle.get(b) == in_cycle[a])

    def lines(p):
        with open(os.path.join(ROOT, p), encoding="utf-8") as f:
            return sum(1 for _ in f)

    print(f"functions over {LIMIT} lines (tests excluded): {len(longs)}")
    if listing:
        for n, p, line, name in sorted(longs, reverse=True):
            print(f"  {n:4d}  {p}:{line}  {name}")
    print(f"module dependency edges: {len(all_edges)}; cycles: {len(cycles)}")
    for c in cycles:
        print("  cycle: " + ", ".join(c))
    if listing and cyc_edges:
        print("  edges inside cycles: " + ", ".join(f"{a}→{b}" for a, b in cyc_edges))
    print(f"src/main.rs: {lines('src/main.rs')} lines")
    print(f"README.md: {lines('README.md')} lines")


if __name__ == "__main__":
    main()

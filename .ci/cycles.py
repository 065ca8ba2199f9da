#!/usr/bin/env python3
"""Import cycles between modules of a crate, at every depth, test code included.

Every path a source file names outside comments is an edge from the file's module to the module
it names: `crate::a::b`, `super::…` and `self::…` paths anywhere in the code, and every leaf of
a `use` tree (`use crate::a::{b::{self, C}, d}` names a::b and a::d; `use super::*` names the
parent). Paths are resolved from the file's own module (a `mod.rs` is its folder's module). An
edge counts at every depth: modules a::b::c and a::d::e give a::b -> a::d at depth 2 and
a::b::c -> a::d::e at depth 3, so a cycle between files of one folder counts as much as one
between folders. A module and its own ancestors are not an edge (a parent declares its
children). Prints each cycle found and exits 1 if there is any."""
import os
import re
import sys


def module_of(root, path):
    rel = os.path.relpath(path, root)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib", "main"):
        rel = rel[:-1]
    return tuple(rel)


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    # Line comments, but not `//` inside string literals such as URLs.
    out = []
    for line in text.splitlines():
        in_str = False
        cut = len(line)
        i = 0
        while i < len(line) - 1:
            c = line[i]
            if c == "\\" and in_str:
                i += 2
                continue
            if c == '"':
                in_str = not in_str
            elif not in_str and line[i : i + 2] == "//":
                cut = i
                break
            i += 1
        out.append(line[:cut])
    return "\n".join(out)


def expand_use(tree):
    """The leaf paths of a use tree (`a::{b, c::{self, D}}` -> a::b, a::c, a::c::D)."""
    tree = re.sub(r"\s+", "", tree)
    depth, start, parts = 0, 0, []
    brace = tree.find("{")
    if brace < 0:
        return [tree.split(" as ")[0]]
    prefix, inner = tree[:brace], tree[brace + 1 : tree.rfind("}")]
    for i, c in enumerate(inner):
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(inner[start:i])
            start = i + 1
    parts.append(inner[start:])
    leaves = []
    for p in filter(None, parts):
        for leaf in expand_use(p):
            leaves.append(prefix + leaf if leaf != "self" else prefix.rstrip(":"))
    return leaves


def resolve(me, path):
    """The module path `path` names from module `me` (None for an external crate's)."""
    segs = [s for s in path.split("::") if s]
    if not segs:
        return None
    if segs[0] == "crate":
        return tuple(segs[1:])
    base = list(me)
    if segs[0] == "self":
        segs = segs[1:]
    elif segs[0] == "super":
        while segs and segs[0] == "super":
            base = base[:-1]
            segs = segs[1:]
    else:
        return None
    return tuple(base) + tuple(s for s in segs if s != "*")


def edges(root):
    out = {}
    for dirpath, _, files in os.walk(root):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(dirpath, f)
            me = module_of(root, path)
            code = strip_comments(open(path, encoding="utf-8").read())
            deps = set()
            for m in re.finditer(r"\buse\s+([^;]+);", code):
                for leaf in expand_use(m.group(1)):
                    d = resolve(me, leaf)
                    if d is not None:
                        deps.add(d)
            for m in re.finditer(r"\b((?:crate|super|self)(?:::(?:super|\w+))+)", code):
                d = resolve(me, m.group(1))
                if d is not None:
                    deps.add(d)
            out[me] = deps
    return out


def cycles(root):
    mods = edges(root)
    found = set()
    deepest = max((len(m) for m in mods), default=0)
    for depth in range(1, deepest + 1):
        graph = {}
        for m, deps in mods.items():
            a = m[:depth]
            if len(a) < depth:
                continue
            for d in deps:
                # Keep only the part that names a module that exists.
                while d and d not in mods:
                    d = d[:-1]
                b = d[:depth]
                if len(b) < depth or a == b or b[: len(a)] == a or a[: len(b)] == b:
                    continue
                graph.setdefault(a, set()).add(b)
        for start in graph:
            stack = [(start, [start])]
            while stack:
                node, path = stack.pop()
                for nxt in graph.get(node, ()):
                    if nxt == start:
                        found.add(" -> ".join("::".join(p) for p in path + [start]))
                    elif nxt not in path and len(path) < 8:
                        stack.append((nxt, path + [nxt]))
    return found


bad = False
for root in sys.argv[1:]:
    for c in sorted(cycles(root)):
        print(f"{root}: import cycle {c}")
        bad = True
sys.exit(1 if bad else 0)

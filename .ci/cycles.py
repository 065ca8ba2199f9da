#!/usr/bin/env python3
"""Import cycles between modules of a crate: every `crate::a::b` (and `super::`) path a source
file names, outside comments, is an edge from the file's module to that module; modules are
compared at every depth (a::b and its parent a), so a cycle between folders counts as much as
one between files. Prints each cycle found and exits 1 if there is any."""
import os
import re
import sys


def module_of(root, path):
    rel = os.path.relpath(path, root)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib", "main"):
        rel = rel[:-1]
    return rel


def edges(root):
    out = {}
    for dirpath, _, files in os.walk(root):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(dirpath, f)
            me = module_of(root, path)
            text = open(path, encoding="utf-8").read()
            # Unit tests may use anything.
            text = text.split("#[cfg(test)]")[0]
            code = "\n".join(l.split("//")[0] for l in text.splitlines())
            deps = set()
            for m in re.finditer(r"\bcrate((?:::\w+)+)", code):
                deps.add(tuple(m.group(1).strip(":").split("::")))
            for m in re.finditer(r"\b((?:super::)+)((?:\w+::)*\w+)", code):
                up = m.group(1).count("super")
                base = me[: len(me) - up] if f not in ("mod.rs", "lib.rs") else me[: len(me) - up]
                deps.add(tuple(base) + tuple(m.group(2).split("::")))
            out[tuple(me)] = deps
    return out


def cycles(root):
    mods = edges(root)
    found = set()
    for depth in (1, 2):
        graph = {}
        for m, deps in mods.items():
            a = m[:depth]
            for d in deps:
                # Keep only the part that names a module that exists.
                while d and tuple(d) not in mods:
                    d = d[:-1]
                b = tuple(d)[:depth]
                if b and a and a != b and not (b[: len(a)] == a or a[: len(b)] == b):
                    graph.setdefault(a, set()).add(b)
        for start in graph:
            stack = [(start, [start])]
            while stack:
                node, path = stack.pop()
                for nxt in graph.get(node, ()):
                    if nxt == start:
                        found.add(" -> ".join("::".join(p) for p in path + [start]))
                    elif nxt not in path and len(path) < 6:
                        stack.append((nxt, path + [nxt]))
    return found


bad = False
for root in sys.argv[1:]:
    for c in sorted(cycles(root)):
        print(f"{root}: import cycle {c}")
        bad = True
sys.exit(1 if bad else 0)

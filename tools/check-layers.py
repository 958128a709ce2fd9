#!/usr/bin/env python3
"""Checks the module graph of a Rust crate: no import cycles, layers that only point down.

Usage: tools/check-layers.py [SRC_DIR] [--cycles-under PREFIX ...] [--coarse]
       SRC_DIR defaults to crates/flexcam/src.

Nodes are file modules (src/a/b.rs and src/a/b/mod.rs are `a::b`). An edge A -> B means code of
A names an item of B: a `use crate::...`, `use super::...`, `use self::...` item or an inline
path `crate::x::y` / `super::y`. Paths are resolved through `use` items (re-exports and private imports) to the
module that defines the item, so a facade mod.rs that re-exports its children does not by itself tie
them into a cycle (a re-export is not a use). A module's uses of its own submodules are
ownership, not edges: a parent is made of its children, and a child may use its parent's
items (that edge counts). Test code is left out: modules declared under
`#[cfg(test)]` and inline `#[cfg(test)] mod ... { }` blocks.

Reports
- every cycle (strongly connected component of more than one module), with one concrete
  circle through it;
- every edge that points up the layer order below (a module of a lower layer naming a higher
  one).
Exits 1 when it finds either, 0 otherwise. With --cycles-under PREFIX (repeatable), only
cycles whose modules all lie under one of the prefixes count towards the exit status (the
others are still printed).
With --coarse, the graph is that of the library's parts instead of its files: every module
stands for its top-level module (`scene`, `projection`, ...), and under `render` for its
renderer or service (`render::raycast`, `render::shading`, ...; `render` itself is mod.rs).
A cycle there is two parts that use each other through any of their files.
"""

import os
import re
import sys

# Layers from the bottom up; a module may name modules of its own layer or of layers below.
# Modules not listed (error, the crate root) belong to no layer and are not checked.
LAYERS = ["geometry", "projection", "calibrate", "scene", "displace", "render", "image_io"]

USE_RE = re.compile(r"\b(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);", re.S)
INLINE_RE = re.compile(r"(?<![\w:])((?:crate|super|self)(?:::(?:super|[A-Za-z_]\w*))+)")
MOD_DECL_RE = re.compile(r"(#\[cfg\(test\)\]\s*)?(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;")
CFG_TEST_INLINE_RE = re.compile(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{")


def strip_comments_and_strings(text):
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'r(#*)"', text[i:])
            end = text.find('"' + m.group(1), i + len(m.group(0)))
            i = n if end < 0 else end + 1 + len(m.group(1))
            out.append('""')
        elif c == '"':
            i += 1
            while i < n and text[i] != '"':
                i += 2 if text[i] == "\\" else 1
            i += 1
            out.append('""')
        elif c == "'" and re.match(r"'(\\.|[^\\'])'|'\\u\{[0-9a-fA-F]+\}'|'\\x..'", text[i:i + 12]):
            m = re.match(r"'(\\.|[^\\'])'|'\\u\{[0-9a-fA-F]+\}'|'\\x..'", text[i:i + 12])
            i += len(m.group(0))
            out.append("' '")
        else:
            out.append(c)
            i += 1
    return "".join(out)


def strip_test_blocks(code):
    while True:
        m = CFG_TEST_INLINE_RE.search(code)
        if not m:
            return code
        depth, i = 1, m.end()
        while i < len(code) and depth:
            depth += {"{": 1, "}": -1}.get(code[i], 0)
            i += 1
        code = code[:m.start()] + code[i:]


def expand_use_tree(tree):
    """`a::{b, c::{d, e as f}}` -> [(['a','b'], None), (['a','c','d'], None), (['a','c','e'], 'f')]."""
    tree = re.sub(r"\s+as\s+", "@", tree)
    tree = re.sub(r"\s+", "", tree)
    results = []

    def split_top(s):
        parts, depth, cur = [], 0, ""
        for ch in s:
            if ch == "," and depth == 0:
                parts.append(cur)
                cur = ""
                continue
            depth += {"{": 1, "}": -1}.get(ch, 0)
            cur += ch
        if cur:
            parts.append(cur)
        return parts

    def walk(prefix, s):
        if not s:
            return
        if s.startswith("{") and s.endswith("}"):
            for part in split_top(s[1:-1]):
                walk(prefix, part)
            return
        brace = s.find("{")
        if brace >= 0 and s.endswith("}"):
            head = s[:brace].rstrip(":")
            walk(prefix + [p for p in head.split("::") if p], s[brace:])
            return
        path, _, alias = s.partition("@")
        segs = [p for p in path.split("::") if p]
        results.append((prefix + segs, alias or None))

    walk([], tree)
    return results


class Crate:
    def __init__(self, src):
        self.src = src
        self.files = {}  # module path (tuple) -> file path
        self.test_modules = set()
        self.code = {}
        self.reexports = {}  # module -> {name: absolute path list}
        self.is_dir_module = {}
        self._collect()

    def _collect(self):
        for root, _, names in os.walk(self.src):
            for name in names:
                if not name.endswith(".rs"):
                    continue
                path = os.path.join(root, name)
                rel = os.path.relpath(path, self.src)[:-3].split(os.sep)
                if rel == ["lib"] or rel == ["main"]:
                    mod = ()
                    self.is_dir_module[mod] = True
                elif rel[-1] == "mod":
                    mod = tuple(rel[:-1])
                    self.is_dir_module[mod] = True
                else:
                    mod = tuple(rel)
                    self.is_dir_module[mod] = False
                self.files[mod] = path
        for mod, path in self.files.items():
            with open(path, encoding="utf-8") as f:
                raw = strip_comments_and_strings(f.read())
            for m in MOD_DECL_RE.finditer(raw):
                if m.group(1):
                    self.test_modules.add(mod + (m.group(2),))
            self.code[mod] = strip_test_blocks(raw)
        # Test modules and everything below them are left out.
        for mod in list(self.files):
            if any(mod[:k] in self.test_modules for k in range(1, len(mod) + 1)):
                del self.files[mod]
                del self.code[mod]
        for mod, code in self.code.items():
            table = {}
            for m in USE_RE.finditer(code):
                for segs, alias in expand_use_tree(m.group(2)):
                    absolute = self.absolute(mod, segs)
                    if absolute is None or not segs:
                        continue
                    name = alias or segs[-1]
                    if name in ("self", "*"):
                        continue
                    table[name] = absolute
            self.reexports[mod] = table

    def absolute(self, mod, segs):
        """Absolute path (list) of a path written in module `mod`, or None if external."""
        if not segs:
            return None
        base = list(mod)
        first = segs[0]
        if first == "crate":
            return segs[1:]
        if first == "self":
            return base + segs[1:]
        if first == "super":
            k = 0
            while k < len(segs) and segs[k] == "super":
                k += 1
            return base[: len(base) - k] + segs[k:]
        # `use child::X` in a module with a child of that name (edition 2018 uniform paths).
        if tuple(base + [first]) in self.files:
            return base + segs
        return None

    def resolve(self, path, depth=0):
        """The module that defines the item at absolute `path`."""
        best = ()
        for k in range(len(path), -1, -1):
            if tuple(path[:k]) in self.files:
                best = tuple(path[:k])
                rest = path[k:]
                break
        else:
            return None
        if rest and depth < 16:
            target = self.reexports.get(best, {}).get(rest[0])
            if target is not None and target != list(best) + rest[:1]:
                return self.resolve(target + rest[1:], depth + 1)
        return best

    def edges(self):
        graph = {mod: set() for mod in self.files}
        for mod, code in self.code.items():
            paths = []
            for m in USE_RE.finditer(code):
                if m.group(1):
                    continue  # a re-export is a facade, not a use
                for segs, _ in expand_use_tree(m.group(2)):
                    paths.append(segs)
            body = USE_RE.sub(" ", code)
            for m in INLINE_RE.finditer(body):
                paths.append(m.group(1).split("::"))
            for segs in paths:
                absolute = self.absolute(mod, segs)
                if absolute is None:
                    continue
                target = self.resolve(absolute)
                if target is None or target[: len(mod)] == mod:
                    continue  # itself, or a module it owns
                # A module naming its own ancestor's item through `super` reaches a facade;
                # resolve() already followed re-exports, so what is left is a real use.
                graph[mod].add(target)
        return graph


def strongly_connected(graph):
    index, low, on_stack, stack, comps = {}, {}, set(), [], []
    counter = [0]
    sys.setrecursionlimit(100000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            comps.append(comp)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return [sorted(c) for c in comps if len(c) > 1]


def a_circle(graph, comp):
    members = set(comp)
    start = comp[0]
    # Breadth-first search back to start inside the component.
    from collections import deque
    prev = {start: None}
    queue = deque([start])
    while queue:
        v = queue.popleft()
        for w in sorted(graph[v]):
            if w not in members:
                continue
            if w == start:
                path = [v]
                while prev[path[-1]] is not None:
                    path.append(prev[path[-1]])
                return list(reversed(path)) + [start]
            if w not in prev:
                prev[w] = v
                queue.append(w)
    return comp


def name(mod):
    return "::".join(mod) or "crate"


def layer(mod):
    if mod and mod[0] in LAYERS:
        return LAYERS.index(mod[0])
    return None


def part(mod):
    """The part of the library `mod` belongs to (see --coarse)."""
    return mod[:2] if mod[:1] == ("render",) else mod[:1]


def coarse(graph):
    """`graph` with every module replaced by its part, edges within a part dropped."""
    parts = {}
    for mod, targets in graph.items():
        edges = parts.setdefault(part(mod), set())
        for target in targets:
            parts.setdefault(part(target), set())
            if part(target) != part(mod):
                edges.add(part(target))
    return parts


def main(argv):
    src = "crates/flexcam/src"
    prefixes = []
    grain = None
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--self-test":
            return self_test()
        if a == "--cycles-under":
            prefixes.append(tuple(args.pop(0).split("::")))
        elif a == "--coarse":
            grain = coarse
        else:
            src = a
    crate = Crate(src)
    graph = crate.edges()
    if grain:
        graph = grain(graph)
    failed = False
    comps = strongly_connected(graph)
    for comp in comps:
        counts = not prefixes or all(any(m[: len(p)] == p for p in prefixes) for m in comp)
        failed |= counts
        circle = " -> ".join(name(m) for m in a_circle(graph, comp))
        print(f"cycle ({len(comp)} modules: {', '.join(name(m) for m in comp)}): {circle}")
    for mod in sorted(graph):
        for target in sorted(graph[mod]):
            lm, lt = layer(mod), layer(target)
            if lm is None or lt is None:
                continue
            if lt > lm:
                print(f"upward: {name(mod)} -> {name(target)}")
                failed = True
    print(f"{len(graph)} modules, {sum(len(e) for e in graph.values())} edges, "
          f"{len(comps)} cycles")
    return 1 if failed else 0


def self_test():
    """Plants a cycle, an upward import and a re-export facade in a scratch crate and checks
    that the first two are reported and the third is not."""
    import tempfile
    import contextlib
    import io

    files = {
        "lib.rs": "pub mod geometry;\npub mod projection;\npub mod scene;\n",
        "geometry/mod.rs": "mod ray;\npub use ray::Ray;\npub struct V;\n",
        "geometry/ray.rs": "use super::V;\npub struct Ray(V);\n",
        "projection/mod.rs": "mod a;\nmod b;\npub use a::A;\n// use crate::scene::S;\n"
        "#[cfg(test)]\nmod tests {\n    use crate::scene::S;\n}\n",
        "projection/a.rs": "use super::b::B;\nuse crate::geometry::{Ray, V as W};\npub struct A;\n",
        "projection/b.rs": "pub struct B;\nfn f() { let _ = crate::projection::A; }\n",
        "scene/mod.rs": "use crate::projection::A;\npub struct S;\n",
    }

    def run(tree, *options):
        with tempfile.TemporaryDirectory() as tmp:
            for rel, text in tree.items():
                path = os.path.join(tmp, rel)
                os.makedirs(os.path.dirname(path), exist_ok=True)
                with open(path, "w", encoding="utf-8") as f:
                    f.write(text)
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                status = main([tmp, *options])
            return status, out.getvalue()

    status, out = run(files)
    expect_cycle = "cycle (2 modules: projection::a, projection::b)"
    assert status == 1 and expect_cycle in out, out
    assert "modules: geometry" not in out, out  # the re-export facade is no cycle
    assert "upward" not in out, out
    files["geometry/ray.rs"] += "fn g() { crate::scene::S; }\n"
    status, out = run(files)
    assert status == 1 and "upward: geometry::ray -> scene" in out, out
    files["geometry/ray.rs"] = "use super::V;\npub struct Ray(V);\n"
    files["projection/b.rs"] = "pub struct B;\n"
    status, out = run(files)
    assert status == 0 and "0 cycles" in out, out
    # Two parts using each other through different files are a coarse cycle only.
    files["scene/mod.rs"] = "mod x;\nuse crate::projection::A;\npub struct S;\n"
    files["scene/x.rs"] = "pub struct X;\n"
    files["projection/b.rs"] = "pub struct B;\nfn f() { let _ = crate::scene::x::X; }\n"
    status, out = run(files)
    assert status == 1 and "upward: projection::b -> scene::x" in out, out
    assert "0 cycles" in out, out
    status, out = run(files, "--coarse")
    assert status == 1 and "cycle (2 modules: projection, scene)" in out, out
    print("self-test passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

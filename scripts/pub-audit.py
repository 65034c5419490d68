#!/usr/bin/env python3
"""Public items of logicrag's reasoning core that no front end names.

The reasoning core is the modules a front end asks through (issue 33:
kb, ask, belief, whynot, pipeline, and what they are made of: engine,
temporal, proof, context, session, source); the front ends are the CLI,
the REPL, serve, plot, the LLM client, Arrow, the renderers at their
edge (JSON, terminal text, scenes, evaluation, batches) and the Python
package. An
item is `pub fn|struct|enum|trait|type|const|static NAME` (methods
included, fields not); it counts as named when its name appears as a
word in a front end's source (examples and benches included), or when it
is the type of a public field or in a public function's signature of the
core (a front end reaches it through the API without naming it). Prints each unnamed item and the count.

Usage: scripts/pub-audit.py [--max N]   (exit 1 when more than N)
"""
import pathlib, re, sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SRC = ROOT / "logicrag" / "src"
CORE = ["kb", "ask", "belief", "whynot", "pipeline", "engine", "temporal",
        "proof", "context", "session", "source"]
# The front ends and the renderers at their edge (JSON, terminal text,
# scenes for drawing, evaluation reports, batches).
FRONT = ["cli", "repl", "serve", "plot", "llm", "arrow", "main.rs", "json", "render",
         "scene", "images", "eval", "metrics", "questions", "batch"]
ITEM = re.compile(r"^\s*pub\s+(?:const\s+fn|async\s+fn|fn|struct|enum|trait|type|const|static)\s+([A-Za-z_][A-Za-z0-9_]*)", re.M)

def files(names):
    out = []
    for n in names:
        p = SRC / n
        if p.is_dir():
            out += sorted(p.rglob("*.rs"))
        for f in (SRC / (n + ".rs"), p if p.suffix == ".rs" else None):
            if f is not None and f.is_file():
                out.append(f)
    return out

def strip_tests(text):
    # Test modules (a `#[cfg(test)]` line up to the end of the file, or a
    # file named tests.rs) hold no public API.
    i = text.find("#[cfg(test)]\nmod ")
    return text if i < 0 else text[:i]

def main():
    limit = None
    if "--max" in sys.argv:
        limit = int(sys.argv[sys.argv.index("--max") + 1])
    front_text = "\n".join(f.read_text() for f in files(FRONT))
    for extra in ("logicrag-py/src", "logicrag/examples", "logicrag/benches"):
        front_text += "\n".join(f.read_text() for f in (ROOT / extra).rglob("*.rs"))
    words = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", front_text))
    # A type a front end reaches through the API without naming it (the
    # type of a public field, or of a public function's argument or
    # result) is part of that API: named by its place.
    reached = set()
    for f in files(CORE):
        for line in strip_tests(f.read_text()).splitlines():
            if re.match(r"^\s*pub\s+(fn\s|[a-z_][a-z0-9_]*\s*:)", line):
                sig = line.split("(", 1)[1] if line.lstrip().startswith("pub fn") and "(" in line else line.split(":", 1)[1]
                reached |= set(re.findall(r"\b[A-Z][A-Za-z0-9_]*", sig))
    words |= reached
    unnamed = []
    total = 0
    for f in files(CORE):
        if f.name == "tests.rs" or f.name.endswith("_tests.rs"):
            continue
        for m in ITEM.finditer(strip_tests(f.read_text())):
            total += 1
            if m.group(1) not in words:
                line = f.read_text().count("\n", 0, m.start()) + 1
                unnamed.append(f"{f.relative_to(ROOT)}:{line}: {m.group(1)}")
    for u in unnamed:
        print(u)
    print(f"{len(unnamed)} of {total} public items of the reasoning core are named by no front end")
    if limit is not None and len(unnamed) > limit:
        sys.exit(1)

main()

#!/usr/bin/env python3
"""docs/architecture.md's module graph against the CMake targets of the build.

usage: check_module_graph.py BUILD_DIR/module_graph.txt SOURCE_DIR [--self-test]

module_graph.txt is written by pdcg_write_module_graph (cmake/pdcgModule.cmake) at the end of
configuration: the LINK_LIBRARIES and INTERFACE_LINK_LIBRARIES of every module target, the
umbrella pdcg::pdcg and the pdcg executable. The test fails (exit 1, one line per
disagreement) when
  - the table between <!-- module-graph:begin --> and <!-- module-graph:end --> lists other
    targets, or other PUBLIC / PRIVATE links, than the build has;
  - the mermaid diagram there has other module edges than the table;
  - the module graph has a cycle;
  - a header or source of module A includes "pdcg/B/..." for a module B that A does not reach
    through its links, unless the header-only uses list "`A` → `B`" (and a listed use must
    exist);
  - the "what it holds" table does not have one row per module.
--self-test: checks that the comparison fails for documents with a removed link, an added
link, a wrong diagram edge and a missing header-only use (so the test can fail).
"""
import pathlib
import re
import sys


class DocError(Exception):
    pass


def fail(msgs):
    for m in msgs:
        print("module graph:", m)
    print(f"{len(msgs)} disagreement(s); fix docs/architecture.md (or the CMake links)")
    sys.exit(1)


def norm(item):
    """Canonical name of a link item: pdcg_x -> pdcg::x; $<LINK_ONLY:x> -> x."""
    item = item.strip()
    m = re.fullmatch(r"\$<LINK_ONLY:(.+)>", item)
    if m:
        item = m.group(1)
    m = re.fullmatch(r"pdcg_([a-z_]+)", item)
    if m:
        item = "pdcg::" + m.group(1)
    return item


def read_build(path):
    targets, options = {}, {}
    for line in pathlib.Path(path).read_text().splitlines():
        f = line.split("\t")
        if f[0] == "option":
            options[f[1]] = f[2] == "ON"
            continue
        name, kind, link, iface = f[0], f[1], f[2], f[3]
        link = [x for x in link.split(";") if x]
        iface = [x for x in iface.split(";") if x]
        public = {norm(x) for x in iface if not x.startswith("$<LINK_ONLY:")}
        private = {norm(x) for x in link} - public
        if name == "pdcg":
            key = "pdcg (executable)"
        else:
            key = norm(name)
        targets[key] = {"kind": kind, "public": public, "private": private}
    return targets, options


def strip_md(cell):
    return cell.replace("`", "").strip()


def read_doc(text, modules, options):
    m = re.search(r"<!-- module-graph:begin -->(.*?)<!-- module-graph:end -->", text, re.S)
    if not m:
        raise DocError("docs/architecture.md: no <!-- module-graph:begin --> … "
                       "<!-- module-graph:end --> block")
    block = m.group(1)
    errors, table, absent = [], {}, set()
    for line in block.splitlines():
        if not line.startswith("|") or line.startswith("|---") or "PUBLIC links" in line:
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 3:
            errors.append(f"table row with {len(cells)} cells: {line}")
            continue
        name = strip_md(cells[0])
        # an optional module: "`pdcg::x` (with OPTION)", in the table only where OPTION is on
        cond_row = re.fullmatch(r"(.+?)\s*\(with ([A-Z_]+)\)", name)
        if cond_row:
            name = cond_row.group(1)
            if not options.get(cond_row.group(2), False):
                absent.add(name.split("::")[-1])
                continue
        name = re.sub(r"\s*\((interface)\)$", "", name)
        name = re.sub(r"\s*\(executable.*\)$", " (executable)", name)
        cols = []
        for cell in cells[1:]:
            items = set()
            for it in [strip_md(x) for x in cell.split(",") if strip_md(x)]:
                cond = re.fullmatch(r"(.+?)\s*\(with ([A-Z_]+)\)", it)
                if cond:
                    if options.get(cond.group(2), False):
                        items.add(cond.group(1))
                    continue
                but = re.fullmatch(r"every module above(?: but (.+))?", it)
                if but:
                    items |= {f"pdcg::{x}" for x in modules} - {strip_md(but.group(1) or "")}
                    continue
                items.add(it)
            cols.append(items)
        table[name] = {"public": cols[0], "private": cols[1]}
    edges = set()
    for a, arrow, b in re.findall(r"^\s*([a-z_]+)\s*(-->|-\.->)\s*([a-z_]+)\s*$", block, re.M):
        if a not in absent and b not in absent:  # edges of optional modules not built
            edges.add((a, b, "public" if arrow == "-->" else "private"))
    header_only = set(re.findall(r"^- `([a-z_]+)` → `([a-z_]+)`", block, re.M))
    holds = set()
    rest = text[m.end():]
    h = re.search(r"\| module \| what it holds \|.*?\n\n", rest, re.S)
    if h:
        for line in h.group(0).splitlines()[2:]:
            if line.startswith("|"):
                name = line.strip("|").split("|")[0].strip()
                if name not in absent:
                    holds.add(name)
    return table, edges, header_only, holds, errors


def closure(graph, start):
    seen, todo = set(), [start]
    while todo:
        n = todo.pop()
        for d in graph.get(n, ()):
            if d not in seen:
                seen.add(d)
                todo.append(d)
    return seen


def check(graph_file, source, doc_text):
    """The disagreements between the build's graph and the document (empty: they agree)."""
    build, options = read_build(graph_file)
    modules = [k.split("::")[1] for k, v in build.items()
               if k.startswith("pdcg::") and k != "pdcg::pdcg"]
    try:
        table, edges, header_only, holds, errors = read_doc(doc_text, modules, options)
    except DocError as e:
        return [str(e)], None

    for t in sorted(set(build) | set(table)):
        if t not in table:
            errors.append(f"target {t} is built but not in the table")
            continue
        if t not in build:
            errors.append(f"target {t} is in the table but not built")
            continue
        for vis in ("public", "private"):
            missing = build[t][vis] - table[t][vis]
            extra = table[t][vis] - build[t][vis]
            if missing:
                errors.append(f"{t}: {vis.upper()} links {sorted(missing)} missing in the table")
            if extra:
                errors.append(f"{t}: table lists {vis.upper()} links {sorted(extra)} the build does not have")

    # module-to-module graph of the build
    dep = {m: set() for m in modules}
    build_edges = set()
    for m in modules:
        for vis in ("public", "private"):
            for d in build[f"pdcg::{m}"][vis]:
                if d.startswith("pdcg::"):
                    dep[m].add(d[6:])
                    build_edges.add((m, d[6:], vis))
    for e in sorted(build_edges - edges):
        errors.append(f"diagram lacks the edge {e[0]} {'-->' if e[2] == 'public' else '-.->'} {e[1]}")
    for e in sorted(edges - build_edges):
        errors.append(f"diagram has the edge {e[0]} {'-->' if e[2] == 'public' else '-.->'} {e[1]}, the build does not")
    for m in modules:
        if m in closure(dep, m):
            errors.append(f"cycle through module {m}")

    # includes across modules
    used = set()
    for m in modules:
        reach = closure(dep, m)
        files = list((source / "include/pdcg" / m).rglob("*")) + list((source / "src" / m).rglob("*"))
        for f in files:
            if f.suffix not in (".hpp", ".cpp", ".h"):
                continue
            for inc in re.findall(r'#\s*include\s*[<"]pdcg/([a-z_]+)/', f.read_text(errors="replace")):
                if inc == m or inc in reach:
                    continue
                if (m, inc) in header_only:
                    used.add((m, inc))
                    continue
                errors.append(f"{f.relative_to(source)} includes pdcg/{inc}/ but {m} does not link "
                              f"{inc} (link it, or list `{m}` → `{inc}` under header-only uses)")
    for m, inc in sorted(header_only - used):
        errors.append(f"header-only use `{m}` → `{inc}` is listed but no file of {m} includes pdcg/{inc}/")

    for m in sorted(set(modules) - holds):
        errors.append(f"module {m} has no row in the 'what it holds' table")
    for m in sorted(holds - set(modules)):
        errors.append(f"'what it holds' lists {m}, which is not a module target")

    return errors, (len(modules), len(build_edges), len(header_only))


def self_test(graph_file, source, text):
    """Each mutation of a correct document must be reported."""
    errors, _ = check(graph_file, source, text)
    if errors:
        fail(["self-test needs a document that agrees with the build:"] + errors)
    rows = re.findall(r"^\| `pdcg::[a-z_]+` \| [^|]*pdcg::[a-z_]+[^|]*\|.*$", text, re.M)
    row = rows[0]
    cells = row.split("|")
    public = [x.strip() for x in cells[2].split(",")]
    dropped = "|".join(cells[:2] + [" " + ", ".join(public[:-1]) + " "] + cells[3:])
    added = "|".join(cells[:2] + [cells[2].rstrip() + ", pdcg::not_a_module "] + cells[3:])
    edge = re.search(r"^  [a-z_]+ --> [a-z_]+\n", text, re.M)
    mutations = [  # (what, document, expected message)
        ("a link removed from the table", text.replace(row, dropped, 1), "missing in the table"),
        ("a link the build does not have", text.replace(row, added, 1), "does not have"),
        ("a diagram edge removed", text.replace(edge.group(0), "", 1), "diagram lacks"),
        ("a PUBLIC diagram edge drawn PRIVATE",
         text.replace(edge.group(0), edge.group(0).replace("-->", "-.->"), 1), "diagram"),
        ("the block markers removed", text.replace("<!-- module-graph:begin -->", "", 1),
         "no <!-- module-graph:begin -->"),
    ]
    if re.search(r"^- `[a-z_]+` → `[a-z_]+`", text, re.M):
        mutations.append(("a header-only use removed",
                          re.sub(r"^- `([a-z_]+)` → `([a-z_]+)`", r"- \1 to \2", text, count=1,
                                 flags=re.M), "header-only uses"))
    bad = []
    for what, mutated, expect in mutations:
        if mutated == text:
            bad.append(f"self-test: the mutation '{what}' does not apply to the document")
            continue
        errs, _ = check(graph_file, source, mutated)
        if not any(expect in e for e in errs):
            bad.append(f"self-test: '{what}' was not reported (errors: {errs})")
    if bad:
        fail(bad)
    print(f"module graph self-test: all {len(mutations)} mutations of the document reported")


def main():
    graph_file, source = sys.argv[1], pathlib.Path(sys.argv[2])
    text = (source / "docs/architecture.md").read_text()
    if "--self-test" in sys.argv[3:]:
        self_test(graph_file, source, text)
        return
    errors, counts = check(graph_file, source, text)
    if errors:
        fail(errors)
    print(f"module graph: docs/architecture.md agrees with the build ({counts[0]} modules, "
          f"{counts[1]} module links, {counts[2]} header-only use(s))")


if __name__ == "__main__":
    main()

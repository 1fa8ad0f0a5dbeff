#!/usr/bin/env python3
"""Checks the library's includes against the stage table of docs/design.md ("Layers").

Usage: check_layers.py REPO          exits 1 and lists every violation
       check_layers.py REPO --self-test  also checks that planted violations are caught

Rules (docs/design.md): a file of a stage (its public headers, src/<stage>/) includes only its own
stage's headers and those of the stages its row names; public headers include only public
headers ("hemilight/..."); every public header and every src/ folder belongs to a row; the
umbrella header includes every module; the C ABI (capi/) never includes src/; nothing in the
library includes the fixtures.
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def parse_table(design_text):
    """Stage rows of the table whose header starts with '| stage |': {stage: (headers, allowed)}."""
    lines = design_text.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("| stage | public headers |"))
    rows = {}
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        stage, headers, allowed = cells[0], cells[1], cells[2]
        names = re.findall(r"`([a-z_0-9]+\.hpp)`", headers)
        if allowed in ("nothing", ""):
            allow = set()
        elif allowed == "every stage":
            allow = {"*"}
        else:
            allow = {a.strip() for a in allowed.split(",")}
        rows[stage] = (names, allow)
    return rows


def read_tree(repo):
    files = {}
    for top in ("include/hemilight", "src", "capi"):
        for root, _, names in os.walk(os.path.join(repo, top)):
            for n in names:
                if n.endswith((".hpp", ".cpp", ".inl", ".h", ".c")):
                    path = os.path.relpath(os.path.join(root, n), repo)
                    with open(os.path.join(repo, path), encoding="utf-8") as f:
                        files[path] = f.read()
    return files


def check(files, rows):
    problems = []
    header_stage = {}
    for stage, (headers, _) in rows.items():
        for h in headers:
            header_stage[h] = stage
    stages = set(rows)

    def allowed(src_stage, dst_stage):
        allow = rows[src_stage][1]
        return dst_stage == src_stage or "*" in allow or dst_stage in allow

    for path in sorted(files):
        parts = path.split("/")
        if parts[0] == "include":
            if parts[-1] not in header_stage:
                problems.append(f"{path}: a public header that no stage row of docs/design.md names")
                continue
            stage = header_stage[parts[-1]]
        elif parts[0] == "src":
            stage = parts[1] if len(parts) > 2 else None
            if stage not in stages:
                problems.append(f"{path}: src/ holds a file outside the stage folders of docs/design.md")
                continue
        else:
            stage = "capi"
        for inc in INCLUDE.findall(files[path]):
            if inc.startswith("hemilight/"):
                name = inc[len("hemilight/"):]
                if name not in header_stage:
                    problems.append(f"{path}: includes {inc}, which is no stage's public header (fixtures stay outside the library)")
                elif stage != "capi" and not allowed(stage, header_stage[name]):
                    problems.append(f"{path}: stage {stage} includes {inc} of stage {header_stage[name]}, not in its row")
                continue
            if inc == "hemilight.h" and stage == "capi":
                continue
            if parts[0] == "include":
                problems.append(f"{path}: a public header includes \"{inc}\" (public headers include public headers only)")
                continue
            target = os.path.normpath(os.path.join(os.path.dirname(path), inc))
            tparts = target.split("/")
            if stage == "capi":
                if tparts[0] != "capi":
                    problems.append(f"{path}: the C ABI includes \"{inc}\" outside capi/ (it uses the C++ API only)")
                continue
            if tparts[0] != "src" or len(tparts) < 3 or tparts[1] not in stages:
                problems.append(f"{path}: includes \"{inc}\", outside the stage folders")
            elif not allowed(stage, tparts[1]):
                problems.append(f"{path}: stage {stage} includes \"{inc}\" of stage {tparts[1]}, not in its row")
    umbrella = [s for s, (h, a) in rows.items() if "*" in a]
    for s in umbrella:
        for h in rows[s][0]:
            text = files.get(f"include/hemilight/{h}", "")
            have = set(INCLUDE.findall(text))
            for other, name in header_stage.items():
                if name != s and f"hemilight/{other}" not in have:
                    problems.append(f"include/hemilight/{h}: the umbrella header misses hemilight/{other}")
    return problems


def self_test(files, rows):
    """Plants one violation of each rule and checks that each is reported."""
    plants = [
        ("include/hemilight/scene.hpp", '#include "hemilight/bake.hpp"\n', "stage scene includes hemilight/bake.hpp"),
        ("src/cache/validation.cpp", '#include "../bake/checks.hpp"\n', "stage cache includes \"../bake/checks.hpp\""),
        ("capi/capi_options.cpp", '#include "../src/core/table_cache.hpp"\n', "the C ABI includes"),
        ("include/hemilight/raster.hpp", '#include "../../src/raster/internal.hpp"\n', "a public header includes"),
        ("src/bake/checks.cpp", '#include "hemilight/reference_scenes.hpp"\n', "no stage's public header"),
    ]
    failures = []
    for path, line, expect in plants:
        planted = dict(files)
        planted[path] = line + planted[path]
        found = [p for p in check(planted, rows) if p.startswith(path) and expect in p]
        if not found:
            failures.append(f"self-test: planting {line.strip()} in {path} was not reported")
    planted = dict(files)
    planted["src/extra.cpp"] = ""
    if not any(p.startswith("src/extra.cpp") for p in check(planted, rows)):
        failures.append("self-test: a file outside the stage folders was not reported")
    return failures


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    repo = sys.argv[1]
    with open(os.path.join(repo, "docs/design.md"), encoding="utf-8") as f:
        rows = parse_table(f.read())
    files = read_tree(repo)
    problems = check(files, rows)
    if "--self-test" in sys.argv[2:]:
        problems += self_test(files, rows)
    for p in problems:
        print(p)
    if problems:
        return 1
    print(f"layers: {len(files)} files follow the {len(rows)} stage rows of docs/design.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())

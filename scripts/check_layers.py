#!/usr/bin/env python3
"""Fails when a file includes a higher layer, or another layer's private header
(README "How it is built").

Layers, from the bottom: core, kinematics, measurement, identification, design, io, paper, study,
report; src/cli and src/python (the program and the Python module) may include any public header.
A file in include/lrcal/<layer>/ or src/<layer>/ may include "lrcal/<lower or same layer>/..."
and its own layer's private headers "<layer>/..." under src/. Another layer's private header is
allowed only where PRIVATE_ALLOWED lists it, with the reason: the list is the known debt, and a
new entry is a decision to write down, not an accident.
Prints every violation as file:line and exits 1 if there is one.
"""
import pathlib
import re
import sys

LAYERS = ["core", "kinematics", "measurement", "identification", "design", "io", "paper", "study",
          "report", "cli", "python"]
RANK = {name: i for i, name in enumerate(LAYERS)}
INCLUDE = re.compile(r'^\s*#\s*include\s+"(lrcal/)?([a-z_]+)/([^"]+)"')

# (including layer, private header) → why it is allowed.
PRIVATE_ALLOWED = {
    ("measurement", "core/cpu_dispatch.h"): "the batch kernel's run-time ISA dispatch",
    ("measurement", "core/lanes.h"): "the batch kernel's vectors, shared with the normal matrix",
    ("measurement", "core/dense_kernel_variants.h"):
        "the batch kernel weights J's rows with the variant it was handed (ScaleRows)",
    ("study", "identification/levenberg_marquardt.h"):
        "the trial pipeline holds the solver's workspace (issue 25 item 4: a public trial API)",
    ("study", "io/yaml_util.h"): "the study reader uses the robot files' YAML helpers",
}


def layer_of(path, root):
    parts = path.relative_to(root).parts
    if parts[0] == "include" and len(parts) > 2 and parts[1] == "lrcal":
        return parts[2]
    if parts[0] == "src" and len(parts) > 1:
        return parts[1]
    return None


def main():
    root = pathlib.Path(__file__).resolve().parent.parent
    files = [p for d in ("include", "src") for p in (root / d).rglob("*")
             if p.suffix in (".h", ".cc", ".in")]
    violations = []
    used = set()
    for path in sorted(files):
        layer = layer_of(path, root)
        if layer not in RANK:
            violations.append(f"{path.relative_to(root)}: not in a layer folder ({', '.join(LAYERS)})")
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or m.group(2) not in RANK:
                continue
            public, included = m.group(1) is not None, m.group(2)
            where = f"{path.relative_to(root)}:{number}"
            if RANK[included] > RANK[layer]:
                violations.append(f"{where}: layer '{layer}' includes the higher layer "
                                  f"'{included}': {line.strip()}")
            elif not public and included != layer and \
                    (layer, f"{included}/{m.group(3)}") in PRIVATE_ALLOWED:
                used.add((layer, f"{included}/{m.group(3)}"))
            elif not public and included != layer:
                violations.append(f"{where}: layer '{layer}' includes the private header "
                                  f"'{included}/{m.group(3)}' of layer '{included}' (use a "
                                  f"public header, or list it in PRIVATE_ALLOWED with the "
                                  f"reason): {line.strip()}")
    for stale in sorted(set(PRIVATE_ALLOWED) - used):
        violations.append(f"scripts/check_layers.py: PRIVATE_ALLOWED lists {stale}, which no file "
                          f"includes any more: remove it")
    for v in violations:
        print(v)
    print(f"check_layers: {len(files)} files, {len(violations)} violations")
    return 1 if violations else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Fails when a file includes a higher layer (README "How it is built").

Layers, from the bottom: core, kinematics, measurement, identification, design, io, paper, study,
report; src/cli and src/python (the program and the Python module) may include any. A file in include/lrcal/<layer>/ or src/<layer>/ may include
"lrcal/<lower or same layer>/..." and private headers "<lower or same layer>/..." under src/.
Prints every violation as file:line and exits 1 if there is one.
"""
import pathlib
import re
import sys

LAYERS = ["core", "kinematics", "measurement", "identification", "design", "io", "paper", "study",
          "report", "cli", "python"]
RANK = {name: i for i, name in enumerate(LAYERS)}
INCLUDE = re.compile(r'^\s*#\s*include\s+"(?:lrcal/)?([a-z_]+)/[^"]+"')


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
    for path in sorted(files):
        layer = layer_of(path, root)
        if layer not in RANK:
            violations.append(f"{path.relative_to(root)}: not in a layer folder ({', '.join(LAYERS)})")
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or m.group(1) not in RANK:
                continue
            if RANK[m.group(1)] > RANK[layer]:
                violations.append(f"{path.relative_to(root)}:{number}: layer '{layer}' includes "
                                  f"the higher layer '{m.group(1)}': {line.strip()}")
    for v in violations:
        print(v)
    print(f"check_layers: {len(files)} files, {len(violations)} violations")
    return 1 if violations else 0


if __name__ == "__main__":
    sys.exit(main())

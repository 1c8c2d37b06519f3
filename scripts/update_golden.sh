#!/usr/bin/env bash
# Regenerates tests/golden/quick/ from the current code (see tests/golden/README.md). Only for
# changes that are meant to alter the tables: say so in the commit message.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build -j2 --target lrcal_cli
out=$(mktemp -d)
./build/lrcal run studies/quick.yaml --out "$out" --threads 2 --quiet
rm -f tests/golden/quick/*
cp "$out"/tables/* tests/golden/quick/
rm -rf "$out"
git status --short tests/golden/quick

#!/usr/bin/env bash
# lrcal set-up on Debian 12: install what is missing (apt-get), build, then run the main job or
# the whole test suite.
#   bash scripts/setup.sh run    # build and run the main job
#   bash scripts/setup.sh test   # build and run every test (what .ci/run does first)
#   bash scripts/setup.sh build  # build only
# LRCAL_WERROR=ON (CI) turns warnings into errors; LRCAL_UNITY=ON (CI) compiles the library, the
# CLI and the test binaries as unity builds (faster from scratch, slower to rebuild after an edit;
# the results have the same bits: no fused multiply-adds, CMakeLists.txt), LRCAL_UNITY_TESTS=ON
# the test binaries only.
set -euo pipefail
action="${1:-run}"
case "$action" in run|test|build) ;; *) echo "usage: bash scripts/setup.sh run|test|build" >&2; exit 2;; esac
cd "$(dirname "$0")/.."

packages=(g++ cmake make git pkg-config
  libeigen3-dev libceres-dev libyaml-cpp-dev libsqlite3-dev librandom123-dev nlohmann-json3-dev
  libboost-program-options-dev libgtest-dev libbenchmark-dev libopenmpi-dev openmpi-bin
  python3 python3-pandas python3-numpy python3-matplotlib chromium
  pybind11-dev python3-dev python3-pytest liburdfdom-dev libtinyxml-dev)
bash scripts/install_packages.sh "${packages[@]}"

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DLRCAL_WERROR="${LRCAL_WERROR:-OFF}" \
  -DLRCAL_UNITY="${LRCAL_UNITY:-OFF}" -DLRCAL_UNITY_TESTS="${LRCAL_UNITY_TESTS:-${LRCAL_UNITY:-OFF}}"
cmake --build build -j2

case "$action" in
  run) ./build/lrcal run studies/paper.yaml ;;
  test)
    ctest --test-dir build -j2 --output-on-failure
    # The installed package: install to a temporary prefix, build the consumer against it, run
    # it and the installed program (which must find its data there, not in the sources).
    prefix=$(mktemp -d)
    trap 'rm -rf "$prefix"' EXIT
    cmake --install build --prefix "$prefix" > /dev/null
    cmake -S examples/consumer -B "$prefix/consumer-build" -DCMAKE_PREFIX_PATH="$prefix" > /dev/null
    cmake --build "$prefix/consumer-build" -j2 > /dev/null
    "$prefix/consumer-build/lrcal_consumer" "$prefix/share/lrcal/studies/robots/paper.yaml"
    (cd "$prefix" && "$prefix/bin/lrcal" run quick --out "$prefix/quick" --quiet > /dev/null)
    cmp "$prefix/quick/tables/summary.md" tests/golden/quick/summary.md
    # The installed program draws the report with the installed package (python3 -m lrcal.report).
    (cd "$prefix" && env -u PYTHONPATH "$prefix/bin/lrcal" report "$prefix/quick" > /dev/null)
    test -s "$prefix/quick/report/report.html"
    # The installed Python module: the documented import, the tests of the calibration API and of
    # the docs against the installed package (ctest's 'python' test ran the whole suite on the
    # build tree; the installed report was drawn above), and the example.
    site=$(find "$prefix" -path '*/lrcal/_lrcal*.so' -printf '%h\n' | head -1)
    [ -n "$site" ] || { echo "setup: the Python module was not installed" >&2; exit 1; }
    export PYTHONPATH="${site%/lrcal}" LRCAL_CLI="$prefix/bin/lrcal" PYTHONDONTWRITEBYTECODE=1
    (cd "$prefix" && /usr/bin/python3 -c "import lrcal; print('setup: lrcal', lrcal.__version__, 'from', lrcal.__file__)")
    /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python/test_calibration.py \
      tests/python/test_docs.py
    (root=$PWD; cd "$prefix" && /usr/bin/python3 "$root/examples/python/calibrate.py" "$prefix/example" > /dev/null)
    echo "setup: installed package, consumer, Python module and installed lrcal checked" ;;
  build) ;;
esac

#!/usr/bin/env bash
# Builds lrcal's fuzz targets with clang's libFuzzer under AddressSanitizer and
# UndefinedBehaviorSanitizer, and runs each for a bounded time on its checked-in corpus
# (tests/fuzz/corpus/<target>). Any crash, sanitizer report, or reader answer other than a clear
# InputError is a finding: the script fails and leaves the input in build-fuzz/findings/.
#   bash scripts/fuzz.sh [seconds per target, default 25]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-${LRCAL_FUZZ_SECONDS:-25}}"
bash scripts/install_packages.sh clang libclang-rt-14-dev libyaml-cpp-dev libeigen3-dev liburdfdom-dev libtinyxml-dev \
  nlohmann-json3-dev librandom123-dev libboost-dev
out=build-fuzz
mkdir -p "$out/obj" "$out/findings"
flags=(-std=c++17 -O1 -gline-tables-only -fno-omit-frame-pointer -fsanitize=address,undefined
       -fno-sanitize-recover=undefined -Iinclude -Isrc -I/usr/include/eigen3
       "-DLRCAL_SOURCE_DIR=\"$PWD\"")
# The readers and what they need (no Ceres, no SQLite: the fuzzers build in about a minute).
sources=(core/strings core/json core/hash core/data_dir core/random core/settings kinematics/robot_model
         kinematics/rigid_transform kinematics/dh_conversion kinematics/configuration_set
         measurement/plane measurement/parameter_set measurement/measurement_set
         measurement/targeted_configurations measurement/environment_measurement
         kinematics/gravity_torque
         measurement/noise_model measurement/measurement_kind measurement/averaging core/text_table
         identification/identification_options identification/prior design/design_options io/csv
         io/robot_file io/urdf io/yaml_util study/study study/stop_when study/sensitivity
         study/truth_options io/socket_data io/scanner_data io/robot_data
         measurement/scanner_measurement measurement/socket_measurement
         measurement/point_measurement measurement/estimated_planes measurement/constraint_kinds
         kinematics/joint_constraints kinematics/chain measurement/batch_point core/cpu_dispatch)
objects=()
build_object() {  # src/<name>.cc → build-fuzz/obj/<name>.o
  local name=$1 obj="$out/obj/${1//\//_}.o"
  clang++ "${flags[@]}" -fsanitize=fuzzer-no-link -c "src/$name.cc" -o "$obj"
}
for s in "${sources[@]}"; do
  build_object "$s" &
  objects+=("$out/obj/${s//\//_}.o")
  (( $(jobs -r | wc -l) >= 2 )) && wait -n
done
wait
targets=(expression csv robot_file study_file urdf)
for t in "${targets[@]}"; do
  clang++ "${flags[@]}" -fsanitize=fuzzer "tests/fuzz/${t}_fuzzer.cc" "${objects[@]}" \
    -lyaml-cpp -lurdfdom_model -ltinyxml -o "$out/${t}_fuzzer"
done
echo "fuzz: built ${#targets[@]} targets; running each for ${seconds} s"
status=0
export LRCAL_DATA_DIR="$PWD"  # the studies name the shipped robot "paper"
# urdfdom's own leaks on some malformed files are not lrcal's (tests/sanitizers/lsan_urdfdom.supp).
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan_urdfdom.supp"
run_target() {
  local t=$1 work="$out/corpus/$1"
  mkdir -p "$work"
  "$out/${t}_fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$out/findings/${t}-" -print_final_stats=1 "$work" "tests/fuzz/corpus/$t" \
    > "$out/${t}.log" 2>&1
}
pids=()
for t in "${targets[@]}"; do
  run_target "$t" &
  pids+=($!)
  if (( ${#pids[@]} == 2 )); then
    for p in "${pids[@]}"; do wait "$p" || status=1; done
    pids=()
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done
for t in "${targets[@]}"; do
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$out/${t}.log" | grep -o '[0-9]*$' || echo "?")
  echo "fuzz: $t: ${runs} inputs in ${seconds} s"
done
if ((status)); then
  echo "fuzz: FINDINGS (inputs in $out/findings/):" >&2
  ls "$out/findings" >&2
  for t in "${targets[@]}"; do grep -h -A12 "ERROR\|deadly signal\|runtime error" "$out/${t}.log" >&2 || true; done
  exit 1
fi
echo "fuzz: no findings"
